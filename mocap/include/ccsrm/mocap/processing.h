#pragma once
// From labelled marker trajectories to link poses and joint angles (SPEC 5):
// label mapping, gap filling (spline for short gaps, rigid-body fill for long
// ones), zero-lag low-pass filtering, least-squares rigid fit of every body
// (Eigen::umeyama), world frame from the ground cluster, X–Y Cardan joint
// angles with the twist as a consistency check, and quality figures.
//
// Symbols: F frames, K markers of the layout, L links (the largest link
// number in the layout), J = L joints.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/datasets/array.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/marker_table.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::mocap {

struct ProcessingOptions {
  // Longest gap (frames) filled by a cubic spline through the marker's own
  // trajectory. Default 10 frames = 0.1 s at 100 Hz: the arm moves little in
  // that time, so the spline error stays well below the marker noise.
  int max_spline_gap_frames = 10;
  // Finite samples on each side of a gap that the spline passes through.
  int spline_context_frames = 10;
  // Fill what the spline cannot (longer gaps, gaps at either end) from the
  // body's other markers in the same frame (at least 3 of them).
  bool rigid_fill = true;
  // Zero-lag Butterworth low-pass (forward–backward, so -6 dB at the cutoff)
  // of the fitted motion: joint angles, twists and link poses; cutoff_hz = 0
  // turns it off. Default 1 Hz, order 2. With the 6 cm plates of the default
  // layout a 0.2 mm marker noise leaves about 0.25 deg per frame on θx, θy
  // after the joint-constrained fit (0.4 deg with independent link fits);
  // the forward–backward pass keeps about 1.1·fc of the 50 Hz noise band,
  // so at 1 Hz the noise falls below 0.05 deg RMS. The paper's protocol
  // (quintic ramps of 20 s) has almost nothing above 0.2 Hz; ramps of 6 s
  // lose about 0.02 deg RMS of the arm's own small oscillations
  // (tests/mocap/round_trip_test.cc). Faster motions need a higher cutoff
  // and accept more noise.
  double cutoff_hz = 1.0;
  int filter_order = 2;  // per pass, 1..8
  // Finite runs shorter than this (frames) are not filtered: too short for
  // a meaningful low-pass.
  int min_filter_run_frames = 4;
  // When the joint positions are known (a JointChain is given), fit each
  // frame's consecutive links together with their joint centres shared
  // (spherical joints: every link keeps three rotations, so the twist stays
  // a check), by Gauss–Newton from the per-link fits. A plate alone fixes a
  // link's rotation about y' poorly (its markers spread 6 cm along z' but
  // under 1 cm along x'); the joints 8.5–10 cm apart add that lever and
  // roughly halve the joint-angle noise.
  bool joint_constrained_fit = true;

  // Checks ranges; on failure returns false with the reason in *error.
  bool IsValid(std::string* error) const;
};

// Figures per marker of the layout.
struct MarkerQuality {
  std::string name;
  std::string body;
  bool in_file = false;     // a column of the input matched the name
  double visibility = 0.0;  // fraction of frames seen in the input (0..1)
  std::size_t gaps_before_fill = 0;
  std::size_t longest_gap_before_fill = 0;  // frames; a never-seen marker has F
  std::size_t gaps_after_fill = 0;
  std::size_t longest_gap_after_fill = 0;
  std::size_t spline_filled_frames = 0;
  std::size_t rigid_filled_frames = 0;
  // RMS of the rigid-fit residual over the frames where the marker was seen
  // and its body's pose was fitted [m]; NaN when there are none.
  double fit_rms_m = 0.0;
};

// Figures per body (the ground and every link of the layout).
struct BodyQuality {
  std::string name;
  int link = 0;
  // RMS over its seen markers and fitted frames of the fit residual [m].
  double fit_rms_m = 0.0;
  // Frames with no pose (fewer than 3 markers after filling).
  std::size_t frames_lost = 0;
  // Frames where none of its markers was seen (whole-body losses, never
  // filled), and the number of such runs.
  std::size_t whole_loss_frames = 0;
  std::size_t whole_loss_runs = 0;
};

struct JointQuality {
  int joint = 0;                   // 1-based
  std::size_t frames_lost = 0;     // frames without an angle (a pose of either link missing)
  double max_abs_twist_rad = 0.0;  // over the frames with an angle; NaN when there are none
};

struct ProcessingSummary {
  std::size_t frames = 0;
  double rate_hz = 0.0;
  // The zero-lag low-pass applied to the joint angles, twists and poses
  // (ProcessingOptions; cutoff 0: none). Stored with the quality figures, so
  // that identification can pass simulated angles through the same filter.
  double filter_cutoff_hz = 0.0;
  int filter_order = 0;
  int min_filter_run_frames = 0;
  // True when the links were fitted as a chain with shared joint centres.
  bool joint_constrained = false;
  // True when the ground cluster fixed the world frame W; false: the file
  // frame is W (no ground body, or fewer than 3 of its markers seen).
  bool world_from_ground = false;
  // RMS residual of the fit of the ground markers' mean positions [m].
  double ground_fit_rms_m = 0.0;
  std::vector<MarkerQuality> markers;   // layout order
  std::vector<BodyQuality> bodies;      // layout order
  std::vector<JointQuality> joints;     // joint 1..J
  std::size_t input_labels_unused = 0;  // columns of the input no layout marker matched
  // The input table's own warnings (MarkerTable::warnings, each prefixed with
  // the source's name), then those of processing. BriefReport counts them,
  // FullReport lists them.
  std::vector<std::string> warnings;

  // One line; and the quality figures of SPEC 5 as a table.
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct ProcessingResult {
  std::vector<double> time;  // F, s
  // In W (SPEC 2). NaN where a link was lost.
  datasets::Array link_pose;     // F × L × 7: x, y, z [m], e0..e3 (body to world)
  datasets::Array joint_angles;  // F × J × 2: θx, θy [rad]
  datasets::Array joint_twist;   // F × J: third angle of Rx·Ry·Rz [rad]
  // The markers as used for the fits: filled, in W (F × K × 3, m), and the
  // fit residual of each (F × K, m; NaN where not fitted), before filtering.
  datasets::Array markers;
  datasets::Array marker_residual;
  // The raw input markers of the layout (unfilled, unfiltered) mapped into W
  // (F × K × 3, m; NaN where not seen): what an experiment file records.
  datasets::Array raw_markers;
  std::vector<std::string> marker_names;  // K, layout order
  ProcessingSummary summary;
};

// Where the joints sit on the links: joint i (1-based) at p_BJ_proximal[i-1]
// in link i's frame and joint i+1 at p_BJ_distal[i-1] (SPEC 2: z' = ∓L/2).
struct JointChain {
  std::vector<Eigen::Vector3d> p_BJ_proximal;
  std::vector<Eigen::Vector3d> p_BJ_distal;

  static JointChain FromModel(const sim::ArmModel& model);
};

// Column of `table` for each name: the label equal to it, else the one label
// whose part after the last ':' equals it (Vicon's "subject:marker"); none
// when neither exists (a warning is added to *warnings when not null).
std::vector<std::optional<std::size_t>> MatchMarkerLabels(const std::vector<std::string>& names,
                                                          const MarkerTable& table,
                                                          std::vector<std::string>* warnings);

// The rigid transform X (rotation and translation, no scaling) minimising
// Σ |to_i - X·from_i|², by Eigen::umeyama. Requires from.size() == to.size()
// >= 3 (checked, aborts).
Eigen::Isometry3d FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                                    const std::vector<Eigen::Vector3d>& to);

// Processes a table of F frames at the times `time` (F values, strictly
// increasing and uniformly spaced within 1 %: the filter needs a fixed rate;
// empty = frame i at i / table.rate_hz). `chain` (may be null: every link is
// then fitted on its own) gives the joint positions for the joint-constrained
// fit; it must cover every link of the layout. `source` names the input in
// errors. Throws InputError for fewer than 2 frames, a table without any
// finite marker sample (all NaN or infinite), invalid options, a bad time
// base, a layout that does not validate, a chain shorter than the layout's
// links, or no layout marker in the table. Lost frames and missing markers are numerical
// outcomes: NaN in the result, counted in the summary.
ProcessingResult ProcessMarkers(const MarkerTable& table, const std::vector<double>& time,
                                const MarkerLayout& layout, const ProcessingOptions& options,
                                const std::string& source, const JointChain* chain = nullptr);

// Records the result in an experiment file: /measured/joint_angles,
// /measured/link_pose, /measured/joint_twist and the quality figures under
// /mocap/quality (names and units in datasets/README.md). Requires the
// experiment's mocap time base to have the result's F frames (checked, aborts).
void StoreInExperiment(const ProcessingResult& result, datasets::ExperimentFile* experiment);

}  // namespace ccsrm::mocap
