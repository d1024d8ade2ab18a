// Runs of the arm from protocol files and from recorded inputs (issue 25):
// the frictionless arm follows a two-axis protocol as it follows the
// paper's, and a protocol driven through a table of its own input lengths
// gives the same run. One process: the tests share the protocol's run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
const std::string kConfigs = std::string(CCSRM_SOURCE_DIR) + "/configs";

struct ProtocolRun {
  PaperRun run;
  SimulationResult result;
};

// Paper case 1 (no friction) on the paper's arm over configs/protocols/two-axis.yaml.
const ProtocolRun& TwoAxisCaseOne() {
  static const ProtocolRun* cached = [] {
    PaperRunOptions options;
    options.config_path = kConfigs + "/paper.yaml";
    options.protocol_path = kConfigs + "/protocols/two-axis.yaml";
    options.case_number = 1;
    PaperRun run = PreparePaperRun(options);
    SimulationResult result =
        Simulate(run.model, run.config.parameters, run.inputs, run.simulation);
    return new ProtocolRun{std::move(run), std::move(result)};
  }();
  return *cached;
}

// The sine of two-axis.yaml: segment 1, 16-22 s (after the 15 s move and
// a 1 s hold); the arm rings on for a couple of seconds after it.
constexpr double kSineStart = 16.0, kSineEnd = 22.0, kRingDown = 3.0;

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
  ASSERT_EQ(r.result.trajectory.time.back(), r.run.protocol->duration_s());
  const double error_x = LargestQuasiStaticError(*r.run.protocol, r.result.trajectory, 0);
  const double error_y = LargestQuasiStaticError(*r.run.protocol, r.result.trajectory, 1);
  std::printf(
      "two-axis, case 1, outside the sine: largest error to plan %.4f deg (theta_x), %.4f deg "
      "(theta_y)\n",
      error_x, error_y);
  // SPEC 3 asks the paper's case 1 to stay within 0.1 deg of the plan; it
  // does with both segments bent together (0.095 deg at 6 deg, the paper's
  // protocol). Pure kinematic planning leaves a static offset that grows
  // when the segments bend apart: 0.154 deg in segment 2's theta_x at -6 deg
  // with segment 1 straight or bent in theta_y, 0.101 deg in segment 1's
  // theta_y at 8 deg (measured in holds; 0.154 and 0.139 deg over this run
  // outside the sine, docs/protocols.md). So the paper's
  // 0.1 deg is not met here; this bound, twice it, guards the measured
  // offsets against regression (it is not a requirement of the physics).
  EXPECT_LT(error_x, 0.2);
  EXPECT_LT(error_y, 0.2);
  // And the motion is there to follow: 8 deg in theta_y, 6 deg in theta_x.
  double largest_y = 0.0, largest_x = 0.0;
  for (const TrajectoryFrame& frame : r.result.trajectory.frames) {
    largest_y = std::max(largest_y, std::abs(frame.joint_angles[0].y()));
    largest_x = std::max(largest_x, std::abs(frame.joint_angles[6].x()));
  }
  EXPECT_GT(largest_y * kDegPerRad, 8.5);  // 8 deg plus the sine
  EXPECT_GT(largest_x * kDegPerRad, 5.9);
}

TEST(TwoAxisProtocol, SineOnSegmentOneIsFollowedInPhaseAndAmplifiedBelowTheFirstMode) {
  const ProtocolRun& r = TwoAxisCaseOne();
  ASSERT_TRUE(r.result.summary.completed()) << r.result.summary.message;
  // Segment 1's theta_y about its value at the start of the sine, against
  // the plan's, over the sine.
  const Trajectory& trajectory = r.result.trajectory;
  double base = 0.0, planned_base = 0.0;
  double dot = 0.0, simulated_square = 0.0, planned_square = 0.0, worst_other_axis = 0.0;
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    const double t = trajectory.time[f];
    if (t < kSineStart) {
      base = trajectory.frames[f].joint_angles[0].y();
      planned_base = r.run.protocol->PlannedAngles(t)[0].y();
      continue;
    }
    if (t > kSineEnd) break;
    const JointAngles plan = r.run.protocol->PlannedAngles(t);
    const double simulated = trajectory.frames[f].joint_angles[0].y() - base;
    const double planned = plan[0].y() - planned_base;
    dot += simulated * planned;
    simulated_square += simulated * simulated;
    planned_square += planned * planned;
    // Segment 2 holds theta_x = -6 deg meanwhile.
    worst_other_axis = std::max(worst_other_axis,
                                std::abs(trajectory.frames[f].joint_angles[6].x() - plan[6].x()));
  }
  const double correlation = dot / std::sqrt(simulated_square * planned_square);
  const double gain = std::sqrt(simulated_square / planned_square);
  std::printf("two-axis sine: correlation %.3f, gain %.2f, segment 2 theta_x error %.3f deg\n",
              correlation, gain, worst_other_axis * kDegPerRad);
  // Driven below its first bending mode (about 0.9 Hz in this model), a
  // frictionless arm swings in phase with the drive and by more than it
  // (1 / (1 − (f/f1)²) = 1.4 for a single mode). Out of phase, or less than
  // planned, would mean the inputs do not bend the arm in theta_y as planned.
  EXPECT_GT(correlation, 0.95);
  EXPECT_GT(gain, 1.0);
  EXPECT_LT(gain, 2.0);
  // The swing of segment 1 reaches segment 2 only through the arm's
  // dynamics: it stays within the quasi-static bound above.
  EXPECT_LT(worst_other_axis * kDegPerRad, 0.2);
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
