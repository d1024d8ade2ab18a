// The list of effects, and what the simulator does with the ones that are on.
#include <cctype>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "effect.h"

namespace ccsrm::sim {
namespace internal {
namespace {

// Fills in what the registry owns: the effect, the full name and the key
// under a configuration's `effects:`.
void Complete(const std::string& effect, ParameterInfo* p) {
  p->effect = effect;
  p->name = effect + "." + p->short_name;
  p->config_key = "effects." + p->name;
}

int CountOf(const IndexedParameters& indexed, const ArmSize& arm) {
  switch (indexed.per) {
    case IndexedParameters::Per::kJoint:
      return arm.joints;
    case IndexedParameters::Per::kCable:
      return arm.cables;
    case IndexedParameters::Per::kSegment:
      return arm.segments;
  }
  return 0;
}

const char* UnitOf(const IndexedParameters& indexed) {
  switch (indexed.per) {
    case IndexedParameters::Per::kJoint:
      return "joint";
    case IndexedParameters::Per::kCable:
      return "driving cable";
    case IndexedParameters::Per::kSegment:
      return "segment";
  }
  return "";
}

// The index k of `short_name` in `pattern` ("joint12_x_rad" in
// "joint<k>_x_rad": 12), or 0 when it is not of that pattern. Indices are
// written as the registry writes them: decimal, no sign, no leading zero.
int IndexIn(const std::string& pattern, const std::string& short_name) {
  const std::size_t at = pattern.find("<k>");
  CCSRM_CHECK(at != std::string::npos);
  const std::string prefix = pattern.substr(0, at), suffix = pattern.substr(at + 3);
  if (short_name.size() <= prefix.size() + suffix.size() ||
      short_name.compare(0, prefix.size(), prefix) != 0 ||
      short_name.compare(short_name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return 0;
  }
  const std::string digits =
      short_name.substr(prefix.size(), short_name.size() - prefix.size() - suffix.size());
  if (digits.size() > 6 || digits[0] == '0') return 0;
  for (char c : digits) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return 0;
  }
  return std::stoi(digits);
}

// Member `member` of index k of `indexed` (full name `name`), made once and
// kept for the program's life: FindEffectParameter hands out pointers to it.
const ParameterInfo* Interned(const EffectDefinition& definition, const IndexedParameters& indexed,
                              int k, std::size_t member, const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<const ParameterInfo>> made;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = made.find(name);
  if (it == made.end()) {
    std::vector<ParameterInfo> entries = indexed.make(k);
    CCSRM_CHECK(entries.size() == indexed.patterns.size());
    ParameterInfo info = std::move(entries[member]);
    Complete(definition.name, &info);
    CCSRM_CHECK(info.name == name);
    it = made.emplace(name, std::make_unique<const ParameterInfo>(std::move(info))).first;
  }
  return it->second.get();
}

}  // namespace

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
        PretensionCreepEffect(), AirDragEffect(),   MocapOffsetEffect(),   JointMomentEffect(),
        SegmentPretensionEffect(),
    };
    for (EffectDefinition& d : list) {
      for (ParameterInfo& p : d.parameters) Complete(d.name, &p);
    }
    return list;
  }();
  return definitions;
}

const EffectDefinition* FindEffectDefinition(const std::string& name) {
  for (const EffectDefinition& d : EffectDefinitions()) {
    if (d.name == name) return &d;
  }
  return nullptr;
}

std::vector<ParameterInfo> ParametersOnArm(const EffectDefinition& definition, const ArmSize& arm) {
  std::vector<ParameterInfo> list = definition.parameters;
  for (const IndexedParameters& indexed : definition.indexed) {
    for (int k = 1; k <= CountOf(indexed, arm); ++k) {
      for (ParameterInfo& p : indexed.make(k)) {
        Complete(definition.name, &p);
        list.push_back(std::move(p));
      }
    }
  }
  return list;
}

const ParameterInfo* FindEffectParameter(const std::string& name, const ArmSize* arm,
                                         std::string* beyond) {
  const std::size_t dot = name.find('.');
  if (dot == std::string::npos) return nullptr;
  const EffectDefinition* definition = FindEffectDefinition(name.substr(0, dot));
  if (definition == nullptr) return nullptr;
  const std::string short_name = name.substr(dot + 1);
  for (const ParameterInfo& p : definition->parameters) {
    if (p.short_name == short_name) return &p;
  }
  for (const IndexedParameters& indexed : definition->indexed) {
    for (std::size_t m = 0; m < indexed.patterns.size(); ++m) {
      const int k = IndexIn(indexed.patterns[m], short_name);
      if (k == 0) continue;
      if (arm != nullptr && k > CountOf(indexed, *arm)) {
        if (beyond != nullptr) {
          const int count = CountOf(indexed, *arm);
          *beyond = "this arm has " + std::to_string(count) + " " + UnitOf(indexed) +
                    (count == 1 ? "" : "s");
        }
        return nullptr;
      }
      return Interned(*definition, indexed, k, m, name);
    }
  }
  return nullptr;
}

std::string DescribeParameters(const EffectDefinition& definition, const ArmSize* arm,
                               bool full_names) {
  const std::string prefix = full_names ? definition.name + "." : "";
  std::string list;
  for (const ParameterInfo& p : definition.parameters) {
    list += (list.empty() ? "" : ", ") + prefix + p.short_name;
  }
  for (const IndexedParameters& indexed : definition.indexed) {
    std::string patterns;
    for (const std::string& pattern : indexed.patterns) {
      patterns += (patterns.empty() ? "" : ", ") + prefix + pattern;
    }
    const std::string unit = UnitOf(indexed);
    std::string range;
    if (arm == nullptr) {
      range = "k = 1, 2, ..., one per " + unit + " of the arm";
    } else if (CountOf(indexed, *arm) == 0) {
      range = "none: the arm has no " + unit + "s";
    } else {
      range = "k = 1.." + std::to_string(CountOf(indexed, *arm)) + ", one per " + unit;
    }
    list += (list.empty() ? "" : ", ") + patterns + " (" + range + ")";
  }
  return list;
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
      list.push_back(EffectInfo{d.name, d.description, d.measurement, d.fingerprint, d.library});
    }
    return list;
  }();
  return effects;
}

std::vector<std::string> EffectParameterNames(const std::string& effect, const ArmSize& arm,
                                              const std::string& where) {
  FindEffect(effect, where);
  std::vector<std::string> names;
  for (const ParameterInfo& p :
       internal::ParametersOnArm(*internal::FindEffectDefinition(effect), arm)) {
    names.push_back(p.name);
  }
  return names;
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
