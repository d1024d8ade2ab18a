#include "ccsrm/sim/kinematics.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "ccsrm/common/error.h"
#include "kernels/rigid_body.h"

namespace ccsrm::sim {

Eigen::Matrix3d RotX(double angle) { return internal::RotationX(angle); }
Eigen::Matrix3d RotY(double angle) { return internal::RotationY(angle); }

std::vector<LinkPose> ForwardKinematics(const ArmModel& model, const JointAngles& angles) {
  CCSRM_CHECK(static_cast<int>(angles.size()) == model.num_joints());
  std::vector<LinkPose> poses(model.num_links());
  Eigen::Matrix3d R_WP = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WJ = Eigen::Vector3d::Zero();  // current joint centre
  for (int i = 1; i <= model.num_links(); ++i) {
    const Eigen::Matrix3d R_WB = R_WP * RotX(angles[i - 1][0]) * RotY(angles[i - 1][1]);
    LinkPose& pose = poses[i - 1];
    pose.R_WB = R_WB;
    pose.p_WB = p_WJ - R_WB * model.p_child_joint(i);
    p_WJ = pose.p_WB + R_WB * Eigen::Vector3d(0, 0, 0.5 * model.link(i).length_m);
    R_WP = R_WB;
  }
  return poses;
}

Eigen::Vector2d UniversalJointAngles(const Eigen::Matrix3d& R_PC) {
  return internal::UniversalJointAngles(R_PC);
}

Eigen::Vector3d CardanXyzAngles(const Eigen::Matrix3d& R_PC) {
  return internal::CardanXYZAngles(R_PC);
}

double JointTiltRad(const Eigen::Vector2d& angles) {
  const double c = std::cos(angles[0]) * std::cos(angles[1]);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

Eigen::Vector3d CableNodePosition(const ArmModel& model, int cable, int node,
                                  const std::vector<LinkPose>& poses) {
  const CableNodeModel& n = model.cables()[cable].nodes[node];
  if (n.link == 0) return n.p_LN;
  const LinkPose& pose = poses[n.link - 1];
  return pose.p_WB + pose.R_WB * n.p_LN;
}

double CablePathLength(const ArmModel& model, int cable, const std::vector<LinkPose>& poses) {
  const int nodes = static_cast<int>(model.cables()[cable].nodes.size());
  double length = 0.0;
  Eigen::Vector3d previous = CableNodePosition(model, cable, 0, poses);
  for (int k = 1; k < nodes; ++k) {
    const Eigen::Vector3d p = CableNodePosition(model, cable, k, poses);
    length += (p - previous).norm();
    previous = p;
  }
  return length;
}

Eigen::MatrixXd SegmentMomentArms(const ArmModel& model, const JointAngles& angles) {
  const int cables = model.num_cables();
  const int segments = static_cast<int>(model.arm().segments.size());
  // Central differences. Where they balance tensions the moments cancel to
  // first order (Σ_c ∂L_c/∂Θ is second order in the bend), so rounding in
  // the path lengths (~1e-15 m) is amplified: a 1e-3 rad step keeps it to
  // ~1e-12 of them, where 1e-6 rad left noise of ~1e-11 m in the planned
  // lengths, 1e-5 m/s² in their splines' second derivative. The step's
  // truncation, ~δ²/6 = 2e-7 of the moment arms, is smooth in the angles.
  constexpr double kStep = 1e-3;
  Eigen::MatrixXd moment_arm(cables, 2 * segments);
  int first_joint = 0;
  for (int s = 0; s < segments; ++s) {
    const int joints = model.arm().segments[s].links;
    for (int axis = 0; axis < 2; ++axis) {
      JointAngles plus = angles, minus = angles;
      for (int j = first_joint; j < first_joint + joints; ++j) {
        plus[j][axis] += kStep;
        minus[j][axis] -= kStep;
      }
      const std::vector<LinkPose> poses_plus = ForwardKinematics(model, plus);
      const std::vector<LinkPose> poses_minus = ForwardKinematics(model, minus);
      for (int c = 0; c < cables; ++c) {
        moment_arm(c, 2 * s + axis) =
            (CablePathLength(model, c, poses_plus) - CablePathLength(model, c, poses_minus)) /
            (2.0 * kStep);
      }
    }
    first_joint += joints;
  }
  return moment_arm;
}

Eigen::MatrixXd SegmentBendingPerPulledLength(const ArmModel& model) {
  // Pulled in is −ΔL: the map inverts −∂L/∂Θ at the straight arm.
  const Eigen::MatrixXd moment_arm =
      SegmentMomentArms(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  return (-moment_arm).completeOrthogonalDecomposition().pseudoInverse();
}

}  // namespace ccsrm::sim
