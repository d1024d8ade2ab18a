#include "ccsrm/identify/prediction.h"
#include "ccsrm/identify/runs.h"

#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/identify/fit_file.h"
#include "ccsrm/sim/effects.h"

namespace ccsrm::identify {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kFitSchema = "ccsrm-fit/1";
constexpr const char* kLoopSchema = "ccsrm-loop/1";

// The parsed JSON of `path`, or nullopt when it is YAML. A file named
// *.json must be JSON; another is JSON when it parses as JSON (YAML's flow
// mappings also start with '{').
std::optional<json> ParseJsonFile(const std::string& path, const std::string& text) {
  json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!parsed.is_discarded() && parsed.is_object()) return parsed;
  if (fs::path(path).extension() == ".json") {
    ThrowInputError(path, "", "is not a JSON object (expected a fit.json, ccsrm-fit/1)");
  }
  return std::nullopt;
}

std::string SchemaOf(const json& j) {
  return j.is_object() && j.contains("schema") && j["schema"].is_string()
             ? j["schema"].get<std::string>()
             : std::string();
}

// A fit.json (ccsrm-fit/1): every parameter's value, the free ones, the arm.
PredictionModel ModelFromFit(const FitFile& fit) {
  PredictionModel model;
  model.source = fit.path;
  model.kind = kFitSchema;
  model.values = fit.values;
  model.free = fit.free;
  model.arm = fit.arm;
  model.capture_placement = fit.capture_placement;
  return model;
}

}  // namespace

PredictionModel LoadPredictionModel(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path folder(path);
    if (fs::is_regular_file(folder / "fit.json", ec))
      return ModelFromFit(ReadFitFile((folder / "fit.json").string()));
    if (fs::is_regular_file(folder / "loop.json", ec)) {
      return ModelFromFit(ReadFitFile((folder / "final" / "fit.json").string()));
    }
    ThrowInputError(path, "",
                    "is a folder holding neither fit.json (ccsrm identify) nor loop.json (ccsrm "
                    "loop)");
  }
  const std::string text = ReadTextFile(path);
  if (const std::optional<json> parsed = ParseJsonFile(path, text)) {
    const std::string schema = SchemaOf(*parsed);
    if (schema == kLoopSchema) {
      // The loop's final model is the fit folder beside its loop.json.
      return ModelFromFit(
          ReadFitFile((fs::path(path).parent_path() / "final" / "fit.json").string()));
    }
    if (schema != kFitSchema) {
      ThrowInputError(path, "key 'schema'",
                      "is '" + schema + "', expected " + kFitSchema + " or " + kLoopSchema);
    }
    return ModelFromFit(FitFileFromJson(*parsed, path));
  }
  // A parameter file, read by the one reader of identify's --params.
  IdentificationOptions read;
  read.values.clear();
  ApplyParameterFile(text, path, &read);
  PredictionModel model;
  model.source = path;
  model.kind = "parameter file";
  model.values = read.values;
  if (model.values.empty()) ThrowInputError(path, "", "gives no parameter value");
  // A truth file's effects are part of the model it describes.
  const YAML::Node root = ParseYamlDocument(text, path);
  if (root.IsMap() && root["parameters"] && root["effects"] && root["effects"].IsMap() &&
      root["effects"].size() > 0) {
    model.effects.push_back({text, path});
  }
  return model;
}

bool PredictionOptions::IsValid(std::string* error) const {
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    *error = problem + ", found " + std::to_string(threads);
    return false;
  }
  if (!(above_noise_ratio > 0.0) || !std::isfinite(above_noise_ratio)) {
    *error = "above_noise_ratio must be > 0";
    return false;
  }
  if (!(significance > 0.0 && significance < 1.0)) {
    *error = "significance must be in (0, 1)";
    return false;
  }
  return true;
}

PredictionErrors ComputePredictionErrors(const std::vector<const Experiment*>& recordings,
                                         const std::vector<const Eigen::MatrixXd*>& predicted) {
  CCSRM_CHECK(!recordings.empty() && recordings.size() == predicted.size());
  PredictionErrors out;
  out.channels = AngleErrors(recordings, predicted);
  const int joints = recordings.front()->joints;
  out.max_abs_deg.assign(static_cast<std::size_t>(joints), {0.0, 0.0});
  out.noise_deg.assign(static_cast<std::size_t>(joints), 0.0);
  std::vector<int> counted(static_cast<std::size_t>(joints), 0);
  double weighted_sq = 0.0;
  std::size_t samples = 0;
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    const Experiment& x = *recordings[e];
    CCSRM_CHECK(x.joints == joints && predicted[e]->rows() == x.measured.rows() &&
                predicted[e]->cols() == x.measured.cols());
    for (int j = 0; j < joints; ++j) {
      const std::size_t jj = static_cast<std::size_t>(j);
      out.noise_deg[jj] += x.noise_deg[jj];
      ++counted[jj];
      for (int a = 0; a < 2; ++a) {
        for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
          const double m = x.measured(f, 2 * j + a);
          if (!std::isfinite(m)) continue;
          // A run that ended early leaves NaN: the error is then unknown.
          const double d = ((*predicted[e])(f, 2 * j + a) - m) * kDeg;
          double& largest = out.max_abs_deg[jj][static_cast<std::size_t>(a)];
          if (!std::isfinite(d)) {
            largest = kNaN;
          } else if (std::isfinite(largest)) {
            largest = std::max(largest, std::abs(d));
          }
        }
      }
    }
    // Identification's weighted residual, over every measured column.
    for (Eigen::Index c = 0; c < x.measured.cols(); ++c) {
      for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
        if (!std::isfinite(x.measured(f, c))) continue;
        const double r = x.WeightedResidual(f, c, (*predicted[e])(f, c));
        weighted_sq += r * r;
        ++samples;
      }
    }
  }
  // Unknown (NaN) without a measured angle: recordings of tracked points.
  out.max_abs_deg_overall = std::isfinite(out.channels.rms_deg_overall) ? 0.0 : kNaN;
  for (int j = 0; j < joints; ++j) {
    const std::size_t jj = static_cast<std::size_t>(j);
    if (counted[jj] > 0) out.noise_deg[jj] /= counted[jj];
    for (int a = 0; a < 2; ++a) {
      const double v = out.max_abs_deg[jj][static_cast<std::size_t>(a)];
      if (out.channels.samples[jj][static_cast<std::size_t>(a)] == 0) {
        out.max_abs_deg[jj][static_cast<std::size_t>(a)] = kNaN;
      } else if (!std::isfinite(v) || !std::isfinite(out.max_abs_deg_overall)) {
        out.max_abs_deg_overall = kNaN;
      } else {
        out.max_abs_deg_overall = std::max(out.max_abs_deg_overall, v);
      }
    }
  }
  out.weighted_rms = samples > 0 ? std::sqrt(weighted_sq / static_cast<double>(samples)) : kNaN;
  return out;
}

PredictionSummary Predict(const std::vector<Experiment>& recordings, const PredictionModel& model,
                          const PredictionOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("prediction", "options", error);
  if (recordings.empty()) ThrowInputError("prediction", "recordings", "none given");

  // Every recording's parameters, checked before the first simulation: its
  // nominal configuration with the model's values (and effects) set over it.
  std::vector<sim::ArmParameters> parameters;
  for (const Experiment& x : recordings) {
    sim::ArmParameters p = x.config.parameters;
    if (model.arm) {
      const bool joints_differ = model.arm->joints != p.arm.joints;
      const bool cables_differ = model.arm->cables != 0 && model.arm->cables != p.arm.cables;
      if (joints_differ || cables_differ) {
        const std::string cables =
            model.arm->cables != 0 ? " and " + std::to_string(model.arm->cables) + " driving cables"
                                   : "";
        ThrowInputError(x.path, "arm",
                        "has " + std::to_string(p.arm.joints) + " joints and " +
                            std::to_string(p.arm.cables) + " driving cables, but " + model.source +
                            " was fitted on an arm of " + std::to_string(model.arm->joints) +
                            " joints" + cables);
      }
    }
    for (const auto& [name, value] : model.values) {
      sim::SetParameter(name, value, model.source + ", on the arm of " + x.path, &p);
    }
    for (const PredictionModel::Effects& e : model.effects)
      sim::ApplyEffectsYaml(e.yaml, e.file, &p);
    if (!p.IsValid(&error)) ThrowInputError(model.source, "parameters", error);
    parameters.push_back(std::move(p));
  }
  for (const Experiment& x : recordings) {
    if (x.joints != recordings.front().joints) {
      ThrowInputError(x.path, "joints",
                      "the recordings' arms differ (" + std::to_string(x.joints) + " against " +
                          std::to_string(recordings.front().joints) + " joints of " +
                          recordings.front().path + ")");
    }
  }

  std::unique_ptr<SimulationBackend> own_backend;
  SimulationBackend* backend = options.backend.get();
  if (backend == nullptr) {
    own_backend = MakeThreadBackend(&recordings, options.threads);
    backend = own_backend.get();
  }
  std::vector<RunRequest> requests;
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    requests.push_back({e, parameters[e], /*keep_trajectory=*/true, {}});
  }
  std::vector<RunResult> results = backend->RunBatch(requests, options.on_run);

  PredictionSummary summary;
  summary.model = model;
  summary.effects = parameters.front().EnabledEffects();
  summary.threads = backend->parallelism();
  summary.simulations = static_cast<std::int64_t>(requests.size());
  std::vector<const Experiment*> all;
  std::vector<const Eigen::MatrixXd*> predicted;
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    const Experiment& x = recordings[e];
    RecordingPrediction r;
    r.name = x.name;
    r.path = x.path;
    r.angles_from_pipeline = x.angles_from_pipeline;
    r.noise_source = x.noise_source;
    r.parameters = parameters[e];
    r.run.summary = results[e].summary;
    r.run.trajectory = std::move(results[e].trajectory);
    r.predicted_rad = std::move(results[e].simulated);
    if (!r.run.summary.completed() && summary.completed) {
      summary.completed = false;
      summary.message = x.name + ": " + r.run.summary.message;
    }
    summary.recordings.push_back(std::move(r));
  }
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    RecordingPrediction& r = summary.recordings[e];
    const Experiment& x = recordings[e];
    if (!x.tracked_points.empty()) {
      r.tracked_points = x.tracked_points;
      r.placed_in_capture_frame = x.point_placement != PointPlacement::kWorld;
      Experiment placed = x;
      if (model.capture_placement && x.point_placement == PointPlacement::kFittedRigidMotion) {
        // The run placed itself; the fit's placement replaces that one.
        placed.point_placement = PointPlacement::kGiven;
        placed.given_placement = *model.capture_placement;
        r.placement_from_fit = true;
      }
      r.placement = RecordTrackedPoints(placed, r.run.trajectory, &r.predicted_rad);
      placed.AsMeasured(&r.predicted_rad);
      r.points = PointErrors(x, r.predicted_rad);
    }
    r.errors = ComputePredictionErrors({&x}, {&r.predicted_rad});
    all.push_back(&x);
    predicted.push_back(&r.predicted_rad);
  }
  summary.adequacy =
      AssessModelAdequacy(all, predicted, options.above_noise_ratio, options.significance);
  summary.errors = ComputePredictionErrors(all, predicted);
  if (summary.completed) summary.message = "every run completed";
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return summary;
}

}  // namespace ccsrm::identify
