// The list of effects, and what the simulator does with the ones that are on.
#include <utility>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "effect.h"

namespace ccsrm::sim {
namespace internal {

ParameterInfo EffectParameter(const std::string& short_name, const std::string& units, double lower,
                              double upper, double default_value, double realistic,
                              const std::string& description) {
  CCSRM_CHECK(lower <= default_value && default_value <= upper);
  CCSRM_CHECK(lower <= realistic && realistic <= upper);
  ParameterInfo p;
  p.short_name = short_name;
  p.units = units;
  p.lower = lower;
  p.upper = upper;
  p.absent_value = default_value;
  p.realistic = realistic;
  p.description = description;
  return p;
}

const std::vector<EffectDefinition>& EffectDefinitions() {
  static const std::vector<EffectDefinition> definitions = [] {
    // One line per effect: its order here is the order of Effects().
    std::vector<EffectDefinition> list = {
        JointFrictionEffect(),   TableTiltEffect(), ActuatorDelayEffect(), BacklashEffect(),
        PretensionCreepEffect(), AirDragEffect(),   MocapOffsetEffect(),
    };
    for (EffectDefinition& d : list) {
      for (ParameterInfo& p : d.parameters) {
        p.effect = d.name;
        p.name = d.name + "." + p.short_name;
        p.config_key = "effects." + p.name;
      }
    }
    return list;
  }();
  return definitions;
}

std::vector<std::unique_ptr<Effect>> MakeEffects(const ArmParameters& parameters) {
  std::vector<std::unique_ptr<Effect>> effects;
  if (!parameters.AnyEffectOn()) return effects;
  for (const EffectDefinition& d : EffectDefinitions()) {
    if (parameters.EffectOn(d.name)) effects.push_back(d.make(parameters));
  }
  return effects;
}

std::unique_ptr<CableInputs> RealisedInputs(const ArmModel& model, const ArmParameters& parameters,
                                            const CableInputs& commanded, double duration_s) {
  std::unique_ptr<CableInputs> realised;
  for (const std::unique_ptr<Effect>& effect : MakeEffects(parameters)) {
    std::unique_ptr<CableInputs> next =
        effect->RealisedInputs(model, realised ? *realised : commanded, duration_s);
    if (next) realised = std::move(next);
  }
  return realised;
}

}  // namespace internal

const std::vector<EffectInfo>& Effects() {
  static const std::vector<EffectInfo> effects = [] {
    std::vector<EffectInfo> list;
    for (const internal::EffectDefinition& d : internal::EffectDefinitions()) {
      EffectInfo info{d.name, d.description, d.measurement, d.fingerprint, {}};
      for (const ParameterInfo& p : d.parameters) info.parameters.push_back(p.name);
      list.push_back(info);
    }
    return list;
  }();
  return effects;
}

const EffectInfo& FindEffect(const std::string& name, const std::string& where) {
  std::string known;
  for (const EffectInfo& e : Effects()) {
    if (e.name == name) return e;
    known += (known.empty() ? "" : ", ") + e.name;
  }
  ThrowInputError(where, "", "unknown effect '" + name + "' (known: " + known + ")");
}

}  // namespace ccsrm::sim
