// Tests of the ALE cable element (eqs. 1-6, 13, 17-20) against quadrature of
// the paper's integrands and finite differences.
#include "kernels/ale_element.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace ccsrm::sim::internal {
namespace {

// Table 1 driving cable: rho A = 7850 * 1.3273e-6, E A = 2.6e10 * 1.3273e-6.
AleElementParams CableParams(double beta, double h) {
  AleElementParams p;
  p.linear_density_kgpm = 7.85e3 * 1.3273e-6;
  p.axial_stiffness_n = 2.6e10 * 1.3273e-6;
  p.rayleigh_beta_s = beta;
  p.smoothing_step_s = h;
  return p;
}

// A random element about 0.1 m long with strain of order `strain`, moving
// and sliding at about 0.1 m/s.
struct ElementState {
  Vector8d q;
  Vector8d q_dot;
};

ElementState RandomState(std::mt19937* rng, double strain) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ElementState st;
  const Eigen::Vector3d r1(u(*rng), u(*rng), u(*rng));
  Eigen::Vector3d dir(u(*rng), u(*rng), u(*rng));
  dir.normalize();
  const double s1 = 0.3 * u(*rng);
  const double ds = 0.1 * (1.0 + 0.2 * u(*rng));
  const Eigen::Vector3d r2 = r1 + ds * (1.0 + strain * (1.0 + 0.5 * u(*rng))) * dir;
  st.q << r1, r2, s1, s1 + ds;
  for (int i = 0; i < 8; ++i) st.q_dot(i) = 0.1 * u(*rng);
  return st;
}

// As RandomState, moving a thousand times slower (0.1 mm/s). At 0.1 m/s an
// element 0.1 m long shortens at eps_dot ~ 1 /s, faster than its damping
// lets it relax from eps ~ 1e-3, and then carries nothing (the unilateral
// law); the checks of eqs. 13 and 20 as printed need it carrying.
ElementState SlowState(std::mt19937* rng, double strain) {
  ElementState st = RandomState(rng, strain);
  st.q_dot *= 1e-3;
  return st;
}

// Gauss-Legendre, 3 points: exact for polynomials of degree <= 5 in zeta.
constexpr double kGaussX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
constexpr double kGaussW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

double RelativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

TEST(AleElement, MassMatchesGaussQuadratureOfEq6) {
  std::mt19937 rng(1);
  const AleElementParams p = CableParams(1e-3, 0.01);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    const double ds = st.q(7) - st.q(6);
    Matrix8d quad = Matrix8d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix<double, 3, 8> n = AleShapeMatrix(st.q, kGaussX[k]);
      quad += kGaussW[k] * p.linear_density_kgpm * n.transpose() * n;
    }
    quad *= ds / 2.0;
    const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
    EXPECT_LT(RelativeError(t.mass, quad), 1e-14);
    EXPECT_LT(RelativeError(t.mass, t.mass.transpose()), 1e-16);
  }
}

TEST(AleElement, KineticEnergyMatchesFineQuadratureOfVelocity) {
  std::mt19937 rng(2);
  const AleElementParams p = CableParams(1e-3, 0.01);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    const double ds = st.q(7) - st.q(6);
    // Composite Simpson over zeta in [-1, 1] of |N q_dot|^2 (the velocity of
    // the material point at s(zeta)).
    const int panels = 1000;
    const double dz = 2.0 / panels;
    double sum = 0.0;
    for (int i = 0; i <= panels; ++i) {
      const double z = -1.0 + i * dz;
      const double w = (i == 0 || i == panels) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
      sum += w * (AleShapeMatrix(st.q, z) * st.q_dot).squaredNorm();
    }
    const double t_quad = 0.5 * p.linear_density_kgpm * (ds / 2.0) * sum * dz / 3.0;
    const double t_kernel = AleKineticEnergy(p, st.q, st.q_dot);
    EXPECT_NEAR(t_kernel, t_quad, 1e-12 * t_quad);

    // dT/dq_dot = M q_dot by central differences.
    const AleElementTerms terms = EvaluateAleElement(p, st.q, st.q_dot);
    const Vector8d momentum = terms.mass * st.q_dot;
    // The evaluation's energy is the same quadratic form of the same mass.
    EXPECT_NEAR(terms.kinetic_energy, 0.5 * st.q_dot.dot(momentum), 1e-12 * t_quad);
    for (int i = 0; i < 8; ++i) {
      const double step = 1e-6;
      Vector8d plus = st.q_dot;
      Vector8d minus = st.q_dot;
      plus(i) += step;
      minus(i) -= step;
      const double fd =
          (AleKineticEnergy(p, st.q, plus) - AleKineticEnergy(p, st.q, minus)) / (2.0 * step);
      EXPECT_NEAR(fd, momentum(i), 1e-9 * momentum.norm() + 1e-14);
    }
  }
}

// Position of the material point s under element coordinates q (eqs. 2-3).
Eigen::Vector3d MaterialPoint(const Vector8d& q, double s) {
  const double zeta = (2.0 * s - q(6) - q(7)) / (q(7) - q(6));
  return 0.5 * (1.0 - zeta) * q.segment<3>(0) + 0.5 * (1.0 + zeta) * q.segment<3>(3);
}

// Shape functions (N1, N2) at fixed material coordinate s as functions of s1, s2.
Eigen::Vector2d ShapeAt(double s, double s1, double s2) {
  const double zeta = (2.0 * s - s1 - s2) / (s2 - s1);
  return {0.5 * (1.0 - zeta), 0.5 * (1.0 + zeta)};
}

// r''_s of eq. 4 written out term by term, with the derivatives of N_r with
// respect to s1 and s2 (at fixed s) taken by central differences.
Eigen::Vector3d AdditionalAccelerationEq4(const Vector8d& q, const Vector8d& q_dot, double s) {
  const double s1 = q(6);
  const double s2 = q(7);
  const double h = 1e-4 * (s2 - s1);
  auto n = [&](double a, double b) { return ShapeAt(s, a, b); };
  const Eigen::Vector2d d1 = (n(s1 + h, s2) - n(s1 - h, s2)) / (2 * h);
  const Eigen::Vector2d d2 = (n(s1, s2 + h) - n(s1, s2 - h)) / (2 * h);
  const Eigen::Vector2d d11 = (n(s1 + h, s2) - 2 * n(s1, s2) + n(s1 - h, s2)) / (h * h);
  const Eigen::Vector2d d22 = (n(s1, s2 + h) - 2 * n(s1, s2) + n(s1, s2 - h)) / (h * h);
  const Eigen::Vector2d d12 =
      (n(s1 + h, s2 + h) - n(s1 + h, s2 - h) - n(s1 - h, s2 + h) + n(s1 - h, s2 - h)) / (4 * h * h);
  auto apply = [](const Eigen::Vector2d& coef, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return Eigen::Vector3d(coef(0) * a + coef(1) * b);
  };
  const Eigen::Vector3d r1 = q.segment<3>(0), r2 = q.segment<3>(3);
  const Eigen::Vector3d v1 = q_dot.segment<3>(0), v2 = q_dot.segment<3>(3);
  const double sd1 = q_dot(6), sd2 = q_dot(7);
  return 2.0 * (apply(d1, v1, v2) * sd1 + apply(d2, v1, v2) * sd2) +
         apply(d11, r1, r2) * sd1 * sd1 + 2.0 * apply(d12, r1, r2) * sd1 * sd2 +
         apply(d22, r1, r2) * sd2 * sd2;
}

TEST(AleElement, AdditionalAccelerationIsSecondTimeDerivativeOfMaterialPoint) {
  // With q'' = 0, r'' of a fixed material point is exactly r''_s (eq. 4).
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    for (double zeta : {-1.0, -0.3, 0.4, 1.0}) {
      const double s = 0.5 * (st.q(6) + st.q(7)) + 0.5 * zeta * (st.q(7) - st.q(6));
      const double dt = 1e-4;
      const Eigen::Vector3d fd =
          (MaterialPoint(st.q + dt * st.q_dot, s) - 2.0 * MaterialPoint(st.q, s) +
           MaterialPoint(st.q - dt * st.q_dot, s)) /
          (dt * dt);
      const Eigen::Vector3d eq4 = AdditionalAccelerationEq4(st.q, st.q_dot, s);
      EXPECT_LT((fd - eq4).norm(), 1e-5 * eq4.norm() + 1e-9) << "zeta " << zeta;
    }
  }
}

TEST(AleElement, AleInertiaForceMatchesQuadratureOfEq4) {
  std::mt19937 rng(4);
  const AleElementParams p = CableParams(1e-3, 0.01);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    const double ds = st.q(7) - st.q(6);
    Vector8d q_p = Vector8d::Zero();
    for (int k = 0; k < 3; ++k) {
      const double s = 0.5 * (st.q(6) + st.q(7)) + 0.5 * kGaussX[k] * ds;
      q_p += kGaussW[k] * p.linear_density_kgpm * AleShapeMatrix(st.q, kGaussX[k]).transpose() *
             AdditionalAccelerationEq4(st.q, st.q_dot, s);
    }
    q_p *= ds / 2.0;
    const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
    // Right-hand-side signed: the kernel returns -Q_p.
    EXPECT_LT(RelativeError(t.ale_inertia_force, -q_p), 1e-6);
  }
}

TEST(AleElement, StrainJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(5);
  const AleElementParams p = CableParams(1e-3, 0.01);
  const Vector8d zero = Vector8d::Zero();
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
    for (int i = 0; i < 8; ++i) {
      const double step = 1e-6;
      Vector8d plus = st.q, minus = st.q;
      plus(i) += step;
      minus(i) -= step;
      const double fd =
          (EvaluateAleElement(p, plus, zero).strain - EvaluateAleElement(p, minus, zero).strain) /
          (2.0 * step);
      EXPECT_NEAR(t.strain_jacobian(i), fd, 1e-7 * t.strain_jacobian.norm()) << "coordinate " << i;
    }
    EXPECT_NEAR(t.strain_rate, t.strain_jacobian.dot(st.q_dot), 1e-15);
  }
}

TEST(AleElement, StrainAccelerationBiasMatchesFiniteDifferences) {
  // eps_dot_q q_dot = d/dtau eps_dot(q + tau q_dot, q_dot) at tau = 0.
  std::mt19937 rng(6);
  const AleElementParams p = CableParams(1e-3, 0.01);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 1e-3);
    const double tau = 1e-5;
    const double fd = (EvaluateAleElement(p, st.q + tau * st.q_dot, st.q_dot).strain_rate -
                       EvaluateAleElement(p, st.q - tau * st.q_dot, st.q_dot).strain_rate) /
                      (2.0 * tau);
    const double bias = EvaluateAleElement(p, st.q, st.q_dot).strain_accel_bias;
    EXPECT_NEAR(bias, fd, 1e-7 * std::abs(bias) + 1e-12);
  }
}

TEST(AleElement, SlackElementCarriesNoTension) {
  // A cable cannot push (docs/model-notes.md row 27): a compressed element
  // carries nothing, however fast it moves, and has no elastic mass.
  std::mt19937 rng(7);
  for (double h : {0.0, 0.01}) {
    const AleElementParams p = CableParams(1e-3, h);
    for (double speed : {0.0, 1.0, 100.0}) {
      const ElementState st = RandomState(&rng, -1e-3);  // compressed
      const AleElementTerms t = EvaluateAleElement(p, st.q, speed * st.q_dot);
      EXPECT_LT(t.strain, 0.0);
      EXPECT_FALSE(t.taut);
      EXPECT_EQ(t.tension, 0.0);
      EXPECT_EQ(t.elastic_force.norm(), 0.0);
      EXPECT_EQ(t.elastic_mass.norm(), 0.0);
      EXPECT_EQ(AleStrainEnergy(p, st.q), 0.0);
    }
  }
}

TEST(AleElement, StretchedElementUnloadingFasterThanItRelaxesCarriesNothing) {
  // eq. 13 with the element shortening at 1 m/s per 0.1 m: EA (eps + beta
  // eps_dot) < 0, a push; the unilateral law applies no force instead.
  const AleElementParams p = CableParams(1e-3, 0.01);
  Vector8d q, q_dot = Vector8d::Zero();
  q << 0, 0, 0, 0, 0, 0.1003, 0.0, 0.1;  // eps = 3e-3 (the paper's pre-tension strain)
  q_dot(5) = -1.0;
  const AleElementTerms t = EvaluateAleElement(p, q, q_dot);
  EXPECT_TRUE(t.taut);
  EXPECT_LT(t.strain + p.rayleigh_beta_s * t.strain_rate, 0.0);  // eq. 13 would push
  EXPECT_TRUE(t.pushing);
  EXPECT_EQ(t.tension, 0.0);
  EXPECT_EQ(t.elastic_force.norm(), 0.0);
  // The smoothing's added mass stays: it only resists strain acceleration,
  // and keeps the inertia the integrator sees from jumping.
  EXPECT_GT(t.elastic_mass.norm(), 0.0);
  // Slowly: eq. 13 as printed.
  const AleElementTerms slow = EvaluateAleElement(p, q, 1e-3 * q_dot);
  EXPECT_FALSE(slow.pushing);
  EXPECT_EQ(slow.tension,
            p.axial_stiffness_n * (slow.strain + p.rayleigh_beta_s * slow.strain_rate));
}

TEST(AleElement, TighteningElementTakesUpItsStiffnessAndDampingWithoutAJump) {
  // Across eps = 0 and the toe, the force is continuous (phi is C1): a sweep of the strain through
  // both shows no step larger than the sweep's own increments make.
  const AleElementParams p = CableParams(1e-3, 0.01);
  const double toe = p.slack_toe_strain;
  EXPECT_EQ(UnilateralElasticStrain(-1e-6, toe).value, 0.0);
  EXPECT_EQ(UnilateralElasticStrain(0.0, toe).slope, 0.0);
  EXPECT_EQ(UnilateralElasticStrain(toe, toe).value, toe);
  EXPECT_EQ(UnilateralElasticStrain(toe, toe).slope, 1.0);
  EXPECT_DOUBLE_EQ(UnilateralElasticStrain(0.5 * toe, toe).value, 0.375 * toe);
  EXPECT_DOUBLE_EQ(UnilateralElasticStrain(0.5 * toe, toe).slope, 1.25);
  // The potential is continuous where the toe meets eq. 13.
  EXPECT_NEAR(UnilateralElasticStrain(toe * (1 - 1e-12), toe).energy,
              UnilateralElasticStrain(toe, toe).energy, 1e-18);  // 2.5e-10 of it
  Vector8d q_dot = Vector8d::Zero();
  // Lengthening at eps_dot ~ 0.1 /s: once engaged, the damping and
  // smoothing stress EA (beta + h/2) eps_dot is about 20 N.
  q_dot(5) = 0.01;
  double previous = 0.0;
  double largest_step = 0.0;
  const int n = 20000;
  for (int i = 0; i <= n; ++i) {
    const double strain = -0.5 * toe + 2.0 * toe * i / n;
    Vector8d q;
    q << 0, 0, 0, 0, 0, 0.1 * std::sqrt(1.0 + 2.0 * strain), 0.0, 0.1;
    const double force = EvaluateAleElement(p, q, q_dot).elastic_force.norm();
    if (i > 0) largest_step = std::max(largest_step, std::abs(force - previous));
    previous = force;
  }
  // One increment of strain (1e-8) is at most 0.5 mN of elastic force (the
  // toe's stiffness peaks at 4/3 EA), and the toe's largest curvature
  // 4/e_t takes up the ~20 N over it at 8 mN per increment. A jump would
  // be the whole 20 N.
  EXPECT_LT(largest_step, 0.05);
}

TEST(AleElement, TautElementTensionIsEq13) {
  std::mt19937 rng(8);
  const AleElementParams p = CableParams(1e-3, 0.01);
  const ElementState st = SlowState(&rng, 2e-3);
  const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
  EXPECT_TRUE(t.taut);
  EXPECT_NEAR(t.tension, p.axial_stiffness_n * (t.strain + p.rayleigh_beta_s * t.strain_rate),
              1e-12);
  EXPECT_GT(t.tension, 0.0);
}

TEST(AleElement, ElasticForceIsMinusStrainEnergyGradientInPositions) {
  std::mt19937 rng(9);
  const AleElementParams p = CableParams(0.0, 0.0);
  for (int trial = 0; trial < 20; ++trial) {
    const ElementState st = RandomState(&rng, 2e-3);
    const AleElementTerms t = EvaluateAleElement(p, st.q, Vector8d::Zero());
    for (int i = 0; i < 6; ++i) {
      const double step = 1e-7;
      Vector8d plus = st.q, minus = st.q;
      plus(i) += step;
      minus(i) -= step;
      const double grad = (AleStrainEnergy(p, plus) - AleStrainEnergy(p, minus)) / (2.0 * step);
      EXPECT_NEAR(t.elastic_force(i), -grad, 1e-6 * t.elastic_force.norm()) << "coordinate " << i;
    }
  }
}

TEST(AleElement, UnsmoothedForceIsEq6) {
  // h = 0: Q'_e = Q_e = Δs eps_q^T T (eq. 6), and no elastic mass.
  std::mt19937 rng(10);
  const AleElementParams p = CableParams(1e-3, 0.0);
  const ElementState st = RandomState(&rng, 1e-3);
  const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
  const Vector8d expected = -(st.q(7) - st.q(6)) * t.tension * t.strain_jacobian.transpose();
  EXPECT_LT(RelativeError(t.elastic_force, expected), 1e-15);
  EXPECT_EQ(t.elastic_mass.norm(), 0.0);
}

TEST(AleElement, SmoothingTermsVanishAsStepGoesToZero) {
  std::mt19937 rng(11);
  const double beta = 1e-3;
  const ElementState st = SlowState(&rng, 1e-3);
  const Vector8d f0 = EvaluateAleElement(CableParams(beta, 0.0), st.q, st.q_dot).elastic_force;
  // M_elastic is proportional to gamma = beta h / 2 + k h^2 / 6 and the extra
  // force to (k h / 2) eps_dot + gamma eps_dot_q q_dot: both O(h) with
  // beta > 0 (the linear regime starts once h << 3 beta), and M_elastic is
  // exactly O(h^2) with beta = 0. Halving h must halve (quarter) them.
  double prev_force = 0.0, prev_mass = 0.0, prev_mass_nodamp = 0.0;
  const double mass_per_gamma =
      EvaluateAleElement(CableParams(beta, 1.0), st.q, st.q_dot).elastic_mass.norm() /
      (beta / 2.0 + 1.0 / 6.0);
  for (double h = 1e-2; h > 1e-7; h /= 2.0) {
    const AleElementTerms t = EvaluateAleElement(CableParams(beta, h), st.q, st.q_dot);
    const AleElementTerms t0 = EvaluateAleElement(CableParams(0.0, h), st.q, st.q_dot);
    const double force = (t.elastic_force - f0).norm();
    const double mass = t.elastic_mass.norm();
    const double mass_nodamp = t0.elastic_mass.norm();
    EXPECT_NEAR(mass / (beta * h / 2.0 + h * h / 6.0), mass_per_gamma, 1e-12 * mass_per_gamma);
    if (prev_force > 0.0) {
      EXPECT_LT(force, prev_force);
      EXPECT_LT(mass, prev_mass);
      EXPECT_NEAR(prev_mass_nodamp / mass_nodamp, 4.0, 1e-9) << "h " << h;
      if (h < 3e-6) {  // asymptotic, linear regime (ratio - 2 ~ h / (3 beta))
        EXPECT_NEAR(prev_force / force, 2.0, 0.01) << "h " << h;
        EXPECT_NEAR(prev_mass / mass, 2.0, 0.01) << "h " << h;
      }
    }
    prev_force = force;
    prev_mass = mass;
    prev_mass_nodamp = mass_nodamp;
  }
}

TEST(AleElement, SmoothedForceMatchesTimeAveragedStrain) {
  // eqs. 14-17: EA (k eps_bar + beta eps_dot_bar) with eps'' = eps_dot_q q_dot
  // + eps_q q''. The kernel splits it into -Q'_e and -M_elastic q''.
  std::mt19937 rng(12);
  const double beta = 1e-3, h = 0.01;
  const AleElementParams p = CableParams(beta, h);
  const ElementState st = SlowState(&rng, 1e-3);
  Vector8d q_ddot;
  for (int i = 0; i < 8; ++i) q_ddot(i) = std::sin(1.0 + i);
  const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
  const double eps_ddot = t.strain_accel_bias + t.strain_jacobian.dot(q_ddot);
  const double eps_bar = t.strain + h / 2 * t.strain_rate + h * h / 6 * eps_ddot;
  const double eps_dot_bar = t.strain_rate + h / 2 * eps_ddot;
  const double stress = p.axial_stiffness_n * (eps_bar + beta * eps_dot_bar);
  const Vector8d expected = -(st.q(7) - st.q(6)) * stress * t.strain_jacobian.transpose();
  EXPECT_LT(RelativeError(t.elastic_force - t.elastic_mass * q_ddot, expected), 1e-12);
}

TEST(AleElement, RigidTranslationAndSteadyFlowAreStrainFree) {
  // A straight stationary cable whose material flows through it (s1_dot =
  // s2_dot) or which translates rigidly feels no strain rate and no
  // additional inertia.
  std::mt19937 rng(13);
  const AleElementParams p = CableParams(1e-3, 0.01);
  ElementState st = RandomState(&rng, 1e-3);
  st.q_dot.setZero();
  st.q_dot.segment<3>(0) = st.q_dot.segment<3>(3) = Eigen::Vector3d(0.1, -0.2, 0.3);
  st.q_dot(6) = st.q_dot(7) = 0.05;
  const AleElementTerms t = EvaluateAleElement(p, st.q, st.q_dot);
  EXPECT_NEAR(t.strain_rate, 0.0, 1e-15);
  EXPECT_NEAR(t.ale_inertia_force.norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace ccsrm::sim::internal
