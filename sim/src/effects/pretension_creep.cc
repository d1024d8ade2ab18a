// pretension_creep: the cables' pre-tensions relax exponentially over the
// experiment (creep of the wire ropes, settling of their terminations):
//
//   T(t) = T0 (1 − f (1 − e^(−t/τ)))
//
// with f `pretension_creep.connecting_fraction` for the connecting cables'
// T_p, `pretension_creep.driving_fraction` for the driving cables' T_d0 (a
// cable's own pre-tension with segment_pretension on: T_d0 plus its
// segment's change; none lost by a cable that starts slack) and
// τ `pretension_creep.time_constant_s`, t from the start of the run.
// Connecting cables: T_p enters the large-S couples (capstan stiffness and
// conduit friction, eqs. 46-53) through PretensionFactor. Driving cables:
// their pre-tension is a pre-strain, not a parameter of the equations, so
// it relaxes as cable length given back at the input: a uniform strain drop
// of ΔT/EA along the straight path length L needs ΔL = f T_d0 L (1 −
// e^(−t/τ)) / EA, subtracted from the pulled-in length (the termination
// slipping, or the rope lengthening, by that much).
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/sim/kinematics.h"
#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

class PretensionCreep final : public Effect {
 public:
  explicit PretensionCreep(const ArmParameters& p)
      : connecting_(GetParameter(p, "pretension_creep.connecting_fraction")),
        driving_(GetParameter(p, "pretension_creep.driving_fraction")),
        tau_s_(GetParameter(p, "pretension_creep.time_constant_s")),
        t_d0_(p.T_d0) {
    if (!p.EffectOn("segment_pretension")) return;
    for (int k = 1; k <= p.arm.segments; ++k) {
      segment_change_n_.push_back(
          GetParameter(p, "segment_pretension.segment" + std::to_string(k) + "_n"));
    }
  }

  bool scales_pretension() const override { return connecting_ > 0.0; }

  double PretensionFactor(double t) const override { return 1.0 - connecting_ * Relaxed(t); }

  std::unique_ptr<CableInputs> RealisedInputs(const ArmModel& model, const CableInputs& commanded,
                                              double duration_s) const override {
    if (driving_ == 0.0) return nullptr;
    const ArmConfig& arm = model.arm();
    const double ea = arm.driving.youngs_modulus_pa * arm.driving.cross_section_m2;
    const std::vector<LinkPose> straight =
        ForwardKinematics(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
    const double start = commanded.start_time();
    const double end = std::max(duration_s, commanded.end_time());
    // 1 ms keeps the command's own spline (sampled at 1 ms by the planner).
    const int n = std::max(2, static_cast<int>(std::ceil((end - start) / 1e-3)) + 1);
    const double step = (end - start) / (n - 1);
    Eigen::VectorXd time(n);
    Eigen::MatrixXd realised(n, commanded.num_cables());
    for (int c = 0; c < commanded.num_cables(); ++c) {
      const double paid_out_full = driving_ * Pretension(model.cables()[c].segment) *
                                   CablePathLength(model, c, straight) / ea;
      for (int k = 0; k < n; ++k) {
        const double t = start + step * k;
        double u, rate, accel;
        commanded.Evaluate(c, t, &u, &rate, &accel);
        time[k] = t;
        realised(k, c) = u - paid_out_full * Relaxed(t);
      }
    }
    return std::make_unique<CableInputs>(std::move(time), std::move(realised));
  }

 private:
  // 1 − e^(−t/τ), the relaxed fraction of f at time t.
  double Relaxed(double t) const { return -std::expm1(-std::max(0.0, t) / tau_s_); }

  // The pre-tension of a driving cable of `segment` (0-based) [N], at least 0.
  double Pretension(int segment) const {
    const std::size_t k = static_cast<std::size_t>(segment);
    return std::max(0.0, t_d0_ + (k < segment_change_n_.size() ? segment_change_n_[k] : 0.0));
  }

  double connecting_, driving_, tau_s_, t_d0_;
  std::vector<double> segment_change_n_;  // segment_pretension's, when on
};

}  // namespace

EffectDefinition PretensionCreepEffect() {
  EffectDefinition d;
  d.name = "pretension_creep";
  d.fingerprint = {"time", "hold_drift", "angle"};
  d.description = "the cables' pre-tensions T_p and T_d0 relax exponentially over the experiment";
  // Realistic: steel wire ropes lose a few percent of their tension in the
  // first minutes after tensioning (constructional stretch, termination
  // settling); 5 % with a 30 s time constant is a freshly tensioned arm.
  // Upper bound: half the tension.
  d.parameters = {
      EffectParameter("connecting_fraction", "1", 0.0, 0.5, 0.0, 0.05,
                      "fraction of the connecting cables' pre-tension T_p lost as t -> infinity"),
      EffectParameter("driving_fraction", "1", 0.0, 0.5, 0.0, 0.05,
                      "fraction of the driving cables' pre-tension T_d0 lost as t -> infinity"),
      // Default 30 s, so that giving only a fraction means a relaxation
      // within the experiment; 1 s to a day.
      EffectParameter("time_constant_s", "s", 1.0, 86400.0, 30.0, 30.0,
                      "time constant of the relaxation"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<PretensionCreep>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
