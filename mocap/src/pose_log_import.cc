// A lab's pose log made a ccsrm-dataset/1 experiment of settled poses
// (issue 46): `ccsrm dataset import-pose-log`.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/actuator_log.h"
#include "ccsrm/mocap/pose_log.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "text_table.h"

namespace ccsrm::mocap {
namespace {

using internal::FormatNumber;

namespace fs = std::filesystem;

// The rows [begin, end) the request selects of a log of `rows` rows.
std::pair<std::size_t, std::size_t> SelectedRows(const PoseLogImportRequest& request,
                                                 std::size_t rows) {
  const std::size_t first = request.first_row == 0 ? 1 : request.first_row;
  const std::size_t last = request.last_row == 0 ? rows : request.last_row;
  if (last > rows || first > last || last - first + 1 < 2) {
    ThrowInputError(request.log, "rows",
                    std::to_string(first) + " to " + std::to_string(last) +
                        " selected, the log has " + std::to_string(rows) +
                        " rows: at least 2 rows within them are needed");
  }
  return {first - 1, last};
}

}  // namespace

ImportedPoseLog ImportPoseLog(const PoseLogImportRequest& request) {
  if (request.tip_unit != "mm" && request.tip_unit != "m") {
    ThrowInputError("dataset import-pose-log", "tip unit",
                    "expected m or mm, found '" + request.tip_unit + "'");
  }
  ActuatorMap map = ReadActuatorMap(request.actuator_map);
  // Settled poses: the time between rows is the lab's pacing, not the arm's
  // motion, so there is nothing to interpolate across and no gap to refuse.
  map.max_gap_s = std::numeric_limits<double>::infinity();
  const ActuatorLog lengths = ReadActuatorLog(request.log, map, request.actuator_map);
  PoseLogColumns columns = request.columns;
  columns.time = map.time_column;
  const PoseLog poses = ReadPoseLog(request.log, columns);
  // Both read the same rows of the same file; they differ only if one reader
  // skipped a row the other took.
  if (poses.lines != std::vector<std::size_t>(lengths.lines.begin(), lengths.lines.end())) {
    ThrowInputError(request.log, "rows", "read differently as a pose log and as an actuator log");
  }

  const sim::Config config = sim::LoadConfig(request.config);
  const sim::ArmModel model(config.arm);
  const auto [begin, end] = SelectedRows(request, poses.time_s.size());
  const std::size_t n = end - begin;
  const Eigen::Index b = static_cast<Eigen::Index>(begin);
  const Eigen::Index rows = static_cast<Eigen::Index>(n);
  CheckActuatorLogOnArm(lengths, map, request.actuator_map, model, request.config, b, rows);

  ImportedPoseLog out;
  datasets::ExperimentFile& e = out.experiment;
  e.name = request.name.empty() ? fs::path(request.log).stem().string() : request.name;
  e.source = datasets::ExperimentSource::kRecorded;
  e.motion = datasets::RecordedMotion::kSettledPoses;
  e.marker_frame = datasets::MarkerFrame::kCapture;
  e.config_yaml = config.source_yaml;
  e.description = "pose log " + fs::path(request.log).filename().string() + ", rows " +
                  std::to_string(begin + 1) + " to " + std::to_string(end) + " of " +
                  std::to_string(poses.time_s.size()) + ", the actuators through " +
                  fs::path(request.actuator_map).filename().string() +
                  "; the tip marker in the capture frame";
  const double t0 = lengths.time_s[b];
  e.input_time = datasets::Array(std::vector<std::size_t>{n});
  e.mocap_time = datasets::Array(std::vector<std::size_t>{n});
  const int cables = model.num_cables();
  e.input_length_change = datasets::Array({n, static_cast<std::size_t>(cables)});
  e.mocap_markers = datasets::Array({n, 1, 3});
  const double tip_scale = request.tip_unit == "mm" ? 1e-3 : 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Index row = b + static_cast<Eigen::Index>(i);
    e.input_time.values[i] = e.mocap_time.values[i] = lengths.time_s[row] - t0;
    for (int c = 0; c < cables; ++c) {
      e.input_length_change.values[i * cables + c] = lengths.length_change_m(row, c);
    }
    for (int k = 0; k < 3; ++k) e.mocap_markers.values[i * 3 + k] = tip_scale * poses.tip(row, k);
  }
  e.input_labels.assign(poses.labels.begin() + b, poses.labels.begin() + b + rows);
  // Without a label column every label is empty: no labels at all.
  if (std::all_of(e.input_labels.begin(), e.input_labels.end(),
                  [](const std::string& label) { return label.empty(); })) {
    e.input_labels.clear();
  }
  const int tip_link = model.num_links();
  const Eigen::Vector3d local =
      Eigen::Vector3d(0.0, 0.0, 0.5 * model.link(tip_link).length_m) + request.tip_from_link_end_m;
  const std::string marker = "tip";
  e.marker_names = {marker};
  e.rigid_bodies.push_back(
      datasets::RigidBody{"link" + std::to_string(tip_link), {marker}, datasets::Array({1, 3})});
  for (int k = 0; k < 3; ++k) e.rigid_bodies[0].local_position.values[k] = local[k];

  const std::set<std::string> patterns(e.input_labels.begin(), e.input_labels.end());
  const auto [low, high] =
      std::minmax_element(e.input_length_change.values.begin(), e.input_length_change.values.end());
  out.report = request.log + ": rows " + std::to_string(begin + 1) + " to " + std::to_string(end) +
               " of " + std::to_string(poses.time_s.size()) + ": " + std::to_string(n) +
               " settled poses over " + FormatNumber("%.1f", e.input_time.values.back()) + " s, " +
               std::to_string(patterns.size()) + " pattern label(s)\n  " + std::to_string(cables) +
               " cables through " + request.actuator_map + ": pulled in " +
               FormatNumber("%.3f", *low * 1e3) + " to " + FormatNumber("%.3f", *high * 1e3) +
               " mm\n  tracked point 'tip' on link" + std::to_string(tip_link) + " at (" +
               FormatNumber("%.2f", local[0] * 1e3) + ", " + FormatNumber("%.2f", local[1] * 1e3) +
               ", " + FormatNumber("%.2f", local[2] * 1e3) +
               ") mm in its frame, in the capture frame (placement unknown)\n";
  return out;
}

}  // namespace ccsrm::mocap
