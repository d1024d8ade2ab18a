// The residual statistics behind the intervals: autocorrelation times of
// series whose answer is known in closed form, and Student's t.
#include <gtest/gtest.h>

#include <cmath>
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

}  // namespace
}  // namespace ccsrm::identify::internal
