#include "ccsrm/datasets/run_file.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/clock.h"
#include "ccsrm/common/error.h"
#include "describe.h"
#include "hdf5_io.h"
#include "validation.h"

namespace ccsrm::datasets {
namespace {

using internal::Bound;
using internal::ExpectShape;
using internal::Fixed;
using internal::Free;

const char* const kCaseNames[] = {"1", "2", "3", "4", "custom"};

std::string CablePath(std::size_t index) { return "/cables/" + std::to_string(index + 1); }

// The one list of ccsrm-run/1 float datasets: path, units, array. Used by the
// writer, the reader (on a skeleton whose optional members and cable count
// were set from the file) and InspectFile. `Run` is RunFile or const RunFile.
template <typename Run, typename Visit>
void VisitArrays(Run& run, Visit&& visit) {
  visit("/time", "s", run.time);
  visit("/joint_angles", "rad", run.joint_angles);
  visit("/joint_rates", "rad/s", run.joint_rates);
  visit("/link_pose", "m, 1", run.link_pose);
  visit("/input_tension", "N", run.input_tension);
  visit("/input_length_change", "m", run.input_length_change);
  visit("/stuck_nodes", "1", run.stuck_nodes);
  if (run.slack_elements) visit("/slack_elements", "1", *run.slack_elements);
  for (std::size_t k = 0; k < run.cables.size(); ++k) {
    const std::string base = CablePath(k);
    visit(base + "/tension", "N", run.cables[k].tension);
    visit(base + "/stuck", "1", run.cables[k].stuck);
    visit(base + "/slip_velocity", "m/s", run.cables[k].slip_velocity);
  }
  visit("/diagnostics/constraint_violation", "mixed", run.constraint_violation);
  visit("/diagnostics/energy", "J", run.energy);
  if (run.markers) visit("/markers", "m", *run.markers);
}

RunStatus ParseStatus(const internal::FileReader& reader, const std::string& text) {
  if (text == RunStatusName(RunStatus::kCompleted)) return RunStatus::kCompleted;
  if (text == RunStatusName(RunStatus::kDiverged)) return RunStatus::kDiverged;
  if (text == RunStatusName(RunStatus::kCancelled)) return RunStatus::kCancelled;
  reader.Fail("attribute 'status' is '" + text + "'",
              "expected 'completed', 'diverged' or 'cancelled'");
}

// Reads the names of /cables/1 .. /cables/C, which must be exactly those.
std::size_t CountCableGroups(const internal::FileReader& reader) {
  std::vector<std::string> names = reader.ListGroup("/cables");
  std::vector<std::size_t> numbers;
  for (const std::string& name : names) {
    const bool digits =
        !name.empty() && name.size() < 6 && name[0] != '0' &&
        std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits) {
      reader.Fail("/cables", "member '" + name + "' is not a cable number (expected 1, 2, ...)");
    }
    numbers.push_back(std::stoul(name));
  }
  std::sort(numbers.begin(), numbers.end());
  for (std::size_t i = 0; i < numbers.size(); ++i) {
    if (numbers[i] != i + 1) {
      reader.Fail(CablePath(i), "missing (cable groups must be numbered 1.." +
                                    std::to_string(numbers.size()) + ")");
    }
  }
  return numbers.size();
}

}  // namespace

const char* RunStatusName(RunStatus status) {
  switch (status) {
    case RunStatus::kCompleted:
      return "completed";
    case RunStatus::kDiverged:
      return "diverged";
    case RunStatus::kCancelled:
      return "cancelled";
  }
  return "completed";
}

void ValidateRunFile(const RunFile& run, const std::string& file) {
  const std::size_t frames = internal::ExpectTimeBase(file, "/time", run.time, "T");
  const internal::Dim t = Bound("T", frames, "/time");

  const auto angles =
      ExpectShape(file, "/joint_angles", run.joint_angles, {t, Free("J"), Fixed(2)});
  const internal::Dim j = Bound("J", angles[1], "/joint_angles");
  ExpectShape(file, "/joint_rates", run.joint_rates, {t, j, Fixed(2)});
  ExpectShape(file, "/link_pose", run.link_pose, {t, Free("L"), Fixed(7)});

  const auto tension = ExpectShape(file, "/input_tension", run.input_tension, {t, Free("C")});
  const internal::Dim c = Bound("C", tension[1], "/input_tension");
  ExpectShape(file, "/input_length_change", run.input_length_change, {t, c});
  ExpectShape(file, "/stuck_nodes", run.stuck_nodes, {t, c});
  if (run.slack_elements) ExpectShape(file, "/slack_elements", *run.slack_elements, {t, c});

  if (run.cables.size() != c.extent) {
    ThrowInputError(file, "/cables",
                    "expected C=" + std::to_string(c.extent) +
                        " cable groups (from /input_tension), found " +
                        std::to_string(run.cables.size()));
  }
  for (std::size_t k = 0; k < run.cables.size(); ++k) {
    const std::string base = CablePath(k);
    const CableRecord& cable = run.cables[k];
    ExpectShape(file, base + "/tension", cable.tension, {t, Free("E")});
    const auto stuck = ExpectShape(file, base + "/stuck", cable.stuck, {t, Free("H")});
    ExpectShape(file, base + "/slip_velocity", cable.slip_velocity,
                {t, Bound("H", stuck[1], base + "/stuck")});
  }

  ExpectShape(file, "/diagnostics/constraint_violation", run.constraint_violation, {t});
  ExpectShape(file, "/diagnostics/energy", run.energy, {t, Fixed(3)});

  if (run.markers) {
    const auto markers = ExpectShape(file, "/markers", *run.markers, {t, Free("M"), Fixed(3)});
    if (run.marker_names.size() != markers[1]) {
      ThrowInputError(file, "/marker_names",
                      "expected M=" + std::to_string(markers[1]) +
                          " names (from /markers), found " +
                          std::to_string(run.marker_names.size()));
    }
    internal::ExpectUniqueNames(file, "/marker_names", run.marker_names);
  } else if (!run.marker_names.empty()) {
    ThrowInputError(file, "/marker_names", "marker names given without /markers");
  }

  if (std::find(std::begin(kCaseNames), std::end(kCaseNames), run.case_name) ==
      std::end(kCaseNames)) {
    ThrowInputError(file, "attribute 'case' is '" + run.case_name + "'",
                    "expected 1, 2, 3, 4 or custom");
  }
  if (!std::isfinite(run.wall_time_s) || run.wall_time_s < 0) {
    ThrowInputError(file, "attribute 'wall_time_s' is " + internal::FormatNumber(run.wall_time_s),
                    "expected a finite number >= 0");
  }
  const std::pair<const char*, std::int64_t> counters[] = {
      {"steps", run.steps},
      {"rejected_steps", run.rejected_steps},
      {"rhs_evaluations", run.rhs_evaluations}};
  for (const auto& [name, value] : counters) {
    if (value < 0) {
      ThrowInputError(file, std::string("attribute '") + name + "' is " + std::to_string(value),
                      "expected a count >= 0");
    }
  }
}

void WriteRunFile(const std::string& path, const RunFile& run) {
  ValidateRunFile(run, path);
  internal::Hdf5Session session;
  AtomicOutputFile output(path);
  {
    internal::FileWriter writer(output.temp_path(), path);
    writer.WriteStringAttribute("schema", kRunSchema);
    writer.WriteStringAttribute("case", run.case_name);
    writer.WriteStringAttribute("status", RunStatusName(run.status));
    writer.WriteStringAttribute("status_message", run.status_message);
    writer.WriteStringAttribute("config_yaml", run.config_yaml);
    if (!run.protocol_yaml.empty()) writer.WriteStringAttribute("protocol_yaml", run.protocol_yaml);
    if (!run.inputs_file.empty()) writer.WriteStringAttribute("inputs_file", run.inputs_file);
    writer.WriteStringAttribute("created", run.created.empty() ? UtcTimestamp() : run.created);
    writer.WriteStringAttribute("ccsrm_version", run.ccsrm_version);
    writer.WriteDoubleAttribute("wall_time_s", run.wall_time_s);
    writer.WriteInt64Attribute("steps", run.steps);
    writer.WriteInt64Attribute("rejected_steps", run.rejected_steps);
    writer.WriteInt64Attribute("rhs_evaluations", run.rhs_evaluations);
    VisitArrays(run, [&](const std::string& dataset, const char* units, const Array& array) {
      writer.WriteArray(dataset, array, units);
    });
    if (run.markers) writer.WriteStrings("/marker_names", run.marker_names);
    writer.Save();
  }
  output.Commit();
}

RunFile ReadRunFile(const std::string& path) {
  internal::Hdf5Session session;
  const internal::FileReader reader(path);
  internal::CheckSchema(reader, kRunSchema);

  RunFile run;
  run.case_name = reader.ReadStringAttribute("case");
  run.status = ParseStatus(reader, reader.ReadStringAttribute("status"));
  run.status_message = reader.ReadStringAttribute("status_message");
  run.config_yaml = reader.ReadStringAttribute("config_yaml");
  // Files written before protocols were recorded have neither.
  run.protocol_yaml = reader.ReadOptionalStringAttribute("protocol_yaml");
  run.inputs_file = reader.ReadOptionalStringAttribute("inputs_file");
  run.created = reader.ReadStringAttribute("created");
  run.ccsrm_version = reader.ReadStringAttribute("ccsrm_version");
  run.wall_time_s = reader.ReadDoubleAttribute("wall_time_s");
  run.steps = reader.ReadInt64Attribute("steps");
  run.rejected_steps = reader.ReadInt64Attribute("rejected_steps");
  run.rhs_evaluations = reader.ReadInt64Attribute("rhs_evaluations");

  // Skeleton first (cable count, optional members), then every array.
  run.cables.resize(CountCableGroups(reader));
  if (reader.Exists("/markers")) run.markers.emplace();
  if (reader.Exists("/slack_elements")) run.slack_elements.emplace();
  VisitArrays(run, [&](const std::string& dataset, const char* units, Array& array) {
    array = reader.ReadArray(dataset, units);
  });
  if (reader.Exists("/marker_names")) run.marker_names = reader.ReadStrings("/marker_names");
  if (run.markers && !reader.Exists("/marker_names")) reader.Fail("/marker_names", "missing");

  ValidateRunFile(run, path);
  return run;
}

namespace internal {
std::vector<DatasetSummary> DescribeDatasets(const RunFile& run) {
  std::vector<DatasetSummary> datasets;
  VisitArrays(run, [&](const std::string& path, const char* units, const Array& array) {
    datasets.push_back({path, array.shape, units, "float64"});
  });
  if (run.markers) datasets.push_back({"/marker_names", {run.marker_names.size()}, "", "string"});
  return datasets;
}
}  // namespace internal

}  // namespace ccsrm::datasets
