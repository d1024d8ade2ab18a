#pragma once
// A loop folder as `ccsrm loop` writes it (identify/src/loop_output.cc),
// read for its page: loop.json (schema ccsrm-loop/1: the rounds with their
// residual diagnostics and candidates, the final parameters, the errors
// before and after, what remains unexplained), the fit folders declared/
// and final/ of the declared and the final model (ReadFitFolder), and per
// held-out experiment holdout/<name>.angles.csv (measured, declared and
// final angles; of tracked points <name>.declared.points.csv and
// <name>.final.points.csv). The numbers are kept as written.
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/datasets/array.h"
#include "fit_folder.h"
#include "json_reader.h"

namespace ccsrm::reports::internal {

// "ccsrm-loop/1": the schema of loop.json.
inline constexpr const char* kLoopSchema = "ccsrm-loop/1";

// A signal's correlation with the residual (or its normalised statistic)
// and the 95 % band of "no relation".
struct LoopSignal {
  std::string signal;
  double value = kUnknown;
  double band = kUnknown;
  bool significant = false;  // as written (|value| > band)
};

// loop.json's diagnostics object (`evidence` of a round, `final_evidence`).
struct LoopDiagnostics {
  double rms_deg = kUnknown;
  double effective_samples = kUnknown;
  std::vector<LoopSignal> pooled;  // in the file's order
  std::vector<double> lags_s;
  // Pooled cross-correlation of each plotted signal at lags_s.
  std::vector<std::pair<std::string, std::vector<double>>> cross_correlation;
  struct Phase {
    std::string name;
    double start_s = kUnknown, end_s = kUnknown;
  };
  struct Experiment {
    std::string name;
    double rms_deg = kUnknown, lag_s = kUnknown, lag_explained = kUnknown;
    std::vector<Phase> phases;
  };
  std::vector<Experiment> experiments;
  // A joint's axis, or a tracked point's coordinate (its figures in mm).
  struct Channel {
    std::string experiment;
    int joint = 0;      // 0 for a tracked point's coordinate
    int axis = 0;       // 0 θx, 1 θy; of a tracked point 0 x, 1 y, 2 z
    std::string point;  // the tracked point's name
    double samples = kUnknown;
    double rms_deg = kUnknown, mean_deg = kUnknown, noise_deg = kUnknown;
    double lags_outside_band = kUnknown;
    double autocorrelation_time = kUnknown, effective_samples = kUnknown;
    double hold_drift_degps = kUnknown, hysteresis_deg2 = kUnknown;
  };
  std::vector<Channel> channels;
};

// A parameter estimate (`parameters` and a candidate's `estimates`).
struct LoopEstimate {
  std::string name;
  std::string units;
  double value = kUnknown, std_error = kUnknown;
  double ci95_lower = kUnknown, ci95_upper = kUnknown;
  bool identifiable = false;
  bool free = false;
};

struct LoopCandidate {
  std::string name;
  std::vector<std::string> parameters;
  double score = kUnknown, p_value = kUnknown;
  bool significant = false;
  std::vector<std::pair<std::string, double>> linearised;
  std::vector<LoopSignal> evidence;
  bool refitted = false;
  double delta_bic = kUnknown, rms_deg = kUnknown, holdout_rms_deg = kUnknown;
  bool holdout_improved = false, size_significant = false;
  std::string termination;
  std::vector<LoopEstimate> estimates;
  bool accepted = false;
  std::string reason;
};

// The backward step's check of an earlier addition (loop.json
// rounds[].backward, issue 28; absent in files written before it).
struct LoopBackwardCheck {
  std::string name;
  std::vector<std::string> parameters;
  bool size_significant = true;
  double delta_chi2_zeroed = kUnknown;
  bool refitted = false;
  double delta_bic_keep = kUnknown, rms_deg_without = kUnknown;
  double holdout_rms_deg_without = kUnknown;
  bool taken_back = false;
  std::string reason;
};

struct LoopRound {
  int index = 0;
  std::vector<std::string> effects_on;
  double rms_deg = kUnknown, holdout_rms_deg = kUnknown;
  LoopDiagnostics evidence;
  std::vector<LoopCandidate> candidates;
  std::string winner;  // empty: none
  std::vector<std::string> tie;
  std::string decision;
  std::vector<LoopBackwardCheck> backward;  // after the winner's addition
};

// `before`, `after`, `holdout_before`, `holdout_after`: overall and per
// joint, [axis] 0 = θx, 1 = θy.
struct LoopErrors {
  double rms_deg = kUnknown;
  std::vector<std::array<double, 2>> joint_rms_deg;
};

struct LoopUnexplained {
  std::string experiment;
  int joint = 0;      // 0 for a tracked point's coordinate
  int axis = 0;       // as LoopDiagnostics::Channel's
  std::string point;  // the tracked point's name
  double rms_deg = kUnknown, noise_deg = kUnknown;
  std::string worst_phase;
  double worst_phase_rms_deg = kUnknown;
};

struct LoopFitRun {  // declared_fit, final_fit
  std::string termination;
  double iterations = 0;
};

// A held-out experiment's angles (holdout/<name>.angles.csv), or of a loop
// over tracked points its points (holdout/<name>.declared.points.csv and
// <name>.final.points.csv).
struct LoopHoldout {
  std::string name, path;
  std::string file;  // as read (the declared points' file); empty when the folder holds none
  std::vector<double> time_s;
  datasets::Array measured_deg, declared_deg, final_deg;    // T × J × 2
  std::vector<std::string> points;                          // names; empty: angles
  datasets::Array declared_residual_mm, final_residual_mm;  // T × P × 3
};

// A declared value the loop corrected (loop.json 'declared_corrections',
// issue 28; absent in files written before it).
struct LoopDeclaredCorrection {
  std::string parameter, config_key, sentence;
  double declared = kUnknown, corrected = kUnknown, relative = kUnknown;
  double relative_std_error = kUnknown;
  std::array<double, 2> relative_ci95 = {kUnknown, kUnknown};
  std::vector<std::string> indistinguishable;
};

// A moment the loop found in the data (loop.json 'discovered_terms').
struct LoopDiscoveredMoment {
  int segment = 0;
  std::array<double, 2> joints = {kUnknown, kUnknown};
  std::string axis;     // "x" or "y"
  std::string formula;  // "joints 1-6 (segment 1) θx: M = ..."
  struct Term {
    std::string term, formula, units;
    LoopEstimate estimate;
  };
  std::vector<Term> terms;
};

struct LoopFolder {
  std::string folder;  // as given
  struct Data {
    std::string name, path;
    bool holdout = false;
  };
  std::vector<Data> data;
  std::vector<std::string> declared_free;
  std::vector<LoopRound> rounds;
  std::vector<std::string> added_effects;
  std::vector<LoopDeclaredCorrection> declared_corrections;
  std::vector<LoopDiscoveredMoment> discovered_terms;
  std::vector<LoopEstimate> parameters;  // the final model's free parameters
  // The unit of every RMS figure (the fields named _deg): loop.json 'unit',
  // "mm" for a loop over tracked points; "deg" in files written before it.
  std::string unit = "deg";
  double rms_before_deg = kUnknown, rms_after_deg = kUnknown;
  double holdout_rms_before_deg = kUnknown, holdout_rms_after_deg = kUnknown;
  LoopErrors before, after;
  std::optional<LoopErrors> holdout_before, holdout_after;
  double noise_floor_deg = kUnknown;
  std::vector<LoopUnexplained> unexplained;
  LoopDiagnostics final_evidence;
  std::string conclusion;
  double simulations = 0, wall_time_s = kUnknown, threads = 0;
  LoopFitRun declared_fit, final_fit;

  // The fit folders declared/ and final/, when written (a failed declared
  // fit leaves them out).
  std::optional<FitFolder> declared, final_model;
  std::vector<LoopHoldout> holdout;
  // What is missing from the folder, one sentence each (shown as notices).
  std::vector<std::string> problems;
};

// True when `folder` is a folder holding a loop.json: what `ccsrm report`
// takes for a loop folder.
bool LooksLikeLoopFolder(const std::string& folder);

// Reads the folder. Throws InputError naming the file and the key or line:
// "<folder>: not a loop folder (no loop.json)", a loop.json that is not
// JSON or not of schema ccsrm-loop/1, a missing key or a value of the wrong
// type, a broken declared/ or final/ fit folder or held-out angles file. A
// missing declared/, final/ or held-out angles file is not an error: it is
// named in `problems`.
LoopFolder ReadLoopFolder(const std::string& folder);

}  // namespace ccsrm::reports::internal
