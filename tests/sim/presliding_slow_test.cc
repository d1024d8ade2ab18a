// Holds that hold (issue 31): the paper's protocol with a 60 s hold, joint
// theta_x drift over the hold after the ramp has settled (20.5-80 s). The
// smoothed treatment creeps at up to v_eps; the presliding law holds.
// CTest label `slow` (three runs of 80 s of the arm). CCSRM_HOLD_TRACE=1
// prints the drifting joint, the stuck nodes and the fastest slip every 0.5 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kHoldFrom = 20.5, kHoldTo = 80.0;  // s

// configs/paper.yaml with a 60 s hold and `hole_friction: word`, written
// beside the test binary.
std::string HoldConfig(const std::string& word) {
  std::ifstream in(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) yaml.replace(at, from.size(), to);
  };
  replace("hold_s: 4.0", "hold_s: 60.0");
  replace("hole_friction: smoothed", "hole_friction: " + word);
  const std::string path = "presliding_hold_" + word + ".yaml";
  std::ofstream(path) << yaml;
  return path;
}

struct Drift {
  double deg = 0.0;  // largest range of theta_x over the hold, over joints
  int joint = 0;     // 1-based
};

Drift HoldDrift(const std::string& word, int case_number,
                const std::vector<std::string>& sets = {}) {
  PaperRunOptions o;
  o.sets = sets;
  o.config_path = HoldConfig(word);
  o.case_number = case_number;
  o.duration_s = kHoldTo;
  const PaperRun run = PreparePaperRun(o);
  const SimulationResult r = Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
  EXPECT_TRUE(r.summary.completed()) << r.summary.message;
  Drift d;
  const std::size_t joints = r.trajectory.frames.front().joint_angles.size();
  for (std::size_t j = 0; j < joints; ++j) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t f = 0; f < r.trajectory.size(); ++f) {
      if (r.trajectory.time[f] < kHoldFrom - 1e-9) continue;
      const double theta = r.trajectory.frames[f].joint_angles[j][0];
      lo = std::min(lo, theta);
      hi = std::max(hi, theta);
    }
    if ((hi - lo) / kDeg > d.deg) d = {(hi - lo) / kDeg, static_cast<int>(j) + 1};
  }
  if (std::getenv("CCSRM_HOLD_TRACE") != nullptr) {
    for (std::size_t f = 0; f < r.trajectory.size(); f += 50) {
      if (r.trajectory.time[f] < 15.0) continue;
      int stuck = 0, holes = 0;
      double fastest = 0.0;
      for (std::size_t c = 0; c < r.trajectory.frames[f].hole_stuck.size(); ++c) {
        for (std::size_t h = 0; h < r.trajectory.frames[f].hole_stuck[c].size(); ++h) {
          stuck += r.trajectory.frames[f].hole_stuck[c][h];
          ++holes;
          fastest = std::max(fastest, std::abs(r.trajectory.frames[f].hole_slip_velocity[c][h]));
        }
      }
      std::printf("  t %6.2f theta_x(joint %d) %.6f deg, stuck %d/%d, max |s_dot| %.2e\n",
                  r.trajectory.time[f], d.joint,
                  r.trajectory.frames[f].joint_angles[d.joint - 1][0] / kDeg, stuck, holes,
                  fastest);
    }
  }
  for (const std::string& set : sets) std::printf("%s ", set.c_str());
  std::printf("%s, case %d: drift over the hold %.4g deg (joint %d); %s\n", word.c_str(),
              case_number, d.deg, d.joint, r.summary.BriefReport().c_str());
  return d;
}

constexpr double kHoldBoundDeg = 0.01;  // issue 31

TEST(HoleFrictionHold, PreslidingHoldsCase3WithoutDrift) {
  EXPECT_LE(HoldDrift("presliding", 3).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, PreslidingHoldsCase3AtRealisticStaticFriction) {
  // mu' = 0.25 against mu = 0.21 (SPEC 10): the hold starts below the
  // static limit, well inside the presliding range.
  EXPECT_LE(HoldDrift("presliding", 3, {"mu_s=0.25"}).deg, kHoldBoundDeg);
}

// Not yet: the large-S conduits' friction (eq. 45, smoothed over its stick
// band like the holes' smoothed law) creeps too, 0.12 deg over the hold at
// joint 10 with presliding holes (0.21 deg with smoothed ones); the
// conduits need the presliding law as well (issue 31, next step).
TEST(HoleFrictionHold, DISABLED_PreslidingHoldsCase2WithoutDrift) {
  EXPECT_LE(HoldDrift("presliding", 2).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, ConduitFrictionAloneStillCreeps) {
  // Case 4: friction in the conduits only, none in the holes. What case 2
  // still drifts by comes from here.
  EXPECT_GT(HoldDrift("presliding", 4).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, SmoothedCreepsThroughTheHold) {
  // The reason for the presliding law: a node loaded below its limit
  // creeps at up to v_eps (0.15 deg over 60 s in case 3).
  EXPECT_GT(HoldDrift("smoothed", 3).deg, 10.0 * kHoldBoundDeg);
}

}  // namespace
}  // namespace ccsrm::sim
