// The four cases of the paper (section 6; SPEC 3 "The four cases"), each
// claim checked with a tolerance stated beside it, over the paper's 48 s
// protocol (CTest label `slow`). A protocol compressed in time is no
// shortcut: at a 2 s ramp the smoothed cables' inertia alone spreads the
// joints of case 1 by about 1 deg.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "ccsrm/sim_io/run_file.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::string kPaper = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";

// One simulated case, run once and shared by the tests that read it.
struct CaseRun {
  Config config;
  datasets::RunFile run;
  SimulationSummary summary;

  double t(std::size_t f) const { return run.time.at(f); }
  std::size_t Frame(double time_s) const {
    std::size_t best = 0;
    for (std::size_t f = 0; f < run.frames(); ++f) {
      if (std::abs(t(f) - time_s) < std::abs(t(best) - time_s)) best = f;
    }
    return best;
  }
  // theta_x or theta_y [deg] of joint j (1-based) at frame f.
  double Theta(std::size_t f, int joint, int axis = 0) const {
    return run.joint_angles.at(f, joint - 1, axis) / kDeg;
  }
  // Largest minus smallest theta_x of the joints of segment s (0-based).
  double Spread(std::size_t f, int segment) const {
    double lo = 1e9, hi = -1e9;
    for (int j = 1 + 6 * segment; j <= 6 + 6 * segment; ++j) {
      lo = std::min(lo, Theta(f, j));
      hi = std::max(hi, Theta(f, j));
    }
    return hi - lo;
  }
  // Swing of the largest input tension over the ramp [N].
  double RampTensionSwing() const {
    const double ramp_end = config.protocol.ramp_s;
    double swing = 0.0;
    for (std::size_t c = 0; c < run.input_tension.shape[1]; ++c) {
      double lo = 1e9, hi = -1e9;
      for (std::size_t f = 0; f < run.frames() && t(f) <= ramp_end; ++f) {
        lo = std::min(lo, run.input_tension.at(f, c));
        hi = std::max(hi, run.input_tension.at(f, c));
      }
      swing = std::max(swing, hi - lo);
    }
    return swing;
  }
  double MaxAbsThetaY() const {
    double m = 0.0;
    for (std::size_t f = 0; f < run.frames(); ++f)
      for (int j = 1; j <= 12; ++j) m = std::max(m, std::abs(Theta(f, j, 1)));
    return m;
  }
  void Print(const char* name) const {
    const std::size_t f = Frame(config.protocol.ramp_s);
    std::printf("%s (A = %+.0f deg) at end of ramp:", name, config.protocol.amplitude_rad / kDeg);
    for (int j = 1; j <= 12; ++j) std::printf(" %.2f", Theta(f, j));
    std::printf(" | ramp tension swing %.1f N | %s\n", RampTensionSwing(),
                summary.BriefReport().c_str());
  }
};

// The default test run's version checks the same claims on a protocol three
// times faster (6 s ramps, 16 s in all). The arm then rings by about 0.1 deg
// at its 1-3 Hz modes, which the full protocol's 20 s ramps do not excite:
// the tolerances below that depend on it say so.
#ifdef CCSRM_SHORT_PROTOCOL
constexpr bool kShortProtocol = true;
#else
constexpr bool kShortProtocol = false;
#endif

const CaseRun& RunCase(int case_number, double amplitude_deg) {
  static std::map<std::pair<int, int>, CaseRun> cache;
  const auto key = std::make_pair(case_number, static_cast<int>(amplitude_deg));
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  CaseRun r;
  r.config = LoadConfig(kPaper);
  ApplyPaperCase(case_number, &r.config.parameters);
  ProtocolConfig& p = r.config.protocol;
  p.amplitude_rad = amplitude_deg * kDeg;
  if (kShortProtocol) {
    p.ramp_s = 6.0;
    p.hold_s = 2.0;
    p.return_s = 6.0;
    p.rest_s = 2.0;
  }
  const ArmModel model(r.config.arm);
  const CableInputs inputs = PlanCableInputs(model, PaperTrajectory(model, p), p.duration_s());
  SimulationOptions options;
  options.duration_s = p.duration_s();
  options.solver = r.config.solver;
  const SimulationResult result = Simulate(model, r.config.parameters, inputs, options);
  r.run = sim_io::ToRunFile(model, result, {});
  r.summary = result.summary;
  r.Print(("case " + std::to_string(case_number)).c_str());
  // |Phi| (universal joints, unit quaternions, cable nodes on their disks)
  // stays under a micrometre over the whole run (measured 3e-8).
  EXPECT_LT(r.summary.max_constraint_violation, 1e-6) << "case " << case_number;
  return cache.emplace(key, std::move(r)).first->second;
}

TEST(PaperCases, Case1FollowsThePlanWithEqualJointsInEachSegment) {
  const CaseRun& r = RunCase(1, 6.0);
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const JointTrajectory plan = PaperTrajectory(ArmModel(r.config.arm), r.config.protocol);
  double worst_spread = 0.0, worst_error = 0.0;
  for (std::size_t f = 0; f < r.run.frames(); ++f) {
    worst_spread = std::max({worst_spread, r.Spread(f, 0), r.Spread(f, 1)});
    for (int j = 1; j <= 12; ++j) {
      worst_error = std::max(worst_error, std::abs(r.Theta(f, j) - plan(r.t(f))[j - 1][0] / kDeg));
    }
  }
  std::printf("case 1: largest in-segment spread %.4f deg, largest error to plan %.4f deg\n",
              worst_spread, worst_error);
  // SPEC 3: within 0.1 deg of the plan everywhere; constant curvature to a
  // half of that (only cable stretch differs between joints). The short
  // protocol's ringing (measured 0.13 deg to plan, 0.10 deg spread) doubles
  // both bounds.
  EXPECT_LT(worst_error, kShortProtocol ? 0.2 : 0.1);
  EXPECT_LT(worst_spread, kShortProtocol ? 0.15 : 0.05);
}

TEST(PaperCases, Case2LosesConstantCurvatureAmplitudeFallingRootToTip) {
  const CaseRun& r = RunCase(2, 6.0);
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const std::size_t f = r.Frame(r.config.protocol.ramp_s);
  for (int s = 0; s < 2; ++s) {
    // Constant curvature is lost: joints of a segment differ by > 0.5 deg.
    EXPECT_GT(r.Spread(f, s), 0.5) << "segment " << s + 1;
    // Amplitude falls from root to tip except the last joint; 0.05 deg
    // allows for the near-equal pairs the large S mechanisms hold together.
    for (int j = 1 + 6 * s; j < 5 + 6 * s; ++j) {
      EXPECT_GE(r.Theta(f, j) + 0.05, r.Theta(f, j + 1)) << "joints " << j << ", " << j + 1;
    }
    EXPECT_GT(r.Theta(f, 1 + 6 * s), r.Theta(f, 5 + 6 * s) + 0.5);
    // Large S pairs (2-3, 4-5) synchronise better than small S (1-2, 3-4,
    // 5-6), on average: the tip pair 5-6 is the SPEC's "except the last
    // joint", which can leave that one small-S pair nearly equal.
    auto gap = [&](int a) { return std::abs(r.Theta(f, a + 6 * s) - r.Theta(f, a + 1 + 6 * s)); };
    const double large = (gap(2) + gap(4)) / 2.0;
    const double small = (gap(1) + gap(3) + gap(5)) / 3.0;
    std::printf("case 2 segment %d: mean gap large S %.3f deg, small S %.3f deg\n", s + 1, large,
                small);
    EXPECT_LT(large, 0.5 * small) << "segment " << s + 1;
  }
}

TEST(PaperCases, Case3HoldsUnequalJointsWhileInputsAreHeld) {
  const CaseRun& r = RunCase(3, 6.0);
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const ProtocolConfig& p = r.config.protocol;
  // Skip the start of the hold, while the arm settles from the ramp: 2 % of
  // it (0.08 s) after the paper's ramp, 25 % (0.5 s) after the short one.
  const double settle = kShortProtocol ? 0.25 : 0.02;
  const std::size_t a = r.Frame(p.ramp_s + settle * p.hold_s), b = r.Frame(p.ramp_s + p.hold_s);
  double drift = 0.0;
  int stuck = 0;
  for (std::size_t f = a; f <= b; ++f) {
    for (int j = 1; j <= 12; ++j) drift = std::max(drift, std::abs(r.Theta(f, j) - r.Theta(a, j)));
    for (std::size_t c = 0; c < 6; ++c)
      stuck = std::max(stuck, static_cast<int>(r.run.stuck_nodes.at(f, c)));
  }
  std::printf(
      "case 3: drift during hold %.5f deg, most stuck nodes on a cable %d, segment spreads "
      "%.2f / %.2f deg, max |theta_y| %.3f deg\n",
      drift, stuck, r.Spread(a, 0), r.Spread(a, 1), r.MaxAbsThetaY());
  // The joint angles stay put (0.01 deg, a tenth of what mocap resolves) and unequal.
  EXPECT_LT(drift, 0.01);
  EXPECT_GT(r.Spread(a, 0), 0.5);
  EXPECT_GT(stuck, 0);
  // Segment 2 synchronises better than segment 1 (fewer cables rub on it).
  EXPECT_LT(r.Spread(a, 1), r.Spread(a, 0));
  // A small theta_y appears: present, but far below theta_x.
  EXPECT_GT(r.MaxAbsThetaY(), 1e-3);
  EXPECT_LT(r.MaxAbsThetaY(), 0.5);
}

TEST(PaperCases, Case4MovesSegmentEndsFirstAndSegmentsAlike) {
  const CaseRun& r = RunCase(4, 6.0);
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  // SPEC ballpark at 7 s of the 20 s ramp: ends near 2.0 deg, middles near 1.2.
  const std::size_t f = r.Frame(0.35 * r.config.protocol.ramp_s);
  for (int s = 0; s < 2; ++s) {
    const int o = 6 * s;
    const double ends = std::min(r.Theta(f, 1 + o), r.Theta(f, 6 + o));
    const double middles = std::max(r.Theta(f, 3 + o), r.Theta(f, 4 + o));
    std::printf("case 4 segment %d at %.2f s: ends %.2f / %.2f, middles %.2f / %.2f deg\n", s + 1,
                r.t(f), r.Theta(f, 1 + o), r.Theta(f, 6 + o), r.Theta(f, 3 + o), r.Theta(f, 4 + o));
    EXPECT_GT(ends, middles + 0.1) << "segment " << s + 1;
  }
  // The two segments behave alike: corresponding joints within 0.5 deg.
  for (int j = 1; j <= 6; ++j) EXPECT_NEAR(r.Theta(f, j), r.Theta(f, j + 6), 0.5) << "joint " << j;
  EXPECT_GT(r.MaxAbsThetaY(), 1e-4);
  EXPECT_LT(r.MaxAbsThetaY(), 0.5);
}

TEST(PaperCases, MoreFrictionNeedsMoreInputTension) {
  const double t1 = RunCase(1, 6.0).RampTensionSwing();
  const double t2 = RunCase(2, 6.0).RampTensionSwing();
  const double t3 = RunCase(3, 6.0).RampTensionSwing();
  const double t4 = RunCase(4, 6.0).RampTensionSwing();
  std::printf(
      "ramp swing of the largest input tension: case 1 %.1f N, 2 %.1f N, 3 %.1f N, 4 %.1f N\n", t1,
      t2, t3, t4);
  EXPECT_GT(t2, t3);
  EXPECT_GT(t3, t4);
  EXPECT_GT(t4, t1);
}

TEST(PaperCases, PlusAndMinusSixDegreesMirror) {
  const CaseRun& plus = RunCase(2, 6.0);
  const CaseRun& minus = RunCase(2, -6.0);
  ASSERT_EQ(plus.run.frames(), minus.run.frames());
  double worst = 0.0;
  for (std::size_t f = 0; f < plus.run.frames(); ++f)
    for (int j = 1; j <= 12; ++j)
      worst = std::max(worst, std::abs(plus.Theta(f, j) + minus.Theta(f, j)));
  std::printf("case 2: largest |theta_x(+6) + theta_x(-6)| %.4f deg\n", worst);
  // Mirror symmetry of the layout (SPEC 2); 0.05 deg allows for the
  // switching times, located only to the solver's tolerance.
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace ccsrm::sim
