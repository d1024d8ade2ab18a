#pragma once
// Recorded input lengths from any file a user has them in: an experiment's
// /input (ccsrm-dataset/1), a run's /input_length_change (ccsrm-run/1), or a
// CSV/TSV table (sim::ParseInputTable). The checks against the arm and the
// resampling are sim::MakeRecordedCableInputs.
#include <string>

#include "ccsrm/datasets/array.h"

#include "ccsrm/sim/recorded_inputs.h"

namespace ccsrm::sim_io {

// Recorded inputs from a file's arrays: `time` (N) and `length` (N × C),
// named in messages by their paths (`time_name`, `length_name`). Throws
// InputError when `length` has no column (no actuator record).
sim::RecordedInputs InputsFromArrays(const std::string& path, const std::string& time_name,
                                     const std::string& length_name, const datasets::Array& time,
                                     const datasets::Array& length);

// Reads `path`: an HDF5 file (by its signature) of either ccsrm kind, read
// through ReadCheckedFile (an experiment or run checked against its own
// config_yaml first, as every command checks it), else a text table.
// Throws InputError naming the file: unreadable, a file of another kind or
// one its own configuration refuses, an experiment without an actuator
// record (no /input/length_change columns), or a bad table.
sim::RecordedInputs ReadRecordedInputs(const std::string& path,
                                       const sim::RecordedInputOptions& options = {});

}  // namespace ccsrm::sim_io
