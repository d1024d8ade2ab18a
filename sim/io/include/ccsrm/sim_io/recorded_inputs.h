#pragma once
// Recorded input lengths from any file a user has them in: an experiment's
// /input (ccsrm-dataset/1), a run's /input_length_change (ccsrm-run/1), or a
// CSV/TSV table (sim::ParseInputTable). The checks against the arm and the
// resampling are sim::MakeRecordedCableInputs.
#include <string>

#include "ccsrm/sim/recorded_inputs.h"

namespace ccsrm::sim_io {

// Reads `path`: an HDF5 file (by its signature) of either ccsrm kind, else
// a text table. Throws InputError naming the file: unreadable, a file of
// another kind, an experiment without an actuator record (no
// /input/length_change columns), or a bad table.
sim::RecordedInputs ReadRecordedInputs(const std::string& path,
                                       const sim::RecordedInputOptions& options = {});

}  // namespace ccsrm::sim_io
