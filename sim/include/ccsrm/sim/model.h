#pragma once
// The immutable model of an arm (MuJoCo's "model"): geometry, inertia,
// cable routing, the coordinate layout and the sparsity pattern of its
// equations with their fill-reducing ordering. Built once from an ArmConfig
// and shared read-only by any number of runs, in any threads; what a run
// may change (friction, damping, pre-tension: ArmParameters) is not in it,
// so changing a parameter never rebuilds the model.
//
// Frames and names follow docs/conventions.md: W is the world frame (origin
// at joint 1, z along the straight arm, x normal to the table), B_i the body
// frame of link i at its mass centre. p_BH is a hole H in its link's frame.
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "ccsrm/sim/config.h"

namespace ccsrm::sim {

namespace internal {
class SparseLayout;
}

struct LinkModel {
  int segment = 0;  // 0-based
  double length_m = 0.0;
  double mass_kg = 0.0;
  Eigen::Vector3d inertia_kgm2 = Eigen::Vector3d::Zero();  // diagonal of J' in B
};

// One node of a driving cable. Input nodes sit on the ground with a
// prescribed material coordinate; hole nodes are Eulerian (fixed to a disk,
// free material coordinate); the anchor node is fixed to its link in both
// position and material coordinate.
struct CableNodeModel {
  enum class Kind { kInput, kHole, kAnchor };
  Kind kind = Kind::kHole;
  int link = 0;  // 0 = ground, else 1-based link index
  // Position in the link frame (or in W when link == 0).
  Eigen::Vector3d p_LN = Eigen::Vector3d::Zero();
};

struct DrivingCableModel {
  int segment = 0;  // 0-based
  double radius_m = 0.0;
  double angle_rad = 0.0;
  std::vector<CableNodeModel> nodes;  // input, holes ..., anchor
  int num_elements() const { return static_cast<int>(nodes.size()) - 1; }
  int num_holes() const { return static_cast<int>(nodes.size()) - 2; }
};

// A connecting mechanism between joints i and j = i + 1 (1-based) of one
// segment.
struct ConnectingPairModel {
  ConnectingKind kind = ConnectingKind::kSmallS;
  int joint_i = 0;
  int joint_j = 0;
  double stiffness_nmprad = 0.0;  // small S: k_sc (eq. 41); large S: E_cA_c r_lc^2/l_lc
  double cable_length_m = 0.0;    // l_sc or l_lc
  double pulley_radius_m = 0.0;   // r_sc or r_lc
  double wrap_angle_rad = 0.0;    // large S: Theta_lc
};

// The widest hole circle [m] through each joint of `arm` (index joint - 1):
// that of the cables passing it (a joint no cable passes: its segment's).
// Its disks are at least that wide, so the joint's range is at most
// 2 atan(d / 2R) (ArmModel::joint_range_rad).
std::vector<double> JointDiskRadiiM(const ArmConfig& arm);

// The range [rad] of each joint of `arm` (index joint - 1): 2 atan(d / 2R)
// with R from JointDiskRadiiM (ArmModel::joint_range_rad).
std::vector<double> JointRangesRad(const ArmConfig& arm);

class ArmModel {
 public:
  // Builds the model. Throws InputError if the configuration is invalid.
  explicit ArmModel(const ArmConfig& arm);

  const ArmConfig& arm() const { return arm_; }
  int num_links() const { return static_cast<int>(links_.size()); }
  int num_joints() const { return num_links(); }  // joint i joins link i-1 and link i
  int num_cables() const { return static_cast<int>(cables_.size()); }
  const LinkModel& link(int i) const { return links_[i - 1]; }  // 1-based
  const std::vector<LinkModel>& links() const { return links_; }
  const std::vector<DrivingCableModel>& cables() const { return cables_; }
  const std::vector<ConnectingPairModel>& connecting_pairs() const { return pairs_; }

  // Coordinate layout (eq. 59): every cable node (x, y, z, s), then every
  // link (x, y, z, e0, e1, e2, e3).
  int num_coordinates() const { return num_coordinates_; }
  int node_offset(int cable, int node) const { return node_offsets_[cable][node]; }
  int link_offset(int link) const { return link_offsets_[link - 1]; }  // 1-based

  // The largest tilt [rad] of joint i (1-based), the angle between the two
  // links' axes (JointTiltRad), before its disks meet: 2 atan(d / 2R), with
  // d the disk gap and R the widest hole circle of the cables through it
  // (the disks are at least that wide, so the true range is no larger).
  // Beyond it a cable's path through the gap folds back; ccsrm has no
  // contact between disks, so a plan beyond it is refused and a run that
  // reaches it stops (docs/model-notes.md row 27).
  double joint_range_rad(int joint) const { return joint_range_rad_[joint - 1]; }
  // E I / l [N m/rad] of the elastic backbone at joint `joint` (its
  // segment's, BackboneGeometry), before the scale k_b; 0 without one.
  double backbone_stiffness_nmprad(int joint) const {
    return backbone_stiffness_nmprad_[joint - 1];
  }
  // The hole circle radius R [m] that sets joint i's range.
  double joint_disk_radius_m(int joint) const { return joint_disk_radius_m_[joint - 1]; }

  // Joint i (1-based) in the frame of link i-1 (in W for i = 1) and of link i.
  Eigen::Vector3d p_parent_joint(int joint) const;
  Eigen::Vector3d p_child_joint(int joint) const;

  // The sparse system's topology, pattern and ordering (internal to sim).
  const internal::SparseLayout& sparse_layout() const { return *sparse_layout_; }

 private:
  ArmConfig arm_;
  std::vector<LinkModel> links_;
  std::vector<DrivingCableModel> cables_;
  std::vector<ConnectingPairModel> pairs_;
  std::vector<std::vector<int>> node_offsets_;
  std::vector<int> link_offsets_;
  std::vector<double> joint_range_rad_, joint_disk_radius_m_;
  std::vector<double> backbone_stiffness_nmprad_;  // per joint, index joint - 1
  int num_coordinates_ = 0;
  std::shared_ptr<const internal::SparseLayout> sparse_layout_;  // immutable, shared by copies
};

}  // namespace ccsrm::sim
