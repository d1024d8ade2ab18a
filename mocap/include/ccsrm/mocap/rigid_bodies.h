#pragma once
// The rigid-bodies file, schema "ccsrm-rigid-bodies/1" (mocap/README.md): the
// marker clusters of the arm in YAML, read into and written from a
// MarkerLayout; conversion to and from the /mocap/rigid_bodies records of an
// experiment file; refinement of a layout from a static trial.
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/marker_table.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::mocap {

// "ccsrm-rigid-bodies/1": the schema this ccsrm writes and the only one it reads.
inline constexpr const char* kRigidBodiesSchema = "ccsrm-rigid-bodies/1";

// Checks a layout: at least one body; body names "base" (link 0) or
// "link<n>" (link n >= 1) matching their link number; no body or link twice;
// at least three markers per body, not collinear (a pose needs three points
// that span a plane); finite positions; marker names non-empty and unique
// across bodies. Throws InputError "<source>: <where>: <problem>".
void ValidateMarkerLayout(const MarkerLayout& layout, const std::string& source);

// Parses YAML text of schema ccsrm-rigid-bodies/1. Bodies are returned base
// first, then by link number. Throws InputError "<file>: line N, key
// 'bodies[i].markers[j].name': <problem>" for an unknown or missing key, a
// wrong type, fewer than three markers, a duplicate name and the other
// problems ValidateMarkerLayout names.
MarkerLayout ParseRigidBodies(const std::string& yaml_text, const std::string& file);

// Reads and parses a rigid-bodies file. Throws InputError.
MarkerLayout ReadRigidBodiesFile(const std::string& path);

// The layout as ccsrm-rigid-bodies/1 YAML (positions to 0.1 µm), and written
// atomically to `path`.
std::string RigidBodiesToYaml(const MarkerLayout& layout);
void WriteRigidBodiesFile(const std::string& path, const MarkerLayout& layout);

// Experiment records <-> layout. ToExperimentRigidBodies keeps the body order;
// LayoutFromExperiment takes the link number from the name ("base" = 0,
// "link<n>" = n) and validates the result (InputError naming `file`).
std::vector<datasets::RigidBody> ToExperimentRigidBodies(const MarkerLayout& layout);
MarkerLayout LayoutFromExperiment(const std::vector<datasets::RigidBody>& bodies,
                                  const std::string& file);

// What a static-trial refinement did.
struct StaticTrialRefinement {
  MarkerLayout layout;  // the refined layout
  // Per marker of the layout (MarkerNames() order): how far the refined
  // position moved from the nominal one [m]; NaN when the marker was never
  // seen in the trial (it keeps its nominal position).
  std::vector<double> displacement_m;
  std::vector<std::string> warnings;
};

// Refines a layout from a static trial with the arm straight: every marker's
// position is averaged over the frames where it was seen, and expressed in its
// link's frame as the straight-arm kinematics of `model` predicts it (all
// joint angles zero). When the layout has a ground body with at least three
// markers seen, its (unchanged) positions fix the world frame: the averaged
// positions are mapped into W by the rigid fit of the ground markers first;
// without one, the file frame is taken as W. Markers are matched to the
// table's labels as ProcessMarkers matches them.
// Throws InputError (naming `source`) when a body's link is not in the model
// or no marker of the layout is in the table.
StaticTrialRefinement RefineFromStaticTrial(const MarkerLayout& layout, const sim::ArmModel& model,
                                            const MarkerTable& trial, const std::string& source);

}  // namespace ccsrm::mocap
