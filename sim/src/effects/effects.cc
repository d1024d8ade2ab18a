// The public face of the effect library: switching effects on from text,
// and what motion capture records (ccsrm/sim/effects.h).
#include "ccsrm/sim/effects.h"

#include <cstdlib>
#include <memory>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/sim/kinematics.h"
#include "effect.h"
#include "effects_yaml.h"

namespace ccsrm::sim {
namespace {

// `effect`'s parameters by short name on the parameters' arm, for messages.
std::string ParameterList(const std::string& effect, const ArmSize& arm) {
  return internal::DescribeParameters(*internal::FindEffectDefinition(effect), &arm, false);
}

// The entry of `effect`'s parameter `short_name` on `arm`, or null; *beyond
// says why when it is a per-joint or per-cable parameter the arm lacks.
const ParameterInfo* EffectParameterInfo(const std::string& effect, const std::string& short_name,
                                         const ArmSize& arm, std::string* beyond) {
  return internal::FindEffectParameter(effect + "." + short_name, &arm, beyond);
}

// "unknown parameter of mocap_offset (this arm has 9 joints: known: ...)".
std::string UnknownParameterText(const std::string& effect, const std::string& beyond,
                                 const ArmSize& arm) {
  return "(" + (beyond.empty() ? std::string("known") : beyond + ": known") + ": " +
         ParameterList(effect, arm) + ")";
}

}  // namespace

namespace internal {

void ApplyEffectsNode(const YAML::Node& node, const std::string& file,
                      const std::string& key_prefix, ArmParameters* parameters) {
  auto line_of = [](const YAML::Node& n) { return "line " + std::to_string(n.Mark().line + 1); };
  if (node.IsNull()) return;
  if (!node.IsMap()) {
    ThrowInputError(file,
                    line_of(node) + ", key '" + key_prefix.substr(0, key_prefix.size() - 1) + "'",
                    "expected a mapping from effect name to its parameters, e.g. "
                    "'joint_friction: {coulomb_nm: 0.01}'");
  }
  ArmParameters updated = *parameters;
  for (const auto& entry : node) {
    const std::string effect = entry.first.as<std::string>();
    const std::string where = line_of(entry.first) + ", key '" + key_prefix + effect + "'";
    std::string known;
    for (const EffectInfo& e : Effects()) known += (known.empty() ? "" : ", ") + e.name;
    bool found = false;
    for (const EffectInfo& e : Effects()) found = found || e.name == effect;
    if (!found) ThrowInputError(file, where, "unknown effect (known: " + known + ")");
    updated.EnableEffect(effect);
    const YAML::Node values = entry.second;
    if (values.IsNull()) continue;
    if (!values.IsMap()) {
      ThrowInputError(file, where,
                      "expected a mapping of the effect's parameters to values (" +
                          ParameterList(effect, updated.arm) + "), or {} for its defaults");
    }
    for (const auto& value_entry : values) {
      const std::string name = value_entry.first.as<std::string>();
      const std::string value_where =
          line_of(value_entry.first) + ", key '" + key_prefix + effect + "." + name + "'";
      std::string beyond;
      const ParameterInfo* info = EffectParameterInfo(effect, name, updated.arm, &beyond);
      if (info == nullptr) {
        ThrowInputError(file, value_where,
                        "unknown parameter of " + effect + " " +
                            UnknownParameterText(effect, beyond, updated.arm));
      }
      const double value = ReadYamlNumber(value_entry.second, file, value_where);
      const std::string problem = ParameterValueProblem(*info, value);
      if (!problem.empty()) ThrowInputError(file, value_where, problem);
      SetParameter(info->name, value, file, &updated);
    }
  }
  *parameters = updated;
}

}  // namespace internal

void EnableEffectAtRealisticMagnitude(const std::string& effect, const std::string& where,
                                      ArmParameters* parameters) {
  ArmParameters updated = *parameters;
  updated.EnableEffect(effect, where);
  for (const std::string& name : EffectParameterNames(effect, updated.arm, where)) {
    SetParameter(name, FindParameter(name, where, updated.arm).realistic, where, &updated);
  }
  *parameters = updated;
}

std::string ApplyEffectSpec(const std::string& text, const std::string& where,
                            ArmParameters* parameters) {
  const std::size_t colon = text.find(':');
  const std::string effect = text.substr(0, colon);
  if (effect.empty()) {
    ThrowInputError(where, "'" + text + "'",
                    "expected NAME or NAME:param=value,... (e.g. joint_friction:coulomb_nm=0.01)");
  }
  if (colon == std::string::npos) {
    EnableEffectAtRealisticMagnitude(effect, where, parameters);
    return effect;
  }
  FindEffect(effect, where);
  ArmParameters updated = *parameters;
  updated.EnableEffect(effect, where);
  std::string rest = text.substr(colon + 1);
  if (rest.empty()) {
    ThrowInputError(where, "'" + text + "'",
                    "expected param=value after ':' (parameters of " + effect + ": " +
                        ParameterList(effect, updated.arm) + ")");
  }
  std::size_t begin = 0;
  while (begin <= rest.size()) {
    const std::size_t comma = rest.find(',', begin);
    const std::string item =
        rest.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    const std::size_t equals = item.find('=');
    if (equals == std::string::npos || equals == 0) {
      ThrowInputError(where, "'" + text + "'",
                      "expected param=value, found '" + item + "' (parameters of " + effect + ": " +
                          ParameterList(effect, updated.arm) + ")");
    }
    const std::string name = item.substr(0, equals);
    std::string beyond;
    const ParameterInfo* p = EffectParameterInfo(effect, name, updated.arm, &beyond);
    if (p == nullptr) {
      ThrowInputError(where, "'" + text + "'",
                      "unknown parameter '" + name + "' of " + effect + " " +
                          UnknownParameterText(effect, beyond, updated.arm));
    }
    double value = 0.0;
    const std::string problem = ParseNumberText(item.substr(equals + 1), &value);
    if (!problem.empty()) {
      ThrowInputError(where, "'" + text + "'",
                      "value '" + item.substr(equals + 1) + "' of " + name + " " + problem);
    }
    SetParameter(p->name, value, where, &updated);
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  *parameters = updated;
  return effect;
}

void ApplyEffectsYaml(const std::string& yaml_text, const std::string& file,
                      ArmParameters* parameters) {
  YAML::Node root = ParseYamlDocument(yaml_text, file);
  std::string prefix;
  if (root.IsMap() && root["effects"]) {
    root = root["effects"];
    prefix = "effects.";
  }
  if (!root.IsMap()) {
    ThrowInputError(file, "",
                    "expected a mapping from effect name to its parameters, e.g. "
                    "'joint_friction: {coulomb_nm: 0.01}'");
  }
  internal::ApplyEffectsNode(root, file, prefix, parameters);
}

std::vector<Eigen::Vector2d> RecordedJointAngles(const ArmParameters& parameters,
                                                 const TrajectoryFrame& frame) {
  std::vector<Eigen::Vector2d> angles = frame.joint_angles;
  if (!parameters.AnyEffectOn()) return angles;
  for (const internal::EffectDefinition& d : internal::EffectDefinitions()) {
    if (d.measurement && parameters.EffectOn(d.name)) d.make(parameters)->Record(&angles);
  }
  return angles;
}

std::vector<Eigen::Matrix<double, 7, 1>> RecordedLinkPoses(const ArmModel& model,
                                                           const ArmParameters& parameters,
                                                           const TrajectoryFrame& frame) {
  const std::vector<Eigen::Vector2d> recorded = RecordedJointAngles(parameters, frame);
  if (recorded == frame.joint_angles) return frame.link_pose;
  CCSRM_CHECK(static_cast<int>(frame.link_pose.size()) == model.num_links() &&
              recorded.size() == frame.link_pose.size());
  std::vector<Eigen::Matrix<double, 7, 1>> poses = frame.link_pose;
  // Joint 1 where link 1 has it; then R_W(i) = R_W(i-1) Rx(θx) Ry(θy) (SPEC
  // 2, R_W0 = I) and each link hung from its proximal joint.
  const Eigen::Quaterniond q1(poses[0][3], poses[0][4], poses[0][5], poses[0][6]);
  Eigen::Vector3d p_WJ = poses[0].head<3>() + q1.toRotationMatrix() * model.p_child_joint(1);
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();
  for (int i = 1; i <= model.num_links(); ++i) {
    R_WB = R_WB * RotX(recorded[i - 1][0]) * RotY(recorded[i - 1][1]);
    const Eigen::Vector3d p_WB = p_WJ - R_WB * model.p_child_joint(i);
    const Eigen::Quaterniond q(R_WB);
    poses[i - 1] << p_WB, q.w(), q.x(), q.y(), q.z();
    if (i < model.num_links()) p_WJ = p_WB + R_WB * model.p_parent_joint(i + 1);
  }
  return poses;
}

}  // namespace ccsrm::sim
