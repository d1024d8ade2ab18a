#pragma once
// The identifiable parameters of the arm by name (SPEC 6): the names used in
// YAML, on the command line (`--set name=value`), in truth files and in every
// JSON output, each mapped onto one field of sim::Config.
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/sim/config.h"

namespace ccsrm::sim {

struct ParameterInfo {
  std::string name;        // "mu", "T_d0", ...
  std::string config_key;  // the YAML key it sets, e.g. "driving_cables.friction_kinetic"
  std::string units;       // SI units of the value ("1" for a dimensionless one)
  double lower = 0.0;      // bounds accepted by SetParameter and by identification
  double upper = 0.0;
  std::string description;
};

// Every named parameter, in SPEC 6 order: mu, mu_s, mu_c, mu_c_s, beta, c_sc,
// c_lc, T_p, T_d0.
const std::vector<ParameterInfo>& Parameters();

// The entry of `name`. Throws InputError("<where>: unknown parameter 'x'
// (known: mu, mu_s, ...)") for a name that is not one of Parameters().
const ParameterInfo& FindParameter(const std::string& name, const std::string& where);

// Reads / writes the parameter's field of `config`. SetParameter checks the
// value against the bounds and throws InputError naming `where` and the
// parameter when it is outside them or not finite.
double GetParameter(const Config& config, const std::string& name);
void SetParameter(const std::string& name, double value, const std::string& where, Config* config);

// Parses "name=value" (e.g. "mu=0.18"). Throws InputError naming `where`
// (e.g. "--set") for a missing '=', an unknown name or a value that is not a
// number.
std::pair<std::string, double> ParseParameterAssignment(const std::string& text,
                                                        const std::string& where);

// Applies a YAML mapping of parameter names to numbers (e.g. "mu: 0.18\nT_d0:
// 80"), as in a `--params truth.yaml` file; `file` names it in errors.
// Throws InputError "<file>: line N, key 'x': ..." for an unknown name, a
// value that is not a number or out of bounds, or text that is not a mapping.
// Returns the assignments in file order.
std::vector<std::pair<std::string, double>> ApplyParameterYaml(const std::string& yaml_text,
                                                               const std::string& file,
                                                               Config* config);

}  // namespace ccsrm::sim
