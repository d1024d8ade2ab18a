// Tests of the presliding (elastoplastic) friction: of the holes,
// PreslidingHoleFriction (solver.hole_friction: presliding), and of the
// large-S conduits, PreslidingConduitFriction (solver.conduit_friction:
// presliding). The holes' on one hole node: a node of mass m on
// its material coordinate s, loaded by a constant force P and held by the
// friction, with the model smoothing that ArmDynamics applies (a damper
// k g h/2 and k (h^2/6) g of added mass, g = d xi_dot / d s_dot >= 0).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/connecting.h"
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

// The relaxation rate -d xi_dot / d xi at (v, xi), by central differences.
double RelaxationRate(const PreslidingLaw& law, double v, double xi) {
  const double d = 1e-6 * kXiMax;
  return -(PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, xi + d).rate -
           PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, xi - d).rate) /
         (2.0 * d);
}

TEST(PreslidingFriction, SmoothedRelaxationKeepsTheLimitAndRelaxesNoFasterThanTheResolution) {
  // Model smoothing of the relaxation (model notes row 28): sliding at the
  // limit, xi relaxes to xi_ss at v / xi_ss, far above 1/h when fast; the
  // smoothed law relaxes at most at 1/h, and leaves the fixed point, slow
  // sliding and the elastic range as they were.
  PreslidingLaw smoothed = Law();
  smoothed.relaxation_resolution_s = kSmoothing;
  const PreslidingLaw plain = Law();
  for (double v : {1e-2, -1e-2, 1e-4, -3e-6}) {
    // xi_ss at z = 1: where the plain law's steady sliding puts it.
    const double sigma = v > 0.0 ? 1.0 : -1.0;
    const double xi_ss =
        sigma * kXiMax * std::abs(std::expm1(-0.25 * kWrap * sigma)) / std::sinh(0.25 * kWrap);
    const PreslidingFriction at_limit =
        PreslidingHoleFriction(smoothed, kTension, kWrap, v, 1.0, xi_ss);
    EXPECT_NEAR(at_limit.rate, 0.0, 1e-9 * std::abs(v)) << "rho = 1 is still the fixed point";
    EXPECT_NEAR(at_limit.force, HoleSlipFriction(kTension, 0.25, kWrap, v),
                1e-9 * std::abs(at_limit.force));
    const double plain_rate = RelaxationRate(plain, v, xi_ss);
    const double smoothed_rate = RelaxationRate(smoothed, v, xi_ss);
    EXPECT_NEAR(plain_rate, std::abs(v) / std::abs(xi_ss), 1e-4 * plain_rate);
    // c = (1 + x^4)^(-1/4) with x = |v| h / xi_ss: at most 1/h, and 1 - x^4/4 slow.
    const double x = std::abs(v) * kSmoothing / std::abs(xi_ss);
    EXPECT_NEAR(smoothed_rate, plain_rate / std::pow(1.0 + std::pow(x, 4), 0.25),
                1e-4 * smoothed_rate);
    EXPECT_LE(smoothed_rate, 1.0 / kSmoothing * (1.0 + 1e-4));
    // Elastic range and unloading: the same law.
    for (double xi : {0.3 * xi_ss, 1.2 * xi_ss}) {
      const double unloading = -v;
      EXPECT_EQ(PreslidingHoleFriction(smoothed, kTension, kWrap, v, 1.0, 0.3 * xi_ss).rate, v);
      EXPECT_EQ(PreslidingHoleFriction(smoothed, kTension, kWrap, unloading, 1.0, xi).rate,
                unloading);
    }
  }
}

TEST(PreslidingFriction, SmoothedRelaxationsEngagedFractionIsTheRatesSlopeAndDissipates) {
  // engaged_fraction (model smoothing's share of k) is d xi_dot / d s_dot,
  // c's dependence on the slip speed included, and the plastic power is
  // never negative.
  PreslidingLaw law = Law();
  law.relaxation_resolution_s = kSmoothing;
  for (double rho : {0.6, 0.8, 0.95, 1.0, 1.1}) {
    for (double v : {2e-3, 1e-2, -5e-2, 4e-7}) {
      const double sigma = v > 0.0 ? 1.0 : -1.0;
      const double xi_ss =
          kXiMax * std::abs(std::expm1(-0.25 * kWrap * sigma)) / std::sinh(0.25 * kWrap);
      const double xi = sigma * rho * xi_ss;
      const PreslidingFriction f = PreslidingHoleFriction(law, kTension, kWrap, v, 1.0, xi);
      const double d = 1e-6 * std::abs(v);
      const double slope = (PreslidingHoleFriction(law, kTension, kWrap, v + d, 1.0, xi).rate -
                            PreslidingHoleFriction(law, kTension, kWrap, v - d, 1.0, xi).rate) /
                           (2.0 * d);
      if (slope >= 0.0) EXPECT_NEAR(f.engaged_fraction, slope, 1e-5) << rho << " " << v;
      EXPECT_GE(f.plastic_power, 0.0) << rho << " " << v;
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

// The quasi-static replay's displacement after a finite slip is the law's
// slow limit: ElastoplasticSlide integrated over the slip at a speed far
// beyond its band (the yield's ramp is then the speed itself), without the
// relaxation's smoothing, by RK4 in fine steps; the steady displacements
// differ with the direction, as the capstan's do.
double IntegratedDisplacementAfterSlip(double xi, double slip, double ss_up, double ss_down) {
  const double v = slip > 0.0 ? 1.0 : -1.0;  // m/s: slip as time
  const double band = 1e-12;                 // m/s, far below v
  auto rate = [&](double x) {
    const double sigma = x < 0.0 ? -1.0 : 1.0;
    const double rho = std::abs(x) / (sigma > 0.0 ? ss_up : ss_down);
    return v - ElastoplasticSlide(rho, sigma, v, band).sliding;
  };
  const int steps = 200000;
  const double dt = std::abs(slip) / steps;
  for (int k = 0; k < steps; ++k) {
    const double k1 = rate(xi), k2 = rate(xi + 0.5 * dt * k1), k3 = rate(xi + 0.5 * dt * k2),
                 k4 = rate(xi + dt * k3);
    xi += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return xi;
}

TEST(PreslidingFriction, DisplacementAfterASlipAtRestIsTheLawsSlowLimit) {
  const double up = 1.0e-5, down = 1.3e-5;  // xi_ss by direction [m]
  struct Case {
    const char* what;
    double xi, slip;
  };
  const Case cases[] = {
      {"elastic from rest", 0.0, 0.3 * up},
      {"loading past the breakaway", 0.0, 0.8 * up},
      {"loading to the limit", 0.0, 6.0 * up},
      {"on from part way", 0.7 * up, 0.2 * up},
      {"unloading", 0.9 * up, -0.4 * up},
      {"reversal through zero", 0.9 * up, -3.0 * down},
      {"reversal from the other side", -0.95 * down, 2.5 * up},
      {"beyond a limit that fell", 1.6 * up, 0.7 * up},
  };
  for (const Case& c : cases) {
    const double reference = IntegratedDisplacementAfterSlip(c.xi, c.slip, up, down);
    // RK4 over 2e5 steps of the C1 law resolves it to ~1e-12 of xi_ss; the
    // closed form's quadrature is good to ~1e-10 of its range.
    EXPECT_NEAR(ElastoplasticDisplacementAfterSlip(c.xi, c.slip, up, down), reference, 1e-9 * up)
        << c.what;
  }
  // Far beyond the limit the displacement is the limit, in the slip's direction.
  EXPECT_NEAR(ElastoplasticDisplacementAfterSlip(0.2 * up, -1e3 * down, up, down), -down,
              1e-15 * down);
  // Loading, d xi_new / d slip is the law's 1 - alpha rho at the end point:
  // the map is smooth in the slip, as a Newton solve over it needs.
  const double xi0 = 0.4 * up, slip = 0.5 * up, h = 1e-6 * up;
  const double plus = ElastoplasticDisplacementAfterSlip(xi0, slip + h, up, down);
  const double minus = ElastoplasticDisplacementAfterSlip(xi0, slip - h, up, down);
  const double end = ElastoplasticDisplacementAfterSlip(xi0, slip, up, down);
  const double slope = 1.0 - ElastoplasticSlide(end / up, 1.0, 1.0, 1e-12).sliding;
  EXPECT_NEAR((plus - minus) / (2.0 * h), slope, 1e-5);
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

// The conduits' law on one couple: the two joints of a large S turning
// together by psi (theta_i = theta_j = psi, so the spring between them is
// idle), inertia 2 J, under a moment M on each joint and the conduit
// friction M_p on each, with the model smoothing ArmDynamics applies (the
// damper (h/2) k and (h^2/6) k of added mass on each joint, k = K g r / 2).
constexpr double kConduitRadius = 0.016;  // r_lc [m]
constexpr double kConduitWrap = 3.21;     // Theta_lc [rad]
constexpr double kConduitTension = 50.0;  // T_p [N]
constexpr double kJointInertia = 6.6e-5;  // J [kg m^2]

ConduitPreslidingLaw ConduitLaw() { return {0.21, 0.25, kXiMax, kStickBand}; }

LargeSParams Couple() {
  LargeSParams p;
  p.axial_stiffness_n = 3.45e4;
  p.pulley_radius_m = kConduitRadius;
  p.cable_length_m = 0.109;
  p.wrap_angle_rad = kConduitWrap;
  p.pretension_n = kConduitTension;
  p.friction = {0.21, 0.25, 1e-4, 5e-3};
  return p;
}

// The static limit of the conduit friction on one joint, T_p r Theta mu'_c.
double ConduitLimit() { return kConduitTension * kConduitRadius * kConduitWrap * 0.25; }

struct CouplePose {
  double psi = 0.0, rate = 0.0, eta = 0.0;
};

CouplePose SettleCouple(double moment, double duration, double dt, CouplePose c = {},
                        double ramp_s = 0.0) {
  const ConduitPreslidingLaw law = ConduitLaw();
  const LargeSParams couple = Couple();
  auto rate = [&](const CouplePose& x, double at, CouplePose* d) {
    const double m = at < ramp_s ? moment * at / ramp_s : moment;
    const double v = ConduitSlipVelocity(couple, x.rate, x.rate);
    const ConduitPresliding f = PreslidingConduitFriction(law, v, 1.0, x.eta);
    const LargeSResult r =
        LargeSMomentsWithCoefficient(couple, x.psi, x.psi, x.rate, x.rate, f.coefficient, 0.0);
    const double spring =
        -kConduitTension * kConduitRadius * kConduitWrap * f.coefficient_per_displacement;
    const double k = 0.5 * spring * f.engaged_fraction * kConduitRadius;
    // Per joint: inertia J + 2 (h^2/6) k (the form [1 1; 1 1] on equal rates).
    const double inertia = kJointInertia + 2.0 * kSmoothing * kSmoothing / 6.0 * k;
    d->psi = x.rate;
    d->rate = (m + r.moments.on_i - 0.5 * kSmoothing * k * 2.0 * x.rate) / inertia;
    d->eta = f.rate;
  };
  auto add = [](const CouplePose& x, const CouplePose& d, double a) {
    return CouplePose{x.psi + a * d.psi, x.rate + a * d.rate, x.eta + a * d.eta};
  };
  for (double t = 0.0; t < duration; t += dt) {
    CouplePose k1, k2, k3, k4;
    rate(c, t, &k1);
    rate(add(c, k1, dt / 2), t + dt / 2, &k2);
    rate(add(c, k2, dt / 2), t + dt / 2, &k3);
    rate(add(c, k3, dt), t + dt, &k4);
    c.psi += dt / 6 * (k1.psi + 2 * k2.psi + 2 * k3.psi + k4.psi);
    c.rate += dt / 6 * (k1.rate + 2 * k2.rate + 2 * k3.rate + k4.rate);
    c.eta += dt / 6 * (k1.eta + 2 * k2.eta + 2 * k3.eta + k4.eta);
  }
  return c;
}

TEST(ConduitPreslidingFriction, CoupleLoadedBelowBreakawayHoldsWithoutDrift) {
  // A third of the limit: the couple turns by what the presliding spring
  // takes, then not at all; eq. 45 would let it creep inside v_s.
  const double moment = ConduitLimit() / 3.0;
  const CouplePose settled = SettleCouple(moment, 1.0, 1e-5);
  const CouplePose later = SettleCouple(moment, 10.0, 1e-5, settled);
  const ConduitPresliding f = PreslidingConduitFriction(ConduitLaw(), 0.0, 1.0, later.eta);
  const double friction = -kConduitTension * kConduitRadius * kConduitWrap * f.coefficient;
  EXPECT_NEAR(friction, -moment, 1e-9 * moment);
  // Nothing slid: eta is all the couple's travel, -r psi.
  EXPECT_NEAR(later.eta, -kConduitRadius * later.psi, 1e-15);
  EXPECT_LT(std::abs(later.psi - settled.psi), 1e-13) << "drift over 10 s [rad]";
  EXPECT_LT(f.load_ratio, kPreslidingBreakaway);
}

TEST(ConduitPreslidingFriction, CoupleLoadedBeyondTheLimitSlidesAtEquation45sFriction) {
  // At a prescribed slip speed beyond the bands, eta settles and the
  // coefficient is eq. 45's at the memory, both ways; the moments are then
  // LargeSMoments' to the last bit.
  const ConduitPreslidingLaw law = ConduitLaw();
  const LargeSParams couple = Couple();
  for (double v : {2e-2, -2e-2, 3e-4, -3e-4}) {
    for (double z : {1.0, 0.3}) {
      double eta = 0.0;
      const double dt = 1e-3 * kXiMax / std::abs(v);
      for (int k = 0; k < 20000; ++k) eta += dt * PreslidingConduitFriction(law, v, z, eta).rate;
      const ConduitPresliding f = PreslidingConduitFriction(law, v, z, eta);
      const double expected = ModifiedCoulombWithMemory(couple.friction, v, z, nullptr);
      EXPECT_NEAR(f.coefficient, expected, 1e-6 * std::abs(expected)) << v << " " << z;
      EXPECT_NEAR(f.sliding_speed, v, 1e-6 * std::abs(v));
      const double rate = -2.0 * v / kConduitRadius;  // theta_dot_i = theta_dot_j
      const LargeSResult a =
          LargeSMomentsWithCoefficient(couple, 0.01, 0.02, rate / 2, rate / 2, expected, 0.0);
      const LargeSResult b = LargeSMoments(couple, 0.01, 0.02, rate / 2, rate / 2, z);
      EXPECT_EQ(a.moments.on_i, b.moments.on_i);
      EXPECT_EQ(a.moments.on_j, b.moments.on_j);
    }
  }
}

TEST(ConduitPreslidingFriction, UnloadingAndRestAreElastic) {
  const ConduitPreslidingLaw law = ConduitLaw();
  EXPECT_EQ(PreslidingConduitFriction(law, -3e-4, 1.0, 0.99 * kXiMax).rate, -3e-4);
  EXPECT_EQ(PreslidingConduitFriction(law, 0.0, 1.0, 0.99 * kXiMax).rate, 0.0);
  // Without static friction there is no spring, and eta stays bounded.
  const ConduitPresliding none =
      PreslidingConduitFriction({0.0, 0.0, kXiMax, kStickBand}, 1e-3, 1.0, 2.0 * kXiMax);
  EXPECT_EQ(none.coefficient, 0.0);
  EXPECT_LT(none.rate, 0.0);
}

TEST(ConduitPreslidingFriction, FrictionMomentsNeverDoMoreWorkThanTheEnergyStored) {
  // The moments' power, M_p (theta_dot_i + theta_dot_j) = -2 K eta v / r,
  // equals -d/dt (K eta^2 / r) minus a plastic power 2 K eta (v - eta_dot) / r
  // >= 0, whatever the slip speed, displacement and memory.
  const ConduitPreslidingLaw law = ConduitLaw();
  const LargeSParams couple = Couple();
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> speed(-4e-4, 4e-4), state(-2e-5, 2e-5), memory(0.0, 1.0);
  for (int trial = 0; trial < 5000; ++trial) {
    const double v = speed(rng), eta = state(rng), z = memory(rng);
    const ConduitPresliding f = PreslidingConduitFriction(law, v, z, eta);
    const double rate = -v / kConduitRadius;  // each joint's, so v_tau1 = v
    const LargeSResult m =
        LargeSMomentsWithCoefficient(couple, 0.0, 0.0, rate, rate, f.coefficient, 0.0);
    const double K =
        -kConduitTension * kConduitRadius * kConduitWrap * f.coefficient_per_displacement;
    const double power = m.moments.on_i * rate + m.moments.on_j * rate;
    const double stored_rate = 2.0 * K * eta * f.rate / kConduitRadius;
    const double plastic = 2.0 * K * eta * f.sliding_speed / kConduitRadius;
    EXPECT_GE(plastic, 0.0);
    EXPECT_NEAR(power, -stored_rate - plastic, 1e-9 * std::abs(2.0 * K * eta * v / kConduitRadius));
  }
}

}  // namespace
}  // namespace ccsrm::sim::internal
