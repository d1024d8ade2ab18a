// The second arm shipped in configs/ (three-segment.yaml: three segments of
// four links, nine cables staggered 40 deg between segments), on the
// configuration's own 48 s protocol (8 deg): case 1 follows its plan in
// both axes, every segment bends with constant curvature, and its effects
// are sized to it. About 7 s.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/describe.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = 180.0 / M_PI;
const std::string kThreeSegment = std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml";

TEST(SecondArm, Case1FollowsItsPlanInBothAxesWithConstantCurvature) {
  PaperRunOptions options;
  options.config_path = kThreeSegment;
  options.case_number = 1;
  const PaperRun run = PreparePaperRun(options);
  ASSERT_EQ(run.model.num_joints(), 12);
  ASSERT_EQ(run.model.num_cables(), 9);
  EXPECT_FALSE(IsPaperArm(run.config.arm));
  const SimulationResult result =
      Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
  ASSERT_TRUE(result.summary.completed()) << result.summary.message;
  const JointTrajectory plan = PaperTrajectory(run.model, run.config.protocol);
  const double amplitude_deg = run.config.protocol.amplitude_rad * kDeg;
  Eigen::Array3d worst_x = Eigen::Array3d::Zero();  // per segment [deg]
  double worst_y = 0.0, worst_spread = 0.0;
  for (std::size_t f = 0; f < result.trajectory.size(); ++f) {
    const JointAngles planned = plan(result.trajectory.time[f]);
    const auto& angles = result.trajectory.frames[f].joint_angles;
    for (int s = 0; s < 3; ++s) {
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < 4; ++k) {
        const int j = 4 * s + k;
        worst_x[s] = std::max(worst_x[s], std::abs(angles[j][0] - planned[j][0]) * kDeg);
        worst_y = std::max(worst_y, std::abs(angles[j][1] - planned[j][1]) * kDeg);
        lo = std::min(lo, angles[j][0] * kDeg);
        hi = std::max(hi, angles[j][0] * kDeg);
      }
      worst_spread = std::max(worst_spread, hi - lo);
    }
  }
  std::printf(
      "second arm, case 1 at %.0f deg: largest theta_x error to plan %.4f / %.4f / %.4f deg "
      "(segments 1-3), largest |theta_y| %.5f deg, largest in-segment spread %.5f deg, %.1f s "
      "wall\n",
      amplitude_deg, worst_x[0], worst_x[1], worst_x[2], worst_y, worst_spread,
      result.summary.wall_time_s);
  // SPEC 3 holds the paper's frictionless arm to 0.1 deg of its 6 deg plan,
  // where each cable crosses 6 joints. What is left is the cables' elastic
  // stretch, which the kinematic planner ignores: it grows with the bend
  // (the tension swing) and with the cable between input and anchor. So the
  // same bound scaled by amplitude and joints crossed: 0.1 (A / 6) (n / 6)
  // deg, 0.27 deg for segment 3's cables across 12 joints at 8 deg.
  for (int s = 0; s < 3; ++s) {
    const double crossed = 4.0 * (s + 1);
    EXPECT_LT(worst_x[s], 0.1 * (amplitude_deg / 6.0) * (crossed / 6.0)) << "segment " << s + 1;
  }
  // The plan's theta_y is 0: following it in both axes holds theta_y to the
  // same 0.1 deg SPEC 3 gives (a layout its cables cannot bend both ways
  // swung 17-23 deg out of plane, issue 32).
  EXPECT_LT(worst_y, 0.1);
  // Every joint of a segment sees the same cable geometry: constant
  // curvature, to SPEC 3's half of the plan's bound (0.05 deg).
  EXPECT_LT(worst_spread, 0.05);
}

TEST(SecondArm, EffectsAreSizedToItsTwelveJoints) {
  const Config c = LoadConfig(kThreeSegment);
  EXPECT_EQ(c.parameters.arm, (ArmSize{12, 9}));
  const std::vector<std::string> offsets = EffectParameterNames("mocap_offset", c.parameters.arm);
  ASSERT_EQ(offsets.size(), 24u);
  EXPECT_EQ(offsets.back(), "mocap_offset.joint12_y_rad");
  ArmParameters p = c.parameters;
  EnableEffectAtRealisticMagnitude("mocap_offset", "--effect", &p);
  TrajectoryFrame frame;
  frame.joint_angles.assign(12, Eigen::Vector2d::Zero());
  const std::vector<Eigen::Vector2d> recorded = RecordedJointAngles(p, frame);
  for (int j = 0; j < 12; ++j) {
    EXPECT_EQ(recorded[j][0], GetParameter(p, offsets[2 * j])) << offsets[2 * j];
    EXPECT_NE(recorded[j][0], 0.0) << "joint " << j + 1 << " is not offset";
  }
}

}  // namespace
}  // namespace ccsrm::sim
