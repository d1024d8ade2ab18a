#include "ccsrm/datasets/inspect.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/array.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "describe.h"
#include "hdf5_io.h"
#include "validation.h"

namespace ccsrm::datasets {
namespace {

using internal::FormatNumber;

// Times in listings: 9 significant digits hide binary noise such as
// 0.051000000000000004 (the JSON keeps every digit).
std::string FormatSeconds(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

// Keeps a free-text attribute (a description, a divergence message) on its
// row of the listing.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

std::string LineCount(const std::string& text) {
  std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  if (!text.empty() && text.back() != '\n') ++lines;
  return std::to_string(lines) + (lines == 1 ? " line" : " lines");
}

TimeBaseSummary SummariseTimeBase(const std::string& path, const Array& time) {
  // A validated time base has at least one value.
  return {path, time.size(), time.values.front(), time.values.back()};
}

// Columns are padded by display width: "×" is one column but two bytes.
std::size_t DisplayWidth(const std::string& text) {
  return static_cast<std::size_t>(std::count_if(text.begin(), text.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  }));
}

std::string Pad(const std::string& text, std::size_t width) {
  const std::size_t shown = DisplayWidth(text);
  return text + std::string(width > shown ? width - shown : 0, ' ');
}

void SummariseRun(const RunFile& run, FileSummary* summary) {
  summary->attributes = {
      {"schema", kRunSchema},
      {"case", run.case_name},
      {"status", RunStatusName(run.status)},
      {"status_message", run.status_message},
      {"created", run.created},
      {"ccsrm_version", run.ccsrm_version},
      {"wall_time_s", FormatNumber(run.wall_time_s)},
      {"steps", std::to_string(run.steps)},
      {"rejected_steps", std::to_string(run.rejected_steps)},
      {"rhs_evaluations", std::to_string(run.rhs_evaluations)},
      {"config_yaml", LineCount(run.config_yaml)},
  };
  summary->counts = {
      {"frames", run.frames()},
      {"joints", run.joint_angles.shape[1]},
      {"links", run.link_pose.shape[1]},
      {"cables", run.cables.size()},
      {"markers", run.markers ? run.markers->shape[1] : 0},
  };
  summary->time_bases = {SummariseTimeBase("/time", run.time)};
  summary->datasets = internal::DescribeDatasets(run);
}

void SummariseExperiment(const ExperimentFile& experiment, FileSummary* summary) {
  summary->attributes = {
      {"schema", kExperimentSchema},           {"name", experiment.name},
      {"description", experiment.description}, {"source", ExperimentSourceName(experiment.source)},
      {"created", experiment.created},         {"config_yaml", LineCount(experiment.config_yaml)},
  };
  if (experiment.motion != RecordedMotion::kContinuous) {
    summary->attributes.emplace_back("motion", RecordedMotionName(experiment.motion));
  }
  if (experiment.marker_frame != MarkerFrame::kWorld) {
    summary->attributes.emplace_back("marker_frame", MarkerFrameName(experiment.marker_frame));
  }
  if (const auto& a = experiment.clock_alignment) {
    char text[160];
    std::snprintf(text, sizeof(text), "%s: offset %.6f ± %.6f s, drift %.2f ± %.2f ppm",
                  a->method.c_str(), a->offset_s, a->offset_uncertainty_s, a->drift_ppm,
                  a->drift_uncertainty_ppm);
    summary->attributes.emplace_back("clock_alignment", text);
    summary->attributes.emplace_back("actuator_log", a->actuator_log);
  }
  summary->counts = {
      {"input_samples", experiment.input_time.size()},
      {"mocap_frames", experiment.mocap_time.size()},
      {"markers", experiment.marker_names.size()},
      {"cables", experiment.input_length_change.shape[1]},
      {"rigid_bodies", experiment.rigid_bodies.size()},
  };
  summary->time_bases = {SummariseTimeBase("/input/time", experiment.input_time),
                         SummariseTimeBase("/mocap/time", experiment.mocap_time)};
  summary->datasets = internal::DescribeDatasets(experiment);
}

}  // namespace

const char* FileKindName(FileKind kind) { return kind == FileKind::kRun ? "run" : "experiment"; }

AnyFile ReadAnyFile(const std::string& path) {
  std::string schema;
  {
    internal::Hdf5Session session;
    const internal::FileReader reader(path);
    if (!reader.HasRootAttribute("schema")) {
      reader.Fail("", std::string("root attribute 'schema' missing: not a ccsrm file (expected ") +
                          kRunSchema + " or " + kExperimentSchema + ")");
    }
    schema = reader.ReadStringAttribute("schema");
  }
  const std::string kind = schema.substr(0, schema.find('/'));
  if (kind == "ccsrm-run") return ReadRunFile(path);
  if (kind == "ccsrm-dataset") return ReadExperimentFile(path);
  ThrowInputError(
      path, "attribute 'schema' is '" + schema + "'",
      std::string("not a ccsrm file (expected ") + kRunSchema + " or " + kExperimentSchema + ")");
}

FileKind KindOf(const AnyFile& file) {
  return std::holds_alternative<RunFile>(file) ? FileKind::kRun : FileKind::kExperiment;
}

FileSummary InspectFile(const std::string& path) { return Summarise(ReadAnyFile(path), path); }

FileSummary Summarise(const AnyFile& file, const std::string& path) {
  FileSummary summary;
  summary.file = path;
  summary.kind = KindOf(file);
  if (const RunFile* run = std::get_if<RunFile>(&file)) {
    summary.schema = kRunSchema;
    SummariseRun(*run, &summary);
  } else {
    summary.schema = kExperimentSchema;
    SummariseExperiment(std::get<ExperimentFile>(file), &summary);
  }
  return summary;
}

std::string ToText(const FileSummary& summary) {
  std::ostringstream out;
  out << "file    " << summary.file << "\n";
  out << "schema  " << summary.schema << " ("
      << (summary.kind == FileKind::kRun ? "simulation run" : "experiment") << ")\n";

  std::size_t key_width = 0;
  for (const auto& [key, value] : summary.attributes) key_width = std::max(key_width, key.size());
  for (const auto& [key, value] : summary.counts) key_width = std::max(key_width, key.size());

  out << "\nattributes\n";
  for (const auto& [key, value] : summary.attributes) {
    out << "  " << Pad(key, key_width) << "  " << (value.empty() ? "(empty)" : OneLine(value))
        << "\n";
  }
  out << "\ncounts\n";
  for (const auto& [key, value] : summary.counts) {
    out << "  " << Pad(key, key_width) << "  " << value << "\n";
  }
  out << "\ntime\n";
  for (const TimeBaseSummary& time : summary.time_bases) {
    out << "  " << Pad(time.path, key_width) << "  " << time.frames << " samples, "
        << FormatSeconds(time.first) << " s to " << FormatSeconds(time.last) << " s\n";
  }

  std::size_t path_width = 4;
  std::size_t shape_width = 5;
  for (const DatasetSummary& dataset : summary.datasets) {
    path_width = std::max(path_width, DisplayWidth(dataset.path));
    shape_width = std::max(shape_width, DisplayWidth(ShapeToString(dataset.shape)));
  }
  out << "\ndatasets\n";
  out << "  " << Pad("path", path_width) << "  " << Pad("shape", shape_width) << "  "
      << Pad("type", 7) << "  units\n";
  for (const DatasetSummary& dataset : summary.datasets) {
    std::string line = "  " + Pad(dataset.path, path_width) + "  " +
                       Pad(ShapeToString(dataset.shape), shape_width) + "  " +
                       Pad(dataset.type, 7) + "  " + dataset.units;
    line.erase(line.find_last_not_of(' ') + 1);  // string datasets have no units
    out << line << "\n";
  }
  return out.str();
}

nlohmann::json ToJson(const FileSummary& summary) {
  nlohmann::json json;
  json["file"] = summary.file;
  json["schema"] = summary.schema;
  json["kind"] = FileKindName(summary.kind);
  json["attributes"] = nlohmann::json::object();
  for (const auto& [key, value] : summary.attributes) json["attributes"][key] = value;
  json["counts"] = nlohmann::json::object();
  for (const auto& [key, value] : summary.counts) json["counts"][key] = value;
  json["time_bases"] = nlohmann::json::array();
  for (const TimeBaseSummary& time : summary.time_bases) {
    json["time_bases"].push_back(
        {{"path", time.path}, {"frames", time.frames}, {"first", time.first}, {"last", time.last}});
  }
  json["datasets"] = nlohmann::json::array();
  for (const DatasetSummary& dataset : summary.datasets) {
    json["datasets"].push_back({{"path", dataset.path},
                                {"shape", dataset.shape},
                                {"units", dataset.units},
                                {"type", dataset.type}});
  }
  return json;
}

std::string ReadSchemaAttribute(const std::string& path) {
  try {
    internal::Hdf5Session session;
    const internal::FileReader reader(path);
    return reader.ReadOptionalStringAttribute("schema");
  } catch (const InputError&) {
    return "";
  }
}

}  // namespace ccsrm::datasets
