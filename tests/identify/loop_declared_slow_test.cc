// Declared values as the loop's candidates (issue 28): recordings of an arm
// whose configuration declares one geometric value wrongly (a hole circle
// drilled small), nothing else
// wrong, fitted under the declared configuration. The loop names the value
// and recovers its error, adds no effect, and writes the corrected
// configuration; without the declared values among its candidates, it does
// not dress the residual up as a library effect (the partial-explanation
// rule). Experiments: the paper's arm on the compressed protocol of
// synthetic_experiment.h, white noise of 0.03 deg (the mocap floor).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/identify/loop.h"
#include "ccsrm/sim/declared_values.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::HasSubstr;
using testing_support::Nominal;
using testing_support::Record;

constexpr double kNoiseDeg = 0.03;
// The error of the declared value: segment 2's hole circle is 5 % (0.8 mm)
// smaller than declared. Its angles scale by about as much, 0.05 deg on
// the 1 deg a joint bends here: above the 0.03 deg noise. (A link 1 %
// long or a disk gap 0.5 mm long change this arm's joint angles far less
// than the noise: docs/loop.md.)
constexpr double kError = -0.05;
constexpr const char* kValue = "declared.segment2.hole_circle_radius";

// Recorded from the arm as built (`built`), loaded under the declared
// configuration (Nominal()), as a lab records its arm.
std::vector<Experiment> Recordings(const sim::Config& built, std::vector<unsigned> seeds) {
  ExperimentLoadOptions load;
  load.config = std::make_shared<const sim::Config>(
      sim::ParseConfig(sim::ToYaml(Nominal()), "declared.yaml"));
  std::vector<Experiment> out;
  for (unsigned seed : seeds) {
    out.push_back(MakeExperiment(Record(built.parameters, kNoiseDeg, seed, built),
                                 "synthetic" + std::to_string(seed) + ".h5", load));
    out.back().name = "synthetic" + std::to_string(seed);
  }
  return out;
}

sim::Config Built() {
  sim::Config c = Nominal();
  c.arm.segments[1].hole_circle_radius_m *= 1.0 + kError;
  return c;
}

LoopOptions Options(std::vector<std::string> candidates) {
  LoopOptions o;
  o.fit.free_parameters = {"T_p"};
  o.fit.threads = 2;
  o.max_rounds = 2;
  o.candidates = std::move(candidates);
  return o;
}

TEST(LoopDeclaredValues, NamesAWrongHoleCircleRecoversItAndAddsNoEffect) {
  const std::vector<Experiment> training = Recordings(Built(), {1, 2});
  const std::vector<Experiment> holdout = Recordings(Built(), {3});
  const LoopSummary s =
      CloseLoop(training, holdout, Options({"joint_friction", "table_tilt", "declared"}));
  EXPECT_TRUE(s.added_effects.empty());  // no library effect
  ASSERT_EQ(s.declared_corrections.size(), 1u) << s.conclusion;
  const DeclaredCorrection& d = s.declared_corrections.front();
  // Named: the hole circle, or a combination that holds it (values the
  // data cannot tell apart).
  const bool named = d.parameter == kValue ||
                     std::count(d.indistinguishable.begin(), d.indistinguishable.end(), kValue) > 0;
  EXPECT_TRUE(named) << d.Sentence();
  if (d.parameter == kValue) {
    // The bar: within 20 % of the error, or the truth inside the interval.
    const bool close = std::abs(d.relative - kError) <= 0.2 * std::abs(kError);
    const bool covered =
        d.identifiable && d.relative_ci95_lower <= kError && kError <= d.relative_ci95_upper;
    EXPECT_TRUE(close || covered) << d.Sentence();
    ASSERT_TRUE(s.calibrated.has_value());
    EXPECT_NEAR(s.calibrated->arm.segments[1].hole_circle_radius_m, 0.016 * (1.0 + kError),
                0.2 * 0.016 * std::abs(kError));
    EXPECT_DOUBLE_EQ(s.calibrated->arm.segments[0].hole_circle_radius_m, 0.021);  // untouched
  }
  EXPECT_THAT(d.Sentence(), HasSubstr("is off by"));
  EXPECT_THAT(s.conclusion, HasSubstr("no effect added"));
  // Corrected, the residual is at the noise (1.5x: the unexplained level).
  EXPECT_LT(s.rms_after_deg, 1.5 * kNoiseDeg);
}

TEST(LoopDeclaredValues, WithoutTheDeclaredValuesNoEffectIsNamedForTheirResidual) {
  const std::vector<Experiment> training = Recordings(Built(), {1, 2});
  const std::vector<Experiment> holdout = Recordings(Built(), {3});
  const LoopSummary s = CloseLoop(
      training, holdout, Options({"joint_friction", "table_tilt", "backlash", "actuator_delay"}));
  // The hole circle is none of these: whatever they remove, none is its cause.
  EXPECT_TRUE(s.added_effects.empty()) << s.conclusion;
  EXPECT_TRUE(s.declared_corrections.empty());
  EXPECT_FALSE(s.unexplained.empty());  // and the residual stays listed
  for (const LoopRound& r : s.rounds) {
    for (const CandidateResult& c : r.candidates) {
      if (c.partial) {
        EXPECT_THAT(r.decision, HasSubstr("not explained")) << r.decision;
      }
    }
  }
}

}  // namespace
}  // namespace ccsrm::identify
