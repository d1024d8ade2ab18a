#pragma once
// Small arms and short runs shared by the simulator's physics tests
// (dynamics_test, effects_test): an arm built inline, inputs that pull one
// cable and hold, and the energy balance of a run.
#include <gtest/gtest.h>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim::test_support {

inline std::string PaperConfigPath() {
  return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
}

// One segment of `links` links with the paper's geometry and three cables.
inline Config SmallArm(int links) {
  Config c = LoadConfig(PaperConfigPath());
  c.arm.segments.resize(1);
  c.arm.segments[0].links = links;
  c.arm.segments[0].connecting_pattern.assign(links - 1, ConnectingKind::kSmallS);
  for (int k = 1; k < links - 1; k += 2)
    c.arm.segments[0].connecting_pattern[k] = ConnectingKind::kLargeS;
  c.arm.driving.cables.resize(3);
  c.parameters.arm = c.arm.size();
  Validate(c);
  return c;
}

// Inputs that pull cable `pulled` in by `amount_m` along a quintic over
// [0, ramp_s] and then hold it (and every other cable) fixed.
inline CableInputs PullAndHold(const ArmModel& model, int pulled, double amount_m, double ramp_s,
                               double end_s) {
  const int n = static_cast<int>(end_s / 1e-3) + 1;
  Eigen::VectorXd time(n);
  Eigen::MatrixXd change = Eigen::MatrixXd::Zero(n, model.num_cables());
  for (int i = 0; i < n; ++i) {
    time[i] = i * 1e-3;
    change(i, pulled) = amount_m * QuinticBlend(time[i] / ramp_s);
  }
  return CableInputs(time, change);
}

inline double TotalEnergy(const TrajectoryFrame& frame) {
  return frame.kinetic_energy + frame.elastic_energy + frame.dissipated_energy;
}

// Energy figures of a run from `from_s` on (after the inputs have stopped).
struct EnergyBalance {
  double reference = 0.0;      // kinetic + elastic + dissipated at from_s [J]
  double drift = 0.0;          // largest change of that total [J]
  double kinetic_max = 0.0;    // [J]
  double elastic_swing = 0.0;  // largest change of the elastic energy [J]
  double dissipated = 0.0;     // dissipated from from_s to the end [J]
  double span_s = 0.0;
};

inline EnergyBalance BalanceAfter(const Trajectory& run, double from_s) {
  std::size_t start = 0;
  while (run.time[start] < from_s) ++start;
  const TrajectoryFrame& first = run.frames[start];
  const TrajectoryFrame& last = run.frames.back();
  EnergyBalance b;
  b.reference = TotalEnergy(first);
  for (std::size_t f = start; f < run.size(); ++f) {
    const TrajectoryFrame& frame = run.frames[f];
    b.drift = std::max(b.drift, std::abs(TotalEnergy(frame) - b.reference));
    b.kinetic_max = std::max(b.kinetic_max, frame.kinetic_energy);
    b.elastic_swing =
        std::max(b.elastic_swing, std::abs(frame.elastic_energy - first.elastic_energy));
  }
  b.dissipated = last.dissipated_energy - first.dissipated_energy;
  b.span_s = run.time.back() - run.time[start];
  return b;
}

// No friction and no damping anywhere; the equations keep all their terms.
inline void SwitchOffDissipation(ArmParameters* p) {
  p->mu = p->mu_s = p->mu_c = p->mu_c_s = 0.0;
  p->beta = p->c_sc = p->c_lc = 0.0;
}

inline SimulationOptions OptionsFor(const Config& c, double duration_s) {
  SimulationOptions options;
  options.duration_s = duration_s;
  options.solver = c.solver;
  return options;
}

// `arm` with dissipation off except what `edit` switches on, cable 3
// pulled in by 0.5 mm over 20 ms and held to 0.2 s at tight tolerances; the
// energy balance once the input holds (after 30 ms), printed under `label`.
template <typename Edit>
EnergyBalance PullAndHoldBalance(const char* label, Config arm, Edit edit) {
  Config& c = arm;
  SwitchOffDissipation(&c.parameters);
  edit(&c);
  c.solver.relative_tolerance = 1e-8;
  c.solver.absolute_tolerance = 1e-11;
  c.solver.output_rate_hz = 1000.0;
  const ArmModel model(c.arm);
  const CableInputs inputs = PullAndHold(model, 2, 0.5e-3, 0.02, 0.2);
  const SimulationResult result = Simulate(model, c.parameters, inputs, OptionsFor(c, 0.2));
  EXPECT_TRUE(result.summary.completed()) << result.summary.message;
  const EnergyBalance e = BalanceAfter(result.trajectory, 0.03);
  std::printf(
      "%s: kinetic up to %.3e J, elastic swing %.3e J, dissipation and smoothing took %.3e "
      "J, drift %.3e J\n",
      label, e.kinetic_max, e.elastic_swing, e.dissipated, e.drift);
  return e;
}

}  // namespace ccsrm::sim::test_support
