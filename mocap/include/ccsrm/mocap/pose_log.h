#pragma once
// A lab's log of settled poses (issue 46): one row per commanded pose, the
// actuators' readings and a tracked point (the tip marker), each row with
// the label of the pattern it belongs to, as the tendon-driven robot's
// recordings of ../shared/data/tdcr/ are written. And which actuator drives
// which tendon, identified from a log that pulls one tendon at a time
// (`ccsrm dataset tendon-map`): docs/tdcr-recordings.md says what such a
// log holds.
#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"

namespace ccsrm::mocap {

inline constexpr const char* kTendonMapSchema = "ccsrm-tendon-map/1";

// The columns of a pose log, by header name.
struct PoseLogColumns {
  std::string time = "timestamp";       // [s]
  std::string label = "pattern_label";  // "" or absent from the header: no labels
  // Every column whose name starts with this is an actuator's reading.
  std::string actuator_prefix = "servo_";
  std::array<std::string, 3> tip = {"tip_x", "tip_y", "tip_z"};
};

struct PoseLog {
  std::string source_name;
  std::vector<std::size_t> lines;             // file line of each row
  std::vector<double> time_s;                 // as logged
  std::vector<std::string> labels;            // per row; empty strings without a label column
  std::vector<std::string> actuator_columns;  // header names, in file order
  Eigen::MatrixXd actuators;                  // rows × actuators, in the columns' units
  Eigen::MatrixXd tip;                        // rows × 3, in the log's units
};

// Parses a CSV (comma) or TSV (tab in the header) pose log: '#' and blank
// lines skipped, the first other line the header. Throws InputError naming
// the file, the line and the column: a named column missing from the
// header, no actuator column, a cell that is not a finite number, time not
// increasing, fewer than 2 rows.
PoseLog ParsePoseLog(const std::string& text, const std::string& source_name,
                     const PoseLogColumns& columns = {});
PoseLog ReadPoseLog(const std::string& path, const PoseLogColumns& columns = {});

struct TendonMapOptions {
  // Tendons per segment, spread evenly around the backbone. Default 3.
  int tendons_per_segment = 3;
  // The arm's axis in the capture frame (0 x, 1 y, 2 z): the tip's motion
  // across it is the bending. Default 2.
  int axis = 2;
  // A pattern of fewer rows is not a pull (a label's tail, a hold).
  // Default 5.
  int min_rows = 5;
};

// One tendon as the log shows it.
struct TendonPull {
  std::string label;   // the pattern that pulls it
  std::string column;  // the actuator column that drives it
  // +1 when the reading grows as the tendon is pulled in, −1 when it
  // shrinks.
  int sign = 1;
  // The reading at which the tendon starts to bend the arm while pulled in
  // (below it the tendon is slack), from a hinge fit of the tip's travel
  // across the axis against the reading over the pull up to its peak.
  double engagement = 0.0;
  // Tip travel across the axis per unit of reading beyond the engagement
  // [the log's tip units per reading unit], and the hinge fit's RMS.
  double tip_per_unit = 0.0;
  double fit_rms = 0.0;
  // Direction the tip moves towards when the tendon is pulled, about the
  // axis (from the first of the two other capture axes towards the
  // second), in (−180, 180] deg: the tip's path from the pattern's last row
  // back to its farthest one (from its first, when the pull is not released
  // by half).
  double azimuth_deg = 0.0;
  int segment = 0;    // identified, 1 = proximal
  int index = 0;      // within the segment, 0-based, by increasing azimuth
  int labelled = -1;  // the tendon "tendon<K>" in the label names; −1: none
};

struct TendonMap {
  int tendons_per_segment = 3;
  std::vector<TendonPull> tendons;  // segment by segment, index by index
  // RMS over every segment of its azimuth gaps' deviation from
  // 360 / tendons_per_segment [deg]: how evenly the grouping spreads them.
  double spacing_rms_deg = 0.0;
  // Tendons whose label names the same tendon as identified
  // ((segment − 1)·n + index), of those whose label names one.
  int labels_agreeing = 0;
  int labels_naming = 0;

  // The table and the labels' agreement, for a terminal.
  std::string Report() const;
  // ccsrm-tendon-map/1 YAML.
  std::string ToYaml(const std::string& source) const;
  // The same as a ccsrm-actuators/1 map (datasets/README.md): cable k is
  // the k-th tendon here (segment by segment, by increasing azimuth: the
  // order of a configuration whose hole angles are the capture frame's), a
  // length_change in `unit` ("m" or "mm", the log's) with its sign and
  // zero (the engagement); `time_column` in seconds.
  std::string ActuatorMapYaml(const std::string& source, const std::string& time_column,
                              const std::string& unit) const;
};

// Identifies the map from a log in which each pattern pulls one tendon
// (every pattern of at least min_rows rows): its actuator (the column that
// best follows the tip's travel across the axis), sign, engagement and
// direction; then which tendons form a segment (the grouping whose
// directions are closest to evenly spaced) and which segment is which (under
// position control a proximal tendon moves the tip most per unit of pull).
// Throws InputError naming the log: a number of pulls that is not a
// multiple of tendons_per_segment, two pulls on one column, a pull that
// does not move the tip, invalid options.
TendonMap IdentifyTendonMap(const PoseLog& log, const TendonMapOptions& options = {});

// A pose log made an experiment (`ccsrm dataset import-pose-log`): the
// actuators' readings through an actuator map (ccsrm-actuators/1, e.g. the
// one `tendon-map --actuator-map` writes) as the cables' pulled-in lengths,
// the tracked point as the one marker of a rigid body on the arm's last
// link, the pattern labels as /input/labels; marked as settled poses
// (motion "settled_poses": no gap limit, each row a static equilibrium) in
// the capture frame (marker_frame "capture": its placement is a fit's).
struct PoseLogImportRequest {
  std::string log;           // the pose log (CSV/TSV)
  std::string actuator_map;  // ccsrm-actuators/1 YAML: its time column is the log's
  std::string config;        // the arm (ccsrm-config/1 YAML)
  PoseLogColumns columns;    // the label and tip columns (the time is the map's)
  // Unit of the tip columns: "mm" or "m". Default "mm".
  std::string tip_unit = "mm";
  // The tracked point in the last link's body frame, from the centre of its
  // distal end (z' = +L/2) [m]. Default: that centre.
  Eigen::Vector3d tip_from_link_end_m = Eigen::Vector3d::Zero();
  // The data rows to import, 1-based and inclusive, counted as the log's
  // rows (not its file lines); 0: from the first, to the last.
  std::size_t first_row = 0;
  std::size_t last_row = 0;
  std::string name;  // the experiment's name; default: the log's stem
};

struct ImportedPoseLog {
  datasets::ExperimentFile experiment;
  std::string report;  // a few lines for a terminal: what was read and made
};

// Reads the log twice, through the map (the lengths) and as a pose log (the
// labels and the tip), checks the lengths against the arm (sim::
// CheckRecordedInputsOnArm) and makes the experiment. Throws InputError
// naming the file and the field: a map of another number of cables than the
// arm's, rows out of range, a tip unit not m or mm, the map's time column
// not the log's.
ImportedPoseLog ImportPoseLog(const PoseLogImportRequest& request);

}  // namespace ccsrm::mocap
