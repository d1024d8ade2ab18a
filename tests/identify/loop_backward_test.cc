// The loop's size test and the order of its backward step
// (identify/src/loop_backward.h, issue 28), on numbers: no simulation.
#include "loop_backward.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace ccsrm::identify::internal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

ParameterEstimate Estimate(double lower, double upper, bool identifiable = true) {
  ParameterEstimate e;
  e.identifiable = identifiable;
  e.ci95_lower = lower;
  e.ci95_upper = upper;
  return e;
}

TEST(LoopSizeTest, AnIntervalExcludingZeroOrTheJointChiSquareSizesAnAddition) {
  EXPECT_TRUE(IntervalExcludesZero(Estimate(0.1, 0.3)));
  EXPECT_TRUE(IntervalExcludesZero(Estimate(-0.3, -0.1)));
  EXPECT_FALSE(IntervalExcludesZero(Estimate(-0.1, 0.3)));
  // Not identifiable: no interval to trust, whatever its numbers.
  EXPECT_FALSE(IntervalExcludesZero(Estimate(0.1, 0.3, false)));
  // The 95 % quantile of a chi-square: 3.84 for one degree of freedom,
  // 5.99 for two (tables).
  EXPECT_TRUE(SizeSignificant(false, 3.9, 1));
  EXPECT_FALSE(SizeSignificant(false, 3.8, 1));
  EXPECT_TRUE(SizeSignificant(false, 6.0, 2));
  EXPECT_FALSE(SizeSignificant(false, 5.9, 2));
  EXPECT_TRUE(SizeSignificant(true, 0.0, 2));
  // The run at 0 failed: only an interval can size it.
  EXPECT_FALSE(SizeSignificant(false, kNaN, 2));
  EXPECT_TRUE(SizeSignificant(true, kNaN, 2));
}

TEST(LoopSizeTest, DeltaBicCountsEffectiveSamplesAndChargesEachParameter) {
  // 2 (1000 - 990) * 500 / 1000 = 10 effective chi-square, less 2 ln 500.
  EXPECT_NEAR(DeltaBic(1000.0, 990.0, 500.0, 1000.0, 2), 10.0 - 2.0 * std::log(500.0), 1e-12);
  // A refit without the addition that lands lower: keeping it is worth less than nothing.
  EXPECT_LT(DeltaBic(985.0, 990.0, 500.0, 1000.0, 1), 0.0);
}

TEST(LoopBackwardStep, TriesOnlyAdditionsOfUnsizedSizeLeastUsefulFirst) {
  std::vector<AdditionCheck> checks(5);
  // 0: an interval excludes 0: kept, not tried.
  checks[0] = {1, true, kNaN, kNaN};
  // 1: two parameters, Δχ² 1.2 at 0 (below 5.99): tried.
  checks[1] = {2, false, 1.2, 1.2 - 2.0 * std::log(500.0)};
  // 2: one parameter, Δχ² 50 at 0 (sized jointly): kept.
  checks[2] = {1, false, 50.0, 50.0 - std::log(500.0)};
  // 3: one parameter, Δχ² 0.5: tried, after 1 (its ΔBIC at 0 is larger).
  checks[3] = {1, false, 0.5, 0.5 - std::log(500.0)};
  // 4: its run at 0 failed: not judged.
  checks[4] = {1, false, kNaN, kNaN};
  const std::vector<std::size_t> order = TakeBackOrder(checks);
  ASSERT_EQ(order.size(), 2u);
  EXPECT_EQ(order[0], 1u);
  EXPECT_EQ(order[1], 3u);
  // 2 again, with its parameter not identifiable in the new fit: its cost
  // at 0 (no refit) cannot size it, so the refit is tried; last, as its
  // ΔBIC at 0 is the largest.
  checks[2].identifiable = false;
  EXPECT_EQ(TakeBackOrder(checks), (std::vector<std::size_t>{1, 3, 2}));
  // An interval that excludes 0 sizes an addition whatever the rest.
  checks[0].identifiable = false;
  EXPECT_EQ(TakeBackOrder(checks), (std::vector<std::size_t>{1, 3, 2}));
  checks[0].identifiable = checks[2].identifiable = true;
  // Nothing earlier, or everything sized: no backward step.
  EXPECT_TRUE(TakeBackOrder({}).empty());
  EXPECT_TRUE(TakeBackOrder({checks[0], checks[2]}).empty());
}

}  // namespace
}  // namespace ccsrm::identify::internal
