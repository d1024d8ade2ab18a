#include "ccsrm/sim_io/recorded_inputs.h"

#include <fstream>
#include <string>
#include <variant>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/sim_io/experiment_check.h"

namespace ccsrm::sim_io {
namespace {

// HDF5's format signature, at offset 0 of a file written by the library.
bool LooksLikeHdf5(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char signature[8] = {};
  in.read(signature, sizeof(signature));
  return in.gcount() == 8 && std::string(signature, 8) == "\x89HDF\r\n\x1a\n";
}

}  // namespace

sim::RecordedInputs InputsFromArrays(const std::string& path, const std::string& time_name,
                                     const std::string& length_name, const datasets::Array& time,
                                     const datasets::Array& length) {
  sim::RecordedInputs r;
  r.source_name = path;
  r.time_name = time_name;
  const std::size_t n = time.shape.empty() ? 0 : time.shape[0];
  const std::size_t cables = length.shape.size() == 2 ? length.shape[1] : 0;
  if (cables == 0) {
    ThrowInputError(path, length_name, "has no columns: the file holds no actuator record");
  }
  r.time_s.resize(static_cast<Eigen::Index>(n));
  r.length_change_m.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(cables));
  for (std::size_t i = 0; i < n; ++i) {
    r.time_s[i] = time.at(i);
    for (std::size_t c = 0; c < cables; ++c) r.length_change_m(i, c) = length.at(i, c);
  }
  for (std::size_t c = 0; c < cables; ++c) {
    r.cable_names.push_back(length_name + "[:, " + std::to_string(c) + "]");
  }
  return r;
}

sim::RecordedInputs ReadRecordedInputs(const std::string& path,
                                       const sim::RecordedInputOptions& options) {
  if (!LooksLikeHdf5(path)) return sim::ParseInputTable(ReadTextFile(path), path, options);
  const datasets::AnyFile file = ReadCheckedFile(path);
  if (const auto* experiment = std::get_if<datasets::ExperimentFile>(&file)) {
    return InputsFromArrays(path, "/input/time", "/input/length_change", experiment->input_time,
                            experiment->input_length_change);
  }
  const auto& run = std::get<datasets::RunFile>(file);
  return InputsFromArrays(path, "/time", "/input_length_change", run.time, run.input_length_change);
}

}  // namespace ccsrm::sim_io
