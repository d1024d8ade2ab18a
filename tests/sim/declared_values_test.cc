// Declared values (issue 28): a relative correction of a configuration's
// measured value, by name, that runs the arm exactly as a configuration
// with the corrected value does, and changes nothing while not given.
#include "ccsrm/sim/declared_values.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {
using ::testing::HasSubstr;

Config Paper() {
  Config c = LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml");
  c.protocol.ramp_s = 1.0;
  c.protocol.hold_s = 0.5;
  return c;
}

// A frame's joint angles, one vector.
Eigen::VectorXd Angles(const TrajectoryFrame& frame) {
  Eigen::VectorXd out(2 * static_cast<Eigen::Index>(frame.joint_angles.size()));
  for (std::size_t j = 0; j < frame.joint_angles.size(); ++j) {
    out.segment<2>(2 * static_cast<Eigen::Index>(j)) = frame.joint_angles[j];
  }
  return out;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Simulates the protocol's ramp and hold of `config`'s arm with `parameters`.
Trajectory RunRamp(const Config& config, const ArmModel& model, const ArmParameters& parameters) {
  const double duration = config.protocol.ramp_s + config.protocol.hold_s;
  const CableInputs inputs =
      PlanCableInputs(model, PaperTrajectory(model, config.protocol), duration);
  SimulationOptions options;
  options.duration_s = duration;
  options.solver = config.solver;
  SimulationResult r = Simulate(model, parameters, inputs, options);
  EXPECT_TRUE(r.summary.completed()) << r.summary.message;
  return r.trajectory;
}

TEST(DeclaredValues, NamedPerArmAndSegmentWithTheTablesBounds) {
  const Config c = Paper();
  EXPECT_EQ(c.parameters.arm.segments, 2);
  const std::vector<ParameterInfo> list = DeclaredValueParameters(c.arm.size());
  ASSERT_EQ(list.size(), 4u + 2u * 7u);  // four arm-wide, seven per segment
  EXPECT_EQ(list[0].name, "declared.joint_disk_gap");
  EXPECT_EQ(FindParameter("declared.segment2.link_length", "t", c.arm.size()).config_key,
            "arm.segments[1].link_length_m");
  EXPECT_DOUBLE_EQ(DeclaredValue(c.arm, "declared.segment2.link_length"), 0.100);
  EXPECT_DOUBLE_EQ(DeclaredValue(c.arm, "declared.segment1.large_s_pulley_radius"), 0.016);
  EXPECT_THAT(
      ErrorOf([&] { FindParameter("declared.segment3.link_length", "--free", c.arm.size()); }),
      HasSubstr("this arm has 2 segments"));
  EXPECT_THAT(ErrorOf([&] { FindParameter("declared.segment1.colour", "--free", c.arm.size()); }),
              HasSubstr("unknown parameter 'declared.segment1.colour'"));
  ArmParameters p = c.parameters;
  EXPECT_EQ(GetParameter(p, "declared.joint_disk_gap"), 0.0);  // as declared
  SetParameter("declared.joint_disk_gap", 0.03, "t", &p);
  EXPECT_EQ(GetParameter(p, "declared.joint_disk_gap"), 0.03);
  EXPECT_TRUE(p.effects_on.empty());  // a declared value is no effect
  // ±30 %: an error, not another arm.
  EXPECT_THAT(ErrorOf([&] { SetParameter("declared.joint_disk_gap", -0.5, "--set", &p); }),
              HasSubstr("is outside [-0.3, 0.3]"));
}

TEST(DeclaredValues, ACorrectionRunsAsTheCorrectedConfigurationAndZeroChangesNothing) {
  const Config c = Paper();
  const ArmModel model(c.arm);
  const Trajectory declared = RunRamp(c, model, c.parameters);
  // Zero corrections given: bit for bit the declared arm's run.
  ArmParameters zero = c.parameters;
  SetParameter("declared.segment2.link_length", 0.0, "t", &zero);
  const Trajectory same = RunRamp(c, model, zero);
  ASSERT_EQ(same.size(), declared.size());
  for (std::size_t f = 0; f < same.size(); ++f) {
    ASSERT_EQ(Angles(same.frames[f]), Angles(declared.frames[f])) << f;
  }
  // A link 1 % long and a large-S pulley 5 % large, by name: bit for bit the
  // run of a configuration that declares them so.
  ArmParameters corrected = c.parameters;
  SetParameter("declared.segment2.link_length", 0.01, "t", &corrected);
  SetParameter("declared.segment1.large_s_pulley_radius", 0.05, "t", &corrected);
  Config edited = c;
  edited.arm.segments[1].link_length_m = 0.100 * 1.01;
  edited.arm.segments[0].large_s.pulley_radius_m = 0.016 * 1.05;
  const ArmModel edited_model(edited.arm);
  // Planned on the declared arm: the same inputs drive both.
  const double duration = c.protocol.ramp_s + c.protocol.hold_s;
  const CableInputs inputs = PlanCableInputs(model, PaperTrajectory(model, c.protocol), duration);
  SimulationOptions options;
  options.duration_s = duration;
  options.solver = c.solver;
  const SimulationResult a = Simulate(model, corrected, inputs, options);
  const SimulationResult b = Simulate(edited_model, c.parameters, inputs, options);
  ASSERT_TRUE(a.summary.completed() && b.summary.completed());
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  double moved = 0.0;
  for (std::size_t f = 0; f < a.trajectory.size(); ++f) {
    ASSERT_EQ(Angles(a.trajectory.frames[f]), Angles(b.trajectory.frames[f])) << f;
    moved = std::max(
        moved, (Angles(a.trajectory.frames[f]) - Angles(declared.frames[f])).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(moved, 0.0);  // and it is another arm than the declared one
  // The corrected arm itself.
  const ArmConfig arm = CorrectedArm(c.arm, corrected);
  EXPECT_DOUBLE_EQ(arm.segments[1].link_length_m, 0.101);
  EXPECT_DOUBLE_EQ(arm.segments[0].large_s.pulley_radius_m, 0.0168);
  EXPECT_DOUBLE_EQ(arm.segments[0].link_length_m, 0.085);
}

}  // namespace
}  // namespace ccsrm::sim
