// Runs of the arm from protocol files and from recorded inputs (issue 25):
// the frictionless arm follows a two-axis protocol as it follows the
// paper's, the kinematic plan's static offset is the pre-tension's, and a
// protocol driven through a table of its own input lengths gives the same
// run. One process: the tests share the protocol's run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
const std::string kConfigs = std::string(CCSRM_SOURCE_DIR) + "/configs";

// SPEC 3: the paper's case 1 (no friction) sits within 0.1° of its plan
// everywhere; a motion "followed" is held to the same.
constexpr double kFollowToleranceDeg = 0.1;

struct ProtocolRun {
  PaperRun run;
  SimulationResult result;
};

ProtocolRun RunCaseOne(const std::string& protocol_path) {
  PaperRunOptions options;
  options.config_path = kConfigs + "/paper.yaml";
  options.protocol_path = protocol_path;
  options.case_number = 1;
  PaperRun run = PreparePaperRun(options);
  SimulationResult result = Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
  return ProtocolRun{std::move(run), std::move(result)};
}

// Paper case 1 (no friction) on the paper's arm over configs/protocols/two-axis.yaml.
const ProtocolRun& TwoAxisCaseOne() {
  static const ProtocolRun* cached =
      new ProtocolRun(RunCaseOne(kConfigs + "/protocols/two-axis.yaml"));
  return *cached;
}

// The sine of two-axis.yaml: segment 1, 16-22 s (after the 15 s move and
// a 1 s hold); the arm rings on for a few seconds after it.
constexpr double kSineStart = 16.0, kSineEnd = 22.0, kRingDown = 4.0;

// Largest |simulated − planned| about `axis` over the frames outside the
// sine and its ring-down [deg].
double LargestQuasiStaticError(const Protocol& protocol, const Trajectory& trajectory, int axis) {
  double worst = 0.0;
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    const double t = trajectory.time[f];
    if (t >= kSineStart && t <= kSineEnd + kRingDown) continue;
    const JointAngles plan = protocol.PlannedAngles(t);
    for (std::size_t j = 0; j < plan.size(); ++j) {
      worst = std::max(worst, std::abs(trajectory.frames[f].joint_angles[j][axis] - plan[j][axis]));
    }
  }
  return worst * kDegPerRad;
}

TEST(TwoAxisProtocol, FrictionlessArmFollowsThePlanInBothAxesWhereItMovesSlowly) {
  const ProtocolRun& r = TwoAxisCaseOne();
  ASSERT_TRUE(r.result.summary.completed()) << r.result.summary.message;
  ASSERT_EQ(r.run.protocol->planning, InputPlanning::Method::kStaticEquilibrium);
  ASSERT_EQ(r.result.trajectory.time.back(), r.run.protocol->duration_s());
  const double error_x = LargestQuasiStaticError(*r.run.protocol, r.result.trajectory, 0);
  const double error_y = LargestQuasiStaticError(*r.run.protocol, r.result.trajectory, 1);
  std::printf(
      "two-axis, case 1, outside the sine: largest error to plan %.4f deg (theta_x), %.4f deg "
      "(theta_y)\n",
      error_x, error_y);
  EXPECT_LT(error_x, kFollowToleranceDeg);
  EXPECT_LT(error_y, kFollowToleranceDeg);
  // And the motion is there to follow: 8 deg in theta_y, 6 deg in theta_x.
  double largest_y = 0.0, largest_x = 0.0;
  for (const TrajectoryFrame& frame : r.result.trajectory.frames) {
    largest_y = std::max(largest_y, std::abs(frame.joint_angles[0].y()));
    largest_x = std::max(largest_x, std::abs(frame.joint_angles[6].x()));
  }
  EXPECT_GT(largest_y * kDegPerRad, 8.5);  // 8 deg plus the sine
  EXPECT_GT(largest_x * kDegPerRad, 5.9);
}

TEST(TwoAxisProtocol, SineBendsSegmentOneAsPlannedAndExcitesItsSShapedModeBelowResonance) {
  const ProtocolRun& r = TwoAxisCaseOne();
  ASSERT_TRUE(r.result.summary.completed()) << r.result.summary.message;
  const Trajectory& trajectory = r.result.trajectory;
  const int joints = r.run.protocol->segment_joints[0];  // segment 1: joints 1..6
  double worst_bend = 0.0, worst_joint = 0.0, worst_other_axis = 0.0, worst_other_bend = 0.0;
  double dot = 0.0, simulated_square = 0.0, planned_square = 0.0;
  double base = 0.0, planned_base = 0.0;  // joint 1's θy as the sine starts
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    const double t = trajectory.time[f];
    if (t < kSineStart) {
      base = trajectory.frames[f].joint_angles[0].y();
      planned_base = r.run.protocol->PlannedAngles(t)[0].y();
      continue;
    }
    if (t > kSineEnd) break;
    const JointAngles plan = r.run.protocol->PlannedAngles(t);
    const JointAngles& angles = trajectory.frames[f].joint_angles;
    // The segment's bend: the mean θy of its joints, what its three cables
    // set (they see the sum of the joints' angles).
    double bend = 0.0, planned_bend = 0.0;
    for (int j = 0; j < joints; ++j) {
      bend += angles[j].y() / joints;
      planned_bend += plan[j].y() / joints;
      worst_joint = std::max(worst_joint, std::abs(angles[j].y() - plan[j].y()));
    }
    worst_bend = std::max(worst_bend, std::abs(bend - planned_bend));
    // Joint 1's swing against the plan's.
    const double swing = angles[0].y() - base;
    const double planned_swing = plan[0].y() - planned_base;
    dot += swing * planned_swing;
    simulated_square += swing * swing;
    planned_square += planned_swing * planned_swing;
    // Segment 2 holds θx = −6° meanwhile, and its bend in θy stays 0 (its
    // joints swing in θy with segment 1's mode: ±0.35° at joints 7 and 12).
    double bend_2y = 0.0, planned_bend_2y = 0.0;
    for (int j = joints; j < static_cast<int>(plan.size()); ++j) {
      worst_other_axis = std::max(worst_other_axis, std::abs(angles[j].x() - plan[j].x()));
      bend_2y += angles[j].y() / (plan.size() - joints);
      planned_bend_2y += plan[j].y() / (plan.size() - joints);
    }
    worst_other_bend = std::max(worst_other_bend, std::abs(bend_2y - planned_bend_2y));
  }
  // The ring-down after the sine: segment 1's joint 1 about its final
  // value, its period from the zero crossings.
  std::vector<double> crossings;
  double previous = NAN;
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    const double t = trajectory.time[f];
    if (t < kSineEnd + 0.5 || t > kSineEnd + kRingDown) continue;
    const double x =
        trajectory.frames[f].joint_angles[0].y() - r.run.protocol->PlannedAngles(t)[0].y();
    if (!std::isnan(previous) && (x > 0.0) != (previous > 0.0)) crossings.push_back(t);
    previous = x;
  }
  ASSERT_GE(crossings.size(), 3u) << "segment 1 does not ring after the sine";
  const double mode_hz = 0.5 * (crossings.size() - 1) / (crossings.back() - crossings.front());
  const double correlation = dot / std::sqrt(simulated_square * planned_square);
  const double gain = std::sqrt(simulated_square / planned_square);
  std::printf(
      "two-axis sine: segment 1 bend error %.4f deg, largest joint error %.3f deg; joint 1 "
      "correlation %.3f, gain %.2f; ring-down at %.2f Hz; segment 2 theta_x error %.4f deg, "
      "theta_y bend error %.4f deg\n",
      worst_bend * kDegPerRad, worst_joint * kDegPerRad, correlation, gain, mode_hz,
      worst_other_axis * kDegPerRad, worst_other_bend * kDegPerRad);
  // The cables set the segment's bend, and it follows the 0.5 Hz sine as
  // the paper's case 1 follows its plan.
  EXPECT_LT(worst_bend * kDegPerRad, kFollowToleranceDeg);
  // How the bend spreads over the joints is left to the connecting cables,
  // whose finite stiffness against the links' masses makes an S-shaped
  // mode (joint 1 against joint 6; 1.4 Hz here): the drive sits below it,
  // so the root joint swings in phase with the plan and by more than it,
  // and the arm rings at that mode after the sine. Out of phase, less than
  // planned, or a ring below the drive's 0.5 Hz would contradict that.
  EXPECT_GT(correlation, 0.95);
  EXPECT_GT(gain, 1.0);
  EXPECT_GT(mode_hz, 0.5);
  // The swing of segment 1 reaches segment 2 only through the arm's
  // dynamics, and stays within the tolerance.
  EXPECT_LT(worst_other_axis * kDegPerRad, kFollowToleranceDeg);
  EXPECT_LT(worst_other_bend * kDegPerRad, kFollowToleranceDeg);
}

// Segment 2 bent to θx = −6° alone and held, by `planning`, at a driving
// cable pre-tension T_d0 [N]: the largest |error| of its joints at the end of
// the hold [deg].
double SegmentTwoHoldError(const std::string& planning, double pretension_n) {
  const std::string text = "schema: ccsrm-protocol/1\nplanning: " + planning +
                           "\nsegments:\n  1:\n    - hold: {duration_s: 9}\n"
                           "  2:\n    - move: {to: {theta_x_deg: -6}, duration_s: 6}\n"
                           "    - hold: {duration_s: 3}\n";
  const Config config = LoadConfig(kConfigs + "/paper.yaml");
  const ArmModel model(config.arm);
  const Protocol protocol = ParseProtocol(text, "segment-2.yaml", config.arm);
  ArmParameters parameters = config.parameters;
  ApplyPaperCase(1, &parameters);
  parameters.T_d0 = pretension_n;
  SimulationOptions simulation;
  simulation.duration_s = protocol.duration_s();
  simulation.solver = config.solver;
  const SimulationResult result =
      Simulate(model, parameters, PlanProtocolInputs(model, protocol, parameters, 9.0), simulation);
  EXPECT_TRUE(result.summary.completed()) << result.summary.message;
  double worst = 0.0;
  const JointAngles& angles = result.trajectory.frames.back().joint_angles;
  for (std::size_t j = 6; j < angles.size(); ++j) {
    worst = std::max(worst, std::abs(angles[j].x() * kDegPerRad + 6.0));
  }
  return worst;
}

TEST(InputPlanning, KinematicPlansOffsetTheArmInProportionToThePretension) {
  const double at_100 = SegmentTwoHoldError("kinematic", 100.0);
  const double at_25 = SegmentTwoHoldError("kinematic", 25.0);
  const double balanced = SegmentTwoHoldError("static_equilibrium", 100.0);
  std::printf(
      "segment 2 held at -6 deg: kinematic plan off by %.4f deg at T_d0 = 100 N, %.4f deg at "
      "25 N; static-equilibrium plan off by %.4f deg\n",
      at_100, at_25, balanced);
  // Equal tensions do not balance a bent segment: the sum of its cables'
  // path lengths shortens as it bends, so T_d0 pulls it further until the
  // cables' stretch (∝ 1/EA) balances it. The offset is first order in
  // T_d0/EA (2.9e-3 at 100 N): a quarter of the pre-tension, a quarter of
  // the offset, to within the second-order terms (~1 % of it).
  EXPECT_NEAR(at_100 / at_25, 4.0, 0.2);
  // Planning the tensions that balance the planned state removes it to
  // within the tolerance the paper's case 1 meets.
  EXPECT_LT(balanced, kFollowToleranceDeg);
  EXPECT_LT(balanced, 0.25 * at_100);
}

TEST(RecordedInputs, AProtocolDrivenThroughATableOfItsOwnInputLengthsGivesTheSameRun) {
  const ProtocolRun& r = TwoAxisCaseOne();
  ASSERT_TRUE(r.result.summary.completed()) << r.result.summary.message;
  // The table a lab's actuator log would be: the planned lengths at 100 Hz
  // in mm, written with every digit.
  std::string csv =
      "# two-axis.yaml, planned\ntime_s,cable1_mm,cable2_mm,cable3_mm,cable4_mm,"
      "cable5_mm,cable6_mm\n";
  for (double t = 0.0; t <= r.run.simulation.duration_s + 1e-9; t += 0.01) {
    char line[256];
    int n = std::snprintf(line, sizeof(line), "%.17g", t);
    for (int c = 0; c < r.run.model.num_cables(); ++c) {
      double value, rate, accel;
      r.run.inputs.Evaluate(c, t, &value, &rate, &accel);
      // Lengths below 1e-300 m are 0 to a log (and a reader refuses a
      // value that underflows a double).
      n += std::snprintf(line + n, sizeof(line) - n, ",%.17g",
                         std::abs(value) < 1e-300 ? 0.0 : value * 1e3);
    }
    csv += std::string(line) + "\n";
  }
  std::string note;
  const CableInputs recorded = MakeRecordedCableInputs(ParseInputTable(csv, "two-axis.csv"),
                                                       r.run.model.num_cables(), {}, &note);
  EXPECT_NE(note.find("used as recorded"), std::string::npos) << note;  // regular stamps
  const SimulationResult from_table =
      Simulate(r.run.model, r.run.config.parameters, recorded, r.run.simulation);
  ASSERT_TRUE(from_table.summary.completed()) << from_table.summary.message;
  ASSERT_EQ(from_table.trajectory.size(), r.result.trajectory.size());
  double worst = 0.0;
  for (std::size_t f = 0; f < from_table.trajectory.size(); ++f) {
    for (std::size_t j = 0; j < from_table.trajectory.frames[f].joint_angles.size(); ++j) {
      const Eigen::Vector2d d = from_table.trajectory.frames[f].joint_angles[j] -
                                r.result.trajectory.frames[f].joint_angles[j];
      worst = std::max(worst, d.cwiseAbs().maxCoeff());
    }
  }
  std::printf("protocol against its table of inputs: largest joint-angle difference %.3g deg\n",
              worst * kDegPerRad);
  // The two input splines (knots every 1 ms and every 10 ms) differ by
  // their interpolation error, ~h⁴ L'''' ≈ 1e-9 m here, which moves a joint
  // by ~1e-8 rad; what remains is the integrator's own noise, bounded by
  // its relative tolerance (1e-5) times the angles reached (9°): 1e-4°.
  EXPECT_LT(worst * kDegPerRad, 1e-4);
}

}  // namespace
}  // namespace ccsrm::sim
