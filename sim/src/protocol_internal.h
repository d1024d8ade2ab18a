#pragma once
// The pieces of a protocol as functions of time, shared by the file reader
// (which checks joins and bends with them) and the Protocol's evaluation.
#include <Eigen/Core>
#include <string>

#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim::internal {

// (θx, θy) [rad] of a universal joint whose link axis points as a rotation
// by `bend_rad` in the bending plane at `plane_rad` (from x' toward y': the
// tip moves toward (cos φ, sin φ)). A universal joint has no twist, so only
// the axis is matched: θy = asin(cos φ sin β), θx = atan2(−sin φ sin β, cos β).
Eigen::Vector2d PlaneBendToCardan(double plane_rad, double bend_rad);

// The piece's joint angles [rad] and rates [rad/s] at `local_s` seconds
// after it starts (before 0: its start; beyond its duration: extrapolated
// by its own formula, which for a move holds the target).
JointAngles PieceAngles(const ProtocolPiece& piece, double local_s);
JointAngles PieceRates(const ProtocolPiece& piece, double local_s);

// Why joint `joint` (1-based) has the range it has, when another segment
// sets it: " (R = 160 mm: the hole circle of segment 3, whose cables pass
// joint 1; segment 1's own is 20 mm)". Empty when the joint's own segment's
// hole circle is the widest through it (JointDiskRadiiM).
std::string RangeSetBy(const ArmConfig& arm, int joint);

}  // namespace ccsrm::sim::internal
