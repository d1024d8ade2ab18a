// Tests of the presliding (elastoplastic) hole friction, PreslidingHoleFriction
// (solver.hole_friction: presliding), on one hole node: a node of mass m on
// its material coordinate s, loaded by a constant force P and held by the
// friction, with the model smoothing that ArmDynamics applies (a damper
// k g h/2 and k (h^2/6) g of added mass, g = d xi_dot / d s_dot >= 0).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/hole_friction.h"

namespace ccsrm::sim::internal {
namespace {

constexpr double kTension = 100.0;   // T_b [N]
constexpr double kWrap = 0.05;       // theta [rad]
constexpr double kNodeMass = 1e-4;   // kg
constexpr double kSmoothing = 0.01;  // h [s]
constexpr double kXiMax = 1e-5;      // xi_f [m]
constexpr double kStickBand = 1e-6;  // v_eps [m/s]

PreslidingLaw Law() { return {{0.21, 0.25, 5e-3, kStickBand}, kXiMax}; }

// The static capstan force in the direction of a load pulling s up (eq. 9
// at s_dot > 0 with mu'): the limit a node pulled up can hold.
double UpLimit() { return kTension * -std::expm1(-0.25 * kWrap); }

struct Node {
  double s = 0.0, v = 0.0, xi = 0.0;
};

// One node under the load P [N] (reached linearly over ramp_s from the
// start, then constant), memory z = 1 (at rest), by RK4 at dt; returns the
// state after `duration`.
Node Settle(double load, double duration, double dt, Node node = {}, double ramp_s = 0.0) {
  const PreslidingLaw law = Law();
  double t = 0.0;
  auto rate = [&](const Node& n, double at, Node* d) {
    const double p = at < ramp_s ? load * at / ramp_s : load;
    const PreslidingFriction f = PreslidingHoleFriction(law, kTension, kWrap, n.v, 1.0, n.xi);
    const double mass =
        kNodeMass + kSmoothing * kSmoothing / 6.0 * f.stiffness * f.engaged_fraction;
    d->s = n.v;
    d->v = (p + f.force - 0.5 * kSmoothing * f.stiffness * f.engaged_fraction * n.v) / mass;
    d->xi = f.rate;
  };
  auto add = [](const Node& n, const Node& d, double a) {
    return Node{n.s + a * d.s, n.v + a * d.v, n.xi + a * d.xi};
  };
  for (; t < duration; t += dt) {
    Node k1, k2, k3, k4;
    rate(node, t, &k1);
    rate(add(node, k1, dt / 2), t + dt / 2, &k2);
    rate(add(node, k2, dt / 2), t + dt / 2, &k3);
    rate(add(node, k3, dt), t + dt, &k4);
    node.s += dt / 6 * (k1.s + 2 * k2.s + 2 * k3.s + k4.s);
    node.v += dt / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v);
    node.xi += dt / 6 * (k1.xi + 2 * k2.xi + 2 * k3.xi + k4.xi);
  }
  return node;
}

TEST(PreslidingFriction, NodeLoadedBelowBreakawayHoldsWithoutDrift) {
  // A third of the limit: purely elastic presliding. The node moves by
  // P / k, then not at all.
  const double load = UpLimit() / 3.0;
  const Node settled = Settle(load, 1.0, 1e-5);
  const Node later = Settle(load, 10.0, 1e-5, settled);
  const PreslidingFriction f = PreslidingHoleFriction(Law(), kTension, kWrap, 0.0, 1.0, later.xi);
  EXPECT_NEAR(f.force, -load, 1e-9 * load);
  EXPECT_NEAR(later.s, load / f.stiffness, 1e-9 * later.s);  // xi = s: nothing slid
  EXPECT_NEAR(later.xi, later.s, 1e-15);
  EXPECT_LT(std::abs(later.s - settled.s), 1e-15) << "drift over 10 s [m]";
  EXPECT_LT(f.load_ratio, kPreslidingBreakaway);
}

TEST(PreslidingFriction, NodeLoadedBetweenBreakawayAndTheLimitYieldsOnceThenHolds) {
  // 90 % of the limit, applied over 0.5 s (a step would overshoot past the
  // limit): part of the travel is plastic, and it stops.
  const double load = 0.9 * UpLimit();
  const Node settled = Settle(load, 1.0, 1e-5, {}, 0.5);
  const Node later = Settle(load, 10.0, 1e-5, settled);
  const PreslidingFriction f = PreslidingHoleFriction(Law(), kTension, kWrap, 0.0, 1.0, later.xi);
  EXPECT_NEAR(f.force, -load, 1e-9 * load);
  EXPECT_GT(later.s - later.xi, 0.0) << "some of it slid";
  EXPECT_LT(later.s, 3.0 * kXiMax) << "but only a few presliding displacements";
  EXPECT_LT(std::abs(later.s - settled.s), 1e-15) << "drift over 10 s [m]";
}

TEST(PreslidingFriction, NodeLoadedBeyondTheLimitSlidesAtTheSteadyCapstanFriction) {
  // At a prescribed slip speed the displacement settles at xi_ss and the
  // force is eq. 9's with the coefficient of the memory, both ways.
  const PreslidingLaw law = Law();
  for (double v : {2e-4, -2e-4, 3e-6, -5e-2}) {
    for (double z : {1.0, 0.3}) {
      double xi = 0.0;
      const double dt = 1e-3 * kXiMax / std::abs(v);
      for (int k = 0; k < 20000; ++k) {
        xi += dt * PreslidingHoleFriction(law, kTension, kWrap, v, z, xi).rate;
      }
      const PreslidingFriction f = PreslidingHoleFriction(law, kTension, kWrap, v, z, xi);
      const double mu = 0.21 + 0.04 * z;
      EXPECT_NEAR(f.force, HoleSlipFriction(kTension, mu, kWrap, v), 1e-6 * std::abs(f.force))
          << v << " " << z;
      EXPECT_NEAR(f.sliding_speed, v, 1e-6 * std::abs(v));
      EXPECT_NEAR(f.load_ratio, 1.0, 1e-6);
    }
  }
}

TEST(PreslidingFriction, UnloadingIsElasticAndALimitThatFallsIsSlidDownTo) {
  const PreslidingLaw law = Law();
  // Unloading: all of s_dot goes into xi, nothing slides.
  const PreslidingFriction back =
      PreslidingHoleFriction(law, kTension, kWrap, -3e-4, 1.0, 0.99 * kXiMax);
  EXPECT_EQ(back.rate, -3e-4);
  EXPECT_EQ(back.plastic_power, 0.0);
  // At rest nothing moves, whatever the load.
  EXPECT_EQ(PreslidingHoleFriction(law, kTension, kWrap, 0.0, 1.0, 0.99 * kXiMax).rate, 0.0);
  // The memory falls to kinetic while xi holds the static force: sliding on
  // brings the force down to the kinetic limit instead of storing it.
  const double v = 1e-4;
  double xi = PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, 0.0).stiffness > 0.0
                  ? UpLimit() / PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, 0.0).stiffness
                  : 0.0;
  const PreslidingFriction start = PreslidingHoleFriction(law, kTension, kWrap, v, 0.0, xi);
  EXPECT_GT(start.load_ratio, 1.0);
  EXPECT_LT(start.rate, 0.0);
  for (int k = 0; k < 20000; ++k)
    xi += 1e-4 * PreslidingHoleFriction(law, kTension, kWrap, v, 0.0, xi).rate;
  EXPECT_NEAR(PreslidingHoleFriction(law, kTension, kWrap, v, 0.0, xi).force,
              HoleSlipFriction(kTension, 0.21, kWrap, v), 1e-6 * UpLimit());
}

TEST(PreslidingFriction, FrictionNeverReturnsMoreThanTheElasticEnergyItStored) {
  // Pointwise: F s_dot = -d/dt (k xi^2 / 2) - plastic power, plastic power
  // >= 0. Over a random slip history (loading, breakaway, reversals): the
  // work of friction on the node plus the energy stored in xi never exceeds
  // what was stored at the start (zero).
  const PreslidingLaw law = Law();
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> speed(-4e-4, 4e-4), state(-2e-5, 2e-5), memory(0.0, 1.0);
  for (int trial = 0; trial < 5000; ++trial) {
    const double v = speed(rng), xi = state(rng), z = memory(rng);
    const PreslidingFriction f = PreslidingHoleFriction(law, kTension, kWrap, v, z, xi);
    EXPECT_GE(f.plastic_power, 0.0);
    EXPECT_NEAR(f.force * v, -f.stiffness * xi * f.rate - f.plastic_power,
                1e-9 * std::abs(f.stiffness * xi * v) + 1e-18);
  }
  double xi = 0.0, work = 0.0, k = 0.0;
  const double dt = 1e-4;
  double v = 0.0;
  for (int step = 0; step < 200000; ++step) {
    if (step % 500 == 0) v = speed(rng);  // a new slip speed every 50 ms
    const PreslidingFriction f = PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, xi);
    // Midpoint in xi for the work, so that the balance is exact to O(dt^2).
    const double xi_mid = xi + 0.5 * dt * f.rate;
    const PreslidingFriction m = PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, xi_mid);
    work += m.force * v * dt;
    xi += dt * m.rate;
    k = m.stiffness;
    ASSERT_LE(work + 0.5 * k * xi * xi, 1e-6 * 0.5 * k * kXiMax * kXiMax) << step;
  }
}

}  // namespace
}  // namespace ccsrm::sim::internal
