#pragma once
// fit.json (schema ccsrm-fit/1, identify/README.md) read back by the jobs:
// the model `ccsrm predict` runs and the noise `ccsrm design --noise-from`
// plans with. The one reader of the file in identify/; the report's page
// reads every key for display with its own reader (reports/src/fit_folder.h),
// as reports/ does not link identification.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ccsrm/identify/experiment.h"

#include "ccsrm/sim/parameters.h"

namespace ccsrm::identify {

struct FitFile {
  std::string path;  // as given (messages)
  // Every parameter's value by SPEC 6 name or "<effect>.<parameter>", each
  // known and within its bounds.
  std::map<std::string, double> values;
  std::vector<std::string> free;  // in the fit's order
  // The arm the fit was made on: `arm` (since issue 25), else the number of
  // joints of the error table; unset when neither is there.
  std::optional<sim::ArmSize> arm;
  // Residuals, their effective count and the residual variance (against the
  // noise); NaN when the file does not give them (a fit.json written before
  // they were recorded).
  double residuals = 0.0;
  double effective_samples = 0.0;
  double residual_variance = 0.0;
  // Per experiment, the noise of each joint [deg] as estimated for the fit
  // (entries that are not positive numbers left out).
  std::vector<std::vector<double>> noise_deg;
  // The capture frame's placement the fit found: that of its first
  // experiment of tracked points recorded in the capture frame (the same
  // capture system places a prediction's recordings so); unset without one.
  std::optional<RigidPlacement> capture_placement;
};

// Reads `path`. Throws InputError "<path>: <key>: <problem>" for a file that
// is not JSON, another schema, or a parameter without a finite value, of an
// unknown name or out of its bounds.
FitFile ReadFitFile(const std::string& path);

// The same from the parsed JSON of `path` (schema already checked).
FitFile FitFileFromJson(const nlohmann::json& fit, const std::string& path);

// The noise of recordings like those the fit saw, for planning new ones:
// the RMS of its experiments' per-joint noise times the root of its
// residual variance (what the residuals were against that noise), and its
// effective samples per residual. Throws InputError naming the file and key
// when the file lacks them.
struct RecordingNoise {
  double noise_deg = 0.0;
  double effective_sample_fraction = 1.0;  // N_eff / N
};
RecordingNoise RecordingNoiseOf(const FitFile& fit);

}  // namespace ccsrm::identify
