#include "ccsrm/sim/parameters.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/sim/declared_values.h"
#include "ccsrm/sim/effects.h"
#include "effects/effect.h"
#include "effects/effects_yaml.h"

namespace ccsrm::sim {
namespace {

// The model's names, then how effect parameters are named: listing all of
// them would bury the line.
std::string KnownNames() {
  std::string names;
  for (const ParameterInfo& p : Parameters()) names += (names.empty() ? "" : ", ") + p.name;
  std::string effects;
  for (const EffectInfo& e : Effects()) effects += (effects.empty() ? "" : ", ") + e.name;
  return names + "; effects' parameters as <effect>.<parameter>, effects: " + effects +
         "; declared values as declared.<value> (ccsrm generate --list-effects)";
}

// For "effect.x": that effect's parameters (on `arm`, when known), when the
// effect exists.
std::string KnownNamesFor(const std::string& name, const ArmSize* arm) {
  const std::size_t dot = name.find('.');
  if (dot != std::string::npos) {
    const internal::EffectDefinition* d = internal::FindEffectDefinition(name.substr(0, dot));
    if (d != nullptr) return internal::DescribeParameters(*d, arm, true);
  }
  return KnownNames();
}

std::string FormatValue(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

// The entry of `name` (a model parameter, or an effect's on `arm` when
// given, on any arm otherwise), or null with *beyond saying why when it is
// an indexed effect parameter the arm does not have.
const ParameterInfo* LookUp(const std::string& name, const ArmSize* arm,
                            std::string* beyond = nullptr) {
  for (const ParameterInfo& p : Parameters()) {
    if (p.name == name) return &p;
  }
  if (name.rfind("declared.", 0) == 0) return internal::FindDeclaredParameter(name, arm, beyond);
  return internal::FindEffectParameter(name, arm, beyond);
}

[[noreturn]] void ThrowUnknown(const std::string& name, const std::string& where,
                               const ArmSize* arm, const std::string& beyond) {
  ThrowInputError(where, "",
                  "unknown parameter '" + name + "' (" +
                      (beyond.empty() ? "known" : beyond + ": known") + ": " +
                      KnownNamesFor(name, arm) + ")");
}

}  // namespace

bool ArmParameters::IsValid(std::string* error) const {
  for (const ParameterInfo& p : Parameters()) {
    const std::string problem = ParameterValueProblem(p, this->*p.field);
    if (!problem.empty()) {
      *error = problem;
      return false;
    }
  }
  for (const std::string& effect : effects_on) {
    bool known = false;
    for (const EffectInfo& e : Effects()) known = known || e.name == effect;
    if (!known) {
      *error = "unknown effect '" + effect + "'";
      return false;
    }
  }
  for (const auto& [name, value] : effect_values) {
    std::string beyond;
    const ParameterInfo* info = LookUp(name, &arm, &beyond);
    if (info == nullptr || !info->is_effect()) {
      *error =
          "unknown effect parameter '" + name + "'" + (beyond.empty() ? "" : " (" + beyond + ")");
      return false;
    }
    const std::string problem = ParameterValueProblem(*info, value);
    if (!problem.empty()) {
      *error = problem;
      return false;
    }
  }
  for (const auto& [name, value] : declared_deltas) {
    std::string beyond;
    const ParameterInfo* info = LookUp(name, &arm, &beyond);
    if (info == nullptr || !info->declared) {
      *error =
          "unknown declared value '" + name + "'" + (beyond.empty() ? "" : " (" + beyond + ")");
      return false;
    }
    const std::string problem = ParameterValueProblem(*info, value);
    if (!problem.empty()) {
      *error = problem;
      return false;
    }
  }
  return true;
}

bool ArmParameters::EffectOn(const std::string& effect) const {
  return effects_on.count(effect) != 0;
}

void ArmParameters::EnableEffect(const std::string& effect, const std::string& where) {
  FindEffect(effect, where);
  effects_on.insert(effect);
}

void ArmParameters::DisableEffect(const std::string& effect) {
  effects_on.erase(effect);
  for (auto it = effect_values.begin(); it != effect_values.end();) {
    if (it->first.compare(0, effect.size() + 1, effect + ".") == 0) {
      it = effect_values.erase(it);
    } else {
      ++it;
    }
  }
}

std::vector<std::string> ArmParameters::EnabledEffects() const {
  std::vector<std::string> names;
  for (const EffectInfo& e : Effects()) {
    if (EffectOn(e.name)) names.push_back(e.name);
  }
  return names;
}

const std::vector<ParameterInfo>& Parameters() {
  // Bounds: friction coefficients up to 2 (steel on polymer is 0.1-0.5;
  // 2 leaves room for a badly worn hole); damping up to 10 N m s/rad (200x
  // the assumed 0.05); pre-tensions from 1 N (a cable barely held straight)
  // to what a 1.3 mm wire rope carries well below its breaking load.
  using P = ArmParameters;
  static const std::vector<ParameterInfo> parameters = {
      {"mu", "driving_cables.friction_kinetic", "1", 0.0, 2.0,
       "kinetic friction coefficient of the driving cables (mu)", &P::mu},
      {"mu_s", "driving_cables.friction_static", "1", 0.0, 2.0,
       "static friction coefficient of the driving cables (mu')", &P::mu_s},
      {"mu_c", "connecting_cables.friction_kinetic", "1", 0.0, 2.0,
       "kinetic friction coefficient of the connecting cables (mu_c)", &P::mu_c},
      {"mu_c_s", "connecting_cables.friction_static", "1", 0.0, 2.0,
       "static friction coefficient of the connecting cables (mu'_c)", &P::mu_c_s},
      {"beta", "driving_cables.rayleigh_beta_s", "s", 0.0, 0.1,
       "Rayleigh damping factor of the driving cables", &P::beta},
      {"c_sc", "connecting_cables.damping_small_nmsprad", "N m s/rad", 0.0, 10.0,
       "damping of the small-S connecting mechanisms", &P::c_sc},
      {"c_lc", "connecting_cables.damping_large_nmsprad", "N m s/rad", 0.0, 10.0,
       "damping of the large-S connecting mechanisms", &P::c_lc},
      {"T_p", "connecting_cables.pretension_n", "N", 1.0, 500.0,
       "pre-tension of the connecting cables", &P::T_p},
      {"T_d0", "driving_cables.pretension_n", "N", 1.0, 1000.0, "pre-tension of the driving cables",
       &P::T_d0},
      // 0 is the paper's law (mu' drops to mu at once); 0.1 m/s is well
      // above any slip speed of the arm (inputs move at ~1 mm/s).
      {"v_s", "driving_cables.stribeck_velocity_mps", "m/s", 0.0, 0.1,
       "Stribeck velocity of the holes: the static coefficient falls to the kinetic one over it",
       &P::v_s, 0.0},
      // Absent: the paper's v_d - v_s (eq. 45's tolerances, 2e-4 - 1e-4 m/s).
      {"v_c_s", "connecting_cables.stribeck_velocity_mps", "m/s", 0.0, 0.1,
       "Stribeck velocity of the large-S conduits: the static coefficient falls to the kinetic "
       "one over it",
       &P::v_c_s, 1e-4},
      // 0 is the memoryless law; 1 s is far slower than any frictional lag
      // reported for dry or lubricated contacts (milliseconds to tens of ms).
      {"tau_f", "driving_cables.friction_memory_s", "s", 0.0, 1.0,
       "frictional memory of the holes: time for the coefficient to follow the slip speed",
       &P::tau_f, 0.0},
      {"tau_c_f", "connecting_cables.friction_memory_s", "s", 0.0, 1.0,
       "frictional memory of the large-S conduits: time for the coefficient to follow the slip "
       "speed",
       &P::tau_c_f, 0.0},
      // Presliding (Dahl) displacements of metal contacts are reported from
      // about 1 to 50 um (Dupont, Hayward, Armstrong and Altpeter, IEEE TAC
      // 47(5), 2002; Armstrong-Helouvry et al., Automatica 30(7), 1994); the
      // bounds leave a decade either side. It must be positive: the
      // presliding stiffness is the capstan force over it.
      {"xi_f", "driving_cables.presliding_displacement_m", "m", 1e-7, 1e-4,
       "presliding displacement of the holes: elastic travel of a node before its friction "
       "reaches the capstan force (hole_friction: presliding)",
       &P::xi_f, 1e-5},
      // The conduit is a wire rope in a steel sleeve: the same contacts and
      // the same literature range as the holes.
      {"xi_c", "connecting_cables.presliding_displacement_m", "m", 1e-7, 1e-4,
       "presliding displacement of the large-S conduits: elastic travel of a couple before its "
       "friction reaches the limit (conduit_friction: presliding)",
       &P::xi_c, 1e-5},
      // A scale on the rod's nominal E I / l: a superelastic rod's modulus
      // is known to tens of per cent (austenite 40-90 GPa) and the lumped
      // joints stand for a continuous rod, so two decades either side.
      {"k_b", "backbone.stiffness_scale", "1", 0.01, 100.0,
       "scale on the elastic backbone's bending stiffness E I / l per joint", &P::k_b, 1.0},
      {"c_b", "backbone.damping_nmsprad", "N m s/rad", 0.0, 10.0,
       "damping of each elastic backbone joint and axis", &P::c_b, 0.0},
  };
  return parameters;
}

std::vector<ParameterInfo> AllParameters(const ArmSize& arm) {
  std::vector<ParameterInfo> list = Parameters();
  for (const internal::EffectDefinition& d : internal::EffectDefinitions()) {
    const std::vector<ParameterInfo> on_arm = internal::ParametersOnArm(d, arm);
    list.insert(list.end(), on_arm.begin(), on_arm.end());
  }
  return list;
}

const ParameterInfo& FindParameter(const std::string& name, const std::string& where,
                                   const ArmSize& arm) {
  std::string beyond;
  const ParameterInfo* info = LookUp(name, &arm, &beyond);
  if (info == nullptr) ThrowUnknown(name, where, &arm, beyond);
  return *info;
}

const ParameterInfo& FindParameter(const std::string& name, const std::string& where) {
  const ParameterInfo* info = LookUp(name, nullptr);
  if (info == nullptr) ThrowUnknown(name, where, nullptr, "");
  return *info;
}

std::string ParameterValueProblem(const ParameterInfo& info, double value) {
  if (std::isfinite(value) && value >= info.lower && value <= info.upper) return "";
  return "parameter '" + info.name + "' = " + FormatValue(value) + " is outside [" +
         FormatValue(info.lower) + ", " + FormatValue(info.upper) + "] " + info.units;
}

double GetParameter(const ArmParameters& parameters, const std::string& name) {
  const ParameterInfo& info = FindParameter(name, "GetParameter", parameters.arm);
  if (info.field != nullptr) return parameters.*info.field;
  if (info.declared) {
    const auto d = parameters.declared_deltas.find(name);
    return d != parameters.declared_deltas.end() ? d->second : 0.0;
  }
  const auto it = parameters.effect_values.find(name);
  return it != parameters.effect_values.end() ? it->second : info.absent_value;
}

void SetParameter(const std::string& name, double value, const std::string& where,
                  ArmParameters* parameters) {
  const ParameterInfo& info = FindParameter(name, where, parameters->arm);
  const std::string problem = ParameterValueProblem(info, value);
  if (!problem.empty()) ThrowInputError(where, "", problem);
  if (info.field != nullptr) {
    parameters->*info.field = value;
    return;
  }
  if (info.declared) {
    parameters->declared_deltas[name] = value;
    return;
  }
  parameters->effect_values[name] = value;
  parameters->effects_on.insert(info.effect);
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
  double value = 0.0;
  const std::string problem = ParseNumberText(value_text, &value);
  if (!problem.empty()) {
    ThrowInputError(where, "'" + text + "'", "value '" + value_text + "' " + problem);
  }
  return {name, value};
}

std::vector<std::pair<std::string, double>> ApplyParameterYaml(const std::string& yaml_text,
                                                               const std::string& file,
                                                               ArmParameters* parameters) {
  YAML::Node root = ParseYamlDocument(yaml_text, file);
  // A truth file (`ccsrm generate`) keeps the values under `parameters:`
  // beside its other records; a plain file is the mapping itself.
  std::string prefix;
  YAML::Node effects;
  if (root.IsMap() && root["parameters"]) {
    effects = root["effects"];
    root = root["parameters"];
    prefix = "parameters.";
  } else if (root.IsMap() && root["effects"] && root["effects"].IsMap()) {
    // A plain file may carry effects like a configuration does.
    effects = root["effects"];
  }
  if (!root.IsMap()) {
    ThrowInputError(file, "", "expected a mapping of parameter names to values (e.g. 'mu: 0.18')");
  }
  // Checked whole before anything is applied, so a bad file changes nothing.
  ArmParameters updated = *parameters;
  std::vector<std::pair<std::string, double>> applied;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (prefix.empty() && key == "effects" && effects) continue;  // below
    const std::string where =
        "line " + std::to_string(entry.first.Mark().line + 1) + ", key '" + prefix + key + "'";
    std::string beyond;
    const ParameterInfo* info = LookUp(key, &updated.arm, &beyond);
    if (info == nullptr) {
      ThrowInputError(file, where,
                      "unknown parameter (" + (beyond.empty() ? "known" : beyond + ": known") +
                          ": " + KnownNamesFor(key, &updated.arm) + ")");
    }
    const double value = ReadYamlNumber(entry.second, file, where);
    const std::string problem = ParameterValueProblem(*info, value);
    if (!problem.empty()) ThrowInputError(file, where, problem);
    SetParameter(key, value, file, &updated);
    applied.emplace_back(key, value);
  }
  if (effects) {
    const ArmParameters before = updated;
    internal::ApplyEffectsNode(effects, file, "effects.", &updated);
    for (const auto& [name, value] : updated.effect_values) {
      const auto it = before.effect_values.find(name);
      if (it == before.effect_values.end() || it->second != value)
        applied.emplace_back(name, value);
    }
  }
  *parameters = updated;
  return applied;
}

}  // namespace ccsrm::sim
