#pragma once
// Rigid-link kinematics of the arm: link poses from joint angles and the
// X-Y Cardan joint-angle convention of SPEC 2 (R_{L(i-1) L(i)} = Rx(θx) Ry(θy)).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "ccsrm/sim/model.h"

namespace ccsrm::sim {

// Joint angles of every joint, (θx, θy) in rad, index 0 = joint 1.
using JointAngles = std::vector<Eigen::Vector2d>;

// Pose of link i's body frame B in the world W.
struct LinkPose {
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();  // mass centre [m]
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();
};

// Rotation about x, y, z by `angle` [rad].
Eigen::Matrix3d RotX(double angle);
Eigen::Matrix3d RotY(double angle);

// Poses of links 1..N (index 0 = link 1) for the given joint angles.
// Precondition: angles.size() == model.num_joints().
std::vector<LinkPose> ForwardKinematics(const ArmModel& model, const JointAngles& angles);

// (θx, θy) of a universal joint from the relative rotation R_PC = R_WPᵀ R_WC
// of child C in parent P (SPEC 2).
Eigen::Vector2d UniversalJointAngles(const Eigen::Matrix3d& R_PC);

// (θx, θy, twist) with R_PC = Rx(θx) Ry(θy) Rz(twist); a true universal
// joint keeps the twist at zero (used as a consistency check on measured poses).
Eigen::Vector3d CardanXyzAngles(const Eigen::Matrix3d& R_PC);

// Tilt [rad] of a universal joint at (θx, θy): the angle between the parent's
// and the child's z axes, acos(cos θx cos θy).
double JointTiltRad(const Eigen::Vector2d& angles);

// World position of cable node `node` of cable `cable` (0-based) for the
// given link poses.
Eigen::Vector3d CableNodePosition(const ArmModel& model, int cable, int node,
                                  const std::vector<LinkPose>& poses);

// Geometric length of a driving cable's path from its input point through
// every hole to its anchor [m].
double CablePathLength(const ArmModel& model, int cable, const std::vector<LinkPose>& poses);

// The moment arms of the driving cables on each segment's bending at
// `angles`: a C × 2S matrix (C cables, S segments) of ∂L_c/∂Θ [m/rad],
// column 2(k − 1) + axis the derivative of cable c's path length
// (CablePathLength) when every joint of segment k turns together about x
// (axis 0) or y (axis 1).
Eigen::MatrixXd SegmentMomentArms(const ArmModel& model, const JointAngles& angles);

// The bending each segment's joints take, kinematically, for given
// pulled-in lengths of the driving cables: a 2S × C matrix (S segments, C
// cables) whose row 2(k − 1) + axis maps the C pulled-in lengths [m] to the
// angle [rad] about x (axis 0) or y (axis 1) that every joint of segment k
// would take. SPEC 3's kinematic planning linearised at the straight arm
// (SegmentMomentArms there) and inverted by least squares (minimum norm where the cables cannot
// tell two bendings apart). Applied to the input rates it gives the bending rate the inputs command
// (the discovered terms' input rate, sim/effects.h).
Eigen::MatrixXd SegmentBendingPerPulledLength(const ArmModel& model);

}  // namespace ccsrm::sim
