// Where the arm leaves the paper's ground (issue 32): cables that would
// push go slack instead and are reported, and joints are kept within the
// range where their disks have not met (docs/model-notes.md row 27).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

Config LoadBundled(const std::string& name) {
  return LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/" + name);
}

TEST(JointRange, IsWhereTheDisksMeet) {
  // Two disks d apart at the joint centre, R wide, touch at a tilt of
  // 2 atan(d / 2R); R is the widest hole circle through the joint.
  const ArmModel paper(LoadBundled("paper.yaml").arm);
  EXPECT_DOUBLE_EQ(paper.joint_range_rad(1), 2.0 * std::atan(0.016 / (2.0 * 0.021)));
  EXPECT_DOUBLE_EQ(paper.joint_range_rad(6), paper.joint_range_rad(1));
  EXPECT_DOUBLE_EQ(paper.joint_range_rad(7), 2.0 * std::atan(0.016 / (2.0 * 0.016)));
  EXPECT_NEAR(paper.joint_range_rad(1) / kDeg, 41.71, 0.005);
  const ArmModel three(LoadBundled("three-segment.yaml").arm);
  EXPECT_NEAR(three.joint_range_rad(1) / kDeg, 35.49, 0.005);
  EXPECT_NEAR(three.joint_range_rad(12) / kDeg, 56.14, 0.005);
  // The tilt is the angle between the links' axes, in any bending plane.
  EXPECT_NEAR(JointTiltRad(Eigen::Vector2d(0.3, 0.0)), 0.3, 1e-15);
  EXPECT_NEAR(JointTiltRad(Eigen::Vector2d(0.0, -0.3)), 0.3, 1e-15);
  EXPECT_NEAR(JointTiltRad(Eigen::Vector2d(0.2, 0.2)), std::acos(std::cos(0.2) * std::cos(0.2)),
              1e-15);
}

TEST(JointRange, PlannerRefusesAMotionPastItNamingTheJoint) {
  // Issue 32's -40 deg on the three-segment arm: its segment 1 bends at most
  // 35.5 deg per joint before the disks meet.
  Config three = LoadBundled("three-segment.yaml");
  three.protocol.amplitude_rad = -40.0 * kDeg;
  const ArmModel model(three.arm);
  try {
    PlanCableInputs(model, PaperTrajectory(model, three.protocol), three.protocol.duration_s(),
                    1e-2, "--amplitude");
    ADD_FAILURE() << "a plan past the joints' range was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("--amplitude"), std::string::npos) << message;
    EXPECT_NE(message.find("joint 1 (segment 1)"), std::string::npos) << message;
    EXPECT_NE(message.find("range of 35.5 deg"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // Within the range (and the paper's arm at 40 deg, its range 41.7 deg):
  // planned as before.
  three.protocol.amplitude_rad = -35.0 * kDeg;
  EXPECT_NO_THROW(PlanCableInputs(model, PaperTrajectory(model, three.protocol),
                                  three.protocol.duration_s(), 1e-2));
  Config paper = LoadBundled("paper.yaml");
  paper.protocol.amplitude_rad = 40.0 * kDeg;
  const ArmModel paper_model(paper.arm);
  EXPECT_NO_THROW(PlanCableInputs(paper_model, PaperTrajectory(paper_model, paper.protocol),
                                  paper.protocol.duration_s(), 1e-2));
}

// The paper's arm without friction, straight, with all three cables of
// segment 1 paid out together by twice their elastic stretch: bending can
// take up one cable's release only by shortening another's path, so
// nothing can take up all three and they must go slack.
struct PaidOutSegment {
  Config config = LoadBundled("paper.yaml");
  ArmModel model{config.arm};
  double stretch_m = 0.0;  // the elastic stretch of a segment-1 cable at T_d0
  double release_m = 0.0;
  static constexpr double kRamp = 0.5, kDuration = 1.0;
  CableInputs Inputs() {
    ApplyPaperCase(1, &config.parameters);
    const std::vector<LinkPose> straight =
        ForwardKinematics(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
    const double ea = config.arm.driving.youngs_modulus_pa * config.arm.driving.cross_section_m2;
    // The straight path is stretched by (lambda - 1) ~ T_d0 / EA.
    stretch_m = CablePathLength(model, 0, straight) * config.parameters.T_d0 / ea;
    release_m = 2.0 * stretch_m;
    const int samples = 1001;
    Eigen::VectorXd time(samples);
    Eigen::MatrixXd change = Eigen::MatrixXd::Zero(samples, model.num_cables());
    for (int k = 0; k < samples; ++k) {
      time[k] = kDuration * k / (samples - 1);
      for (int c = 0; c < 3; ++c) change(k, c) = -release_m * QuinticBlend(time[k] / kRamp);
    }
    return CableInputs(time, change);
  }
};

TEST(Slack, CablesPaidOutBeyondTheirStretchGoSlackInsteadOfPushing) {
  PaidOutSegment setup;
  const CableInputs inputs = setup.Inputs();
  SimulationOptions options;
  options.duration_s = PaidOutSegment::kDuration;
  options.solver = setup.config.solver;
  const SimulationResult result = Simulate(setup.model, setup.config.parameters, inputs, options);
  ASSERT_TRUE(result.summary.completed()) << result.summary.message;

  // No element of any cable ever pushes.
  double lowest = INFINITY;
  for (const TrajectoryFrame& frame : result.trajectory.frames) {
    for (const std::vector<double>& cable : frame.element_tension)
      for (double tension : cable) lowest = std::min(lowest, tension);
  }
  EXPECT_GE(lowest, 0.0);

  // The three cables of segment 1 are reported slack, once each, from the
  // moment their release passes their stretch to the end; segment 2's
  // cables stay taut.
  const std::vector<SlackInterval>& slack = result.summary.slack;
  ASSERT_EQ(slack.size(), 3u) << result.summary.FullReport();
  // The release passes the stretch halfway up the quintic ramp (at 0.25 s,
  // release = 2 x stretch x blend); without friction the whole cable
  // tightens or slackens at once, so within a few frames (10 ms each) of it.
  const double onset = PaidOutSegment::kRamp / 2.0;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(slack[c].cable, c + 1);
    EXPECT_NEAR(slack[c].start_s, onset, 0.03) << "cable " << c + 1;
    EXPECT_DOUBLE_EQ(slack[c].end_s, result.trajectory.time.back());
    EXPECT_EQ(slack[c].most_elements, setup.model.cables()[c].num_elements());
  }
  const TrajectoryFrame& last = result.trajectory.frames.back();
  for (int c = 3; c < 6; ++c) EXPECT_EQ(CountSlackElements(last.element_tension[c]), 0);
  const std::string report = result.summary.FullReport();
  EXPECT_NE(report.find("cable 1 slack from"), std::string::npos) << report;
}

TEST(JointRange, RunThatReachesItStopsNamingTheJoint) {
  // Case 2 planned at 40 deg (within joint 1's 41.7 deg): friction makes
  // the proximal joints bend further than planned, and joint 1 reaches its
  // range at about 13.45 s. The run stops there, keeping its frames.
  PaperRunOptions options;
  options.config_path = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
  options.case_number = 2;
  options.amplitude_deg = 40.0;
  options.duration_s = 16.0;
  const PaperRun run = PreparePaperRun(options);
  const SimulationResult result =
      Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
  EXPECT_EQ(result.summary.status, SimulationStatus::kDiverged);
  EXPECT_NE(result.summary.message.find("joint 1 tilted to 41.7"), std::string::npos)
      << result.summary.message;
  EXPECT_GT(result.summary.simulated_s, 12.0);
  EXPECT_LT(result.summary.simulated_s, 15.0);
  ASSERT_FALSE(result.trajectory.frames.empty());
  EXPECT_GT(JointTiltRad(result.trajectory.frames.back().joint_angles[0]),
            run.model.joint_range_rad(1));
}

TEST(Slack, SummarySaysNoneWhereNoCableWentSlack) {
  Config config = LoadBundled("paper.yaml");
  const ArmModel model(config.arm);
  const CableInputs inputs = PlanCableInputs(model, PaperTrajectory(model, config.protocol), 0.5);
  SimulationOptions options;
  options.duration_s = 0.5;
  options.solver = config.solver;
  const SimulationResult result = Simulate(model, config.parameters, inputs, options);
  ASSERT_TRUE(result.summary.completed());
  EXPECT_TRUE(result.summary.slack.empty());
  EXPECT_NE(result.summary.FullReport().find("slack cables:              none"), std::string::npos);
}

TEST(Slack, IntervalsAreTheStretchesOfConsecutiveSlackFrames) {
  const std::vector<double> time = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5};
  Eigen::MatrixXi count(6, 2);
  count << 0, 1,  //
      2, 1,       //
      3, 0,       //
      0, 0,       //
      1, 0,       //
      0, 4;
  const std::vector<SlackInterval> v = FindSlackIntervals(time, count);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[0].cable, 1);
  EXPECT_EQ(v[0].start_s, 0.1);
  EXPECT_EQ(v[0].end_s, 0.2);
  EXPECT_EQ(v[0].most_elements, 3);
  EXPECT_EQ(v[1].start_s, 0.4);
  EXPECT_EQ(v[1].end_s, 0.4);
  EXPECT_EQ(v[2].cable, 2);
  EXPECT_EQ(v[2].start_s, 0.0);
  EXPECT_EQ(v[2].end_s, 0.1);
  EXPECT_EQ(v[3].start_s, 0.5);
  EXPECT_EQ(v[3].most_elements, 4);
  EXPECT_EQ(CountSlackElements({10.0, 0.0, -1.0, 5.0}), 2);
}

}  // namespace
}  // namespace ccsrm::sim
