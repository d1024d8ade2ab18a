#include "ccsrm/sim/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/describe.h"
#include "ccsrm/sim/paper_run.h"

namespace ccsrm::sim {
namespace {
using ::testing::HasSubstr;

const std::string kPaperConfig = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";

std::string PaperText() { return ReadTextFile(kPaperConfig); }

// Replaces the first occurrence of `from` in the paper configuration.
std::string Edited(const std::string& from, const std::string& to) {
  std::string text = PaperText();
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  return text;
}

std::string ErrorOf(const std::string& text) {
  try {
    ParseConfig(text, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// Line (1-based) of the first occurrence of `needle` in `text`.
int LineOf(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n';
  return line;
}

TEST(Config, PaperConfigurationHoldsTable1) {
  const Config c = LoadConfig(kPaperConfig);
  ASSERT_EQ(c.arm.segments.size(), 2u);
  EXPECT_EQ(c.arm.total_links(), 12);
  EXPECT_DOUBLE_EQ(c.arm.segments[0].link_length_m, 0.085);
  EXPECT_DOUBLE_EQ(c.arm.segments[1].link_length_m, 0.100);
  EXPECT_DOUBLE_EQ(c.arm.segments[0].link_inertia_kgm2[0], 66e-6);
  EXPECT_DOUBLE_EQ(c.arm.segments[1].hole_circle_radius_m, 0.016);
  EXPECT_NEAR(c.arm.segments[0].large_s.wrap_angle_rad, 184.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(c.arm.segments[0].connecting_pattern[1], ConnectingKind::kLargeS);
  EXPECT_EQ(c.arm.driving.cables.size(), 6u);
  EXPECT_EQ(c.arm.driving.cables[3].segment, 2);
  EXPECT_NEAR(c.arm.driving.cables[3].hole_angle_rad, M_PI / 3.0, 1e-15);
  EXPECT_DOUBLE_EQ(c.arm.driving.youngs_modulus_pa, 2.6e10);
  EXPECT_DOUBLE_EQ(c.parameters.T_p, 50.0);
  EXPECT_DOUBLE_EQ(c.parameters.mu_s, 0.21);
  EXPECT_EQ(c.solver.hole_friction, HoleFrictionModel::kPresliding);
  EXPECT_EQ(c.solver.conduit_friction, ConduitFrictionModel::kPresliding);
  EXPECT_DOUBLE_EQ(c.parameters.xi_f, 1e-5);
  EXPECT_DOUBLE_EQ(c.parameters.xi_c, 1e-5);
  EXPECT_DOUBLE_EQ(c.parameters.v_s, 5e-3);
  EXPECT_DOUBLE_EQ(c.parameters.v_c_s, 5e-3);
  EXPECT_DOUBLE_EQ(c.parameters.tau_f, 0.01);
  EXPECT_DOUBLE_EQ(c.parameters.tau_c_f, 0.01);
  EXPECT_DOUBLE_EQ(c.solver.smoothing_step_s, 0.01);
  EXPECT_DOUBLE_EQ(c.protocol.duration_s(), 48.0);
  EXPECT_EQ(c.arm.segment_of_link(6), 0);
  EXPECT_EQ(c.arm.segment_of_link(7), 1);
}

TEST(Config, TypoInKeyNamesFileLineAndKey) {
  const std::string text = Edited("      link_mass_kg: 0.095", "      link_mas_kg: 0.095");
  const std::string error = ErrorOf(text);
  EXPECT_THAT(error, HasSubstr("bad.yaml: line " + std::to_string(LineOf(text, "link_mas_kg"))));
  EXPECT_THAT(error, HasSubstr("arm.segments[0].link_mas_kg"));
  EXPECT_THAT(error, HasSubstr("unknown key"));
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(Config, NegativeLengthNamesFileLineAndKey) {
  const std::string text = Edited("link_length_m: 0.100", "link_length_m: -0.1");
  const std::string error = ErrorOf(text);
  EXPECT_THAT(error, HasSubstr("bad.yaml: line " + std::to_string(LineOf(text, "-0.1"))));
  EXPECT_THAT(error, HasSubstr("arm.segments[1].link_length_m"));
  EXPECT_THAT(error, HasSubstr("must be > 0"));
}

TEST(Config, MissingSectionNamesIt) {
  std::string text = PaperText();
  text = text.substr(0, text.find("protocol:"));
  const std::string error = ErrorOf(text);
  EXPECT_THAT(error, HasSubstr("bad.yaml: line "));
  EXPECT_THAT(error, HasSubstr("key 'protocol'"));
  EXPECT_THAT(error, HasSubstr("missing"));
}

TEST(Config, RejectsBadValues) {
  EXPECT_THAT(ErrorOf(Edited("links: 6", "links: 0")), HasSubstr("arm.segments[0].links"));
  EXPECT_THAT(ErrorOf(Edited("youngs_modulus_pa: 2.6e10", "youngs_modulus_pa: -1")),
              HasSubstr("driving_cables.youngs_modulus_pa"));
  EXPECT_THAT(
      ErrorOf(Edited("{segment: 1, hole_angle_deg: 0.0}", "{segment: 3, hole_angle_deg: 0.0}")),
      HasSubstr("driving_cables.cables[0].segment"));
  EXPECT_THAT(ErrorOf(Edited("[small, large, small, large, small]", "[small, large]")),
              HasSubstr("connecting_pattern"));
  EXPECT_THAT(
      ErrorOf(Edited("[small, large, small, large, small]", "[small, larg, small, large, small]")),
      HasSubstr("found 'larg'"));
  EXPECT_THAT(ErrorOf(Edited("link_mass_kg: 0.095", "link_mass_kg: heavy")),
              HasSubstr("expected a number, found 'heavy'"));
  EXPECT_THAT(ErrorOf(Edited("schema: ccsrm-config/1", "schema: ccsrm-config/2")),
              HasSubstr("schema"));
  EXPECT_THAT(ErrorOf("arm: [1, 2"), HasSubstr("YAML syntax error"));
}

TEST(Config, YamlRoundTripKeepsEveryValue) {
  const Config a = LoadConfig(kPaperConfig);
  const Config b = ParseConfig(ToYaml(a), "roundtrip.yaml");
  EXPECT_EQ(ToYaml(a), ToYaml(b));
  EXPECT_EQ(b.arm.segments[1].large_s.wrap_angle_rad, a.arm.segments[1].large_s.wrap_angle_rad);
  EXPECT_EQ(b.arm.driving.cables[5].hole_angle_rad, a.arm.driving.cables[5].hole_angle_rad);
}

TEST(Config, StepperIsOneOfGslsFourFivePairsAndDefaultsToCashKarp) {
  // `solver.stepper` chooses how, not what, is integrated: a file without
  // the key (written before it existed) gets the default.
  EXPECT_EQ(ParseConfig(Edited("  stepper: rkck\n", ""), "s.yaml").solver.stepper,
            RungeKuttaStepper::kCashKarp);
  EXPECT_EQ(ParseConfig(Edited("stepper: rkck", "stepper: rkf45"), "s.yaml").solver.stepper,
            RungeKuttaStepper::kFehlberg);
  EXPECT_THAT(ErrorOf(Edited("stepper: rkck", "stepper: rk4")),
              HasSubstr("key 'solver.stepper': expected one of 'rkck', 'rkf45', found 'rk4'"));
}

TEST(Config, KeysAddedLaterMayBeLeftOutAndMeanThePapersLaw) {
  // `solver.hole_friction`, the Stribeck velocities and the frictional
  // memories came after ccsrm-config/1 was first published; a run file's
  // config_yaml from before them still parses, with the paper's trial and
  // error, no Stribeck transition in the holes, no memory, and the conduits'
  // fall closed by the paper's v_d (so v_c_s = v_d - v_s).
  std::string old = Edited("  hole_friction: presliding\n", "");
  const std::string conduit_line = "  conduit_friction: presliding\n";
  old.replace(old.find(conduit_line), conduit_line.size(), "");
  for (const std::string line :
       {"  stribeck_velocity_mps: 5.0e-3\n", "  friction_memory_s: 0.01\n",
        "  stribeck_velocity_mps: 5.0e-3\n", "  friction_memory_s: 0.01\n"}) {
    old.replace(old.find(line), line.size(), "");
  }
  const std::string v_s_line = "  large_s_static_velocity_mps: 1.0e-4";
  const std::string with_v_d = old;
  old.insert(old.find(v_s_line), "  large_s_dynamic_velocity_mps: 3.0e-4\n");
  const Config c = ParseConfig(old, "old.yaml");
  EXPECT_EQ(c.solver.hole_friction, HoleFrictionModel::kEvents);
  EXPECT_EQ(c.solver.conduit_friction, ConduitFrictionModel::kModifiedCoulomb);  // eq. 45
  EXPECT_EQ(c.parameters.v_s, 0.0);
  EXPECT_EQ(c.parameters.tau_f, 0.0);
  EXPECT_EQ(c.parameters.tau_c_f, 0.0);
  EXPECT_NEAR(c.parameters.v_c_s, 2.0e-4, 1e-18);
  EXPECT_EQ(ParseConfig(with_v_d, "no_v_d.yaml").parameters.v_c_s, 1.0e-4);
  EXPECT_EQ(
      ParseConfig(Edited("\n  hole_friction: presliding", "\n  hole_friction: events"), "s.yaml")
          .solver.hole_friction,
      HoleFrictionModel::kEvents);
  EXPECT_EQ(
      ParseConfig(Edited("\n  hole_friction: presliding", "\n  hole_friction: smoothed"), "s.yaml")
          .solver.hole_friction,
      HoleFrictionModel::kSmoothed);
  EXPECT_EQ(HoleFrictionWord(HoleFrictionModel::kPresliding), "presliding");
  EXPECT_EQ(ParseConfig(Edited("\n  conduit_friction: presliding",
                               "\n  conduit_friction: modified_coulomb"),
                        "s.yaml")
                .solver.conduit_friction,
            ConduitFrictionModel::kModifiedCoulomb);
  EXPECT_THAT(ErrorOf(Edited("\n  conduit_friction: presliding", "\n  conduit_friction: lugre")),
              HasSubstr("key 'solver.conduit_friction': expected one of 'modified_coulomb', "
                        "'presliding', found 'lugre'"));
  EXPECT_THAT(ErrorOf(Edited("\n  hole_friction: presliding", "\n  hole_friction: sticky")),
              HasSubstr("key 'solver.hole_friction': expected one of 'events', 'smoothed', 'off', "
                        "'presliding', found 'sticky'"));
  // The old key and the new one together are ambiguous.
  std::string both = PaperText();
  both.insert(both.find(v_s_line), "  large_s_dynamic_velocity_mps: 2.0e-4\n");
  EXPECT_THAT(ErrorOf(both), HasSubstr("key 'solver.large_s_dynamic_velocity_mps': replaced by "
                                       "connecting_cables.stribeck_velocity_mps"));
}

TEST(Config, DuplicateKeyNamesBothLines) {
  // yaml-cpp keeps the first of two equal keys: the second mass would be
  // ignored without a word.
  const std::string first = "      link_mass_kg: 0.095\n";
  std::string text = PaperText();
  const std::string hole = "      hole_circle_radius_m: 0.021\n";
  text.insert(text.find(hole) + hole.size(), "      link_mass_kg: 0.2\n");
  EXPECT_EQ(ErrorOf(text),
            "bad.yaml: line " + std::to_string(LineOf(text, hole) + 1) +
                ", key 'arm.segments[0].link_mass_kg': duplicate key (first at line " +
                std::to_string(LineOf(text, first)) + ")");
  // A second section at the top level.
  std::string sections = PaperText() + "solver:\n  relative_tolerance: 1e-3\n";
  EXPECT_THAT(ErrorOf(sections),
              HasSubstr("key 'solver': duplicate key (first at line " +
                        std::to_string(LineOf(sections, "\nsolver:") + 1) + ")"));
}

TEST(Config, PhysicalValuesOutsideAnyArmAreRefused) {
  const std::string text = Edited("youngs_modulus_pa: 2.6e10", "youngs_modulus_pa: 1e300");
  EXPECT_EQ(ErrorOf(text), "bad.yaml: line " +
                               std::to_string(LineOf(text, "youngs_modulus_pa: 1e300")) +
                               ", key 'driving_cables.youngs_modulus_pa': must be in [1e+06, "
                               "2e+12] Pa, found 1e+300");
  const struct {
    std::string from, to, message;
  } cases[] = {
      {"joint_disk_gap_m: 0.016", "joint_disk_gap_m: 3e-5",
       "key 'arm.joint_disk_gap_m': must be in [0.0001, 1] m, found 3e-05"},
      {"gravity_mps2: [0.0, 0.0, 0.0]", "gravity_mps2: [0.0, 0.0, -1e6]",
       "key 'arm.gravity_mps2': magnitude must be in [0, 30] m/s^2, found 1e+06"},
      {"link_length_m: 0.100", "link_length_m: 50",
       "key 'arm.segments[1].link_length_m': must be in [0.001, 2] m"},
      {"link_mass_kg: 0.095", "link_mass_kg: 1e9", "key 'arm.segments[0].link_mass_kg'"},
      {"[66.0e-6, 62.0e-6, 19.0e-6]", "[66.0e-6, 62.0e6, 19.0e-6]",
       "key 'arm.segments[0].link_inertia_kgm2': must be in [1e-12, 100] kg m^2"},
      {"hole_circle_radius_m: 0.021", "hole_circle_radius_m: 21",
       "key 'arm.segments[0].hole_circle_radius_m'"},
      {"cable_length_m: 0.084", "cable_length_m: 84",
       "key 'arm.segments[0].small_s.cable_length_m'"},
      {"pulley_radius_m: 0.016", "pulley_radius_m: 1e-9",
       "key 'arm.segments[0].large_s.pulley_radius_m'"},
      {"cross_section_m2: 1.3273e-6      # A_c", "cross_section_m2: 1.3",
       "key 'connecting_cables.cross_section_m2': must be in [1e-10, 0.001] m^2"},
      {"density_kgpm3: 7850.0", "density_kgpm3: 7.85e6",
       "key 'driving_cables.density_kgpm3': must be in [500, 25000] kg/m^3"},
      {"input_offset_m: 0.05", "input_offset_m: 5e4", "key 'driving_cables.input_offset_m'"},
      {"youngs_modulus_pa: 2.6e10        # E_c", "youngs_modulus_pa: 1e3",
       "key 'connecting_cables.youngs_modulus_pa': must be in [1e+06, 2e+12] Pa, found 1000"},
      // Issue 44: holes outside a link's disks (a hole circle beyond the
      // link length), with the range such disks would leave: 2 atan(d / 2R)
      // = 2 atan(0.016 / 1) = 1.83 deg.
      {"hole_circle_radius_m: 0.016", "hole_circle_radius_m: 0.5",
       "key 'arm.segments[1].hole_circle_radius_m': 0.5 m is beyond the link length 0.1 m: the "
       "holes would lie outside the link's disks"},
  };
  for (const auto& c : cases) EXPECT_THAT(ErrorOf(Edited(c.from, c.to)), HasSubstr(c.message));
}

TEST(Config, EveryConfigurationInTheRepositoryPassesWithoutWarnings) {
  for (const char* path :
       {"/configs/paper.yaml", "/configs/three-segment.yaml", "/datasets/samples/loop/arm.yaml"}) {
    Config c;
    EXPECT_NO_THROW(c = LoadConfig(std::string(CCSRM_SOURCE_DIR) + path)) << path;
    EXPECT_TRUE(c.warnings.empty()) << path << ": " << c.warnings.front();
  }
}

// The second arm (three segments of four links, nine cables) with the first
// occurrence of `from` replaced; every `from` must be there.
std::string EditedThreeSegment(const std::string& from, const std::string& to) {
  std::string text = ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Issue 32: layouts whose cables cannot bend a segment about both axes
// "completed" with the segment swinging to 53 deg. Each is refused with one
// line naming the file, the cable (or segment) line and the segment.
TEST(Config, SegmentsTheirCablesCannotBendBothWaysAreRefused) {
  const std::string seg2 = "segment 2 ('segment2')";
  const struct {
    std::string what, text, message;
  } cases[] = {
      {"no cable",
       EditedThreeSegment("    - {segment: 2, hole_angle_deg: 40.0}\n"
                          "    - {segment: 2, hole_angle_deg: 160.0}\n"
                          "    - {segment: 2, hole_angle_deg: 280.0}\n",
                          ""),
       "key 'arm.segments[1]': " + seg2 + " has no driving cable: at least three are needed"},
      {"two cables", EditedThreeSegment("    - {segment: 2, hole_angle_deg: 280.0}\n", ""),
       "key 'driving_cables.cables[4]': " + seg2 +
           " has 2 driving cables (cables 4 and 5): at least three are needed"},
      {"coincident angles",
       EditedThreeSegment("{segment: 2, hole_angle_deg: 160.0}",
                          "{segment: 2, hole_angle_deg: 40.5}"),
       "key 'driving_cables.cables[4]': " + seg2 +
           ": cables 4 and 5 sit at hole angles 40 and 40.5 deg, closer than 3.72 deg"},
      // Equal angles written differently (360 deg apart) are still one hole.
      {"one angle twice",
       EditedThreeSegment("{segment: 2, hole_angle_deg: 160.0}",
                          "{segment: 2, hole_angle_deg: -320.0}"),
       "cables 4 and 5 sit at hole angles 40 and -320 deg"},
      {"open half-plane",
       EditedThreeSegment("{segment: 2, hole_angle_deg: 280.0}",
                          "{segment: 2, hole_angle_deg: 100.0}"),
       "key 'driving_cables.cables[4]': " + seg2 +
           ": its 3 cables (hole angles 40, 100, 160 deg) lie within a half-plane, no cable "
           "between 160 and 40 deg (a gap of 240 deg)"},
      // A gap of exactly 180 deg: nothing pulls across it either.
      {"closed half-plane",
       EditedThreeSegment("{segment: 2, hole_angle_deg: 280.0}",
                          "{segment: 2, hole_angle_deg: 220.0}"),
       "lie within a half-plane, no cable between 220 and 40 deg (a gap of 180 deg)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string error = ErrorOf(c.text);
    EXPECT_THAT(error, HasSubstr("bad.yaml: line "));
    EXPECT_THAT(error, HasSubstr(c.message));
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
  // Four cables 90 deg apart (no gap reaches 180) bend a segment both ways.
  EXPECT_EQ(ErrorOf(EditedThreeSegment("{segment: 2, hole_angle_deg: 280.0}",
                                       "{segment: 2, hole_angle_deg: 280.0}\n"
                                       "    - {segment: 2, hole_angle_deg: 350.0}")),
            "(no error)");
  // Validate applies the same rule to an arm built in code.
  Config c = LoadConfig(kPaperConfig);
  c.arm.driving.cables[5].hole_angle_rad = c.arm.driving.cables[4].hole_angle_rad;
  EXPECT_THROW(Validate(c), InputError);
}

// Far outside the range of such arms but runnable: a warning naming the
// key and the reason; the file still loads.
TEST(Config, ValuesFarOutsideSuchArmsAreWarnedWithTheReason) {
  const struct {
    std::string from, to, warning;
  } cases[] = {
      {"hole_circle_radius_m: 0.015", "hole_circle_radius_m: 0.0015",
       "key 'arm.segments[2].hole_circle_radius_m': hole circle radius 0.0015 m is 0.0187 times "
       "the link length 0.08 m: the cables would have almost no lever"},
      {"link_mass_kg: 0.085", "link_mass_kg: 85",
       "key 'arm.segments[1].link_mass_kg': a link of 85 kg in an envelope of 0.000427 m^3"},
      {"[58.0e-6, 56.0e-6, 14.0e-6]", "[58.0e-6, 56.0e-6, 140.0e-6]",
       "key 'arm.segments[1].link_inertia_kgm2': the principal moments break the triangle "
       "inequality"},
      {"[58.0e-6, 56.0e-6, 14.0e-6]", "[58.0e-2, 56.0e-2, 14.0e-2]",
       "key 'arm.segments[1].link_inertia_kgm2': a principal moment of 0.58 kg m^2 exceeds"},
      {"pretension_n: 100.0", "pretension_n: 900.0",
       "key 'driving_cables.pretension_n': the pre-tension 900 N stretches the driving cables by "
       "2.61 %"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.to);
    Config config;
    ASSERT_NO_THROW(config = ParseConfig(EditedThreeSegment(c.from, c.to), "odd.yaml"));
    ASSERT_FALSE(config.warnings.empty());
    EXPECT_THAT(config.warnings.front(), HasSubstr("odd.yaml: line "));
    EXPECT_THAT(config.warnings.front(), HasSubstr(c.warning));
  }
}

TEST(Config, NonFiniteAndUnrepresentableNumbersAreRefused) {
  EXPECT_THAT(ErrorOf(Edited("link_mass_kg: 0.095", "link_mass_kg: .nan")),
              HasSubstr("key 'arm.segments[0].link_mass_kg': '.nan' is not a finite number"));
  EXPECT_THAT(ErrorOf(Edited("youngs_modulus_pa: 2.6e10", "youngs_modulus_pa: .inf")),
              HasSubstr("key 'driving_cables.youngs_modulus_pa': '.inf' is not a finite number"));
  EXPECT_THAT(ErrorOf(Edited("ramp_s: 20.0", "ramp_s: -.inf")),
              HasSubstr("key 'protocol.ramp_s': '-.inf' is not a finite number"));
  EXPECT_THAT(ErrorOf(Edited("youngs_modulus_pa: 2.6e10", "youngs_modulus_pa: 1e400")),
              HasSubstr("'1e400' is outside the range of a double"));
  EXPECT_THAT(ErrorOf(Edited("cross_section_m2: 1.3273e-6", "cross_section_m2: 1e-400")),
              HasSubstr("key 'driving_cables.cross_section_m2': '1e-400' underflows"));
}

// Issue 32: the default --config was relative to the repository, so the bare
// command failed anywhere else. The bundled files are found by path.
TEST(Config, BundledConfigurationsAreFoundWhereverTheCommandRuns) {
  EXPECT_EQ(BundledConfigPath("paper.yaml"), kPaperConfig);
  EXPECT_EQ(ConfigPathOrBundled(""), kPaperConfig);
  EXPECT_EQ(ConfigPathOrBundled("mine.yaml"), "mine.yaml");
  EXPECT_EQ(BundledConfigPath("three-segment.yaml"),
            std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  // PreparePaperRun without a path reads it, and says which file it read.
  PaperRunOptions options;
  options.duration_s = 0.01;
  EXPECT_EQ(PreparePaperRun(options).config_path, kPaperConfig);
  // Neither place holds it: one line naming both, asking for --config.
  try {
    BundledConfigPath("none.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_THAT(message, HasSubstr("--config: not given, and the bundled none.yaml is in neither " +
                                   std::string(CCSRM_SOURCE_DIR) + "/configs nor "));
    EXPECT_THAT(message, HasSubstr("share/ccsrm/configs: pass --config FILE"));
  }
}

// What decides whether a run may cite the paper: the paper's arm, however
// its file is named or its friction and protocol are set.
TEST(Describe, ThePapersArmIsRecognisedAndAnyArmIsNamedAsConfigured) {
  const Config paper = LoadConfig(kPaperConfig);
  const Config three = LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  EXPECT_TRUE(IsPaperArm(paper.arm));
  EXPECT_TRUE(IsPaperArm(ParseConfig(ToYaml(paper), "written.yaml").arm));  // written back
  EXPECT_TRUE(IsPaperArm(ParseConfig(Edited("friction_kinetic: 0.21", "friction_kinetic: 0.3"),
                                     "mine.yaml")
                             .arm));  // friction is not the arm
  EXPECT_FALSE(IsPaperArm(three.arm));
  EXPECT_FALSE(IsPaperArm(
      ParseConfig(Edited("hole_angle_deg: 300.0", "hole_angle_deg: 290.0"), "m.yaml").arm));
  EXPECT_FALSE(
      IsPaperArm(ParseConfig(Edited("link_mass_kg: 0.070", "link_mass_kg: 0.071"), "m.yaml").arm));
  EXPECT_EQ(DescribeArm(paper.arm), "2 segments of 6 and 6 links (12 joints), 6 driving cables");
  EXPECT_EQ(DescribeArm(three.arm), "3 segments of 4, 4 and 4 links (12 joints), 9 driving cables");
  EXPECT_EQ(DescribeProtocol(three.protocol),
            "θx of every joint 0 → 8° along a quintic over 20 s, held 4 s, back over 20 s, at "
            "rest 4 s; θy planned 0");
  EXPECT_EQ(DescribeCase(2, true), "paper case 2 (friction on all cables)");
  EXPECT_EQ(DescribeCase(1, false), "case 1 (no friction)");
  EXPECT_EQ(DescribeCase(0, true), "friction as configured");
}

TEST(Config, ValidateRejectsConfigBuiltInCode) {
  Config c = LoadConfig(kPaperConfig);
  c.arm.segments[0].link_length_m = 0.0;
  EXPECT_THROW(Validate(c), InputError);
}

}  // namespace
}  // namespace ccsrm::sim
