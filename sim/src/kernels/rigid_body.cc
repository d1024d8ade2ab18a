#include "rigid_body.h"

#include <Eigen/Geometry>
#include <cmath>

namespace ccsrm::sim::internal {

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),   //
      -a.y(), a.x(), 0.0;
  return s;
}

Eigen::Matrix3d RotationFromQuaternion(const Eigen::Vector4d& e) {
  const double e0 = e(0);
  const Eigen::Vector3d v = e.tail<3>();
  Eigen::Matrix3d a = 2.0 * (v * v.transpose()) + (2.0 * e0) * Skew(v);
  a.diagonal().array() += e0 * e0 - v.squaredNorm();
  return a;
}

Matrix34d QuaternionRateMatrix(const Eigen::Vector4d& e) {
  // eq. 26: G = 2 [-v, e0 I - Skew(v)].
  Matrix34d g;
  g << -e(1), e(0), e(3), -e(2),  //
      -e(2), -e(3), e(0), e(1),   //
      -e(3), e(2), -e(1), e(0);
  return 2.0 * g;
}

Eigen::Vector3d BodyAngularVelocity(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot) {
  return QuaternionRateMatrix(e) * e_dot;
}

Matrix34d PointJacobian(const Eigen::Vector4d& e, const Eigen::Vector3d& u_body) {
  const double e0 = e(0);
  const Eigen::Vector3d v = e.tail<3>();
  Matrix34d d;
  d.col(0) = 2.0 * (e0 * u_body + v.cross(u_body));
  Eigen::Matrix3d dv = v * u_body.transpose() - u_body * v.transpose() - e0 * Skew(u_body);
  dv.diagonal().array() += v.dot(u_body);
  d.rightCols<3>() = 2.0 * dv;
  return d;
}

BodyPointKinematics::BodyPointKinematics(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot)
    : rate_quadratic(2.0 * RotationFromQuaternion(e_dot)) {
  for (int k = 0; k < 3; ++k) axis_jacobian[k] = PointJacobian(e, Eigen::Vector3d::Unit(k));
}

Eigen::Matrix4d QuaternionMass(const Eigen::Vector4d& e, const Eigen::Matrix3d& inertia_body) {
  const Matrix34d g = QuaternionRateMatrix(e);
  return g.transpose() * inertia_body * g;
}

Eigen::Vector4d QuaternionVelocityForce(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot,
                                        const Eigen::Matrix3d& inertia_body) {
  const Eigen::Vector3d w = QuaternionRateMatrix(e) * e_dot;
  return -2.0 * (QuaternionRateMatrix(e_dot).transpose() * (inertia_body * w));
}

Eigen::Vector4d QuaternionMomentForce(const Eigen::Vector4d& e,
                                      const Eigen::Vector3d& moment_body) {
  return QuaternionRateMatrix(e).transpose() * moment_body;
}

Eigen::Matrix3d RotationX(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix3d r;
  r << 1.0, 0.0, 0.0,  //
      0.0, c, -s,      //
      0.0, s, c;
  return r;
}

Eigen::Matrix3d RotationY(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix3d r;
  r << c, 0.0, s,     //
      0.0, 1.0, 0.0,  //
      -s, 0.0, c;
  return r;
}

Eigen::Matrix3d RotationZ(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix3d r;
  r << c, -s, 0.0,  //
      s, c, 0.0,    //
      0.0, 0.0, 1.0;
  return r;
}

Eigen::Vector2d UniversalJointAngles(const Eigen::Matrix3d& rel) {
  // Rx(a) Ry(b) = [[cb, 0, sb], [sa sb, ca, -sa cb], [-ca sb, sa, ca cb]].
  return {std::atan2(rel(2, 1), rel(1, 1)), std::atan2(rel(0, 2), rel(0, 0))};
}

Eigen::Vector3d CardanXYZAngles(const Eigen::Matrix3d& rel) {
  // Rx(a) Ry(b) Rz(c): first row [cb cc, -cb sc, sb], last column
  // [sb, -sa cb, ca cb].
  const double cb = std::hypot(rel(0, 0), rel(0, 1));
  const double b = std::atan2(rel(0, 2), cb);
  if (cb < 1e-12) {
    // Gimbal lock (|b| = pi/2): only a + c (or a - c) is defined; put it all
    // in a, where rel(2,1) = sin(a +- c) and rel(1,1) = cos(a +- c).
    return {std::atan2(rel(2, 1), rel(1, 1)), b, 0.0};
  }
  return {std::atan2(-rel(1, 2), rel(2, 2)), b, std::atan2(-rel(0, 1), rel(0, 0))};
}

Eigen::Vector3d RelativeAngularVelocity(const Eigen::Matrix3d& rel, const Eigen::Vector3d& w_child,
                                        const Eigen::Vector3d& w_parent) {
  // The paper's R_{i/(i-1)} = R_i R_{i-1}^T = A_i^T A_{i-1} = rel^T.
  return w_child - rel.transpose() * w_parent;
}

Matrix32d UniversalJointRateMatrix(double theta_y) {
  // rel^T rel_dot = Skew(Ry^T x) theta_x_dot + Skew(y) theta_y_dot.
  Matrix32d b;
  b << std::cos(theta_y), 0.0,  //
      0.0, 1.0,                 //
      std::sin(theta_y), 0.0;
  return b;
}

Eigen::Vector2d UniversalJointRates(double theta_y, const Eigen::Vector3d& w_rel) {
  return UniversalJointRateMatrix(theta_y).transpose() * w_rel;
}

JointBodyMoments JointMomentsToBodies(const Eigen::Matrix3d& rel, double theta_y,
                                      const Eigen::Vector2d& joint_moment) {
  JointBodyMoments m;
  m.on_child_body = UniversalJointRateMatrix(theta_y) * joint_moment;  // eq. 55
  m.on_parent_body = -(rel * m.on_child_body);                         // eq. 56
  return m;
}

}  // namespace ccsrm::sim::internal
