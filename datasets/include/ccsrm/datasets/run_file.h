#pragma once
// A simulation run file, schema "ccsrm-run/1" (SPEC §4; the layout, shapes
// and units are tabulated in datasets/README.md, a public contract).
//
// Symbols used below: T frames, J joints, L links, C driving cables, E_k
// elements and H_k hole nodes of cable k, M markers. All of them are read from
// the arrays themselves (the default arm has J = L = 12, C = 6).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/common/version.h"
#include "ccsrm/datasets/array.h"

namespace ccsrm::datasets {

// "ccsrm-run/1": the schema this ccsrm writes and the only one it reads.
inline constexpr const char* kRunSchema = "ccsrm-run/1";

// How the run ended: a diverging run is a numerical outcome, recorded in the
// file with the frames written so far (SPEC §3, "Divergence").
enum class RunStatus { kCompleted, kDiverged, kCancelled };

// "completed" / "diverged" / "cancelled", the values of the root attribute
// `status`.
const char* RunStatusName(RunStatus status);

// Per-cable records, stored under /cables/<k> (k = 1..C).
struct CableRecord {
  Array tension;        // T × E_k, N: tension of every element.
  Array stuck;          // T × H_k, 1: 1 where the hole node is stuck, else 0.
  Array slip_velocity;  // T × H_k, m/s: ṡ of every hole node.
};

struct RunFile {
  // --- Root attributes -----------------------------------------------------
  // Paper case "1".."4", or "custom" for any other protocol.
  std::string case_name = "custom";
  // The full YAML configuration the run used.
  std::string config_yaml;
  // Extension (optional attributes, written when not empty): the protocol
  // that drove the run (a ccsrm-protocol/1 document, its parameters at the
  // values used), or the file of recorded inputs it was driven from.
  std::string protocol_yaml;
  std::string inputs_file;
  // ISO 8601 UTC time of writing; left empty, WriteRunFile stamps the
  // current time (the struct itself is not modified).
  std::string created;
  std::string ccsrm_version = kVersion;
  // Solver statistics.
  double wall_time_s = 0.0;  // s, >= 0
  std::int64_t steps = 0;    // accepted steps, >= 0
  std::int64_t rejected_steps = 0;
  std::int64_t rhs_evaluations = 0;
  // Extension: how the run ended, and why when it diverged (e.g.
  // "constraint violation 3.2e-3 above bound 1e-3 at t = 12.37 s").
  RunStatus status = RunStatus::kCompleted;
  std::string status_message;

  // --- Datasets --------------------------------------------------------------
  Array time;                 // /time, T, s: strictly increasing, finite, T >= 1.
  Array joint_angles;         // /joint_angles, T × J × 2 (θx, θy), rad.
  Array joint_rates;          // /joint_rates, T × J × 2, rad/s.
  Array link_pose;            // /link_pose, T × L × 7 (x, y, z, e0..e3), m and 1.
  Array input_tension;        // /input_tension, T × C, N.
  Array input_length_change;  // /input_length_change, T × C, m (positive = pulled).
  Array stuck_nodes;          // /stuck_nodes, T × C, 1 (stuck hole nodes per cable).
  // Extension, optional on reading (files before it): /slack_elements, T × C,
  // 1: elements of each cable that carry no tension (sim::CountSlackElements).
  std::optional<Array> slack_elements;
  std::vector<CableRecord> cables;  // C entries, /cables/1 .. /cables/C.
  Array constraint_violation;       // /diagnostics/constraint_violation, T, mixed (‖Φ‖).
  Array energy;                     // /diagnostics/energy, T × 3 (kinetic, elastic,
                                    // dissipated), J.
  // Optional, present when a marker layout was given: /markers, T × M × 3, m,
  // and (extension) /marker_names, M strings.
  std::optional<Array> markers;
  std::vector<std::string> marker_names;

  std::size_t frames() const { return time.rows(); }
};

// Checks that `run` is a consistent ccsrm-run/1 record: every array's shape
// agrees with /time and with the others, time is strictly increasing and
// finite, the attributes hold allowed values. `file` only labels the message.
// Throws InputError "<file>: <path>: <problem>" on the first inconsistency.
void ValidateRunFile(const RunFile& run, const std::string& file);

// Writes `run` to `path` atomically: ValidateRunFile first (nothing is
// created when it throws), then a temporary file in the same directory that is
// renamed onto `path` once complete and closed. On any failure the temporary
// is removed and an existing file at `path` is left untouched.
// Throws InputError naming `path` (inconsistent record, missing directory,
// write failure).
void WriteRunFile(const std::string& path, const RunFile& run);

// Reads and validates a ccsrm-run/1 file (read-only; the file is never
// modified). Throws InputError with a one-line message naming the file and the
// problem: not HDF5 or truncated, wrong schema kind or version, a missing
// path or attribute, a wrong shape, dtype or units attribute, bad time.
RunFile ReadRunFile(const std::string& path);

}  // namespace ccsrm::datasets
