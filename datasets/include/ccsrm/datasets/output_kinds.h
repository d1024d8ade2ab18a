#pragma once
// The files of datasets/ as outputs of the one output policy
// (common/output_policy.h): an earlier file of the kind is recognised by
// its schema attribute, and replaced; any other file is refused.
#include "ccsrm/common/output_policy.h"

namespace ccsrm::datasets {

OutputKind RunFileOutput();         // ccsrm-run/1: simulate, generate's truth run
OutputKind ExperimentFileOutput();  // ccsrm-dataset/1: mocap process, dataset
// generate: an earlier generated experiment only. A recorded one holds
// measurements no run can give back, so a simulation never replaces it.
OutputKind GeneratedExperimentFileOutput();

}  // namespace ccsrm::datasets
