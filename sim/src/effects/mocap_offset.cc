// mocap_offset: constant zero offsets of the measured joint angles. A
// measurement effect: the rigid bodies' frames (marker clusters, or a
// static trial taken with the arm not quite straight) are off, so the
// recorded angles are the physical ones plus an offset per joint and axis:
//
//   θ_recorded = θ + δ,  δ = `mocap_offset.joint<k>_x_rad`, `..._y_rad`.
//
// One pair of parameters per joint of the arm (ArmParameters::arm): on a
// 16-joint arm joint16_x_rad exists, on a 9-joint arm joint12_x_rad does not.
// The dynamics are untouched: RecordedJointAngles and RecordedLinkPoses
// (ccsrm/sim/effects.h) apply it.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

std::string Name(int joint, int axis) {
  return "joint" + std::to_string(joint) + (axis == 0 ? "_x_rad" : "_y_rad");
}

class MocapOffset final : public Effect {
 public:
  explicit MocapOffset(const ArmParameters& p)
      : offset_(static_cast<std::size_t>(p.arm.joints), Eigen::Vector2d::Zero()) {
    for (int j = 1; j <= p.arm.joints; ++j) {
      for (int a = 0; a < 2; ++a) offset_[j - 1][a] = GetParameter(p, "mocap_offset." + Name(j, a));
    }
  }

  void Record(std::vector<Eigen::Vector2d>* joint_angles) const override {
    // The parameters are the recorded arm's (RecordedJointAngles' precondition).
    CCSRM_CHECK(joint_angles->size() == offset_.size());
    for (std::size_t j = 0; j < offset_.size(); ++j) (*joint_angles)[j] += offset_[j];
  }

 private:
  std::vector<Eigen::Vector2d> offset_;  // per joint (θx, θy) [rad]
};

}  // namespace

EffectDefinition MocapOffsetEffect() {
  EffectDefinition d;
  d.name = "mocap_offset";
  d.fingerprint = {"constant"};
  d.description =
      "constant zero offsets of the measured joint angles (measurement only, not the dynamics)";
  d.measurement = true;
  // Realistic: rigid bodies defined from a static trial of a straight arm
  // that is straight to ~0.1-0.2°: offsets of 2e-3 rad (0.11°) in θx, half
  // that in θy (the arm lies flat on the table), with signs and sizes that
  // differ joint by joint (a fixed pattern, so that a generated experiment
  // is reproducible). Bounds ±0.05 rad (±2.9°, a cluster visibly askew).
  IndexedParameters per_joint;
  per_joint.per = IndexedParameters::Per::kJoint;
  per_joint.patterns = {"joint<k>_x_rad", "joint<k>_y_rad"};
  per_joint.make = [](int j) {
    std::vector<ParameterInfo> pair;
    for (int a = 0; a < 2; ++a) {
      // A fixed pattern in [-1, 1] by joint and axis.
      const double pattern = std::sin(2.3 * j + 1.1 * a + 0.4);
      const double realistic = std::round(pattern * (a == 0 ? 2e-3 : 1e-3) * 1e5) / 1e5;
      pair.push_back(EffectParameter(
          Name(j, a), "rad", -0.05, 0.05, 0.0, realistic,
          "zero offset of joint " + std::to_string(j) + "'s measured " + (a == 0 ? "θx" : "θy")));
    }
    return pair;
  };
  d.indexed = {per_joint};
  d.make = [](const ArmParameters& p) { return std::make_unique<MocapOffset>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
