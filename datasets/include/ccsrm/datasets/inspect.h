#pragma once
// A summary of a ccsrm HDF5 file of either kind, for `ccsrm dataset inspect`
// style listings: what a user needs to know before opening it in Python.
#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"

namespace ccsrm::datasets {

enum class FileKind { kRun, kExperiment };

struct DatasetSummary {
  std::string path;                // e.g. "/joint_angles"
  std::vector<std::size_t> shape;  // e.g. {4801, 12, 2}
  std::string units;               // "" for string datasets
  std::string type;                // "float64" or "string"
};

struct TimeBaseSummary {
  std::string path;        // "/time", "/input/time" or "/mocap/time"
  std::size_t frames = 0;  // >= 1 in a valid file
  double first = 0.0;      // s
  double last = 0.0;       // s
};

struct FileSummary {
  std::string file;
  std::string schema;  // e.g. "ccsrm-run/1"
  FileKind kind = FileKind::kRun;
  // Root attributes as text, in the order of datasets/README.md; config_yaml
  // is reported by its length ("87 lines"), not its text.
  std::vector<std::pair<std::string, std::string>> attributes;
  // Sizes read from the arrays: frames, joints, links, cables, markers (run);
  // input samples, mocap frames, markers, cables, rigid bodies (experiment).
  std::vector<std::pair<std::string, std::size_t>> counts;
  std::vector<TimeBaseSummary> time_bases;
  // Every dataset of the schema present in the file, in schema order.
  std::vector<DatasetSummary> datasets;
};

// "run" / "experiment".
const char* FileKindName(FileKind kind);

// A ccsrm file of either kind, read and validated once.
using AnyFile = std::variant<RunFile, ExperimentFile>;

// Detects the kind from the root `schema` attribute and reads the file with
// ReadRunFile or ReadExperimentFile, for commands that take either kind.
// Throws InputError (one line naming the file) for a missing file, a file
// that is not HDF5, or a schema of neither kind.
AnyFile ReadAnyFile(const std::string& path);

// The kind of a file ReadAnyFile returned.
FileKind KindOf(const AnyFile& file);

// Reads the file with ReadAnyFile and summarises it.
// Throws InputError (one line naming the file) for a missing or bad file.
FileSummary InspectFile(const std::string& path);

// The summary of a file already read (by ReadAnyFile), for a caller that
// checks it further before listing it; `path` is the file it was read from.
FileSummary Summarise(const AnyFile& file, const std::string& path);

// A readable listing with aligned columns, ending in a newline.
std::string ToText(const FileSummary& summary);

// {"file", "schema", "kind", "attributes": {...}, "counts": {...},
//  "time_bases": [{"path", "frames", "first", "last"}],
//  "datasets": [{"path", "shape", "units", "type"}]}
nlohmann::json ToJson(const FileSummary& summary);

// The root `schema` attribute of an HDF5 file ("ccsrm-run/1"), or "" when
// the path is not a readable HDF5 file or has none. Never throws: the output
// policy uses it to recognise an earlier output (common/output_policy.h).
std::string ReadSchemaAttribute(const std::string& path);

}  // namespace ccsrm::datasets
