#pragma once
// The joint-angle tables the identify outputs write beside their JSON
// (<name>.angles.csv of a fit, a loop's held-out angles, a prediction), in
// one format that reports/src/angles_csv.h reads: comment lines starting with
// '#', the header time_s then, for joint j = 1..J and axis x, y, one column
// per kind, <kind>_theta<axis><j>_deg; values in degrees with 6 decimals, an
// empty cell where there is no value.
#include <Eigen/Core>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify::internal {

struct AnglesColumn {
  std::string kind;  // "measured", "fitted", ...
  // The value [deg] at frame f and column c (2 joint + axis); NaN: empty.
  std::function<double(Eigen::Index f, Eigen::Index c)> value_deg;
};

// The table's text. `comment` is the first line's text after "# ".
std::string AnglesCsvText(const std::string& comment, const std::vector<double>& frame_time_s,
                          int joints, const std::vector<AnglesColumn>& columns);

// Unique, file-safe stems for output files named after experiments:
// letters, digits, '-', '_' and '.' kept, anything else '_'; an empty name
// is "experiment"; a repeated one gets "_2", "_3", ...
std::vector<std::string> OutputStems(const std::vector<std::string>& names);

// The files a command writes for one recording it simulated (a fit's, a
// prediction's): <stem><run_suffix>, the run with `parameters` on the
// recording's configuration, left out when the run has no frame; and
// <stem>.angles.csv, the measured angles, `simulated_rad` under `kind`
// ("fitted", "predicted") and their residual (for an experiment of tracked
// points <stem>.points.csv instead, PointsCsvText, named in
// (*entry)["points_file"]). Both go into `tmp_dir`; their
// names into (*entry)["run_file"] (null without a run) and
// ["angles_file"], their final paths (in `directory`) onto *written.
void WriteRecordingOutputs(const Experiment& x, const std::string& name,
                           const sim::SimulationResult& run, const sim::ArmParameters& parameters,
                           const Eigen::MatrixXd& simulated_rad, const std::string& kind,
                           const std::string& stem, const std::string& run_suffix,
                           const std::string& tmp_dir, const std::string& directory,
                           nlohmann::json* entry, std::vector<std::string>* written);

// A recording's tracked-point errors for a report: per point its RMS (from
// `start` when given) and its RMS with the mean offset removed, and the
// capture frame's placement when given; as lines of text and as JSON.
std::string TrackedPointsText(const std::vector<TrackedPoint>& points,
                              const TrackedPointErrors* start, const TrackedPointErrors& errors,
                              const RigidPlacement* placement, bool placement_given = false);
nlohmann::json TrackedPointsJson(const std::vector<TrackedPoint>& points,
                                 const TrackedPointErrors* start, const TrackedPointErrors& errors,
                                 const RigidPlacement* placement, bool placement_given = false);

// The measured and simulated (`kind`) tracked points of x and their residual,
// in mm, one row per frame: time_s, then per point measured, kind and
// residual x, y, z.
std::string PointsCsvText(const Experiment& x, const Eigen::MatrixXd& simulated,
                          const std::string& name, const std::string& kind);

}  // namespace ccsrm::identify::internal
