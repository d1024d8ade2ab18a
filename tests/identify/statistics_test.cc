// The residual statistics behind the intervals: autocorrelation times of
// series whose answer is known in closed form, and Student's t.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "ccsrm/identify/adequacy.h"
#include "ccsrm/identify/experiment.h"
#include "statistics.h"

namespace ccsrm::identify::internal {
namespace {

std::vector<double> Ar1(double phi, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  std::vector<double> x(n);
  double v = 0.0;
  for (std::size_t i = 0; i < n; ++i) x[i] = v = phi * v + e(rng);
  return x;
}

// White noise carries one sample's worth per sample.
TEST(AutocorrelationTime, IsOneForWhiteNoise) {
  EXPECT_NEAR(AutocorrelationTime(Ar1(0.0, 20000, 1)), 1.0, 0.1);
}

// An AR(1) series x_i = φ x_{i-1} + e_i has ρ_k = φ^k and an integrated
// autocorrelation time of (1 + φ) / (1 - φ): 19 for φ = 0.9. The estimate of
// 20 000 samples scatters by a few percent.
TEST(AutocorrelationTime, MatchesTheClosedFormOfAnAr1Series) {
  EXPECT_NEAR(AutocorrelationTime(Ar1(0.9, 20000, 2)), 19.0, 0.15 * 19.0);
  EXPECT_NEAR(AutocorrelationTime(Ar1(0.5, 20000, 3)), 3.0, 0.15 * 3.0);
}

TEST(EffectiveSampleSize, SumsLengthOverTimeAcrossSeries) {
  const double n = EffectiveSampleSize({Ar1(0.0, 10000, 4), Ar1(0.9, 19000, 5)});
  EXPECT_NEAR(n, 10000.0 + 1000.0, 0.15 * 11000.0);
  EXPECT_EQ(EffectiveSampleSize({{1.0, 2.0}}), 2.0);          // too short to estimate: its length
  EXPECT_EQ(AutocorrelationTime({3.0, 3.0, 3.0, 3.0}), 1.0);  // constant: no correlation to find
}

TEST(StudentT975, MatchesTables) {
  EXPECT_NEAR(StudentT975(10.0), 2.228, 1e-3);
  EXPECT_NEAR(StudentT975(1e6), 1.960, 1e-3);
  EXPECT_TRUE(std::isnan(StudentT975(0.5)));
}

// Two parameters whose errors come from two directions at 45°: each
// direction alone gives each parameter 0.3 / √2 = 0.21 relative error (below
// a 0.25 threshold), together 0.3 (above). Both parameters are undetermined,
// and a combination must still be named for them (set F of the recovery
// study named none before).
TEST(AssessIdentifiability, NamesADirectionForAParameterNoSingleDirectionHolds) {
  const double c = std::sqrt(0.5);
  Eigen::MatrixXd v(2, 2);
  v << c, c, c, -c;
  const Eigen::Vector2d error(0.3, 0.29);
  const Identifiability a = AssessIdentifiability(v, error, {1.0, 1.0}, 0.25, 0.2);
  EXPECT_FALSE(a.identifiable[0]);
  EXPECT_FALSE(a.identifiable[1]);
  EXPECT_NEAR(a.direction_worst[0], c * 0.3, 1e-12);
  // The larger share of both, with both its components.
  ASSERT_EQ(a.named.size(), 1u);
  EXPECT_EQ(a.named[0].column, 0);
  EXPECT_EQ(a.named[0].members, std::vector<int>({0, 1}));
}

// A parameter leaking into another's null direction through a small
// component (set F: mu_c into c_lc's): its error is that direction's, which
// is named for the other parameter, so it joins that name.
TEST(AssessIdentifiability, NamesAParameterThatLeaksIntoAnothersNullDirection) {
  const double s = 0.003, c = std::sqrt(1.0 - s * s);
  Eigen::MatrixXd v(2, 2);
  v << c, -s, s, c;  // direction 0: parameter 0; a little of parameter 1
  const Eigen::Vector2d error(150.0, 0.01);
  const Identifiability a = AssessIdentifiability(v, error, {1.0, 1.0}, 0.25, 0.2);
  EXPECT_FALSE(a.identifiable[0]);
  EXPECT_FALSE(a.identifiable[1]);  // 0.003 * 150 = 0.45
  ASSERT_EQ(a.named.size(), 1u);
  EXPECT_EQ(a.named[0].column, 0);
  EXPECT_EQ(a.named[0].members, std::vector<int>({0, 1}));
}

// A well-determined parameter next to one along a null direction: only the
// null direction is named, and it holds the undetermined parameter alone.
TEST(AssessIdentifiability, NamesTheNullDirectionAndNothingElse) {
  const Eigen::MatrixXd v = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::Vector2d error(0.01, std::numeric_limits<double>::infinity());
  const Identifiability a = AssessIdentifiability(v, error, {1.0, 1.0}, 0.25, 0.2);
  EXPECT_TRUE(a.identifiable[0]);
  EXPECT_FALSE(a.identifiable[1]);
  ASSERT_EQ(a.named.size(), 1u);
  EXPECT_EQ(a.named[0].column, 1);
  EXPECT_EQ(a.named[0].members, std::vector<int>({1}));
  EXPECT_TRUE(std::isinf(a.direction_worst[1]));
}

// The relative scale is what turns a scaled error into a relative one: the
// same direction errors leave a parameter whose estimate is large relative
// to its scale determined.
TEST(AssessIdentifiability, JudgesErrorsRelativeToTheEstimate) {
  const Eigen::MatrixXd v = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::Vector2d error(0.5, 0.5);
  const Identifiability a = AssessIdentifiability(v, error, {1.0, 0.1}, 0.25, 0.2);
  EXPECT_FALSE(a.identifiable[0]);
  EXPECT_TRUE(a.identifiable[1]);
  ASSERT_EQ(a.named.size(), 1u);
  EXPECT_EQ(a.named[0].column, 0);
}

}  // namespace
}  // namespace ccsrm::identify::internal

namespace ccsrm::identify {
namespace {

// One joint, one recording: the measured angles 0, the simulated ones white
// noise of `ratio` times the joint's noise (0.03 deg) over 2000 frames.
ModelAdequacy JudgeWhiteResidual(double ratio, double noise_effective_samples) {
  Experiment x;
  x.name = "white";
  x.joints = 1;
  x.measured = Eigen::MatrixXd::Zero(2000, 2);
  x.noise_deg = {0.03};
  x.noise_effective_samples = {noise_effective_samples};
  Eigen::MatrixXd sim(2000, 2);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, ratio * 0.03 * M_PI / 180.0);
  for (Eigen::Index f = 0; f < sim.rows(); ++f) sim(f, 0) = noise(rng), sim(f, 1) = noise(rng);
  return AssessModelAdequacy({&x}, {&sim}, kAboveNoiseRatio, kAboveNoiseSignificance);
}

// A noise estimated from ten independent samples is known to a fifth or so:
// a residual 1.8 times it over 2000 white frames is then no proof of a
// misfit (an F of 2000 and 10 degrees of freedom at 3.24: p 0.03, above
// 0.01 over the 2 channels), though a chi-square against a noise taken as
// exact calls it one; four times it is a misfit either way.
TEST(ModelAdequacy, ANoiseKnownFromFewSamplesIsNotTakenForAMisfit) {
  EXPECT_TRUE(JudgeWhiteResidual(1.8, 10.0).adequate());
  EXPECT_FALSE(JudgeWhiteResidual(1.8, INFINITY).adequate());
  EXPECT_FALSE(JudgeWhiteResidual(4.0, 10.0).adequate());
  EXPECT_TRUE(JudgeWhiteResidual(1.0, INFINITY).adequate());
}

}  // namespace
}  // namespace ccsrm::identify

namespace ccsrm::identify::internal {
namespace {

// Three columns of a Jacobian at relative steps r, r/3, r/9: the first a
// clean derivative, the second one that bends between r/3 and r (its
// central difference at r carries a curvature error the finer two do not),
// the third one that jumps (every step gives another slope).
TEST(ChooseDerivativeSteps, TakesTheFinerColumnOnlyWhereTheFinerStepsAgree) {
  Eigen::MatrixXd at_r(2, 3), at_third(2, 3), at_ninth(2, 3);
  at_r << 1.0, 1.10, 1.0, 2.0, 2.20, 0.0;
  at_third << 1.0, 1.01, 1.5, 2.0, 2.02, 0.5;
  at_ninth << 1.0, 1.00, 0.6, 2.0, 2.00, -0.4;
  Eigen::MatrixXd jacobian = at_r;
  int asked = 0;
  const DerivativeSteps steps = ChooseDerivativeSteps(
      0.01, at_third,
      [&](Eigen::MatrixXd* ninth) {
        ++asked;
        *ninth = at_ninth;
        return true;
      },
      0.05, &jacobian);
  EXPECT_EQ(asked, 1);
  EXPECT_DOUBLE_EQ(steps.relative_step[0], 0.01);
  EXPECT_DOUBLE_EQ(steps.disagreement[0], 0.0);
  // Bends: r against r/3 differ by 8.2 %, r/3 against r/9 by 1 %.
  EXPECT_DOUBLE_EQ(steps.relative_step[1], 0.01 / 3.0);
  EXPECT_NEAR(steps.disagreement[1], 0.01 / 1.01, 1e-12);
  EXPECT_TRUE(jacobian.col(1).isApprox(at_third.col(1)));
  // Jumps: kept at r, with r's disagreement, and its column the fit's.
  EXPECT_DOUBLE_EQ(steps.relative_step[2], 0.01);
  EXPECT_GT(steps.disagreement[2], 0.05);
  EXPECT_TRUE(jacobian.col(2).isApprox(at_r.col(2)));
  EXPECT_TRUE(jacobian.col(0).isApprox(at_r.col(0)));
}

TEST(ChooseDerivativeSteps, AsksForNoNinthWhereEveryColumnAgrees) {
  Eigen::MatrixXd jacobian(1, 2), at_third(1, 2);
  jacobian << 1.0, 2.0;
  at_third << 1.01, 2.02;
  const DerivativeSteps steps = ChooseDerivativeSteps(
      0.01, at_third, [](Eigen::MatrixXd*) -> bool { throw std::logic_error("asked"); }, 0.05,
      &jacobian);
  EXPECT_NEAR(steps.disagreement[1], 0.02 / 2.02, 1e-12);
  EXPECT_DOUBLE_EQ(steps.relative_step[1], 0.01);
}

// A ninth that could not be computed leaves every column at the fit's step.
TEST(ChooseDerivativeSteps, KeepsTheFitsStepWithoutANinth) {
  Eigen::MatrixXd jacobian(1, 1), at_third(1, 1);
  jacobian << 1.1;
  at_third << 1.0;
  const DerivativeSteps steps = ChooseDerivativeSteps(
      0.01, at_third, [](Eigen::MatrixXd*) { return false; }, 0.05, &jacobian);
  EXPECT_NEAR(steps.disagreement[0], 0.1 / 1.1, 1e-12);
  EXPECT_DOUBLE_EQ(steps.relative_step[0], 0.01);
  EXPECT_DOUBLE_EQ(jacobian(0, 0), 1.1);
}

}  // namespace
}  // namespace ccsrm::identify::internal
