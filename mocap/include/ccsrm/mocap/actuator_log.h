#pragma once
// A lab's actuator log: a CSV/TSV table written by the arm's controller at
// its own rate and on its own clock (motor encoder angles or cable lengths),
// and the map (`ccsrm-actuators/1` YAML, datasets/README.md "Actuator logs")
// that says which column is what. The result is the cables' pulled-in length
// on the log's clock; putting it on the mocap clock is clock_alignment.h's.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace ccsrm::sim {
class ArmModel;
}

namespace ccsrm::mocap {

inline constexpr const char* kActuatorMapSchema = "ccsrm-actuators/1";

// What a cable column records.
enum class CableSignal {
  kLengthChange,  // the pulled-in length itself (unit m or mm)
  kMotorAngle,    // the angle of the motor winding the cable on its drum
};

// One driving cable's column (cable k = the k-th entry of the map).
struct CableColumn {
  std::string column;  // header name in the log
  CableSignal signal = CableSignal::kLengthChange;
  // kLengthChange: "m" or "mm". kMotorAngle: "rad", "deg", or "counts"
  // (encoder counts, with counts_per_turn).
  std::string unit;
  // Motor angles only. Pulled-in length = sign × drum_radius_m × (motor
  // angle − its first logged value) / gear_ratio.
  double drum_radius_m = 0.0;  // > 0
  double gear_ratio = 1.0;     // motor turns per drum turn, > 0
  // +1 when the logged quantity grows as the cable is pulled in, −1 when it
  // shrinks (a motor mounted the other way round). Applies to lengths too.
  int sign = 1;
  // Lengths only: the reading at which the cable is just taut, in the log's
  // unit (`ccsrm dataset tendon-map` identifies it): pulled-in length =
  // sign × (reading − zero). Default 0.
  double zero = 0.0;
  // Unit "counts" only: encoder counts per motor turn (> 0), and the modulus
  // at which the counter wraps (65536 for a 16-bit counter; 0 = it does
  // not). A wrapped counter is unwrapped by taking every step between two
  // samples as the shortest one modulo wrap_counts, so the motor must turn
  // less than half the counter's range between two samples.
  double counts_per_turn = 0.0;
  double wrap_counts = 0.0;
};

// The log's trigger (sync) column: an edge where the value crosses
// `threshold` in the direction of `polarity`.
struct TriggerColumn {
  std::string column;
  double threshold = 0.5;           // in the column's own units (0/1 logic by default)
  std::string polarity = "rising";  // "rising" or "falling"
};

struct ActuatorMap {
  std::string time_column;
  std::string time_unit = "s";  // "s", "ms" or "us"
  std::vector<CableColumn> cables;
  std::optional<TriggerColumn> trigger;
  // Longest interval between two log samples [s]: a longer hole is refused
  // rather than interpolated across (default 0.1 s, as for recorded inputs:
  // a tenth of the slowest mode period of the paper's arm).
  double max_gap_s = 0.1;
};

// Parses a ccsrm-actuators/1 map. Throws InputError "<file>: line N, key
// 'cables[2].drum_radius_m': <problem>" for a wrong schema, an unknown or
// missing key, a bad unit or value, a column named twice.
ActuatorMap ParseActuatorMap(const std::string& yaml_text, const std::string& file);
ActuatorMap ReadActuatorMap(const std::string& path);

// A log as read through its map, on the log's own clock.
struct ActuatorLog {
  std::string source_name;
  std::vector<std::size_t> lines;   // file line of each sample
  Eigen::VectorXd time_s;           // N, strictly increasing
  Eigen::MatrixXd length_change_m;  // N × C, pulled in = positive, 0 at the first sample
                                    // for motor angles
  Eigen::VectorXd trigger;          // N values of the trigger column; empty without one
  std::vector<std::string> cable_columns;
};

// Parses a CSV (comma) or TSV (tab in the header line) log: '#' lines and
// blank lines skipped, the first other line the header. Columns the map does
// not name are ignored. Throws InputError naming the file, the line and the
// column: a mapped column missing from the header (and the map key naming
// it), a missing or non-numeric cell, NaN or an infinite value, time not
// strictly increasing, a gap longer than map.max_gap_s, fewer than 2
// samples. `map_file` names the map in messages.
ActuatorLog ParseActuatorLog(const std::string& text, const std::string& source_name,
                             const ActuatorMap& map, const std::string& map_file);
ActuatorLog ReadActuatorLog(const std::string& path, const ActuatorMap& map,
                            const std::string& map_file);

// The one check of a log's lengths against the arm they drive (`dataset
// assemble`, `dataset import-pose-log`): one cable per driving cable of
// `model` (else InputError naming `map_file`, key 'cables', and
// `config_file`), and its samples [first, first + count) within the arm's
// bounds (sim::CheckRecordedInputsOnArm: a column in the wrong unit pulls a
// cable metres). count < 0: to the last sample.
void CheckActuatorLogOnArm(const ActuatorLog& log, const ActuatorMap& map,
                           const std::string& map_file, const sim::ArmModel& model,
                           const std::string& config_file, Eigen::Index first = 0,
                           Eigen::Index count = -1);

}  // namespace ccsrm::mocap
