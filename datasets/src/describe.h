#pragma once
// Private: the datasets of a parsed file, for InspectFile. Defined next to
// each schema's single list of paths (run_file.cc, experiment_file.cc).
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"

namespace ccsrm::datasets::internal {

std::vector<DatasetSummary> DescribeDatasets(const RunFile& run);
std::vector<DatasetSummary> DescribeDatasets(const ExperimentFile& experiment);

}  // namespace ccsrm::datasets::internal
