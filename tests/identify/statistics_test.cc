// The residual statistics behind the intervals: autocorrelation times of
// series whose answer is known in closed form, and Student's t.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

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
