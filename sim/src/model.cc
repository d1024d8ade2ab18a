#include "ccsrm/sim/model.h"

#include <algorithm>
#include <cmath>

#include "sparse_system.h"

namespace ccsrm::sim {

ArmModel::ArmModel(const ArmConfig& arm_config) : arm_(arm_config) {
  ValidateArm(arm_, "arm configuration");
  const ArmConfig& arm = arm_;
  const double d = arm.joint_disk_gap_m;

  for (std::size_t s = 0; s < arm.segments.size(); ++s) {
    const SegmentConfig& seg = arm.segments[s];
    const int first_link = static_cast<int>(links_.size()) + 1;
    for (int k = 0; k < seg.links; ++k) {
      LinkModel link;
      link.segment = static_cast<int>(s);
      link.length_m = seg.link_length_m;
      link.mass_kg = seg.link_mass_kg;
      link.inertia_kgm2 = seg.link_inertia_kgm2;
      links_.push_back(link);
    }
    for (int k = 0; k < seg.links; ++k) {
      backbone_stiffness_nmprad_.push_back(
          seg.backbone.present() ? seg.backbone.bending_stiffness_nm2() / seg.link_length_m : 0.0);
    }
    for (int k = 0; k + 1 < seg.links; ++k) {
      if (seg.connecting_pattern[k] == ConnectingKind::kNone) continue;
      ConnectingPairModel pair;
      pair.kind = seg.connecting_pattern[k];
      pair.joint_i = first_link + k;
      pair.joint_j = first_link + k + 1;
      const ConnectingCableConfig& cc = arm.connecting;
      const double ea = cc.youngs_modulus_pa * cc.cross_section_m2;
      if (pair.kind == ConnectingKind::kSmallS) {
        const double r = seg.small_s.pulley_radius_m;
        pair.stiffness_nmprad = 2.0 * ea * r * r / seg.small_s.cable_length_m;  // eq. 41
        pair.cable_length_m = seg.small_s.cable_length_m;
        pair.pulley_radius_m = r;
      } else {
        const double r = seg.large_s.pulley_radius_m;
        pair.stiffness_nmprad = ea * r * r / seg.large_s.cable_length_m;  // eq. 50 prefactor
        pair.cable_length_m = seg.large_s.cable_length_m;
        pair.pulley_radius_m = r;
        pair.wrap_angle_rad = seg.large_s.wrap_angle_rad;
      }
      pairs_.push_back(pair);
    }
  }

  for (const DrivingCableRoute& route : arm.driving.cables) {
    DrivingCableModel cable;
    cable.segment = route.segment - 1;
    cable.radius_m = arm.segments[cable.segment].hole_circle_radius_m;
    cable.angle_rad = route.hole_angle_rad;
    const double x = cable.radius_m * std::cos(cable.angle_rad);
    const double y = cable.radius_m * std::sin(cable.angle_rad);
    const double ground_z = -0.5 * d;
    cable.nodes.push_back({CableNodeModel::Kind::kInput, 0,
                           Eigen::Vector3d(x, y, ground_z - arm.driving.input_offset_m)});
    cable.nodes.push_back({CableNodeModel::Kind::kHole, 0, Eigen::Vector3d(x, y, ground_z)});
    int last_link = 0;
    for (int s = 0; s <= cable.segment; ++s) last_link += arm.segments[s].links;
    for (int i = 1; i <= last_link; ++i) {
      const double half = 0.5 * links_[i - 1].length_m;
      cable.nodes.push_back(
          {CableNodeModel::Kind::kHole, i, Eigen::Vector3d(x, y, -half + 0.5 * d)});
      const auto distal_kind =
          i == last_link ? CableNodeModel::Kind::kAnchor : CableNodeModel::Kind::kHole;
      cable.nodes.push_back({distal_kind, i, Eigen::Vector3d(x, y, half - 0.5 * d)});
    }
    cables_.push_back(cable);
  }

  joint_disk_radius_m_ = JointDiskRadiiM(arm);
  joint_range_rad_ = JointRangesRad(arm);

  int offset = 0;
  for (const auto& cable : cables_) {
    std::vector<int> offsets;
    for (std::size_t n = 0; n < cable.nodes.size(); ++n) {
      offsets.push_back(offset);
      offset += 4;
    }
    node_offsets_.push_back(offsets);
  }
  for (std::size_t i = 0; i < links_.size(); ++i) {
    link_offsets_.push_back(offset);
    offset += 7;
  }
  num_coordinates_ = offset;
  sparse_layout_ = std::make_shared<const internal::SparseLayout>(*this);
}

std::vector<double> JointDiskRadiiM(const ArmConfig& arm) {
  std::vector<double> radius;
  for (const SegmentConfig& segment : arm.segments) radius.resize(radius.size() + segment.links);
  for (const DrivingCableRoute& route : arm.driving.cables) {
    int passes = 0;  // a cable passes joints 1 .. the last link of its segment
    for (int s = 0; s < route.segment; ++s) passes += arm.segments[s].links;
    const double r = arm.segments[route.segment - 1].hole_circle_radius_m;
    for (int j = 0; j < passes; ++j) radius[j] = std::max(radius[j], r);
  }
  int j = 0;
  for (const SegmentConfig& segment : arm.segments) {
    for (int k = 0; k < segment.links; ++k, ++j) {
      if (radius[j] == 0.0) radius[j] = segment.hole_circle_radius_m;
    }
  }
  return radius;
}

std::vector<double> JointRangesRad(const ArmConfig& arm) {
  std::vector<double> range;
  for (double radius : JointDiskRadiiM(arm))
    range.push_back(2.0 * std::atan(arm.joint_disk_gap_m / (2.0 * radius)));
  return range;
}

Eigen::Vector3d ArmModel::p_parent_joint(int joint) const {
  if (joint == 1) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d(0, 0, 0.5 * link(joint - 1).length_m);
}

Eigen::Vector3d ArmModel::p_child_joint(int joint) const {
  return Eigen::Vector3d(0, 0, -0.5 * link(joint).length_m);
}

}  // namespace ccsrm::sim
