#pragma once
// Rigid links with Euler parameters (paper eqs. 21-34) and universal-joint
// angles (SPEC §2; eqs. 23-29, 55-56).
//
// Notation: e = (e0, e1, e2, e3) is the quaternion of a link, v = (e1, e2, e3).
// A(e) is the body-to-world rotation (x_W = x_C + A x'_B); the paper's R_i is
// A^T (eq. 22). Primes mark body-frame quantities: w' is the body-frame
// angular velocity [rad/s], J' the body-frame inertia [kg m^2], M' a
// body-frame moment [N m]. For a link with q = [x_C (3), e (4)], the
// quaternion block of the mass matrix and forces are given here; the
// translational block is m I3 with no velocity term.
//
// Sign convention: forces are right-hand-side signed (m q'' = F + ...).
#include <Eigen/Core>

namespace ccsrm::sim::internal {

using Matrix34d = Eigen::Matrix<double, 3, 4>;
using Matrix32d = Eigen::Matrix<double, 3, 2>;

// Cross-product matrix: Skew(a) b = a x b.
Eigen::Matrix3d Skew(const Eigen::Vector3d& a);

// A(e) = (e0^2 - v.v) I + 2 v v^T + 2 e0 Skew(v). Quadratic in e; a rotation
// when |e| = 1 (and |e|^2 times a rotation otherwise).
Eigen::Matrix3d RotationFromQuaternion(const Eigen::Vector4d& e);

// G(e) of eq. 26 (3 x 4, linear in e): w' = G(e) e_dot for |e| = 1.
// Identities: G(e) e = 0; G(a) b = -G(b) a; G(e) G(e)^T = 4 |e|^2 I.
Matrix34d QuaternionRateMatrix(const Eigen::Vector4d& e);

// w' = G(e) e_dot (eq. 25) [rad/s]. Precondition: |e| = 1.
Eigen::Vector3d BodyAngularVelocity(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot);

// D(e, u') = d(A(e) u') / de (3 x 4), the exact partial derivative, linear in
// e: column 0 = 2 (e0 u' + v x u'), columns 1..3 = 2 ((v.u') I + v u'^T -
// u' v^T - e0 Skew(u')). The world velocity of body point u' is
// x_C_dot + D(e, u') e_dot and, A being quadratic in e, its acceleration is
// x_C'' + D(e, u') e'' + D(e_dot, u') e_dot.
Matrix34d PointJacobian(const Eigen::Vector4d& e, const Eigen::Vector3d& u_body);

// PointJacobian and the velocity product D(e_dot, u') e_dot of every point of
// one body, from work done once per body: D is linear in u', so D(e, u') =
// sum_k u'_k D(e, e_k); and D(a, u') a = 2 A(a) u' (A's formula is a
// quadratic form in e). A link carries many cable nodes, each needing both.
struct BodyPointKinematics {
  BodyPointKinematics() = default;
  BodyPointKinematics(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot);

  // D(e, u') (3 x 4).
  Matrix34d Jacobian(const Eigen::Vector3d& u_body) const {
    return axis_jacobian[0] * u_body.x() + axis_jacobian[1] * u_body.y() +
           axis_jacobian[2] * u_body.z();
  }
  // D(e_dot, u') e_dot, the acceleration of the point at e'' = 0 and x_C'' = 0.
  Eigen::Vector3d VelocityProduct(const Eigen::Vector3d& u_body) const {
    return rate_quadratic * u_body;
  }

  Matrix34d axis_jacobian[3];                                // D(e, e_k), k = x, y, z
  Eigen::Matrix3d rate_quadratic = Eigen::Matrix3d::Zero();  // 2 A(e_dot)
};

// Quaternion block of the mass matrix, m_e = G^T J' G (eq. 31) [kg m^2].
// Singular (m_e e = 0): the caller adds the constraint e.e = 1 (eq. 35).
Eigen::Matrix4d QuaternionMass(const Eigen::Vector4d& e, const Eigen::Matrix3d& inertia_body);

// Velocity-dependent force on the quaternion (eqs. 33-34), right-hand-side
// signed: -(m_e_dot e_dot - dT/de) = -2 G(e_dot)^T J' w', w' = G(e) e_dot.
// (m_e_dot e_dot = G(e_dot)^T J' w' because G(e_dot) e_dot = 0, and
// dT/de = -G(e_dot)^T J' w' because w' = -G(e_dot) e.)
Eigen::Vector4d QuaternionVelocityForce(const Eigen::Vector4d& e, const Eigen::Vector4d& e_dot,
                                        const Eigen::Matrix3d& inertia_body);

// Generalized force on e of a body-frame moment M' (eq. 32): G(e)^T M'.
Eigen::Vector4d QuaternionMomentForce(const Eigen::Vector4d& e, const Eigen::Vector3d& moment_body);

// Elementary rotations [rad].
Eigen::Matrix3d RotationX(double angle);
Eigen::Matrix3d RotationY(double angle);
Eigen::Matrix3d RotationZ(double angle);

// Universal-joint angles (SPEC §2, eq. 24): rel = A_{i-1}^T A_i =
// Rx(theta_x) Ry(theta_y); returns (theta_x, theta_y) with
// theta_y = atan2(rel(0,2), rel(0,0)), theta_x = atan2(rel(2,1), rel(1,1)).
// Exact for any |theta_x|, |theta_y| < pi/2 when rel has no twist.
Eigen::Vector2d UniversalJointAngles(const Eigen::Matrix3d& rel);

// Full X-Y-Z Cardan decomposition rel = Rx(a) Ry(b) Rz(c); returns (a, b, c)
// with b in [-pi/2, pi/2]. c is the twist a universal joint should not have
// (for mocap consistency checks). Singular at |b| = pi/2 (c set to 0 there).
Eigen::Vector3d CardanXYZAngles(const Eigen::Matrix3d& rel);

// Relative angular velocity of link i w.r.t. link i-1 in link i's frame
// (eq. 27): w_rel = w'_i - rel^T w'_{i-1}, rel = A_{i-1}^T A_i.
Eigen::Vector3d RelativeAngularVelocity(const Eigen::Matrix3d& rel, const Eigen::Vector3d& w_child,
                                        const Eigen::Vector3d& w_parent);

// B(theta_y) of eq. 28 for the X-Y pair: w_rel = B theta_dot with
// B = [[cos theta_y, 0], [0, 1], [sin theta_y, 0]]; B^T B = I.
Matrix32d UniversalJointRateMatrix(double theta_y);

// theta_dot = B^T w_rel (eq. 29; B^T is the left inverse since B^T B = I).
Eigen::Vector2d UniversalJointRates(double theta_y, const Eigen::Vector3d& w_rel);

// Body-frame moments of a joint-space moment M_joint = (M_x, M_y) [N m]
// (eqs. 55-56): on link i (child) B M_joint, on link i-1 (parent)
// -rel B M_joint. Their power on (w'_i, w'_{i-1}) equals M_joint . theta_dot.
struct JointBodyMoments {
  Eigen::Vector3d on_child_body;   // M'_i, link i frame
  Eigen::Vector3d on_parent_body;  // M'_{i-1}, link i-1 frame
};
JointBodyMoments JointMomentsToBodies(const Eigen::Matrix3d& rel, double theta_y,
                                      const Eigen::Vector2d& joint_moment);

}  // namespace ccsrm::sim::internal
