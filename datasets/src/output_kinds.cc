#include "ccsrm/datasets/output_kinds.h"

#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "hdf5_io.h"

namespace ccsrm::datasets {
namespace {

bool HasSchemaPrefix(const std::string& path, const std::string& prefix) {
  return ReadSchemaAttribute(path).rfind(prefix, 0) == 0;
}

// The experiment's `source` attribute, or "" when it cannot be read.
std::string SourceAttribute(const std::string& path) {
  try {
    internal::Hdf5Session session;
    const internal::FileReader reader(path);
    return reader.ReadOptionalStringAttribute("source");
  } catch (const InputError&) {
    return "";
  }
}

}  // namespace

OutputKind RunFileOutput() {
  return {"ccsrm run file (ccsrm-run/1)", false,
          [](const std::string& p) { return HasSchemaPrefix(p, "ccsrm-run/"); }};
}

OutputKind ExperimentFileOutput() {
  return {"ccsrm experiment (ccsrm-dataset/1)", false,
          [](const std::string& p) { return HasSchemaPrefix(p, "ccsrm-dataset/"); }};
}

}  // namespace ccsrm::datasets

namespace ccsrm::datasets {

OutputKind GeneratedExperimentFileOutput() {
  return {
      "generated ccsrm experiment (ccsrm-dataset/1, source 'generated'; a recorded experiment "
      "is never replaced by a simulation)",
      false, [](const std::string& p) {
        return HasSchemaPrefix(p, "ccsrm-dataset/") &&
               SourceAttribute(p) == ExperimentSourceName(ExperimentSource::kGenerated);
      }};
}

}  // namespace ccsrm::datasets
