#pragma once
// Where the markers sit on the arm: one rigid body per link (and one for the
// ground), each a cluster of markers with known positions in the body frame.
// The same layout places virtual markers on a simulation (ccsrm generate, the
// camera rig) and recovers link poses from measured markers (mocap process).
#include <Eigen/Core>

#include <string>
#include <vector>

#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::mocap {

// A marker cluster fixed to one body.
struct RigidBody {
  // "base" for the ground, "link1".."linkN" for the links (the HDF5 group
  // name under /mocap/rigid_bodies/).
  std::string name;
  // 0 = ground (positions are then in W), else the 1-based link number
  // (positions in the link's body frame B, SPEC 2).
  int link = 0;
  std::vector<std::string> marker_names;
  std::vector<Eigen::Vector3d> p_BM;  // marker positions in the body frame [m]
};

struct MarkerLayout {
  // Base first (when present), then links in increasing order.
  std::vector<RigidBody> bodies;

  // Every marker name, body by body in `bodies` order: the marker order of a
  // virtual recording.
  std::vector<std::string> MarkerNames() const;
  std::size_t marker_count() const;
};

// Options of the default layout: a small asymmetric plate on the +x' side of
// every link (the side facing the cameras above the table), and a cluster on
// the ground behind joint 1.
struct DefaultMarkerLayoutOptions {
  // Markers per link plate: 3 or 4. Four lets a link keep its pose when one
  // marker is occluded.
  int markers_per_link = 4;
  // Markers on the ground (>= 4, used for camera extrinsics); 0 = no base.
  int base_markers = 4;
};

// The default layout for an arm. Marker names are "L<ii>_<A..D>" on link ii
// (two digits) and "B0_<A..>" on the ground. The plate pattern is the same on
// every link (about 6 cm square, wider than the link so orientation is well
// determined), scaled along z' to fit links shorter than 0.07 m, and no two of
// its distances are equal, so a labeller can tell its markers apart.
MarkerLayout DefaultMarkerLayout(const sim::ArmModel& model,
                                 const DefaultMarkerLayoutOptions& options = {});

// World positions p_WM of every marker of `layout` (MarkerNames() order) for
// the given link poses (index 0 = link 1).
std::vector<Eigen::Vector3d> PlaceMarkers(const MarkerLayout& layout,
                                          const std::vector<sim::LinkPose>& poses);

}  // namespace ccsrm::mocap
