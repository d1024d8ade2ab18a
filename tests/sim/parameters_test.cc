// Named parameters (SPEC 6): one name, one configuration field, checked bounds.
#include "ccsrm/sim/parameters.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/declared_values.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {
namespace {
using ::testing::HasSubstr;

Config Paper() { return LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml"); }

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Parameters, SpecNamesInOrderEachMappedToItsConfigField) {
  std::vector<std::string> names;
  for (const ParameterInfo& p : Parameters()) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"mu", "mu_s", "mu_c", "mu_c_s", "beta", "c_sc", "c_lc",
                                             "T_p", "T_d0", "v_s", "v_c_s", "tau_f", "tau_c_f",
                                             "xi_f", "xi_c", "k_b", "c_b"}));
  const ArmParameters c = Paper().parameters;
  EXPECT_EQ(GetParameter(c, "mu"), c.mu);
  EXPECT_EQ(GetParameter(c, "T_d0"), 100.0);
  EXPECT_EQ(GetParameter(c, "T_p"), 50.0);
  EXPECT_EQ(GetParameter(c, "c_lc"), 0.05);
  // Setting each one changes exactly its own field.
  for (const ParameterInfo& p : Parameters()) {
    ArmParameters changed = c;
    const double value = 0.5 * (p.lower + p.upper);
    SetParameter(p.name, value, "test", &changed);
    for (const ParameterInfo& other : Parameters()) {
      EXPECT_EQ(GetParameter(changed, other.name),
                other.name == p.name ? value : GetParameter(c, other.name))
          << p.name << " changed " << other.name;
    }
  }
}

// Every door checks a value against the one table and says the same thing
// about it; only the place named before it differs.
TEST(Parameters, OutOfBoundsValueGetsOneMessageFromEveryDoor) {
  const std::string text = ReadTextFile(CCSRM_SOURCE_DIR "/configs/paper.yaml");
  for (const ParameterInfo& p : Parameters()) {
    const double value = p.upper * 2.0 + 1.0;
    const std::string expected = ParameterValueProblem(p, value);
    ASSERT_THAT(expected, HasSubstr("parameter '" + p.name + "'"));
    // A configuration file: the parameter's key in its cable section.
    const std::string key = p.config_key.substr(p.config_key.find('.') + 1);
    const std::string section = p.config_key.substr(0, p.config_key.find('.'));
    // An optional section the paper's arm has no use for (backbone) is
    // added.
    std::string edited = text;
    if (text.find("\n" + section + ":") == std::string::npos) {
      edited += section + ":\n  " + key + ": 1\n";
    }
    const std::size_t at = edited.find("\n  " + key + ":", edited.find(section + ":"));
    ASSERT_NE(at, std::string::npos) << p.config_key;
    const std::size_t end = edited.find('\n', at + 1);
    edited.replace(at, end - at, "\n  " + key + ": " + std::to_string(value));
    const std::string from_config = ErrorOf([&] { ParseConfig(edited, "arm.yaml"); });
    EXPECT_THAT(from_config, HasSubstr("key '" + p.config_key + "': " + expected));
    // --set and --params.
    ArmParameters parameters = Paper().parameters;
    const std::string from_set =
        ErrorOf([&] { SetParameter(p.name, value, "--set", &parameters); });
    EXPECT_EQ(from_set, "--set: " + expected);
    const std::string from_params = ErrorOf([&] {
      ApplyParameterYaml(p.name + ": " + std::to_string(value) + "\n", "p.yaml", &parameters);
    });
    EXPECT_EQ(from_params, "p.yaml: line 1, key '" + p.name + "': " + expected);
    // Simulate's own check of the value it is handed.
    parameters.*p.field = value;
    std::string error;
    EXPECT_FALSE(parameters.IsValid(&error));
    EXPECT_EQ(error, expected);
  }
  // The bounds the configuration used to check on its own are gone: beta
  // above the table's 0.1 s and T_p below its 1 N are refused from a file.
  EXPECT_THAT(ErrorOf([&] {
                std::string edited = text;
                edited.replace(edited.find("rayleigh_beta_s: 1.0e-3"), 23, "rayleigh_beta_s: 0.5");
                ParseConfig(edited, "arm.yaml");
              }),
              HasSubstr("parameter 'beta' = 0.5 is outside [0, 0.1] s"));
}

TEST(Parameters, AssignmentsParseAndBadOnesNameTheProblem) {
  EXPECT_EQ(ParseParameterAssignment("mu=0.18", "--set"), std::make_pair(std::string("mu"), 0.18));
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("mu", "--set"); }),
              HasSubstr("--set: 'mu': expected name=value"));
  EXPECT_THAT(
      ErrorOf([] { ParseParameterAssignment("nu=1", "--set"); }),
      HasSubstr(
          "unknown parameter 'nu' (known: mu, mu_s, mu_c, mu_c_s, beta, c_sc, c_lc, "
          "T_p, T_d0, v_s, v_c_s, tau_f, tau_c_f, xi_f, xi_c, k_b, c_b; effects' parameters as "
          "<effect>.<parameter>"));
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("mu=0.1x", "--set"); }),
              HasSubstr("value '0.1x' is not a number"));
  // Numbers a double cannot hold say so, not that they are no number.
  EXPECT_EQ(ErrorOf([] { ParseParameterAssignment("mu=1e-400", "--set"); }),
            "--set: 'mu=1e-400': value '1e-400' underflows: it is nearer 0 than a double can hold "
            "(2.2e-308); write 0 if 0 is meant");
  EXPECT_EQ(ErrorOf([] { ParseParameterAssignment("mu=1e400", "--set"); }),
            "--set: 'mu=1e400': value '1e400' is outside the range of a double (magnitude above "
            "1.8e+308)");
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("mu=nan", "--set"); }),
              HasSubstr("value 'nan' is not a finite number"));
  EXPECT_EQ(ParseParameterAssignment("mu=0", "--set").second, 0.0);
  ArmParameters c = Paper().parameters;
  EXPECT_THAT(ErrorOf([&] { SetParameter("T_d0", -5, "--set", &c); }),
              HasSubstr("--set: parameter 'T_d0' = -5 is outside [1, 1000] N"));
  EXPECT_EQ(GetParameter(c, "T_d0"), 100.0);  // unchanged
}

TEST(Parameters, YamlFileFlatOrTruthStyleWithLineAndKeyInErrors) {
  ArmParameters c = Paper().parameters;
  const auto applied = ApplyParameterYaml("mu: 0.1\nc_sc: 0.2\n", "p.yaml", &c);
  EXPECT_EQ(applied.size(), 2u);
  EXPECT_EQ(c.mu, 0.1);
  EXPECT_EQ(c.c_sc, 0.2);
  ApplyParameterYaml("schema: ccsrm-truth/1\nseed: 3\nparameters:\n  T_p: 40\n", "t.yaml", &c);
  EXPECT_EQ(c.T_p, 40.0);
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("mu: 0.1\nmuu: 0.2\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: line 2, key 'muu': unknown parameter"));
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("parameters:\n  beta: [1]\n", "t.yaml", &c); }),
              HasSubstr("t.yaml: line 2, key 'parameters.beta': expected a number"));
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("mu: 5\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: line 1, key 'mu': parameter 'mu' = 5 is outside [0, 2]"));
  // A bad file changes nothing, not even the values before the bad line.
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("c_sc: 0.3\nmu: 5\n", "p.yaml", &c); }),
              HasSubstr("line 2"));
  EXPECT_EQ(c.c_sc, 0.2);
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("- mu\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: expected a mapping"));
}

TEST(Parameters, YamlFileWithADuplicateKeyNamesBothLines) {
  // yaml-cpp keeps the first 'mu' and would drop the second without a word.
  ArmParameters c = Paper().parameters;
  EXPECT_EQ(ErrorOf([&] { ApplyParameterYaml("mu: 0.1\nc_sc: 0.2\nmu: 0.3\n", "p.yaml", &c); }),
            "p.yaml: line 3, key 'mu': duplicate key (first at line 1)");
  EXPECT_EQ(
      ErrorOf([&] { ApplyParameterYaml("parameters:\n  T_p: 40\n  T_p: 45\n", "t.yaml", &c); }),
      "t.yaml: line 3, key 'parameters.T_p': duplicate key (first at line 2)");
  EXPECT_EQ(c.mu, Paper().parameters.mu);  // unchanged
}

TEST(Parameters, YamlNumbersOutsideADoubleOrNotFiniteSaySo) {
  ArmParameters c = Paper().parameters;
  EXPECT_EQ(ErrorOf([&] { ApplyParameterYaml("mu: 1e400\n", "p.yaml", &c); }),
            "p.yaml: line 1, key 'mu': '1e400' is outside the range of a double (magnitude above "
            "1.8e+308)");
  EXPECT_EQ(ErrorOf([&] { ApplyParameterYaml("mu: .nan\n", "p.yaml", &c); }),
            "p.yaml: line 1, key 'mu': '.nan' is not a finite number");
}

// Declared values (issue 28): a relative correction of a configuration's
// measured value, by name, that runs the arm exactly as a configuration
// with the corrected value does, and changes nothing while not given.

// The paper's arm on a short protocol (the ramp and hold of 1.5 s).
Config ShortPaper() {
  Config c = Paper();
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
  const Config c = ShortPaper();
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
  const Config c = ShortPaper();
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
