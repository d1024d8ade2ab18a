#pragma once
// A prediction folder as `ccsrm predict` writes it
// (identify/src/prediction_output.cc), read for its page: pred.json (schema
// ccsrm-prediction/1), and per recording the measured, predicted and
// residual angles of <name>.angles.csv and the arm's segments from the
// configuration stored in <name>.pred.h5. The numbers are kept as written.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "arm_facts.h"
#include "ccsrm/datasets/array.h"
#include "json_reader.h"

namespace ccsrm::reports::internal {

inline constexpr const char* kPredictionSchema = "ccsrm-prediction/1";

// pred.json's `errors`, or a recording's: overall and per joint, [axis] 0 =
// θx, 1 = θy; NaN where pred.json has null.
struct PredictionErrors {
  double rms_deg = kUnknown;
  double max_abs_deg = kUnknown;
  double weighted_rms = kUnknown;  // RMS of (predicted − measured) / noise
  double fit_percent = kUnknown;
  struct Joint {
    int joint = 0;
    std::array<double, 2> rms_deg{kUnknown, kUnknown};
    std::array<double, 2> max_abs_deg{kUnknown, kUnknown};
    double noise_deg = kUnknown;
    std::array<double, 2> rms_over_noise{kUnknown, kUnknown};
    std::array<double, 2> fit_percent{kUnknown, kUnknown};
    std::array<double, 2> motion_rms_deg{kUnknown, kUnknown};
    std::array<double, 2> samples{0.0, 0.0};
  };
  std::vector<Joint> per_joint;
};

struct PredictionRecording {
  std::string name;
  std::string path;  // the recording as given to ccsrm predict
  bool angles_from_pipeline = false;
  std::vector<double> noise_deg;
  std::string noise_source;
  PredictionErrors errors;
  std::string run_status, run_message;
  std::string run_file;     // empty: none written (the run failed)
  std::string angles_file;  // empty for a recording of tracked points
  std::vector<double> time_s;
  datasets::Array measured_deg, predicted_deg, residual_deg;  // T × J × 2
  // A recording of tracked points (pred.json 'tracked_points'): its file,
  // the points, their measured, predicted and residual positions [mm]
  // (T × P × 3), per point the RMS error and the same with the mean offset
  // removed [mm], and what placed the capture frame ("fit", "this
  // recording"; empty: recorded in W).
  std::string points_file;
  std::vector<std::string> points;
  std::vector<std::string> labels;  // per frame, the input pattern's; empty: none
  datasets::Array measured_mm, predicted_mm, residual_mm;
  std::vector<double> point_rms_mm, point_rms_mean_removed_mm;
  std::string placement_from;
  std::vector<JointGroup> segments;
  std::vector<std::string> problems;
};

struct PredictionChannel {  // an entry of `above_noise`
  std::string recording;
  int joint = 0;
  int axis = 0;
  std::string point;  // a tracked point's coordinate (axis 0..2): rms and noise in mm
  double rms_deg = kUnknown;
  double noise_deg = kUnknown;
  double effective_samples = kUnknown;
  double p_value = kUnknown;
};

struct PredictionFolder {
  std::string folder;
  std::string model_source, model_kind;
  std::vector<std::string> effects_files;  // where effects over the values came from
  std::vector<std::string> free;
  std::vector<std::pair<std::string, double>> values;  // by name
  std::vector<std::string> effects;
  bool completed = true;
  std::string message;
  PredictionErrors errors;
  double above_noise_ratio = kUnknown;
  double significance = kUnknown;  // family-wise, over `channels`
  double channels = 0;
  std::vector<PredictionChannel> above_noise;
  // pred.json 'verdict' (issue 44; empty in an older pred.json).
  std::string verdict;
  double threads = 0, simulations = 0, wall_time_s = kUnknown;
  std::vector<PredictionRecording> recordings;
};

// True when `folder` is a folder holding a pred.json.
bool LooksLikePredictionFolder(const std::string& folder);

// Reads the folder. Throws InputError naming the file and the key or line:
// no pred.json, not JSON or another schema, a missing key or a value of the
// wrong type, a missing or malformed angles file. A run file that cannot be
// read is a problem shown on the page (its joints in one panel).
PredictionFolder ReadPredictionFolder(const std::string& folder);

}  // namespace ccsrm::reports::internal
