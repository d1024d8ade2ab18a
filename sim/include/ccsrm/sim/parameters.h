#pragma once
// The identifiable parameters of the arm (SPEC 6), apart from its model: a
// small value that each run takes, so that identification can change them
// between runs of one shared ArmModel without rebuilding anything.
//
// One table (Parameters()) gives every parameter its name, units, bounds and
// YAML key; configuration files, `--set`, `--params`, truth files and
// identification all check values against it with the same message.
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace ccsrm::sim {

// How many universal joints and driving cables an arm has: what sizes the
// effects' per-joint and per-cable parameter lists (mocap_offset has
// joint<k>_x_rad and joint<k>_y_rad for k = 1..joints). ArmConfig::size()
// gives an arm's.
struct ArmSize {
  int joints = 0;
  int cables = 0;
  // Segments: what sizes the per-segment declared values
  // (declared_values.h). Not compared: an arm's joints and cables decide
  // its effects' parameters, and files that record an arm's size
  // (prediction) give those two only.
  int segments = 0;
  bool operator==(const ArmSize& other) const {
    return joints == other.joints && cables == other.cables;
  }
  bool operator!=(const ArmSize& other) const { return !(*this == other); }
};

// Friction, damping and pre-tension. Zero-initialised: fill it from a
// configuration (Config::parameters) or set every field; Simulate checks it
// with IsValid. The field names are the SPEC 6 parameter names.
struct ArmParameters {
  double mu = 0.0;      // kinetic friction coefficient, driving cable on hole (mu) [1]
  double mu_s = 0.0;    // static friction coefficient, driving cable on hole (mu') [1]
  double mu_c = 0.0;    // kinetic friction coefficient, large-S conduit (mu_c) [1]
  double mu_c_s = 0.0;  // static friction coefficient, large-S conduit (mu'_c) [1]
  double beta = 0.0;    // Rayleigh damping factor of the driving cables [s]
  double c_sc = 0.0;    // damping of the small-S mechanisms [N m s/rad]
  double c_lc = 0.0;    // damping of the large-S mechanisms [N m s/rad]
  double T_p = 0.0;     // pre-tension of the connecting cables [N]
  double T_d0 = 0.0;    // pre-tension of the driving cables [N]
  double v_s = 0.0;     // Stribeck velocity of the holes: mu' falls to mu over it [m/s]
  // Stribeck velocity of the large-S conduits: mu'_c falls to mu_c over it [m/s]
  double v_c_s = 0.0;
  // Frictional memory: how long the holes' (tau_f) and the conduits'
  // (tau_c_f) friction takes to follow a change of slip speed between its
  // static and kinetic values [s]; 0 follows at once.
  double tau_f = 0.0;
  double tau_c_f = 0.0;
  // Presliding displacement of the holes: how far a hole node moves
  // elastically before its friction reaches the steady capstan force, under
  // solver.hole_friction: presliding (no effect otherwise) [m].
  double xi_f = 0.0;
  // Presliding displacement of the large-S conduits: how far a couple slides
  // elastically in its conduit before its friction reaches the limit, under
  // solver.conduit_friction: presliding (no effect otherwise) [m].
  double xi_c = 0.0;
  // Elastic backbone (BackboneGeometry): a scale on every backbone joint's
  // bending stiffness E I / l [1], and its damping per joint and axis
  // [N m s/rad]. No effect on an arm without a backbone.
  double k_b = 0.0;
  double c_b = 0.0;

  // Effects (ccsrm/sim/effects.h): the physics the paper's model lacks, each
  // off by default. An effect is on once enabled (EnableEffect, a
  // configuration's `effects:` section, or SetParameter on one of its
  // parameters); its parameters "<effect>.<parameter>" are read and written
  // by name with GetParameter / SetParameter like the fields above. A
  // parameter of an effect that is on but was never given has its default
  // (ParameterInfo::absent_value: the neutral value, e.g. 0 friction).
  bool EffectOn(const std::string& effect) const;
  // Throws InputError naming `where` for an effect that is not in Effects().
  void EnableEffect(const std::string& effect, const std::string& where = "EnableEffect");
  // Switches the effect off and forgets its parameter values.
  void DisableEffect(const std::string& effect);
  // The effects that are on, in the order of Effects().
  std::vector<std::string> EnabledEffects() const;
  bool AnyEffectOn() const { return !effects_on.empty(); }

  // Values of effect parameters given so far, by full name; a name absent
  // here reads as its default. Use the functions above and GetParameter /
  // SetParameter rather than these two maps.
  std::map<std::string, double> effect_values;
  std::set<std::string> effects_on;

  // Corrections of the configuration's declared values
  // (ccsrm/sim/declared_values.h), by full name ("declared.segment1.link_length"),
  // relative to the declared value; a name absent here is 0 (as declared).
  std::map<std::string, double> declared_deltas;

  // The arm these parameters are for (ParseConfig sets it from the arm). It
  // decides which per-joint and per-cable effect parameters exist, so that
  // every door that sets a parameter by name (SetParameter, a
  // configuration's `effects:`, `--set`, `--params`, `--effect`, truth
  // files) refuses a name the arm does not have. Zero joints and cables (a
  // hand-built ArmParameters): no per-joint or per-cable parameter exists.
  ArmSize arm;

  // False (with the table's message in *error) when a value is outside its
  // bounds or not finite, effect parameters included.
  bool IsValid(std::string* error) const;
};

struct ParameterInfo {
  std::string name;  // "mu", "T_d0", ...
  std::string
      config_key;      // its key in a configuration file, e.g. "driving_cables.friction_kinetic"
  std::string units;   // SI units of the value ("1" for a dimensionless one)
  double lower = 0.0;  // the bounds every door checks (config, --set, --params, identification)
  double upper = 0.0;
  std::string description;
  // The ArmParameters field of a model parameter; null for an effect
  // parameter (read and write those with GetParameter / SetParameter).
  double ArmParameters::*field = nullptr;
  // What a configuration file written before the parameter existed means
  // by leaving it out (the paper's law); NaN: the key is required.
  // For an effect parameter: its default while the effect is on.
  double absent_value = std::numeric_limits<double>::quiet_NaN();
  // Effect parameters only: the effect ("joint_friction"), the parameter's
  // name within it ("coulomb_nm") and the magnitude an air-table arm like
  // the paper's realistically has (what `ccsrm generate --effect NAME`
  // uses). Empty / NaN for a model parameter.
  std::string effect{};
  std::string short_name{};
  double realistic = std::numeric_limits<double>::quiet_NaN();
  bool is_effect() const { return !effect.empty(); }
  // A declared value's relative correction (declared_values.h): field null,
  // no effect, `realistic` set, absent_value 0.
  bool declared = false;
};

// The model's named parameters: SPEC 6's nine in its order (mu, mu_s, mu_c,
// mu_c_s, beta, c_sc, c_lc, T_p, T_d0), then v_s, v_c_s, tau_f, tau_c_f,
// xi_f, xi_c, k_b, c_b.
// Every entry has a field.
const std::vector<ParameterInfo>& Parameters();

// Every parameter an arm of `arm`'s size has: Parameters(), then the
// parameters of every effect of Effects() in its order, named
// "<effect>.<parameter>" (their `field` is null), an effect's per-joint and
// per-cable ones once per joint or cable of the arm. This is the list
// identification offers.
std::vector<ParameterInfo> AllParameters(const ArmSize& arm);

// The entry of `name` on an arm of `arm`'s size, a model or an effect
// parameter. Throws InputError("<where>: unknown parameter 'x' (known: mu,
// mu_s, ...)") for a name that is not one of AllParameters(arm); for a
// per-joint or per-cable name beyond the arm the message says so ("this arm
// has 9 joints: mocap_offset.joint<k>_x_rad, ..., k = 1..9").
const ParameterInfo& FindParameter(const std::string& name, const std::string& where,
                                   const ArmSize& arm);

// The same before the arm is known (a command line read before its
// experiments): a per-joint or per-cable name is taken for any index from
// 1, as on an arm that has it. Where the arm is known, use the form above.
const ParameterInfo& FindParameter(const std::string& name, const std::string& where);

// "" when `value` is finite and within the parameter's bounds, else the one
// message every door uses: "parameter 'beta' = 5 is outside [0, 0.1] s".
std::string ParameterValueProblem(const ParameterInfo& info, double value);

// Reads / writes a parameter by name, one of AllParameters(parameters.arm)
// (FindParameter's message otherwise). SetParameter checks the value against
// the bounds and throws InputError "<where>: <ParameterValueProblem>" when it
// is outside them or not finite (the parameters are then unchanged).
// SetParameter on an effect parameter switches that effect on; GetParameter
// of an effect parameter reads its value, or its default when it was never
// given (whether or not the effect is on).
double GetParameter(const ArmParameters& parameters, const std::string& name);
void SetParameter(const std::string& name, double value, const std::string& where,
                  ArmParameters* parameters);

// Parses "name=value" (e.g. "mu=0.18"). Throws InputError naming `where`
// (e.g. "--set") for a missing '=', an unknown name or a value that is not a
// number.
std::pair<std::string, double> ParseParameterAssignment(const std::string& text,
                                                        const std::string& where);

// Applies a YAML mapping of parameter names to numbers (e.g. "mu: 0.18\nT_d0:
// 80"), as in a `--params truth.yaml` file; `file` names it in errors. A truth
// file's `parameters:` section is read the same way, and its `effects:`
// section (a map from effect name to a map of its parameters, as in a
// configuration) switches those effects on with their values. Effect
// parameters may also be given by full name ("joint_friction.coulomb_nm:
// 0.01"), which switches the effect on too. Throws InputError
// "<file>: line N, key 'x': ..." for an unknown name, a value that is not a
// number or out of bounds, or text that is not a mapping. Returns the
// assignments in file order (effect parameters by full name).
std::vector<std::pair<std::string, double>> ApplyParameterYaml(const std::string& yaml_text,
                                                               const std::string& file,
                                                               ArmParameters* parameters);

}  // namespace ccsrm::sim
