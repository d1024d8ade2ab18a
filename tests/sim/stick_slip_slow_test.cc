// Realistic static friction (mu' = mu'_c = 0.25 against kinetic 0.21, SPEC
// 10) over the first 12 s of the paper's case-2 protocol: the ramp, where
// the conduits slip at 0.1-0.2 mm/s and the holes at a fraction of a mm/s.
// CTest label `slow` (about a minute): the chattering run is slow by nature.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// RMS over joints and frames in [from, to) of the second difference of
// theta_x between consecutive frames [deg]: the jerk that stick-slip leaves
// in the sampled angles.
double RmsSecondDifferenceDeg(const Trajectory& t, double from_s, double to_s) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t f = 1; f + 1 < t.size(); ++f) {
    if (t.time[f] < from_s || t.time[f] >= to_s) continue;
    for (std::size_t j = 0; j < t.frames[f].joint_angles.size(); ++j) {
      const double d2 = t.frames[f + 1].joint_angles[j][0] - 2.0 * t.frames[f].joint_angles[j][0] +
                        t.frames[f - 1].joint_angles[j][0];
      sum += d2 * d2;
      ++count;
    }
  }
  return std::sqrt(sum / count) / kDeg;
}

SimulationResult RealisticCase2(const std::vector<std::string>& extra) {
  PaperRunOptions o;
  o.config_path = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
  o.case_number = 2;
  o.duration_s = 12.0;
  o.sets = {"mu_s=0.25", "mu_c_s=0.25"};
  o.sets.insert(o.sets.end(), extra.begin(), extra.end());
  const PaperRun run = PreparePaperRun(o);
  return Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
}

// The plan itself (a quintic to 6 deg over 20 s) has a second difference of
// at most 5.77 A / T^2 dt^2 = 8.7e-6 deg per 10 ms frame; smooth sliding
// adds the arm's slow ringing, ~1.6e-5 deg RMS at the paper's friction. A
// stick-slip jerk of even 0.01 deg per frame is 1e-2. The bound, 1e-4 deg,
// sits between: ten times the plan, a hundredth of a jerk.
constexpr double kSmoothBoundDeg = 1e-4;

TEST(RealisticStaticFriction, ArmSlidesWithoutChatterAtTheDefaultStribeckVelocities) {
  const SimulationResult r = RealisticCase2({});
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const double rms = RmsSecondDifferenceDeg(r.trajectory, 6.0, 12.0);
  std::printf("default Stribeck velocities: %s; RMS second difference %.2e deg\n",
              r.summary.BriefReport().c_str(), rms);
  EXPECT_LT(rms, kSmoothBoundDeg);
}

TEST(RealisticStaticFriction, ConduitsStickSlipWhenTheirFallIsThePapersTolerance) {
  // Eq. 45's v_d - v_s = 0.1 mm/s as a Stribeck velocity puts the conduits'
  // ramp speeds on the falling branch, where steady sliding is unstable: the
  // arm chatters. This is what the default's 5 mm/s avoids, and the reason
  // the test above can fail.
  const SimulationResult r = RealisticCase2({"v_c_s=1e-4"});
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const double rms = RmsSecondDifferenceDeg(r.trajectory, 6.0, 12.0);
  std::printf("conduit fall over 0.1 mm/s: %s; RMS second difference %.2e deg\n",
              r.summary.BriefReport().c_str(), rms);
  EXPECT_GT(rms, 10.0 * kSmoothBoundDeg);
}

}  // namespace
}  // namespace ccsrm::sim
