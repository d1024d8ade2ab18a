// The trial points of a derivative near the bounds of its parameter, and the
// weights that make each scheme exact for a quadratic.
#include <gtest/gtest.h>

#include <cmath>

#include "finite_difference.h"

namespace ccsrm::identify::internal {
namespace {

// Each scheme differentiates a quadratic exactly: that is what second order
// means, and what makes the steps of different schemes comparable.
double Apply(const DifferencePlan& plan, double value, double step) {
  const auto f = [](double x) { return 3.0 - 2.0 * x + 5.0 * x * x; };
  return (plan.base_weight * f(value) + plan.trial_weights[0] * f(plan.trial_values[0]) +
          plan.trial_weights[1] * f(plan.trial_values[1])) /
         (2.0 * step);
}

TEST(PlanDifference, CentralInsideTheBounds) {
  const auto plan = PlanDifference(0.21, 0.0021, 0.0, 2.0);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->scheme, DifferenceScheme::kCentral);
  EXPECT_DOUBLE_EQ(plan->trial_values[0], 0.21 - 0.0021);
  EXPECT_DOUBLE_EQ(plan->trial_values[1], 0.21 + 0.0021);
  EXPECT_NEAR(Apply(*plan, 0.21, 0.0021), -2.0 + 10.0 * 0.21, 1e-9);
}

TEST(PlanDifference, ForwardFromALowerBoundBackwardFromAnUpperOne) {
  const auto at_lower = PlanDifference(1.0, 0.01, 1.0, 500.0);
  ASSERT_TRUE(at_lower);
  EXPECT_EQ(at_lower->scheme, DifferenceScheme::kForward);
  EXPECT_DOUBLE_EQ(at_lower->trial_values[0], 1.01);
  EXPECT_DOUBLE_EQ(at_lower->trial_values[1], 1.02);
  EXPECT_NEAR(Apply(*at_lower, 1.0, 0.01), -2.0 + 10.0 * 1.0, 1e-9);

  // Just inside the bound, p - h would cross it: still forward.
  const auto near_lower = PlanDifference(0.005, 0.01, 0.0, 2.0);
  ASSERT_TRUE(near_lower);
  EXPECT_EQ(near_lower->scheme, DifferenceScheme::kForward);

  const auto at_upper = PlanDifference(2.0, 0.02, 0.0, 2.0);
  ASSERT_TRUE(at_upper);
  EXPECT_EQ(at_upper->scheme, DifferenceScheme::kBackward);
  EXPECT_DOUBLE_EQ(at_upper->trial_values[0], 1.98);
  EXPECT_DOUBLE_EQ(at_upper->trial_values[1], 1.96);
  EXPECT_NEAR(Apply(*at_upper, 2.0, 0.02), -2.0 + 10.0 * 2.0, 1e-9);
}

TEST(PlanDifference, NothingWhenTheBoundsAreTooNarrow) {
  // [0, 0.1] around 0.05 with h = 0.06: neither side has room for 2h.
  EXPECT_FALSE(PlanDifference(0.05, 0.06, 0.0, 0.1));
}

}  // namespace
}  // namespace ccsrm::identify::internal
