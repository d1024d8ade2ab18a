#pragma once
// Marker trajectories as read from a motion-capture file, in one shape for
// every format (C3D, TRC, Vicon Nexus CSV, OptiTrack Motive CSV).
//
// Units: positions and residuals are in metres whatever the file used; the
// file's own unit is kept in `units_in_file`. Coordinates are kept in the
// file's frame (no axis swap); `up_axis` records the vertical axis when the
// format defines it.
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ccsrm::mocap {

struct MarkerTable {
  // ---- Trajectories --------------------------------------------------------
  // One label per marker, in file order (trailing spaces trimmed).
  std::vector<std::string> labels;
  // Number of frames (samples in time).
  std::size_t frame_count = 0;
  // p_WM of every marker M at every frame, in metres, row-major
  // [(frame * markers() + marker) * 3 + axis]. NaN in all three axes where the
  // marker was not seen.
  std::vector<double> positions_m;

  // ---- Optional per-sample quality (C3D only) -------------------------------
  // True when `residual_m` and `camera_mask` are filled (frames × markers).
  bool has_residual = false;
  // Reconstruction residual in metres; -1 where the sample is invalid.
  std::vector<double> residual_m;
  // Bit i set when camera i+1 (of 7) contributed to the sample.
  std::vector<std::uint8_t> camera_mask;

  // ---- Timing ----------------------------------------------------------------
  double rate_hz = 0.0;                 // frames per second
  std::int64_t first_frame_number = 1;  // the file's number of frame 0

  // ---- Provenance --------------------------------------------------------------
  std::string format;         // "c3d", "trc", "nexus-csv", "motive-csv"
  std::string units_in_file;  // "mm", "cm" or "m"
  std::string up_axis;        // "y", "z", or "" when the file does not say
  std::string processor;      // C3D: "intel", "dec" or "mips"; "" otherwise
  std::string storage;        // C3D: "integer" or "float"; "" otherwise
  // C3D: |POINT:SCALE| in metres (the integer resolution, and the unit of the
  // residual byte); 0 for other formats.
  double point_scale_m = 0.0;
  // Things the reader tolerated but a user may want to know (a header count
  // that disagrees with the data, a unit that was assumed, ...).
  std::vector<std::string> warnings;

  // ---- Accessors ---------------------------------------------------------------
  std::size_t frames() const { return frame_count; }
  std::size_t markers() const { return labels.size(); }

  // Requires frame < frames() and marker < markers() (checked, aborts).
  Eigen::Vector3d position(std::size_t frame, std::size_t marker) const;
  // True when all three coordinates are finite (the marker was seen).
  bool is_valid(std::size_t frame, std::size_t marker) const;
  // Index of the first marker with this exact label, if any.
  std::optional<std::size_t> index_of(const std::string& label) const;

  // Sets the shape and fills every position with NaN (not seen); allocates
  // residual_m (-1) and camera_mask (0) when with_residual is true.
  void Reset(std::size_t frames, std::vector<std::string> marker_labels, bool with_residual);
  // Requires frame < frames() and marker < markers() (checked, aborts).
  void set_position(std::size_t frame, std::size_t marker, const Eigen::Vector3d& p_m);

  // True when the vectors have the sizes the counts imply; otherwise false
  // with a reason in *error (when error is not null).
  bool IsConsistent(std::string* error) const;
};

// Gaps and visibility of a table.
struct MarkerStatistics {
  std::size_t frames = 0;
  std::size_t markers = 0;
  // Marker samples (frame, marker) that were not seen.
  std::size_t invalid_points = 0;
  // invalid_points / (frames × markers); 0 for an empty table.
  double invalid_fraction = 0.0;
  // The longest run of consecutive not-seen frames of any one marker. Runs at
  // the start or end of the trial count, and a marker never seen has a gap of
  // frames(): this is how long a gap filler would have to bridge or extrapolate.
  std::size_t longest_gap_frames = 0;
  // Where that run is: the marker's label and the index (0-based) of its
  // first frame. Empty / 0 when there is no gap.
  std::string longest_gap_marker;
  std::size_t longest_gap_first_frame = 0;
  // Per marker, the fraction of frames in which it was seen (0..1).
  std::vector<double> visibility;
};

MarkerStatistics Summarize(const MarkerTable& table);

}  // namespace ccsrm::mocap
