// actuator_delay: the input lengths the actuators realise lag the command:
// a dead time d (`actuator_delay.dead_time_s`, communication and control
// cycle) then a first-order lag τ (`actuator_delay.time_constant_s`, the
// position loop's bandwidth 1/(2πτ)):
//
//   τ ẏ + y = u(t − d),  y(0) = u(0) (the arm starts at rest).
//
// The realised inputs are built once before the run on a uniform grid
// (1 ms, or τ/20 when shorter), exactly for a command linear between grid
// points, and interpolated by CableInputs' C2 spline like any input. The
// recorded experiment keeps the command: the lag is what identification
// must find.
#include <algorithm>
#include <cmath>
#include <memory>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

class ActuatorDelay final : public Effect {
 public:
  explicit ActuatorDelay(const ArmParameters& p)
      : tau_s_(GetParameter(p, "actuator_delay.time_constant_s")),
        dead_s_(GetParameter(p, "actuator_delay.dead_time_s")) {}

  std::unique_ptr<CableInputs> RealisedInputs(const ArmModel& /*model*/,
                                              const CableInputs& commanded,
                                              double duration_s) const override {
    if (tau_s_ == 0.0 && dead_s_ == 0.0) return nullptr;  // neutral: leave the inputs exact
    const double start = commanded.start_time();
    // Long enough for the lagged command to settle after its last sample
    // (10 τ: e^-10 of the last change) and to cover the run.
    const double end = std::max(duration_s, commanded.end_time() + dead_s_ + 10.0 * tau_s_);
    double step = 1e-3;
    if (tau_s_ > 0.0) step = std::min(step, tau_s_ / 20.0);
    const int n = std::max(2, static_cast<int>(std::ceil((end - start) / step)) + 1);
    step = (end - start) / (n - 1);
    const int cables = commanded.num_cables();
    Eigen::VectorXd time(n);
    Eigen::MatrixXd realised(n, cables);
    const double a = tau_s_ > 0.0 ? std::exp(-step / tau_s_) : 0.0;
    for (int c = 0; c < cables; ++c) {
      double u_prev = 0.0, y = 0.0;
      for (int k = 0; k < n; ++k) {
        const double t = start + step * k;
        time[k] = t;
        double u, rate, accel;
        commanded.Evaluate(c, t - dead_s_, &u, &rate, &accel);  // held before the start
        if (k == 0 || tau_s_ == 0.0) {
          y = u;
        } else {
          // Exact for u linear over the step: e = y - u decays over τ while
          // u moves at slope s, so e -> -s τ + (e + s τ) e^(-step/τ).
          const double s = (u - u_prev) / step;
          y = u - s * tau_s_ + (y - u_prev + s * tau_s_) * a;
        }
        realised(k, c) = y;
        u_prev = u;
      }
    }
    return std::make_unique<CableInputs>(std::move(time), std::move(realised));
  }

 private:
  double tau_s_, dead_s_;
};

}  // namespace

EffectDefinition ActuatorDelayEffect() {
  EffectDefinition d;
  d.name = "actuator_delay";
  d.fingerprint = {"rate", "input_rate", "lag"};
  d.description = "the input lengths lag the command: a dead time then a first-order lag";
  // Realistic: a servo-driven linear actuator's position loop of 5-10 Hz
  // bandwidth (τ = 16-32 ms) and a 10 ms control and communication cycle.
  d.parameters = {
      EffectParameter("time_constant_s", "s", 0.0, 1.0, 0.0, 0.02,
                      "first-order lag of the realised input length behind the command"),
      EffectParameter("dead_time_s", "s", 0.0, 0.5, 0.0, 0.01,
                      "pure delay of the realised input length behind the command"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<ActuatorDelay>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
