#pragma once
// Input lengths as an actuator recorded them (SPEC 3: "measured input
// lengths read from a dataset"): the samples of a CSV/TSV table or of a
// file's /input, checked and made into the simulator's CableInputs. Reading
// HDF5 files is sim_io's (ccsrm/sim_io/recorded_inputs.h); the text table
// and every check are here.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim {

// Samples as read, before any check against an arm.
struct RecordedInputs {
  std::string source_name;               // the file, in messages
  std::string time_name;                 // the time column or dataset ("time_s", "/input/time")
  std::vector<std::string> cable_names;  // one per cable column, in cable order
  Eigen::VectorXd time_s;                // N [s]
  Eigen::MatrixXd length_change_m;       // N × C [m], pulled in = positive
  // File line of each sample (text tables), for messages; empty for HDF5,
  // whose samples are named by index.
  std::vector<int> lines;
};

struct RecordedInputOptions {
  // Longest interval between two samples [s]: an actuator log with a longer
  // hole is refused rather than interpolated across (0.1 s: a tenth of the
  // arm's slowest mode period, about 1 s on the paper's arm).
  double max_gap_s = 0.1;
  // Steps that differ from the median step by more than this fraction make
  // the time stamps irregular.
  double regular_step_tolerance = 1e-6;
  // Irregular stamps are resampled by linear interpolation (no overshoot
  // between samples) onto a regular grid of this step [s] from the first
  // to the last sample; 0: the record's median step. Regular stamps are used
  // as they are. Either way the simulator then interpolates the samples by
  // its C2 cubic spline (CableInputs).
  double resample_step_s = 0.0;
  // Units of text columns whose names carry none ("time", "cable1"): "s" or
  // "ms" for time, "m" or "mm" for lengths; empty: the name must carry it.
  std::string time_unit;
  std::string length_unit;
  // Fastest a cable may be pulled in or paid out between two samples [m/s]
  // (CheckRecordedInputsOnArm): ten times the protocols' planning limit
  // (ProtocolLimits::cable_speed_mps). No actuator of such an arm reaches
  // it; a length in the wrong unit (mm read as m) or a corrupt sample does.
  double max_cable_speed_mps = 1.0;
  // The samples are settled poses (a quasi-static replay,
  // SimulationOptions::quasi_static): used as recorded whatever their
  // spacing (no gap limit, no resampling), followed along straight lines
  // between them (CableInputs::Interpolation::kLinear).
  bool settled_poses = false;

  bool IsValid(std::string* error) const;
};

// Parses a CSV (comma) or TSV (tab, when the header has a tab) table: '#'
// lines and blank lines are skipped; the first other line is the header,
// naming a time column (time_s, time_ms, or time with options.time_unit)
// and one column per driving cable (cable1_m, cable1_mm, or cable1 with
// options.length_unit), in any order; other columns are ignored. Throws
// InputError "<file>: line N, column 'cable3_mm': <problem>" for a
// missing or unreadable value, a short row, a missing unit, or cable
// columns not numbered 1..C.
RecordedInputs ParseInputTable(const std::string& text, const std::string& source_name,
                               const RecordedInputOptions& options = {});

// Checks the record for an arm of `num_cables` driving cables and makes the
// simulator's inputs: at least 2 samples, one column per cable, finite
// values, time strictly increasing, no gap above options.max_gap_s;
// irregular stamps resampled (see RecordedInputOptions). Throws InputError
// naming the file, the column or dataset, and the line or sample index.
// `note`, when given, receives one line saying how the samples were used.
CableInputs MakeRecordedCableInputs(const RecordedInputs& record, int num_cables,
                                    const RecordedInputOptions& options = {},
                                    std::string* note = nullptr);

// The length [m] of arm a driving cable runs through, from the base to the
// link it is anchored to (the straight arm's link lengths): no pull can
// shorten its path inside the arm by more, nor a payout lengthen it by more
// without the cable lying slack in a heap.
double CableRouteLengthM(const ArmModel& model, int cable);

// The first door of recorded inputs on an arm, after MakeRecordedCableInputs'
// checks of form (every command that takes them calls it: simulate --inputs,
// mocap process --inputs, dataset assemble, every experiment file read):
// no |pulled-in length| beyond the cable's CableRouteLengthM, no speed
// between two samples beyond options.max_cable_speed_mps. Either is a unit
// or a corrupt sample, and would otherwise tear the arm apart in the
// simulator (steps of nanoseconds: a hang, not an answer). Throws
// InputError naming the file, the column and the line (or sample index).
void CheckRecordedInputsOnArm(const RecordedInputs& record, const ArmModel& model,
                              const RecordedInputOptions& options = {});

}  // namespace ccsrm::sim
