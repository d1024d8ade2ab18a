#pragma once
// A design folder as `ccsrm design` writes it (app/cmd_design.cc,
// identify::ToJson of a DesignSummary), read for its page: design.json
// (schema ccsrm-design/1: every candidate plan's predicted errors, the
// ranking, the prior box's corners) and, when a motion was proposed,
// proposed.inputs.csv (its planned cable lengths, their speeds and the
// planned joint angles at the mocap rate). The numbers are kept as written.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/datasets/array.h"
#include "json_reader.h"

namespace ccsrm::reports::internal {

inline constexpr const char* kDesignSchema = "ccsrm-design/1";

struct DesignCorner {
  std::vector<std::pair<std::string, double>> values;
  bool completed = false;
  std::string message;
  std::vector<double> relative_std_error;  // NaN where not informed
  double worst_relative_std_error = kUnknown;
  std::string worst_parameter;
};

struct DesignCandidateRow {
  std::string name;
  std::string protocol_yaml;  // non-empty: a proposed motion
  std::vector<std::string> experiments;
  double duration_s = kUnknown;
  double samples = 0;
  bool completed = false;
  std::string message;
  std::vector<double> prior, std_error,
      relative_std_error;  // per free parameter; NaN: not informed
  double worst_relative_std_error = kUnknown;
  std::string worst_parameter;
  double d_criterion = kUnknown, a_criterion = kUnknown;
  double worst_direction_relative_std_error = kUnknown;
  std::vector<std::pair<std::string, double>> worst_direction;
  std::vector<DesignCorner> corners;
  double robust_worst_relative_std_error = kUnknown;
  // Per free parameter, its derivative's change between relative steps r
  // and r/3 at the prior; empty: not checked (or a design.json before the
  // check). NaN: not computed.
  std::vector<double> derivative_step_disagreement;
  double simulations = 0;
};

// proposed.inputs.csv.
struct PlannedMotion {
  std::string file;
  std::vector<double> time_s;
  datasets::Array length_m;    // T × C
  datasets::Array speed_m_s;   // T × C
  datasets::Array angles_rad;  // T × J × 2
};

struct DesignFolder {
  std::string folder;
  std::vector<std::string> free;
  double noise_deg = kUnknown, effective_sample_fraction = kUnknown;
  double frame_rate_hz = kUnknown, relative_step = kUnknown;
  // The recordings' low-pass the design assumed [Hz] (0: none); unknown in
  // a design.json written before it was recorded.
  double low_pass_hz = kUnknown;
  struct Range {
    std::string name;
    double lower = kUnknown, upper = kUnknown;
  };
  std::vector<Range> prior_box;
  double robust_candidates = 0;
  std::vector<std::size_t> ranking;  // indices into candidates, best first
  double threads = 0, simulations = 0, wall_time_s = kUnknown;
  std::vector<DesignCandidateRow> candidates;
  std::string config_yaml;  // the prior arm's configuration
  std::optional<PlannedMotion> proposed;
};

// True when `folder` is a folder holding a design.json.
bool LooksLikeDesignFolder(const std::string& folder);

// Reads the folder. Throws InputError naming the file and the key or line:
// no design.json, not JSON or another schema, a missing key or a value of
// the wrong type, a ranking that is not a permutation of the candidates, a
// proposed.inputs.csv whose header or rows are malformed. A proposed motion
// without proposed.inputs.csv is read without it (the page says so).
DesignFolder ReadDesignFolder(const std::string& folder);

}  // namespace ccsrm::reports::internal
