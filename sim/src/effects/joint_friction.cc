// joint_friction: Coulomb and viscous friction in every universal joint,
// on both of its axes.
//
//   M = -(M_c tanh(θ̇ / ω_ε) + c_v θ̇)
//
// tanh regularises the Coulomb term's sign over the rate ω_ε
// (`joint_friction.smoothing_rate_radps`, default 1e-3 rad/s = 0.057°/s, a
// tenth of the paper's peak ramp rate, 0.56°/s): slower motions see a
// proportionally smaller moment, so a joint "held" by friction creeps at
// rates below ω_ε. The law's slope, up to M_c / ω_ε (10 N m s/rad at the
// realistic 0.01 N m), is model-smoothed by the simulator (EffectLoads::
// AddJointMoment), which keeps the explicit RK45 at its usual steps.
// The moment's power −M θ̇ >= 0 is booked as dissipation.
#include <cmath>
#include <memory>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

class JointFriction final : public Effect {
 public:
  explicit JointFriction(const ArmParameters& p)
      : coulomb_nm_(GetParameter(p, "joint_friction.coulomb_nm")),
        viscous_nmsprad_(GetParameter(p, "joint_friction.viscous_nmsprad")),
        rate_radps_(GetParameter(p, "joint_friction.smoothing_rate_radps")) {}

  bool adds_loads() const override { return true; }

  void AddLoads(EffectLoads* loads) const override {
    for (int j = 1; j <= loads->num_joints(); ++j) {
      const Eigen::Vector2d& rate = loads->joint_rate(j);
      for (int axis = 0; axis < 2; ++axis) {
        const double w = rate[axis];
        const double t = std::tanh(w / rate_radps_);
        const double moment = -(coulomb_nm_ * t + viscous_nmsprad_ * w);
        // -dM/dθ̇ = M_c sech²(θ̇/ω_ε)/ω_ε + c_v >= 0.
        const double damping = coulomb_nm_ * (1.0 - t * t) / rate_radps_ + viscous_nmsprad_;
        loads->AddJointMoment(j, axis, moment, damping);
        loads->AddDissipation(-moment * w);
      }
    }
  }

 private:
  double coulomb_nm_, viscous_nmsprad_, rate_radps_;
};

}  // namespace

EffectDefinition JointFrictionEffect() {
  EffectDefinition d;
  d.name = "joint_friction";
  d.fingerprint = {"rate_sign", "rate", "hysteresis"};
  d.description = "Coulomb and viscous friction in every universal joint (both axes)";
  // Realistic: the joints carry the driving cables' pre-tension as
  // compression (6 x 100 N in segment 1); on rolling bearings (friction
  // coefficient ~0.002 at a ~5 mm radius) that is ~0.006 N m, on plain pins
  // ten times more. 0.01 N m is 2 % of the large-S conduit friction moment
  // (~0.5 N m, SPEC 3). Upper bound 0.5 N m: as much as the conduits.
  d.parameters = {
      EffectParameter("coulomb_nm", "N m", 0.0, 0.5, 0.0, 0.01,
                      "Coulomb friction moment of every joint axis"),
      // A tenth of the small-S damping c_sc (0.05 N m s/rad) on each joint.
      EffectParameter("viscous_nmsprad", "N m s/rad", 0.0, 1.0, 0.0, 0.005,
                      "viscous friction of every joint axis"),
      // Not a physical property: the rate over which the Coulomb term's sign
      // is smoothed. Bounds: 1e-5 rad/s (steeper costs steps) to 0.1 rad/s
      // (ten times the ramp's peak rate: the term would be viscous).
      EffectParameter("smoothing_rate_radps", "rad/s", 1e-5, 0.1, 1e-3, 1e-3,
                      "rate over which the Coulomb moment's sign is smoothed (tanh)"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<JointFriction>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
