// Tests of cable-hole capstan friction (eqs. 9-12).
#include "kernels/hole_friction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace ccsrm::sim::internal {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(HoleFriction, WrapAngleOfStraightRightAngleAndFoldedCable) {
  const Eigen::Vector3d node(0.1, 0.2, 0.3);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  EXPECT_EQ(WrapAngle(node - 0.5 * x, node, node + 2.0 * x), 0.0);
  EXPECT_NEAR(WrapAngle(node - x, node, node + y), kPi / 2, 1e-15);
  EXPECT_NEAR(WrapAngle(node + x, node, node + 3.0 * x), kPi, 1e-15);
  // Nearly straight: full precision where eq. 12's arccos returns exactly 0.
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  EXPECT_NEAR(WrapAngle(o - x, o, o + x + 1e-9 * y), 1e-9, 1e-22);
}

TEST(HoleFriction, WrapAngleEqualsEq12) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)),
        c(u(rng), u(rng), u(rng));
    const Eigen::Vector3d da = a - b, dc = c - b;
    const double cosine = std::clamp(da.dot(dc) / (da.norm() * dc.norm()), -1.0, 1.0);
    EXPECT_NEAR(WrapAngle(a, b, c), kPi - std::acos(cosine), 1e-12);
  }
}

TEST(HoleFriction, LimitingStaticFrictionIsSymmetricAndVanishesWithoutFriction) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> t(-20.0, 200.0), th(0.0, 1.0), mu(0.0, 0.5);
  for (int trial = 0; trial < 1000; ++trial) {
    const double t1 = t(rng), t2 = t(rng), theta = th(rng), m = mu(rng);
    const double f = LimitingStaticFriction(t1, t2, m, theta);
    EXPECT_EQ(f, LimitingStaticFriction(t2, t1, m, theta));
    EXPECT_EQ(LimitingStaticFriction(t1, t2, 0.0, theta), 0.0);
    EXPECT_GE(f, 0.0);
    EXPECT_NEAR(f, std::max(0.0, std::min(t1, t2)) * (std::exp(m * theta) - 1.0), 1e-12);
  }
}

TEST(HoleFriction, SlipFrictionAlwaysDissipates) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> t(-20.0, 200.0), th(0.0, kPi), mu(0.0, 0.5), v(-1.0, 1.0);
  for (int trial = 0; trial < 10000; ++trial) {
    const double s_dot = v(rng);
    const double f = HoleSlipFriction(t(rng), mu(rng), th(rng), s_dot);
    EXPECT_LE(f * s_dot, 0.0);
  }
  EXPECT_EQ(HoleSlipFriction(100.0, 0.21, 1.0, 0.0), 0.0);
}

TEST(HoleFriction, SlipFrictionIsTheCapstanValue) {
  const double mu = 0.21, theta = 0.4, t_b = 80.0;
  // Cable drawn towards the "after" side (s_dot < 0): the before side is the
  // slack side and friction is T_b (e^{mu theta} - 1).
  EXPECT_NEAR(HoleSlipFriction(t_b, mu, theta, -1e-3), t_b * (std::exp(mu * theta) - 1.0), 1e-12);
  // Drawn towards the "before" side (s_dot > 0) with T_b = T_a e^{mu theta}:
  // friction balances the tension difference.
  const double t_a = t_b * std::exp(-mu * theta);
  EXPECT_NEAR(HoleSlipFriction(t_b, mu, theta, 1e-3), -(t_b - t_a), 1e-12);
  // A slack before side carries nothing.
  EXPECT_EQ(HoleSlipFriction(-5.0, mu, theta, 1e-3), 0.0);
}

TEST(HoleFriction, StribeckCoefficientFallsFromStaticToKineticContinuously) {
  const HoleFrictionLaw law{0.21, 0.25, 1e-3, 1e-6};
  // The static value through the stick band and at its edge; the kinetic
  // value far beyond; in between a monotone, continuous fall.
  EXPECT_EQ(HoleFrictionCoefficient(law, 0.0, nullptr), 0.25);
  EXPECT_EQ(HoleFrictionCoefficient(law, -1e-6, nullptr), 0.25);
  EXPECT_NEAR(HoleFrictionCoefficient(law, 1e-6 + 1e-12, nullptr), 0.25, 1e-9);
  EXPECT_NEAR(HoleFrictionCoefficient(law, 0.05, nullptr), 0.21, 1e-12);
  // One Stribeck velocity past the band: e^-1 of the excess is left.
  EXPECT_NEAR(HoleFrictionCoefficient(law, 1e-6 + 1e-3, nullptr), 0.21 + 0.04 / M_E, 1e-12);
  double previous = 0.25;
  for (double v = 1e-6; v < 5e-3; v += 1e-5) {
    const double mu = HoleFrictionCoefficient(law, v, nullptr);
    EXPECT_LE(mu, previous + 1e-15);
    EXPECT_LT(previous - mu, 1e-3) << "jump at " << v;  // 1e-5 m/s steps: no jumps
    previous = mu;
  }
  // The analytic slope against central differences.
  for (double v : {3e-4, 1e-3, 2.5e-3, -1.7e-3}) {
    double slope = 0.0;
    HoleFrictionCoefficient(law, v, &slope);
    const double dv = 1e-8;
    const double fd = (HoleFrictionCoefficient(law, std::abs(v) + dv, nullptr) -
                       HoleFrictionCoefficient(law, std::abs(v) - dv, nullptr)) /
                      (2.0 * dv);
    EXPECT_NEAR(slope, fd, 1e-6 * std::abs(fd) + 1e-9) << v;
  }
  // With mu = mu' the law is the paper's whatever v_s is; with v_s = 0 the
  // coefficient drops to mu at once beyond the band.
  EXPECT_EQ(HoleFrictionCoefficient({0.21, 0.21, 1e-3, 1e-6}, 5e-4, nullptr), 0.21);
  EXPECT_EQ(HoleFrictionCoefficient({0.21, 0.25, 0.0, 1e-6}, 2e-6, nullptr), 0.21);
}

TEST(HoleFriction, SmoothedFrictionIsTheCapstanValueBeyondTheStickBandAndDissipates) {
  const HoleFrictionLaw law{0.21, 0.25, 1e-3, 1e-6};
  const double theta = 0.4, t_b = 80.0;
  // Beyond the band it is eq. 9 with the Stribeck coefficient.
  for (double v : {5e-6, 4e-4, 2e-3, -3e-5, -1e-2}) {
    const double mu = HoleFrictionCoefficient(law, v, nullptr);
    const double target = HoleMemoryTarget(law, v, nullptr);
    EXPECT_NEAR(law.mu_kinetic + (law.mu_static - law.mu_kinetic) * target, mu, 1e-15) << v;
    EXPECT_NEAR(SmoothedHoleFriction(law, t_b, theta, v, target).force,
                HoleSlipFriction(t_b, mu, theta, v), 1e-12)
        << v;
  }
  // Zero at rest, odd in sign, dissipative, and its slope is the derivative
  // at fixed memory.
  EXPECT_EQ(SmoothedHoleFriction(law, t_b, theta, 0.0, 1.0).force, 0.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> t(-20.0, 200.0), th(0.0, kPi), v(-3e-3, 3e-3),
      memory(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const double s_dot = v(rng), tension = t(rng), angle = th(rng), z = memory(rng);
    const HoleFrictionForce f = SmoothedHoleFriction(law, tension, angle, s_dot, z);
    EXPECT_LE(f.force * s_dot, 0.0);
    EXPECT_LE(f.slope, 0.0);
    const double dv = 1e-10;
    const double fd = (SmoothedHoleFriction(law, tension, angle, s_dot + dv, z).force -
                       SmoothedHoleFriction(law, tension, angle, s_dot - dv, z).force) /
                      (2.0 * dv);
    // Skip the band's edges, where the slope is only continuous (C1 law).
    if (std::abs(std::abs(s_dot) - 1e-6) < 1e-9) continue;
    EXPECT_NEAR(f.slope, fd, 1e-5 * std::abs(fd) + 1e-3) << s_dot;
  }
  // Inside the stick band a node holds up to the static capstan value: at
  // the band's edge the force reaches T_b expm1(-mu' theta).
  EXPECT_NEAR(SmoothedHoleFriction(law, t_b, theta, 1e-6, 1.0).force,
              t_b * std::expm1(-0.25 * theta), 1e-12);
}

}  // namespace
}  // namespace ccsrm::sim::internal
