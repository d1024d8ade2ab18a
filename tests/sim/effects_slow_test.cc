// Effects over longer runs (label `slow`): backlash's hysteresis over a
// ramp up and back (case 3, about 20 s of wall time).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "sim_runs.h"

namespace ccsrm::sim {
namespace {

using test_support::OptionsFor;
using test_support::PaperConfigPath;

constexpr double kDeg = M_PI / 180.0;

TEST(Backlash, BacklashAddsDeadBandHysteresis) {
  // Case 3 over a compressed ramp up (1.5 s), hold (0.5 s) and return
  // (1.5 s). The holes' friction leaves the couples loaded one way on the
  // way up and the other way on the way down, so a couple's relative
  // rotation at the same planned angle differs between the two: a
  // hysteresis loop. With play b each couple gives way inside its band in
  // both directions, so the loop widens, by at most 2b (one band's width).
  Config c = LoadConfig(PaperConfigPath());
  ApplyPaperCase(3, &c.parameters);
  c.protocol.ramp_s = 1.5;
  c.protocol.hold_s = 0.5;
  c.protocol.return_s = 1.5;
  const ArmModel model(c.arm);
  const CableInputs inputs = PlanCableInputs(model, PaperTrajectory(model, c.protocol), 3.5);
  ArmParameters loose = c.parameters;
  const double band = 0.004;
  SetParameter("backlash.dead_band_rad", band, "test", &loose);
  const SimulationResult a = Simulate(model, c.parameters, inputs, OptionsFor(c, 3.5));
  const SimulationResult b = Simulate(model, loose, inputs, OptionsFor(c, 3.5));
  ASSERT_TRUE(a.summary.completed() && b.summary.completed());
  // Half amplitude: 0.75 s up, 2.75 s down (the quintic is symmetric).
  const std::size_t up = 75, down = 275;
  ASSERT_NEAR(a.trajectory.time[up], 0.75, 1e-12);
  ASSERT_NEAR(a.trajectory.time[down], 2.75, 1e-12);
  double width_nominal = 0.0, width_loose = 0.0;
  for (const ConnectingPairModel& pair : model.connecting_pairs()) {
    const int i = pair.joint_i - 1, j = pair.joint_i;
    auto d = [&](const SimulationResult& r, std::size_t f) {
      return r.trajectory.frames[f].joint_angles[j][0] - r.trajectory.frames[f].joint_angles[i][0];
    };
    const double loop_nominal = std::abs(d(a, up) - d(a, down));
    const double loop_loose = std::abs(d(b, up) - d(b, down));
    std::printf("couple %2d-%2d: loop width %.4f° nominal, %.4f° with backlash\n", i + 1, j + 1,
                loop_nominal / kDeg, loop_loose / kDeg);
    width_nominal += loop_nominal;
    width_loose += loop_loose;
  }
  const double pairs = static_cast<double>(model.connecting_pairs().size());
  std::printf("mean loop width %.4f° nominal, %.4f° with backlash (2b = %.4f°)\n",
              width_nominal / pairs / kDeg, width_loose / pairs / kDeg, 2 * band / kDeg);
  EXPECT_GT(width_loose, width_nominal);
  EXPECT_LT((width_loose - width_nominal) / pairs, 2.0 * band);
}

}  // namespace
}  // namespace ccsrm::sim
