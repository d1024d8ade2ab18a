#include "ccsrm/sim/declared_values.h"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include "ccsrm/common/error.h"

namespace ccsrm::sim {
namespace {

// One declared value: its name after "declared." (segment ones after
// "segment<k>."), the configuration key it corrects, and the relative error
// a careful measurement may still have: the loop's score step.
struct DeclaredDefinition {
  const char* short_name;
  const char* config_key;  // "%d" for the segment's index in arm.segments
  double realistic;
  const char* description;
};

// Arm-wide. A vernier or a datasheet gives a gap and an offset to a few
// per cent; a cable's E·A (the datasheet's modulus, the cross-section of a
// stranded cable) to about 10 %.
const std::vector<DeclaredDefinition>& ArmWide() {
  static const std::vector<DeclaredDefinition> list = {
      {"joint_disk_gap", "arm.joint_disk_gap_m", 0.02, "the distance d between a joint's disks"},
      {"driving_cables.axial_stiffness", "driving_cables.youngs_modulus_pa", 0.1,
       "the driving cables' axial stiffness E·A (applied to E)"},
      {"driving_cables.input_offset", "driving_cables.input_offset_m", 0.02,
       "the input point's offset behind the ground-disk hole"},
      {"connecting_cables.axial_stiffness", "connecting_cables.youngs_modulus_pa", 0.1,
       "the connecting cables' axial stiffness E_c·A_c (applied to E_c)"},
  };
  return list;
}

// Per segment. Lengths and radii to about 2 %, a mass to about 5 %, an
// inertia (from CAD) to about 10 %.
const std::vector<DeclaredDefinition>& PerSegment() {
  static const std::vector<DeclaredDefinition> list = {
      {"hole_circle_radius", "arm.segments[%d].hole_circle_radius_m", 0.02,
       "the radius of the circle of the driving cables' holes"},
      {"link_length", "arm.segments[%d].link_length_m", 0.02, "the length of a link"},
      {"link_mass", "arm.segments[%d].link_mass_kg", 0.05, "the mass of a link"},
      {"link_inertia", "arm.segments[%d].link_inertia_kgm2", 0.1,
       "a link's three moments of inertia, together"},
      {"small_s_pulley_radius", "arm.segments[%d].small_s.pulley_radius_m", 0.02,
       "the pulley radius r_sc of the small-S mechanisms"},
      {"large_s_pulley_radius", "arm.segments[%d].large_s.pulley_radius_m", 0.02,
       "the pulley radius r_lc of the large-S mechanisms"},
      {"large_s_wrap_angle", "arm.segments[%d].large_s.wrap_angle_deg", 0.02,
       "the wrap angle Θ_lc of the large-S conduits"},
  };
  return list;
}

ParameterInfo Make(const DeclaredDefinition& d, const std::string& name,
                   const std::string& config_key) {
  ParameterInfo p;
  p.name = name;
  p.config_key = config_key;
  p.units = "1";
  // ±30 %: far beyond a measurement's error, short of an arm that is
  // another arm (a radius or a length of 0).
  p.lower = -0.3;
  p.upper = 0.3;
  p.description = std::string("relative error of the declared value of ") + d.description;
  p.absent_value = 0.0;
  p.realistic = d.realistic;
  p.declared = true;
  return p;
}

std::string SegmentKey(const char* pattern, int k) {
  char text[128];
  std::snprintf(text, sizeof(text), pattern, k - 1);
  return text;
}

// Kept for the program's life: FindDeclaredParameter hands out pointers.
const ParameterInfo* Interned(const ParameterInfo& info) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<const ParameterInfo>> made;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = made.find(info.name);
  if (it == made.end()) {
    it = made.emplace(info.name, std::make_unique<const ParameterInfo>(info)).first;
  }
  return it->second.get();
}

// "segment<k>.<member>" -> k and member, or false.
bool SplitSegment(const std::string& rest, int* k, std::string* member) {
  if (rest.rfind("segment", 0) != 0) return false;
  const std::size_t dot = rest.find('.');
  if (dot == std::string::npos || dot == 7) return false;
  const std::string digits = rest.substr(7, dot - 7);
  for (char c : digits) {
    if (c < '0' || c > '9') return false;
  }
  if (digits.size() > 4 || digits[0] == '0') return false;
  *k = std::stoi(digits);
  *member = rest.substr(dot + 1);
  return true;
}

double& Value(ArmConfig* arm, const std::string& name, Eigen::Vector3d** vector) {
  *vector = nullptr;
  const std::string rest = name.substr(std::string("declared.").size());
  if (rest == "joint_disk_gap") return arm->joint_disk_gap_m;
  if (rest == "driving_cables.axial_stiffness") return arm->driving.youngs_modulus_pa;
  if (rest == "driving_cables.input_offset") return arm->driving.input_offset_m;
  if (rest == "connecting_cables.axial_stiffness") return arm->connecting.youngs_modulus_pa;
  int k = 0;
  std::string member;
  if (SplitSegment(rest, &k, &member) && k <= static_cast<int>(arm->segments.size())) {
    SegmentConfig& s = arm->segments[static_cast<std::size_t>(k - 1)];
    if (member == "hole_circle_radius") return s.hole_circle_radius_m;
    if (member == "link_length") return s.link_length_m;
    if (member == "link_mass") return s.link_mass_kg;
    if (member == "link_inertia") {
      *vector = &s.link_inertia_kgm2;
      return s.link_inertia_kgm2[0];
    }
    if (member == "small_s_pulley_radius") return s.small_s.pulley_radius_m;
    if (member == "large_s_pulley_radius") return s.large_s.pulley_radius_m;
    if (member == "large_s_wrap_angle") return s.large_s.wrap_angle_rad;
  }
  ThrowInputError("declared values", "", "'" + name + "' is not a declared value of this arm");
}

}  // namespace

std::vector<ParameterInfo> DeclaredValueParameters(const ArmSize& arm) {
  std::vector<ParameterInfo> out;
  for (const DeclaredDefinition& d : ArmWide()) {
    out.push_back(Make(d, std::string("declared.") + d.short_name, d.config_key));
  }
  for (int k = 1; k <= arm.segments; ++k) {
    for (const DeclaredDefinition& d : PerSegment()) {
      out.push_back(Make(d, "declared.segment" + std::to_string(k) + "." + d.short_name,
                         SegmentKey(d.config_key, k)));
    }
  }
  return out;
}

namespace internal {

const ParameterInfo* FindDeclaredParameter(const std::string& name, const ArmSize* arm,
                                           std::string* beyond) {
  const std::string prefix = "declared.";
  if (name.rfind(prefix, 0) != 0) return nullptr;
  const std::string rest = name.substr(prefix.size());
  for (const DeclaredDefinition& d : ArmWide()) {
    if (rest == d.short_name) return Interned(Make(d, name, d.config_key));
  }
  int k = 0;
  std::string member;
  if (!SplitSegment(rest, &k, &member)) return nullptr;
  for (const DeclaredDefinition& d : PerSegment()) {
    if (member != d.short_name) continue;
    if (arm != nullptr && k > arm->segments) {
      if (beyond != nullptr) {
        *beyond = "this arm has " + std::to_string(arm->segments) +
                  " segments: declared.segment<k>." + member + ", k = 1.." +
                  std::to_string(arm->segments);
      }
      return nullptr;
    }
    return Interned(Make(d, name, SegmentKey(d.config_key, k)));
  }
  return nullptr;
}

}  // namespace internal

bool AnyDeclaredCorrection(const ArmParameters& parameters) {
  for (const auto& [name, value] : parameters.declared_deltas) {
    if (value != 0.0) return true;
  }
  return false;
}

ArmConfig CorrectedArm(const ArmConfig& arm, const ArmParameters& parameters) {
  ArmConfig out = arm;
  for (const auto& [name, delta] : parameters.declared_deltas) {
    if (delta == 0.0) continue;
    Eigen::Vector3d* vector = nullptr;
    double& value = Value(&out, name, &vector);
    if (vector != nullptr) {
      *vector *= 1.0 + delta;
    } else {
      value *= 1.0 + delta;
    }
  }
  return out;
}

double DeclaredValue(const ArmConfig& arm, const std::string& name) {
  ArmConfig copy = arm;
  Eigen::Vector3d* vector = nullptr;
  return Value(&copy, name, &vector);
}

std::string DeclaredValueKey(const std::string& name) {
  const ParameterInfo* info = internal::FindDeclaredParameter(name, nullptr, nullptr);
  if (info == nullptr)
    ThrowInputError("declared values", "", "unknown declared value '" + name + "'");
  return info->config_key;
}

}  // namespace ccsrm::sim
