#include "ccsrm/mocap/marker_layout.h"

#include <algorithm>
#include <cstdio>

#include "ccsrm/common/error.h"

namespace ccsrm::mocap {
namespace {

// Plate pattern on a link, (x', y', z') in metres: on the +x' side, above the
// hole circle, spread along the link. Heights differ so the cluster is not
// planar (better conditioned fits), and all six pairwise distances differ.
constexpr double kPlate[4][3] = {
    {0.030, -0.028, -0.028},
    {0.034, 0.030, -0.016},
    {0.038, -0.016, 0.010},
    {0.031, 0.022, 0.030},
};
// Ground cluster behind joint 1, (x, y, z) in W [m]; non-planar so a camera's
// pose follows from it alone.
constexpr double kBase[6][3] = {
    {0.020, -0.045, -0.060}, {0.045, 0.040, -0.065},  {0.030, 0.000, -0.105},
    {0.055, 0.025, -0.135},  {0.025, -0.030, -0.150}, {0.040, 0.050, -0.115},
};
// The plate spans z' in [-0.028, 0.030]: keep 1.2 cm clear of each joint.
constexpr double kPlateHalfSpan = 0.030;
constexpr double kJointClearance = 0.012;

std::string MarkerName(const char* prefix, int number, int index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s%02d_%c", prefix, number, static_cast<char>('A' + index));
  return buf;
}

}  // namespace

std::vector<std::string> MarkerLayout::MarkerNames() const {
  std::vector<std::string> names;
  for (const RigidBody& body : bodies) {
    names.insert(names.end(), body.marker_names.begin(), body.marker_names.end());
  }
  return names;
}

std::size_t MarkerLayout::marker_count() const {
  std::size_t count = 0;
  for (const RigidBody& body : bodies) count += body.marker_names.size();
  return count;
}

MarkerLayout DefaultMarkerLayout(const sim::ArmModel& model,
                                 const DefaultMarkerLayoutOptions& options) {
  CCSRM_CHECK(options.markers_per_link == 3 || options.markers_per_link == 4);
  CCSRM_CHECK(options.base_markers == 0 ||
              (options.base_markers >= 4 && options.base_markers <= 6));
  MarkerLayout layout;
  if (options.base_markers > 0) {
    RigidBody base;
    base.name = "base";
    base.link = 0;
    for (int m = 0; m < options.base_markers; ++m) {
      // "B0_A": the ground is body 0; one digit reads better than "B00".
      base.marker_names.push_back(std::string("B0_") + static_cast<char>('A' + m));
      base.p_BM.emplace_back(kBase[m][0], kBase[m][1], kBase[m][2]);
    }
    layout.bodies.push_back(std::move(base));
  }
  for (int i = 0; i < model.num_links(); ++i) {
    const double half_length = 0.5 * model.links()[i].length_m;
    const double z_scale =
        std::min(1.0, std::max(0.0, half_length - kJointClearance) / kPlateHalfSpan);
    CCSRM_CHECK(z_scale > 0.0);
    RigidBody body;
    body.name = "link" + std::to_string(i + 1);
    body.link = i + 1;
    for (int m = 0; m < options.markers_per_link; ++m) {
      body.marker_names.push_back(MarkerName("L", i + 1, m));
      body.p_BM.emplace_back(kPlate[m][0], kPlate[m][1], z_scale * kPlate[m][2]);
    }
    layout.bodies.push_back(std::move(body));
  }
  return layout;
}

std::vector<Eigen::Vector3d> PlaceMarkers(const MarkerLayout& layout,
                                          const std::vector<sim::LinkPose>& poses) {
  std::vector<Eigen::Vector3d> p_WM;
  p_WM.reserve(layout.marker_count());
  for (const RigidBody& body : layout.bodies) {
    CCSRM_CHECK(body.link >= 0 && body.link <= static_cast<int>(poses.size()));
    CCSRM_CHECK(body.p_BM.size() == body.marker_names.size());
    for (const Eigen::Vector3d& p_BM : body.p_BM) {
      if (body.link == 0) {
        p_WM.push_back(p_BM);
      } else {
        const sim::LinkPose& pose = poses[body.link - 1];
        p_WM.push_back(pose.p_WB + pose.R_WB * p_BM);
      }
    }
  }
  return p_WM;
}

}  // namespace ccsrm::mocap
