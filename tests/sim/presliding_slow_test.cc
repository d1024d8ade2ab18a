// Holds that hold (issue 31): the paper's protocol with a 60 s hold, joint
// theta_x drift over the hold after the ramp has settled (20.5-80 s). The
// smoothed treatment creeps at up to v_eps, eq. 45's conduits inside their
// stick band; the presliding laws hold.
// CTest label `slow` (three runs of 80 s of the arm). CCSRM_HOLD_TRACE=1
// prints the drifting joint, the stuck nodes and the fastest slip every 0.5 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
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

// The two treatments of sticking a hold run uses (solver.hole_friction,
// solver.conduit_friction).
struct Friction {
  std::string holes;
  std::string conduits;
  std::string name() const { return holes + "/" + conduits; }
};
const Friction kPresliding{"presliding", "presliding"};

// configs/paper.yaml with a 60 s hold and the given friction treatments,
// written to the temporary directory (never the working directory, which may
// be the source tree).
std::string HoldConfig(const Friction& friction) {
  std::ifstream in(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  // Replaces the value of the first line "  key: value".
  auto set = [&](const std::string& key, const std::string& value) {
    const std::size_t at = yaml.find("\n  " + key + ": ");
    EXPECT_NE(at, std::string::npos) << key;
    if (at == std::string::npos) return;
    const std::size_t from = at + 5 + key.size();
    yaml.replace(from, yaml.find('\n', from) - from, value);
  };
  set("hold_s", "60.0");
  set("hole_friction", friction.holes);
  set("conduit_friction", friction.conduits);
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("ccsrm_presliding_hold_" + friction.holes + "_" + friction.conduits + ".yaml"))
          .string();
  std::ofstream(path) << yaml;
  return path;
}

struct Drift {
  double deg = 0.0;  // largest range of theta_x over the hold, over joints
  int joint = 0;     // 1-based
};

Drift HoldDrift(const Friction& friction, int case_number,
                const std::vector<std::string>& sets = {}) {
  PaperRunOptions o;
  o.sets = sets;
  o.config_path = HoldConfig(friction);
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
  std::printf("%s, case %d: drift over the hold %.4g deg (joint %d); %s\n", friction.name().c_str(),
              case_number, d.deg, d.joint, r.summary.BriefReport().c_str());
  return d;
}

// A third of the motion-capture noise floor (0.03 deg RMS, what 0.2 mm of
// marker noise leaves in the joint angles): a hold must not
// leave a residual that mocap could see (issue 31).
constexpr double kHoldBoundDeg = 0.01;

TEST(HoleFrictionHold, PreslidingHoldsCase3WithoutDrift) {
  EXPECT_LE(HoldDrift(kPresliding, 3).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, PreslidingHoldsCase3AtRealisticStaticFriction) {
  // mu' = 0.25 against mu = 0.21 (SPEC 10): the hold starts below the
  // static limit, well inside the presliding range.
  EXPECT_LE(HoldDrift(kPresliding, 3, {"mu_s=0.25"}).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, PreslidingHoldsCase2WithoutDrift) {
  // Friction in the holes and in the large-S conduits, both presliding.
  EXPECT_LE(HoldDrift(kPresliding, 2).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, PreslidingHoldsCase2AtRealisticStaticFriction) {
  EXPECT_LE(HoldDrift(kPresliding, 2, {"mu_s=0.25", "mu_c_s=0.25"}).deg, kHoldBoundDeg);
}

TEST(HoleFrictionHold, ModifiedCoulombConduitsCreepThroughTheHold) {
  // Case 4: friction in the conduits only. Eq. 45 lets a conduit loaded
  // below its limit creep inside its stick band v_s, as the paper says
  // ("cannot capture stick state in a strict sense"): the reason for the
  // conduits' presliding law.
  EXPECT_GT(HoldDrift({"presliding", "modified_coulomb"}, 4).deg, 10.0 * kHoldBoundDeg);
}

TEST(HoleFrictionHold, SmoothedCreepsThroughTheHold) {
  // The reason for the holes' presliding law: a node loaded below its
  // limit creeps at up to v_eps (0.15 deg over 60 s in case 3).
  EXPECT_GT(HoldDrift({"smoothed", "presliding"}, 3).deg, 10.0 * kHoldBoundDeg);
}

}  // namespace
}  // namespace ccsrm::sim
