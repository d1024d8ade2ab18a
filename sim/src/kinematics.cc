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

Eigen::MatrixXd SegmentBendingPerPulledLength(const ArmModel& model) {
  const int segments = static_cast<int>(model.arm().segments.size());
  const int cables = model.num_cables();
  // Pulled-in length per joint angle of a whole segment: −dL/dθ by central
  // differences at the straight arm. The path lengths are smooth there and
  // a step of 1e-5 rad leaves an error of order h² relative to the slope.
  constexpr double kStepRad = 1e-5;
  Eigen::MatrixXd pulled_per_angle(cables, 2 * segments);
  for (int k = 0; k < segments; ++k) {
    for (int axis = 0; axis < 2; ++axis) {
      JointAngles plus(model.num_joints(), Eigen::Vector2d::Zero()), minus = plus;
      for (int j = 1; j <= model.num_joints(); ++j) {
        if (model.link(j).segment != k) continue;
        plus[j - 1][axis] = kStepRad;
        minus[j - 1][axis] = -kStepRad;
      }
      const std::vector<LinkPose> up = ForwardKinematics(model, plus);
      const std::vector<LinkPose> down = ForwardKinematics(model, minus);
      for (int c = 0; c < cables; ++c) {
        pulled_per_angle(c, 2 * k + axis) =
            -(CablePathLength(model, c, up) - CablePathLength(model, c, down)) / (2.0 * kStepRad);
      }
    }
  }
  return pulled_per_angle.completeOrthogonalDecomposition().pseudoInverse();
}

}  // namespace ccsrm::sim
