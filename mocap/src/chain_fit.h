#pragma once
// The joint-constrained fit of a run of consecutive links (processing.cc).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace ccsrm::mocap::internal {

struct ChainLink {
  Eigen::Vector3d p_BJ_proximal;      // its proximal joint in its frame
  Eigen::Vector3d p_BJ_distal;        // its distal joint in its frame
  std::vector<Eigen::Vector3d> p_BM;  // seen markers, body frame
  std::vector<Eigen::Vector3d> p_WM;  // and where they were seen
  Eigen::Isometry3d* X_WB = nullptr;  // in: its own rigid fit; out: the chain fit
};

// Least-squares fit of the links' markers with every link's distal joint
// on the next link's proximal joint (three rotations per link and the first
// joint's position as unknowns), by Gauss–Newton from the given poses.
// Requires at least 3 markers on every link (checked by the caller). A
// singular step leaves the given poses unchanged.
void FitChain(std::vector<ChainLink>* links);

}  // namespace ccsrm::mocap::internal
