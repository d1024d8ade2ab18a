// Tests of the quaternion rigid-link kernels (eqs. 21-34) and the universal
// joint angles, rates and moments (eqs. 23-29, 55-56).
#include "kernels/rigid_body.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace ccsrm::sim::internal {
namespace {

Eigen::Vector4d RandomUnitQuaternion(std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Vector4d(n(*rng), n(*rng), n(*rng), n(*rng)).normalized();
}

Eigen::Vector4d RandomVector4(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Eigen::Vector4d(u(*rng), u(*rng), u(*rng), u(*rng));
}

Eigen::Vector3d RandomVector3(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Eigen::Vector3d(u(*rng), u(*rng), u(*rng));
}

// A rate tangent to the unit sphere (e.e_dot = 0), as kept by eq. 35.
Eigen::Vector4d TangentRate(const Eigen::Vector4d& e, std::mt19937* rng) {
  Eigen::Vector4d d = RandomVector4(rng);
  return d - e * e.dot(d);
}

Eigen::Vector3d Vee(const Eigen::Matrix3d& s) { return {s(2, 1), s(0, 2), s(1, 0)}; }

// Segment 1 link inertia of Table 1 [kg m^2].
Eigen::Matrix3d Table1Inertia() { return Eigen::Vector3d(66e-6, 62e-6, 19e-6).asDiagonal(); }

TEST(RigidBody, RotationMatchesEigenQuaternion) {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector4d e = RandomUnitQuaternion(&rng);
    const Eigen::Matrix3d a = RotationFromQuaternion(e);
    const Eigen::Matrix3d ref = Eigen::Quaterniond(e(0), e(1), e(2), e(3)).toRotationMatrix();
    EXPECT_LT((a - ref).norm(), 1e-14);
    EXPECT_LT((a.transpose() * a - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  }
}

TEST(RigidBody, RateMatrixIdentities) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector4d a = RandomVector4(&rng), b = RandomVector4(&rng);
    EXPECT_LT((QuaternionRateMatrix(a) * a).norm(), 1e-15);
    EXPECT_LT((QuaternionRateMatrix(a) * b + QuaternionRateMatrix(b) * a).norm(), 1e-15);
    const Matrix34d g = QuaternionRateMatrix(a);
    EXPECT_LT((g * g.transpose() - 4.0 * a.squaredNorm() * Eigen::Matrix3d::Identity()).norm(),
              1e-14);
  }
}

TEST(RigidBody, PointJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(43);
  for (int trial = 0; trial < 50; ++trial) {
    // D is the exact partial derivative, so it holds off the unit sphere too.
    const Eigen::Vector4d e = RandomVector4(&rng);
    const Eigen::Vector3d u = RandomVector3(&rng);
    const Matrix34d d = PointJacobian(e, u);
    for (int k = 0; k < 4; ++k) {
      const double step = 1e-6;
      Eigen::Vector4d plus = e, minus = e;
      plus(k) += step;
      minus(k) -= step;
      const Eigen::Vector3d fd =
          (RotationFromQuaternion(plus) * u - RotationFromQuaternion(minus) * u) / (2.0 * step);
      EXPECT_LT((d.col(k) - fd).norm(), 1e-9) << "column " << k;
    }
    // Linear in e: D(e, u) e = 2 A(e) u (Euler's theorem for the quadratic A).
    EXPECT_LT((d * e - 2.0 * RotationFromQuaternion(e) * u).norm(), 1e-14);
  }
}

TEST(RigidBody, PointAccelerationBiasIsRateJacobianTimesRate) {
  // d^2/dt^2 A(e + t e_dot) u' = D(e_dot, u') e_dot exactly (A quadratic in e).
  std::mt19937 rng(44);
  const Eigen::Vector4d e = RandomVector4(&rng), e_dot = RandomVector4(&rng);
  const Eigen::Vector3d u = RandomVector3(&rng);
  const double dt = 1e-3;
  const Eigen::Vector3d fd =
      (RotationFromQuaternion(e + dt * e_dot) * u - 2.0 * RotationFromQuaternion(e) * u +
       RotationFromQuaternion(e - dt * e_dot) * u) /
      (dt * dt);
  EXPECT_LT((PointJacobian(e_dot, u) * e_dot - fd).norm(), 1e-8);
}

// The per-body shortcut the dynamics uses for every cable node and joint
// point: the same Jacobian and velocity product as the direct formulas, to
// rounding, anywhere (off the unit sphere too).
TEST(RigidBody, BodyPointKinematicsGivesEachPointsJacobianAndVelocityProduct) {
  std::mt19937 rng(45);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector4d e = RandomVector4(&rng), e_dot = RandomVector4(&rng);
    const BodyPointKinematics body(e, e_dot);
    for (int point = 0; point < 5; ++point) {
      const Eigen::Vector3d u = RandomVector3(&rng);
      EXPECT_LT((body.Jacobian(u) - PointJacobian(e, u)).norm(), 1e-14);
      EXPECT_LT((body.VelocityProduct(u) - PointJacobian(e_dot, u) * e_dot).norm(), 1e-14);
    }
  }
}

TEST(RigidBody, BodyAngularVelocityMatchesRotationRate) {
  // A^T A_dot = Skew(w') along a path on the unit sphere.
  std::mt19937 rng(45);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector4d e = RandomUnitQuaternion(&rng);
    const Eigen::Vector4d e_dot = TangentRate(e, &rng);
    const double dt = 1e-6;
    const Eigen::Matrix3d a_dot = (RotationFromQuaternion((e + dt * e_dot).normalized()) -
                                   RotationFromQuaternion((e - dt * e_dot).normalized())) /
                                  (2.0 * dt);
    const Eigen::Matrix3d w_skew = RotationFromQuaternion(e).transpose() * a_dot;
    EXPECT_LT((w_skew + w_skew.transpose()).norm(), 1e-8);
    EXPECT_LT((Vee(w_skew) - BodyAngularVelocity(e, e_dot)).norm(), 1e-8);
  }
}

TEST(RigidBody, QuaternionVelocityForceMatchesLagrangian) {
  // -(m_e_dot e_dot - dT/de) with T = e_dot^T m_e(e) e_dot / 2, by differences.
  std::mt19937 rng(46);
  const Eigen::Matrix3d j = Table1Inertia();
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector4d e = RandomVector4(&rng), e_dot = RandomVector4(&rng);
    const double dt = 1e-6;
    const Eigen::Vector4d m_dot_e_dot =
        (QuaternionMass(e + dt * e_dot, j) - QuaternionMass(e - dt * e_dot, j)) * e_dot /
        (2.0 * dt);
    Eigen::Vector4d dt_de;
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector4d plus = e, minus = e;
      plus(k) += dt;
      minus(k) -= dt;
      dt_de(k) = 0.5 * e_dot.dot((QuaternionMass(plus, j) - QuaternionMass(minus, j)) * e_dot) /
                 (2.0 * dt);
    }
    const Eigen::Vector4d expected = -(m_dot_e_dot - dt_de);
    EXPECT_LT((QuaternionVelocityForce(e, e_dot, j) - expected).norm(), 1e-9 * expected.norm());
  }
}

TEST(RigidBody, MomentForcePowerEqualsMomentTimesAngularVelocity) {
  std::mt19937 rng(47);
  const Eigen::Vector4d e = RandomUnitQuaternion(&rng), e_dot = TangentRate(e, &rng);
  const Eigen::Vector3d m = RandomVector3(&rng);
  EXPECT_NEAR(QuaternionMomentForce(e, m).dot(e_dot), m.dot(BodyAngularVelocity(e, e_dot)), 1e-15);
}

// Quaternion acceleration from eqs. 31-35: [m_e, e; e^T, 0] [e''; -lambda] =
// [velocity force + G^T M'; -e_dot.e_dot - Baumgarte terms of e.e = 1].
Eigen::Vector4d QuaternionAcceleration(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot,
                                       const Eigen::Matrix3d& j, const Eigen::Vector3d& moment) {
  const double alpha = 10.0;  // Baumgarte for g = e.e - 1: g'' + 2 alpha g' + alpha^2 g = 0
  Eigen::Matrix<double, 5, 5> lhs = Eigen::Matrix<double, 5, 5>::Zero();
  lhs.topLeftCorner<4, 4>() = QuaternionMass(e, j);
  lhs.block<4, 1>(0, 4) = e;
  lhs.block<1, 4>(4, 0) = e.transpose();
  Eigen::Matrix<double, 5, 1> rhs;
  rhs.head<4>() = QuaternionVelocityForce(e, e_dot, j) + QuaternionMomentForce(e, moment);
  rhs(4) = -e_dot.squaredNorm() - 2.0 * alpha * e.dot(e_dot) -
           0.5 * alpha * alpha * (e.squaredNorm() - 1.0);
  return lhs.partialPivLu().solve(rhs).head<4>();
}

TEST(RigidBody, QuaternionEquationsReproduceEulerEquations) {
  // For |e| = 1: w'_dot = G e'' (G(e_dot) e_dot = 0) must satisfy
  // J' w'_dot + w' x J' w' = M'.
  std::mt19937 rng(48);
  const Eigen::Matrix3d j = Table1Inertia();
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector4d e = RandomUnitQuaternion(&rng), e_dot = TangentRate(e, &rng);
    const Eigen::Vector3d m = 1e-4 * RandomVector3(&rng);
    const Eigen::Vector3d w = BodyAngularVelocity(e, e_dot);
    const Eigen::Vector3d w_dot = QuaternionRateMatrix(e) * QuaternionAcceleration(e, e_dot, j, m);
    const Eigen::Vector3d euler = j * w_dot + w.cross(j * w) - m;
    EXPECT_LT(euler.norm(), 1e-12 * (m.norm() + (j * w).norm() * w.norm()));
  }
}

TEST(RigidBody, FreeBodyKeepsEnergyAndAngularMomentum) {
  // Torque-free link of Table 1 spinning about all three axes, integrated
  // with classical RK4 on (e, e_dot) for 10 s at a fixed 1 ms step.
  const Eigen::Matrix3d j = Table1Inertia();
  const Eigen::Vector3d w0(1.0, -2.0, 3.0);  // [rad/s]
  Eigen::Vector4d e = Eigen::Vector4d(1.0, 0.2, -0.3, 0.1).normalized();
  // e_dot = G^T w' / 4 for |e| = 1.
  Eigen::Vector4d e_dot = QuaternionRateMatrix(e).transpose() * w0 / 4.0;

  auto energy = [&](const Eigen::Vector4d& q, const Eigen::Vector4d& qd) {
    const Eigen::Vector3d w = BodyAngularVelocity(q, qd);
    return 0.5 * w.dot(j * w);
  };
  auto momentum = [&](const Eigen::Vector4d& q, const Eigen::Vector4d& qd) {
    return Eigen::Vector3d(RotationFromQuaternion(q) * j * BodyAngularVelocity(q, qd));
  };
  const double e0 = energy(e, e_dot);
  const Eigen::Vector3d h0 = momentum(e, e_dot);
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  auto accel = [&](const Eigen::Vector4d& q, const Eigen::Vector4d& qd) {
    return QuaternionAcceleration(q, qd, j, zero);
  };

  const double dt = 1e-3;
  double max_energy_drift = 0.0, max_momentum_drift = 0.0, max_norm_drift = 0.0;
  for (int step = 0; step < 10000; ++step) {
    const Eigen::Vector4d k1x = e_dot, k1v = accel(e, e_dot);
    const Eigen::Vector4d k2x = e_dot + 0.5 * dt * k1v;
    const Eigen::Vector4d k2v = accel(e + 0.5 * dt * k1x, k2x);
    const Eigen::Vector4d k3x = e_dot + 0.5 * dt * k2v;
    const Eigen::Vector4d k3v = accel(e + 0.5 * dt * k2x, k3x);
    const Eigen::Vector4d k4x = e_dot + dt * k3v;
    const Eigen::Vector4d k4v = accel(e + dt * k3x, k4x);
    e += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    e_dot += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    max_energy_drift = std::max(max_energy_drift, std::abs(energy(e, e_dot) - e0) / e0);
    max_momentum_drift = std::max(max_momentum_drift, (momentum(e, e_dot) - h0).norm() / h0.norm());
    max_norm_drift = std::max(max_norm_drift, std::abs(e.norm() - 1.0));
  }
  RecordProperty("max_relative_energy_drift", std::to_string(max_energy_drift));
  RecordProperty("max_relative_momentum_drift", std::to_string(max_momentum_drift));
  std::printf("free body over 10 s: energy drift %.3e, momentum drift %.3e, |e|-1 %.3e\n",
              max_energy_drift, max_momentum_drift, max_norm_drift);
  EXPECT_LT(max_energy_drift, 1e-6);
  EXPECT_LT(max_momentum_drift, 1e-6);
  EXPECT_LT(max_norm_drift, 1e-9);
}

TEST(UniversalJoint, AnglesRoundTrip) {
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int trial = 0; trial < 200; ++trial) {
    const double ax = u(rng), ay = u(rng), az = u(rng);
    const Eigen::Vector2d uj = UniversalJointAngles(RotationX(ax) * RotationY(ay));
    EXPECT_NEAR(uj(0), ax, 1e-14);
    EXPECT_NEAR(uj(1), ay, 1e-14);
    const Eigen::Vector3d c = CardanXYZAngles(RotationX(ax) * RotationY(ay) * RotationZ(az));
    EXPECT_NEAR(c(0), ax, 1e-13);
    EXPECT_NEAR(c(1), ay, 1e-13);
    EXPECT_NEAR(c(2), az, 1e-13);
    const Eigen::Vector3d no_twist = CardanXYZAngles(RotationX(ax) * RotationY(ay));
    EXPECT_NEAR(no_twist(2), 0.0, 1e-14);
  }
  // Gimbal lock: the rotation is still reproduced.
  const Eigen::Matrix3d lock = RotationX(0.3) * RotationY(1.5707963267948966) * RotationZ(0.2);
  const Eigen::Vector3d c = CardanXYZAngles(lock);
  EXPECT_LT((RotationX(c(0)) * RotationY(c(1)) * RotationZ(c(2)) - lock).norm(), 1e-12);
}

TEST(UniversalJoint, RateMatrixIsOrthonormal) {
  for (double ty : {-1.0, 0.0, 0.3, 1.2}) {
    const Matrix32d b = UniversalJointRateMatrix(ty);
    EXPECT_LT((b.transpose() * b - Eigen::Matrix2d::Identity()).norm(), 1e-15);
  }
}

TEST(UniversalJoint, RatesMatchFiniteDifferences) {
  // Parent with an arbitrary motion, child = parent * Rx(theta_x) Ry(theta_y).
  std::mt19937 rng(52);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector4d ep = RandomUnitQuaternion(&rng), ep_dot = TangentRate(ep, &rng);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Eigen::Vector2d theta(u(rng), u(rng)), theta_dot(u(rng), u(rng));
    auto parent = [&](double t) { return RotationFromQuaternion((ep + t * ep_dot).normalized()); };
    auto child = [&](double t) {
      const Eigen::Vector2d th = theta + t * theta_dot;
      return Eigen::Matrix3d(parent(t) * RotationX(th(0)) * RotationY(th(1)));
    };
    const double dt = 1e-6;
    auto body_rate = [&](auto&& rot) {
      const Eigen::Matrix3d s = rot(0.0).transpose() * (rot(dt) - rot(-dt)) / (2.0 * dt);
      return Vee(s);
    };
    const Eigen::Vector3d w_parent = body_rate(parent);
    const Eigen::Vector3d w_child = body_rate(child);
    const Eigen::Matrix3d rel = parent(0.0).transpose() * child(0.0);
    const Eigen::Vector3d w_rel = RelativeAngularVelocity(rel, w_child, w_parent);
    EXPECT_LT((w_rel - UniversalJointRateMatrix(theta(1)) * theta_dot).norm(), 1e-8);
    EXPECT_LT((UniversalJointRates(theta(1), w_rel) - theta_dot).norm(), 1e-8);
    const Eigen::Vector2d fd = (UniversalJointAngles(parent(dt).transpose() * child(dt)) -
                                UniversalJointAngles(parent(-dt).transpose() * child(-dt))) /
                               (2.0 * dt);
    EXPECT_LT((fd - theta_dot).norm(), 1e-8);
  }
}

TEST(UniversalJoint, JointMomentPowerEqualsBodyMomentPower) {
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector2d theta(u(rng), u(rng)), theta_dot(u(rng), u(rng)), m(u(rng), u(rng));
    const Eigen::Matrix3d rel = RotationX(theta(0)) * RotationY(theta(1));
    const Eigen::Vector3d w_parent = RandomVector3(&rng);
    // Child rate consistent with the joint: w_child = rel^T w_parent + B theta_dot.
    const Eigen::Vector3d w_child =
        rel.transpose() * w_parent + UniversalJointRateMatrix(theta(1)) * theta_dot;
    const JointBodyMoments bm = JointMomentsToBodies(rel, theta(1), m);
    EXPECT_NEAR(bm.on_child_body.dot(w_child) + bm.on_parent_body.dot(w_parent), m.dot(theta_dot),
                1e-14);
    // Equal and opposite in the world: A_p M'_parent = -A_c M'_child with A_c = A_p rel.
    EXPECT_LT((bm.on_parent_body + rel * bm.on_child_body).norm(), 1e-15);
  }
}

}  // namespace
}  // namespace ccsrm::sim::internal
