#pragma once
// A fit folder as `ccsrm identify` writes it (identify/src/fit_output.cc),
// read for its page: fit.json (schema ccsrm-fit/1), and per experiment the
// measured, fitted and residual angles of <name>.angles.csv and the arm's
// segments from the configuration stored in <name>.fit.h5. The numbers are
// kept as written; the page computes none of them again.
#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "arm_facts.h"
#include "ccsrm/datasets/array.h"
#include "json_reader.h"

namespace ccsrm::reports::internal {

// "ccsrm-fit/1": the schema of fit.json.
inline constexpr const char* kFitSchema = "ccsrm-fit/1";

// One parameter of fit.json's `parameters`. The fields after `value` are
// written for free parameters only; a null (not identifiable) is NaN.
struct FitParameter {
  std::string name;
  std::string units;
  bool free = false;
  double start = kUnknown;  // free: start value; fixed: the value used
  double value = kUnknown;  // estimate (fixed: the value used)
  bool identifiable = true;
  double std_error = kUnknown;
  double ci95_lower = kUnknown, ci95_upper = kUnknown;
  // The interval widened by the misfit (fit.json 'ci95_scaled_by_misfit');
  // unknown in a fit.json written before it.
  double ci95_misfit_lower = kUnknown, ci95_misfit_upper = kUnknown;
  double lower = kUnknown, upper = kUnknown;  // bounds of the fit
  bool at_bound = false;
  // fit.json 'derivative_step_disagreement': its derivative at the fit's
  // step against a third of it; unknown when not checked or written before.
  double derivative_step_disagreement = kUnknown;
};

// Errors of fit.json's `errors`, `start_errors` or an experiment's
// `start` / `fitted`: overall and per joint, [axis] 0 = θx, 1 = θy.
struct FitErrors {
  double rms_deg = kUnknown;
  double fit_percent = kUnknown;
  struct Joint {
    int joint = 0;
    std::array<double, 2> rms_deg{kUnknown, kUnknown};
    // NaN where the axis barely moves (identify::ChannelErrors).
    std::array<double, 2> fit_percent{kUnknown, kUnknown};
    // RMS of the measured angles about their mean: the axis's motion. NaN
    // in a fit.json written before it was recorded.
    std::array<double, 2> motion_rms_deg{kUnknown, kUnknown};
    std::array<double, 2> samples{0.0, 0.0};
  };
  std::vector<Joint> per_joint;
};

struct FitDirection {  // an entry of `unidentifiable`
  std::string combination;
  std::vector<std::pair<std::string, double>> components;
  double singular_value = kUnknown;
  double relative_std_error = kUnknown;  // null (infinite) -> NaN
};

struct FitExperiment {
  std::string name;
  std::string path;  // the experiment file as given to ccsrm identify
  bool angles_from_pipeline = false;
  std::vector<double> noise_deg;  // per joint
  std::string noise_source;
  FitErrors start, fitted;
  std::string run_status, run_message;  // of the fitted run
  std::string run_file;                 // empty: none written (the run failed)
  std::string angles_file;
  // From angles_file: frame times [s] and T × J × 2 arrays [deg] (NaN where
  // not measured).
  std::vector<double> time_s;
  datasets::Array measured_deg, fitted_deg, residual_deg;
  // An experiment of tracked points (fit.json 'tracked_points'; then
  // angles_file is empty): its points file, the points, their measured,
  // fitted and residual positions [mm] (T × P × 3), and per point the RMS
  // error at the start and fitted, and fitted with the mean offset removed
  // [mm].
  std::string points_file;
  std::vector<std::string> points;
  std::vector<std::string> labels;  // per frame, the input pattern's; empty: none
  datasets::Array measured_mm, fitted_mm, residual_mm;
  std::vector<double> point_start_rms_mm, point_rms_mm, point_rms_mean_removed_mm;
  // From run_file's stored configuration (ReadArmFacts); one group of every
  // joint, with the reason in `problems`, when it cannot be read.
  std::vector<JointGroup> segments;
  std::vector<std::string> problems;
};

struct FitFolder {
  std::string folder;  // as given
  bool converged = false;
  std::string termination, message;
  double iterations = 0, simulations = 0, threads = 0;
  double wall_time_s = kUnknown;
  std::vector<std::string> free;                 // in order
  std::vector<FitParameter> parameters;          // free ones in `free` order, then the fixed ones
  std::vector<std::vector<double>> correlation;  // free × free, NaN where null
  std::vector<double> singular_values;
  std::vector<FitDirection> unidentifiable;
  double rms_deg = kUnknown, rms_deg_start = kUnknown, fit_percent = kUnknown;
  FitErrors errors, start_errors;
  std::vector<double> cost_history;  // start, then each accepted step
  double residuals = 0;
  double effective_samples = kUnknown, residual_variance = kUnknown;
  // fit.json 'adequacy' (absent before issue 44: then not known): whether
  // the model explains the data, in one line, and the factor the intervals
  // widen by when it does not.
  bool adequacy_known = false;
  bool adequate = true;
  std::string verdict;
  double misfit_scale = 1.0;
  std::vector<FitExperiment> experiments;
};

// The segments of the arm a stored run (`run_file` in `folder`, as a JSON
// file `json_name` names it) was made on, from the run's configuration;
// one group of every joint, with the reason added to `problems` ("<subject>:
// ..."), when the name is empty (the `run_word` run failed) or the file
// cannot be read.
std::vector<JointGroup> SegmentsOfRun(const std::string& folder, const std::string& run_file,
                                      std::size_t joints, const std::string& subject,
                                      const std::string& json_name, const std::string& run_word,
                                      std::vector<std::string>* problems);

// True when `folder` is a folder holding a fit.json (of any schema): what
// `ccsrm report` takes for a fit folder.
bool LooksLikeFitFolder(const std::string& folder);

// Reads the folder. Throws InputError naming the file and the key or line:
// "<folder>: not a fit folder (no fit.json)", a fit.json that is not JSON
// or not of schema ccsrm-fit/1, a missing key or a value of the wrong type,
// a missing or malformed angles file (header, number of cells, a cell that
// is not a number). A run file that cannot be read is not an error: its
// experiment's joints are shown in one panel, with the reason.
FitFolder ReadFitFolder(const std::string& folder);

}  // namespace ccsrm::reports::internal
