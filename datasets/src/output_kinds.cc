#include "ccsrm/datasets/output_kinds.h"

#include <string>

#include "ccsrm/datasets/inspect.h"

namespace ccsrm::datasets {
namespace {

bool HasSchemaPrefix(const std::string& path, const std::string& prefix) {
  return ReadSchemaAttribute(path).rfind(prefix, 0) == 0;
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
