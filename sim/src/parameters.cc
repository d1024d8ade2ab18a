#include "ccsrm/sim/parameters.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ccsrm/common/error.h"

namespace ccsrm::sim {
namespace {

// The field a parameter stands for; one table so Get and Set cannot disagree.
double* Field(const std::string& name, Config* config) {
  DrivingCableConfig& d = config->arm.driving;
  ConnectingCableConfig& c = config->arm.connecting;
  if (name == "mu") return &d.friction_kinetic;
  if (name == "mu_s") return &d.friction_static;
  if (name == "mu_c") return &c.friction_kinetic;
  if (name == "mu_c_s") return &c.friction_static;
  if (name == "beta") return &d.rayleigh_beta_s;
  if (name == "c_sc") return &c.damping_small_nmsprad;
  if (name == "c_lc") return &c.damping_large_nmsprad;
  if (name == "T_p") return &c.pretension_n;
  if (name == "T_d0") return &d.pretension_n;
  return nullptr;
}

std::string KnownNames() {
  std::string names;
  for (const ParameterInfo& p : Parameters()) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

std::string FormatValue(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

// "" when value is finite and within the bounds, else what is wrong.
std::string BoundsProblem(const ParameterInfo& info, double value) {
  if (std::isfinite(value) && value >= info.lower && value <= info.upper) return "";
  return FormatValue(value) + " is outside [" + FormatValue(info.lower) + ", " +
         FormatValue(info.upper) + "] " + info.units;
}

}  // namespace

const std::vector<ParameterInfo>& Parameters() {
  // Bounds: friction coefficients as configuration validation accepts them;
  // the others span what a physical arm of this size can plausibly have.
  static const std::vector<ParameterInfo> parameters = {
      {"mu", "driving_cables.friction_kinetic", "1", 0.0, 2.0,
       "kinetic friction coefficient of the driving cables (mu)"},
      {"mu_s", "driving_cables.friction_static", "1", 0.0, 2.0,
       "static friction coefficient of the driving cables (mu')"},
      {"mu_c", "connecting_cables.friction_kinetic", "1", 0.0, 2.0,
       "kinetic friction coefficient of the connecting cables (mu_c)"},
      {"mu_c_s", "connecting_cables.friction_static", "1", 0.0, 2.0,
       "static friction coefficient of the connecting cables (mu'_c)"},
      {"beta", "driving_cables.rayleigh_beta_s", "s", 0.0, 0.1,
       "Rayleigh damping factor of the driving cables"},
      {"c_sc", "connecting_cables.damping_small_nmsprad", "N m s/rad", 0.0, 10.0,
       "damping of the small-S connecting mechanisms"},
      {"c_lc", "connecting_cables.damping_large_nmsprad", "N m s/rad", 0.0, 10.0,
       "damping of the large-S connecting mechanisms"},
      {"T_p", "connecting_cables.pretension_n", "N", 1.0, 500.0,
       "pre-tension of the connecting cables"},
      {"T_d0", "driving_cables.pretension_n", "N", 1.0, 1000.0,
       "pre-tension of the driving cables"},
  };
  return parameters;
}

const ParameterInfo& FindParameter(const std::string& name, const std::string& where) {
  for (const ParameterInfo& p : Parameters()) {
    if (p.name == name) return p;
  }
  ThrowInputError(where, "", "unknown parameter '" + name + "' (known: " + KnownNames() + ")");
}

double GetParameter(const Config& config, const std::string& name) {
  const double* field = Field(name, const_cast<Config*>(&config));
  if (field == nullptr) FindParameter(name, "GetParameter");  // throws with the known names
  return *field;
}

void SetParameter(const std::string& name, double value, const std::string& where, Config* config) {
  const ParameterInfo& info = FindParameter(name, where);
  const std::string problem = BoundsProblem(info, value);
  if (!problem.empty()) ThrowInputError(where, "parameter '" + name + "'", problem);
  *Field(name, config) = value;
}

std::pair<std::string, double> ParseParameterAssignment(const std::string& text,
                                                        const std::string& where) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0) {
    ThrowInputError(where, "'" + text + "'", "expected name=value, e.g. mu=0.18");
  }
  const std::string name = text.substr(0, equals);
  const std::string value_text = text.substr(equals + 1);
  FindParameter(name, where);
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(value_text.c_str(), &end);
  if (value_text.empty() || end != value_text.c_str() + value_text.size() || errno == ERANGE) {
    ThrowInputError(where, "'" + text + "'", "value '" + value_text + "' is not a number");
  }
  return {name, value};
}

std::vector<std::pair<std::string, double>> ApplyParameterYaml(const std::string& yaml_text,
                                                               const std::string& file,
                                                               Config* config) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    ThrowInputError(file, "line " + std::to_string(e.mark.line + 1), "not valid YAML: " + e.msg);
  }
  // A truth file (`ccsrm generate`) keeps the values under `parameters:`
  // beside its other records; a plain file is the mapping itself.
  std::string prefix;
  if (root.IsMap() && root["parameters"]) {
    root = root["parameters"];
    prefix = "parameters.";
  }
  if (!root.IsMap()) {
    ThrowInputError(file, "", "expected a mapping of parameter names to values (e.g. 'mu: 0.18')");
  }
  std::vector<std::pair<std::string, double>> applied;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    const std::string where =
        "line " + std::to_string(entry.first.Mark().line + 1) + ", key '" + prefix + key + "'";
    const ParameterInfo* info = nullptr;
    for (const ParameterInfo& p : Parameters()) {
      if (p.name == key) info = &p;
    }
    if (info == nullptr) {
      ThrowInputError(file, where, "unknown parameter (known: " + KnownNames() + ")");
    }
    double value = 0.0;
    try {
      if (!entry.second.IsScalar()) throw YAML::Exception(entry.second.Mark(), "not a scalar");
      value = entry.second.as<double>();
    } catch (const YAML::Exception&) {
      ThrowInputError(file, where, "expected a number");
    }
    const std::string problem = BoundsProblem(*info, value);
    if (!problem.empty()) ThrowInputError(file, where, problem);
    *Field(key, config) = value;
    applied.emplace_back(key, value);
  }
  return applied;
}

}  // namespace ccsrm::sim
