// Protocol files (ccsrm-protocol/1): the paper's protocol as a file plans
// the same inputs as before to the bit; pieces, targets and rates; recorded
// inputs from a table, resampled.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "protocol_internal.h"

namespace ccsrm::sim {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180.0;
const std::string kConfigs = std::string(CCSRM_SOURCE_DIR) + "/configs";
const std::string kPaperConfig = kConfigs + "/paper.yaml";
const std::string kPaperProtocol = kConfigs + "/protocols/paper.yaml";

std::string ErrorOf(const std::string& yaml, const ArmConfig& arm) {
  try {
    ParseProtocol(yaml, "p.yaml", arm);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Every sample time and every length bit for bit.
void ExpectSameInputs(const CableInputs& a, const CableInputs& b) {
  ASSERT_EQ(a.time().size(), b.time().size());
  ASSERT_EQ(a.length_change().cols(), b.length_change().cols());
  for (Eigen::Index k = 0; k < a.time().size(); ++k) {
    ASSERT_EQ(a.time()[k], b.time()[k]) << "sample " << k;
    for (Eigen::Index c = 0; c < a.length_change().cols(); ++c) {
      ASSERT_EQ(a.length_change()(k, c), b.length_change()(k, c))
          << "sample " << k << " cable " << c + 1;
    }
  }
}

TEST(PaperProtocolFile, PlansTheSameAnglesAndInputsAsThePaperTrajectoryToTheBit) {
  Config config = LoadConfig(kPaperConfig);
  const ArmModel model(config.arm);
  // The paper's timing and the short one of the default paper-cases test,
  // at both signs of the amplitude (the conversions of the configuration
  // and of --amplitude).
  struct Timing {
    double ramp, hold, back, rest;
  };
  for (const Timing timing : {Timing{20, 4, 20, 4}, Timing{6, 2, 6, 2}}) {
    for (const double amplitude_rad : {6.0 * kDeg, -6.0 * M_PI / 180.0, 3.7 * kDeg}) {
      ProtocolConfig p = config.protocol;
      p.amplitude_rad = amplitude_rad;
      p.ramp_s = timing.ramp;
      p.hold_s = timing.hold;
      p.return_s = timing.back;
      p.rest_s = timing.rest;
      ProtocolOptions options;
      options.parameters = PaperProtocolParameters(p);
      const Protocol file = LoadProtocol(kPaperProtocol, config.arm, options);
      ASSERT_EQ(file.duration_s(), p.duration_s());
      const JointTrajectory paper = PaperTrajectory(model, p);
      for (double t = -1.0; t <= p.duration_s() + 1.0; t += 0.0005) {
        const JointAngles a = file.PlannedAngles(t), b = paper(t);
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t j = 0; j < a.size(); ++j) {
          // == on doubles: the same value, bit for bit (0 and -0 aside,
          // which give the same cable lengths).
          ASSERT_EQ(a[j].x(), b[j].x()) << "t = " << t << ", joint " << j + 1;
          ASSERT_EQ(a[j].y(), b[j].y()) << "t = " << t << ", joint " << j + 1;
        }
      }
      ExpectSameInputs(PlanProtocolInputs(model, file, config.parameters, p.duration_s()),
                       PlanCableInputs(model, paper, p.duration_s()));
    }
  }
}

TEST(PaperProtocolFile, IsWhatAPaperRunFollowsByDefault) {
  PaperRunOptions options;
  options.config_path = kPaperConfig;
  options.case_number = 2;
  options.amplitude_deg = -6.0;
  const PaperRun run = PreparePaperRun(options);
  ASSERT_TRUE(run.protocol.has_value());
  EXPECT_TRUE(run.default_protocol);
  EXPECT_THAT(run.protocol->source_name, HasSubstr("protocols/paper.yaml"));
  EXPECT_EQ(run.simulation.duration_s, 48.0);
  ProtocolConfig p = run.config.protocol;
  ExpectSameInputs(run.inputs, PlanCableInputs(run.model, PaperTrajectory(run.model, p), 48.0));
}

TEST(PaperProtocolFile, RunsAsWrittenWithItsAmplitudeSetFromTheOption) {
  PaperRunOptions options;
  options.config_path = kPaperConfig;
  options.protocol_path = kPaperProtocol;
  options.amplitude_deg = 3.0;
  options.duration_s = 10.0;
  const PaperRun run = PreparePaperRun(options);
  EXPECT_FALSE(run.default_protocol);
  EXPECT_NEAR(run.protocol->PlannedAngles(20.0)[0].x(), 3.0 * kDeg, 1e-15);
  // The file records the amplitude it ran with.
  EXPECT_THAT(run.protocol->ToYaml(), HasSubstr("amplitude_deg: 3"));
}

TEST(TwoAxisProtocol, BendsSegmentOneInThetaYAndSegmentTwoInThetaXThenSwingsSegmentOne) {
  const Config config = LoadConfig(kPaperConfig);
  const Protocol p = LoadProtocol(kConfigs + "/protocols/two-axis.yaml", config.arm);
  ASSERT_EQ(p.segments.size(), 2u);
  const JointAngles bent = p.PlannedAngles(15.0);  // both moves done, before the sine
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(bent[j].x(), 0.0, 1e-15);
    EXPECT_NEAR(bent[j].y(), 8.0 * kDeg, 1e-15);
    EXPECT_NEAR(bent[6 + j].x(), -6.0 * kDeg, 1e-15);
    EXPECT_NEAR(bent[6 + j].y(), 0.0, 1e-15);
  }
  // The sine (3 cycles at 0.5 Hz after the 15 s move and 1 s hold): segment
  // 1's θy leaves 8° by up to its 1° amplitude, segment 2 holds.
  double swing = 0.0;
  for (double t = 16.0; t <= 22.0; t += 0.01) {
    const JointAngles a = p.PlannedAngles(t);
    swing = std::max(swing, std::abs(a[0].y() - 8.0 * kDeg));
    EXPECT_NEAR(a[6].x(), -6.0 * kDeg, 1e-15);
  }
  EXPECT_GT(swing, 0.95 * kDeg);
  EXPECT_LE(swing, 1.0 * kDeg + 1e-12);
  EXPECT_NEAR(p.PlannedAngles(p.duration_s() + 1.0)[0].y(), 0.0, 1e-15);
}

TEST(StaticEquilibriumPlanning, PullsTheStretchWhoseTensionsBalanceEveryBentSegment) {
  const Config config = LoadConfig(kPaperConfig);
  const ArmModel model(config.arm);
  const Protocol kinematic = LoadProtocol(kConfigs + "/protocols/two-axis.yaml", config.arm);
  ASSERT_EQ(kinematic.planning, InputPlanning::Method::kStaticEquilibrium);  // as the file asks
  InputPlanning balanced;
  balanced.method = InputPlanning::Method::kStaticEquilibrium;
  balanced.pretension_n = 100.0;
  const CableInputs plain = PlanCableInputs(model, kinematic.Trajectory(), 16.0, 1e-3);
  const CableInputs planned =
      PlanCableInputs(model, kinematic.Trajectory(), 16.0, 1e-3, "two-axis", balanced);
  // Straight (t = 0), equal tensions balance: nothing to add but the
  // rounding of moments that cancel (~1e-15 m).
  for (int c = 0; c < model.num_cables(); ++c) {
    EXPECT_NEAR(planned.length_change()(0, c), plain.length_change()(0, c), 1e-13);
  }
  // Bent (t = 15 s: segment 1 at θy = 8°, segment 2 at θx = −6°): the
  // tensions the extra pull implies, T_d0 + EA·Δu/L, have no moment on
  // either segment's bending, where T_d0 alone has one. Moment arms here by
  // a step (1e-5 rad) other than the planner's.
  const JointAngles bent = kinematic.PlannedAngles(15.0);
  const std::vector<LinkPose> poses = ForwardKinematics(model, bent);
  const double ea = config.arm.driving.youngs_modulus_pa * config.arm.driving.cross_section_m2;
  const int k = 15000;
  ASSERT_EQ(planned.time()[k], 15.0);
  int bent_axes = 0;  // those on which T_d0 alone has a moment
  for (int segment = 0; segment < 2; ++segment) {
    for (int axis = 0; axis < 2; ++axis) {
      JointAngles plus = bent, minus = bent;
      for (int j = 6 * segment; j < 6 * segment + 6; ++j) {
        plus[j][axis] += 1e-5;
        minus[j][axis] -= 1e-5;
      }
      double moment = 0.0, unbalanced = 0.0;
      for (int c = 0; c < model.num_cables(); ++c) {
        const double arm = (CablePathLength(model, c, ForwardKinematics(model, plus)) -
                            CablePathLength(model, c, ForwardKinematics(model, minus))) /
                           2e-5;
        const double extra = planned.length_change()(k, c) - plain.length_change()(k, c);
        const double tension = 100.0 + ea * extra / CablePathLength(model, c, poses);
        moment += tension * arm;
        unbalanced += 100.0 * arm;
      }
      // Straight the pre-tension's moment is 0; bent 8° or 6° it is first
      // order in the bend. The balance leaves the two steps' truncation,
      // ~1e-6 of it.
      if (std::abs(unbalanced) > 1e-3) {
        ++bent_axes;
        EXPECT_LT(std::abs(moment), 1e-5 * std::abs(unbalanced))
            << "segment " << segment + 1 << " axis " << axis;
      }
    }
  }
  EXPECT_EQ(bent_axes, 2);  // segment 1 in θy, segment 2 in θx
}

TEST(ProtocolPieces, RatesAreTheDerivativesOfTheAngles) {
  const Config config = LoadConfig(kPaperConfig);
  const Protocol p = LoadProtocol(kConfigs + "/protocols/examples.yaml", config.arm);
  const double h = 1e-6;
  double worst = 0.0, largest = 0.0;
  for (double t = 0.0; t < p.duration_s(); t += 0.0137) {
    const JointAngles rate = p.PlannedRates(t);
    const JointAngles ahead = p.PlannedAngles(t + h), behind = p.PlannedAngles(t - h);
    for (std::size_t j = 0; j < rate.size(); ++j) {
      const Eigen::Vector2d fd = (ahead[j] - behind[j]) / (2.0 * h);
      worst = std::max(worst, (fd - rate[j]).cwiseAbs().maxCoeff());
      largest = std::max(largest, rate[j].cwiseAbs().maxCoeff());
    }
  }
  EXPECT_GT(largest, 0.01);  // rad/s: the protocol moves
  // Central differences at h = 1e-6 s: truncation ~h² θ''' and rounding
  // ~1e-16/h, both below 1e-8 rad/s, except across a piece's join where
  // the rate is continuous but a difference straddles two formulas.
  EXPECT_LT(worst, 1e-6);
}

TEST(ProtocolTargets, PlaneAndBendPointTheLinkAxisIntoThePlane) {
  for (double plane_deg : {0.0, 45.0, 90.0, 135.0, 200.0, 270.0}) {
    const double plane = plane_deg * kDeg, bend = 10.0 * kDeg;
    const Eigen::Vector2d cardan = internal::PlaneBendToCardan(plane, bend);
    const Eigen::Vector3d axis = RotX(cardan.x()) * RotY(cardan.y()) * Eigen::Vector3d::UnitZ();
    // Bent by `bend` from z, toward (cos φ, sin φ, 0).
    EXPECT_NEAR(std::acos(axis.z()), bend, 1e-12) << plane_deg;
    EXPECT_NEAR(std::atan2(axis.y(), axis.x()), std::remainder(plane, 2 * M_PI), 1e-12)
        << plane_deg;
  }
}

TEST(ProtocolChecks, RefuseWhatCannotBeRunNamingLineAndKey) {
  const ArmConfig arm = LoadConfig(kPaperConfig).arm;
  const std::string head = "schema: ccsrm-protocol/1\nsegments:\n  all:\n";
  EXPECT_THAT(ErrorOf(head + "    - hold: {duraton_s: 1}\n", arm),
              HasSubstr("p.yaml: line 4, key 'segments.all[0].hold.duraton_s': unknown key"));
  EXPECT_THAT(ErrorOf(head + "    - move: {to: {theta_x_deg: 5}, duration_s: -1}\n", arm),
              HasSubstr("key 'segments.all[0].move.duration_s': must be > 0"));
  EXPECT_THAT(ErrorOf(head + "    - sine: {amplitude: {theta_x_deg: 1}, frequency_hz: 1, "
                             "cycles: 2, fade_s: 0}\n",
                      arm),
              HasSubstr("starts with a jump in rate"));
  EXPECT_THAT(ErrorOf(head + "    - move: {to: {theta_x_deg: 50}, duration_s: 40}\n", arm),
              HasSubstr("past its 41.71 deg"));
  EXPECT_THAT(ErrorOf("schema: ccsrm-protocol/1\nsegments:\n  3: [{hold: {duration_s: 1}}]\n", arm),
              HasSubstr("the arm has 2 segments"));
  EXPECT_THAT(ErrorOf("schema: ccsrm-protocol/1\nsegments:\n  1: [{hold: {duration_s: 1}}]\n", arm),
              HasSubstr("has no pieces for segment 2"));
  EXPECT_THAT(ErrorOf(head + "    - move: {to: {theta_x_deg: [1, 2]}, duration_s: 5}\n", arm),
              HasSubstr("has 2 values, the segment has 6 joints"));
  EXPECT_THAT(ErrorOf(head + "    - move: {to: {theta_x_deg: big_deg}, duration_s: 5}\n", arm),
              HasSubstr("expected a number or a parameter's name, found 'big_deg'"));
  EXPECT_THAT(
      ErrorOf("schema: ccsrm-protocol/2\nsegments: {all: [{hold: {duration_s: 1}}]}\n", arm),
      HasSubstr("unsupported version"));
}

TEST(ProtocolChecks, RefuseACableFasterThanTheLimitNamingThePiece) {
  const Config config = LoadConfig(kPaperConfig);
  const ArmModel model(config.arm);
  // 10° of every joint in a 0.5 s rise pulls cable 4 by about 12 joints ×
  // 16 mm × sin 60° × 0.17 rad = 29 mm, at up to 1.875 × 29 mm / 0.5 s =
  // 0.11 m/s (its acceleration, 5.77 × 29 mm / 0.25 s² = 0.67 m/s², within 1).
  const Protocol p = ParseProtocol(
      "schema: ccsrm-protocol/1\nsegments:\n  all:\n"
      "    - step: {to: {theta_x_deg: 10}, rise_s: 0.5, duration_s: 1}\n",
      "p.yaml", config.arm);
  try {
    PlanProtocolInputs(model, p, config.parameters, p.duration_s());
    FAIL() << "a 0.11 m/s cable passed";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("p.yaml: line 4, key 'segments.all[0].step'"));
    EXPECT_THAT(e.what(), HasSubstr("beyond limits.cable_speed_mps = 0.1"));
  }
}

// Issue 44: simulate's summary gives the error to the plan per segment. A
// trajectory that is the plan has none; one joint off by 0.5 deg at one
// frame is the largest, on its own segment only, with its RMS over the
// segment's frames, joints and axes.
TEST(PlanErrors, AreTheDistanceToThePlanPerSegment) {
  PaperRunOptions options;
  options.config_path = kPaperConfig;
  options.duration_s = 4.0;
  const PaperRun run = PreparePaperRun(options);
  Trajectory trajectory;
  for (int f = 0; f <= 40; ++f) {
    const double t = 0.1 * f;
    TrajectoryFrame frame;
    for (const Eigen::Vector2d& a : run.protocol->PlannedAngles(t)) frame.joint_angles.push_back(a);
    trajectory.time.push_back(t);
    trajectory.frames.push_back(frame);
  }
  for (const PlanError& e : PlanErrors(run, trajectory)) EXPECT_EQ(e.max_abs_rad, 0.0);
  trajectory.frames[30].joint_angles[8].y() += 0.5 * kDeg;  // joint 9 θy, segment 2, t = 3 s
  const std::vector<PlanError> errors = PlanErrors(run, trajectory);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].max_abs_rad, 0.0);
  EXPECT_NEAR(errors[1].max_abs_rad, 0.5 * kDeg, 1e-12);
  EXPECT_EQ(errors[1].worst_joint, 9);
  EXPECT_EQ(errors[1].worst_axis, 1);
  EXPECT_DOUBLE_EQ(errors[1].worst_time_s, 3.0);
  // One error among 41 frames x 6 joints x 2 axes.
  EXPECT_NEAR(errors[1].rms_rad, 0.5 * kDeg / std::sqrt(41.0 * 12.0), 1e-12);
}

TEST(RecordedInputTable, ReadsUnitsFromTheHeaderAndResamplesIrregularStampsLinearly) {
  const std::string csv =
      "# actuator log\n"
      "time_ms,cable2_mm,cable1_mm,note\n"
      "0,0,0,start\n"
      "10,1,2,x\n"
      "25,2,4,x\n"
      "30,3,6,x\n";
  const RecordedInputs r = ParseInputTable(csv, "log.csv");
  ASSERT_EQ(r.length_change_m.cols(), 2);
  EXPECT_DOUBLE_EQ(r.time_s[2], 0.025);
  EXPECT_DOUBLE_EQ(r.length_change_m(1, 0), 0.002);  // cable 1 first, whatever the column order
  std::string note;
  const CableInputs inputs = MakeRecordedCableInputs(r, 2, {}, &note);
  EXPECT_THAT(note, HasSubstr("resampled linearly every 0.01 s"));
  ASSERT_EQ(inputs.time().size(), 4);
  EXPECT_DOUBLE_EQ(inputs.time()[2], 0.02);
  // 20 ms lies a third of the way from 10 ms (2 mm) to 25 ms (4 mm).
  EXPECT_NEAR(inputs.length_change()(2, 0), 0.002 + 0.002 * (10.0 / 15.0), 1e-15);
}

TEST(RecordedInputTable, RefusesWhatCannotDriveTheArm) {
  auto error = [](const std::string& csv, int cables = 2) -> std::string {
    try {
      MakeRecordedCableInputs(ParseInputTable(csv, "in.csv"), cables);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_THAT(error("time_s,cable1_m,cable2_m\n0,0,0\n0.02,0,0\n0.01,0,0\n"),
              HasSubstr("in.csv: line 4, column 'time_s': time 0.01 s does not increase"));
  EXPECT_THAT(error("time_s,cable1_m,cable3_m\n0,0,0\n"), HasSubstr("no column for cable 2"));
  EXPECT_THAT(error("time_s,cable1_m,cable2_m\n0,0,0\n0.01,0,0\n", 6),
              HasSubstr("has 2 cable columns, the arm has 6 driving cables"));
  EXPECT_THAT(error("time_s,cable1_m,cable2_m\n0,0,0\n0.01,nan,0\n"),
              HasSubstr("line 3, column 'cable1_m': 'nan' is not a finite number"));
  EXPECT_THAT(error("time_s,cable1_m,cable2_m\n0,0,0\n0.01,0,0\n0.5,0,0\n"),
              HasSubstr("line 4, column 'time_s': a gap of 0.49 s"));
  EXPECT_THAT(error("time,cable1_m,cable2_m\n0,0,0\n"), HasSubstr("needs its unit"));
}

}  // namespace
}  // namespace ccsrm::sim
