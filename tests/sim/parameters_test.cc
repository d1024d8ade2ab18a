// Named parameters (SPEC 6): one name, one configuration field, checked bounds.
#include "ccsrm/sim/parameters.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "ccsrm/common/error.h"

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
                                             "T_p", "T_d0"}));
  const Config c = Paper();
  EXPECT_EQ(GetParameter(c, "mu"), c.arm.driving.friction_kinetic);
  EXPECT_EQ(GetParameter(c, "T_d0"), 100.0);
  EXPECT_EQ(GetParameter(c, "T_p"), 50.0);
  EXPECT_EQ(GetParameter(c, "c_lc"), 0.05);
  // Setting each one changes exactly its own field.
  for (const ParameterInfo& p : Parameters()) {
    Config changed = Paper();
    const double value = 0.5 * (p.lower + p.upper);
    SetParameter(p.name, value, "test", &changed);
    for (const ParameterInfo& other : Parameters()) {
      EXPECT_EQ(GetParameter(changed, other.name),
                other.name == p.name ? value : GetParameter(c, other.name))
          << p.name << " changed " << other.name;
    }
  }
}

TEST(Parameters, AssignmentsParseAndBadOnesNameTheProblem) {
  EXPECT_EQ(ParseParameterAssignment("mu=0.18", "--set"), std::make_pair(std::string("mu"), 0.18));
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("mu", "--set"); }),
              HasSubstr("--set: 'mu': expected name=value"));
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("nu=1", "--set"); }),
              HasSubstr("unknown parameter 'nu' (known: mu, mu_s, mu_c, mu_c_s, beta, c_sc, c_lc, "
                        "T_p, T_d0)"));
  EXPECT_THAT(ErrorOf([] { ParseParameterAssignment("mu=0.1x", "--set"); }),
              HasSubstr("value '0.1x' is not a number"));
  Config c = Paper();
  EXPECT_THAT(ErrorOf([&] { SetParameter("T_d0", -5, "--set", &c); }),
              HasSubstr("--set: parameter 'T_d0': -5 is outside [1, 1000] N"));
  EXPECT_EQ(GetParameter(c, "T_d0"), 100.0);  // unchanged
}

TEST(Parameters, YamlFileFlatOrTruthStyleWithLineAndKeyInErrors) {
  Config c = Paper();
  const auto applied = ApplyParameterYaml("mu: 0.1\nc_sc: 0.2\n", "p.yaml", &c);
  EXPECT_EQ(applied.size(), 2u);
  EXPECT_EQ(c.arm.driving.friction_kinetic, 0.1);
  EXPECT_EQ(c.arm.connecting.damping_small_nmsprad, 0.2);
  ApplyParameterYaml("schema: ccsrm-truth/1\nseed: 3\nparameters:\n  T_p: 40\n", "t.yaml", &c);
  EXPECT_EQ(c.arm.connecting.pretension_n, 40.0);
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("mu: 0.1\nmuu: 0.2\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: line 2, key 'muu': unknown parameter"));
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("parameters:\n  beta: [1]\n", "t.yaml", &c); }),
              HasSubstr("t.yaml: line 2, key 'parameters.beta': expected a number"));
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("mu: 5\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: line 1, key 'mu': 5 is outside [0, 2]"));
  EXPECT_THAT(ErrorOf([&] { ApplyParameterYaml("- mu\n", "p.yaml", &c); }),
              HasSubstr("p.yaml: expected a mapping"));
}

}  // namespace
}  // namespace ccsrm::sim
