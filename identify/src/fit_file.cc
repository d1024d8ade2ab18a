#include "ccsrm/identify/fit_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <Eigen/Geometry>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"

namespace ccsrm::identify {
namespace {

using nlohmann::json;

constexpr const char* kFitSchema = "ccsrm-fit/1";

double NumberOr(const json& j, const char* key, double absent) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : absent;
}

// experiments[k].tracked_points.capture_placement: {rotation_deg,
// rotation_axis, offset_mm}, or null.
std::optional<RigidPlacement> PlacementOf(const json& e, const std::string& path, std::size_t k) {
  if (!e.is_object() || !e.contains("tracked_points") || !e["tracked_points"].is_object())
    return std::nullopt;
  const json& points = e["tracked_points"];
  if (!points.contains("capture_placement") || points["capture_placement"].is_null())
    return std::nullopt;
  const json& x = points["capture_placement"];
  const std::string at =
      "key 'experiments[" + std::to_string(k) + "].tracked_points.capture_placement'";
  const auto vector3 = [&](const char* key) {
    if (!x.contains(key) || !x[key].is_array() || x[key].size() != 3 ||
        !std::all_of(x[key].begin(), x[key].end(), [](const json& v) { return v.is_number(); })) {
      ThrowInputError(path, at + "." + key, "expected three numbers");
    }
    return Eigen::Vector3d(x[key][0].get<double>(), x[key][1].get<double>(),
                           x[key][2].get<double>());
  };
  const Eigen::Vector3d axis = vector3("rotation_axis");
  const Eigen::Vector3d offset_mm = vector3("offset_mm");
  const double angle_deg = NumberOr(x, "rotation_deg", std::nan(""));
  if (!std::isfinite(angle_deg) || !offset_mm.allFinite() ||
      !(std::abs(axis.norm() - 1.0) < 1e-6)) {
    ThrowInputError(path, at,
                    "expected a finite rotation_deg, a unit rotation_axis and a finite offset_mm");
  }
  RigidPlacement placement;
  placement.R_CW = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis).toRotationMatrix();
  placement.p_CW_m = offset_mm * 1e-3;
  return placement;
}

}  // namespace

FitFile FitFileFromJson(const json& fit, const std::string& path) {
  FitFile file;
  file.path = path;
  if (!fit.contains("parameters") || !fit["parameters"].is_object() || fit["parameters"].empty()) {
    ThrowInputError(path, "key 'parameters'", "missing or not a mapping of parameter names");
  }
  for (const auto& [name, entry] : fit["parameters"].items()) {
    const std::string at = "key 'parameters." + name + "'";
    // FindParameter's message names the known parameters.
    const sim::ParameterInfo& info = sim::FindParameter(name, path + ": " + at);
    if (!entry.is_object() || !entry.contains("value") || !entry["value"].is_number()) {
      ThrowInputError(path, at + ".value", "missing or not a number");
    }
    const double value = entry["value"].get<double>();
    const std::string problem = sim::ParameterValueProblem(info, value);
    if (!problem.empty()) ThrowInputError(path, at + ".value", problem);
    file.values[name] = value;
  }
  if (fit.contains("free") && fit["free"].is_array()) {
    for (const json& name : fit["free"]) {
      if (name.is_string()) file.free.push_back(name.get<std::string>());
    }
  }
  if (fit.contains("arm") && fit["arm"].is_object()) {
    const json& arm = fit["arm"];
    if (!arm.contains("joints") || !arm["joints"].is_number_integer() ||
        !arm.contains("driving_cables") || !arm["driving_cables"].is_number_integer()) {
      ThrowInputError(path, "key 'arm'", "expected {joints, driving_cables} (integers)");
    }
    file.arm = sim::ArmSize{arm["joints"].get<int>(), arm["driving_cables"].get<int>()};
  } else if (fit.contains("errors") && fit["errors"].is_object() &&
             fit["errors"].contains("per_joint") && fit["errors"]["per_joint"].is_array()) {
    file.arm = sim::ArmSize{static_cast<int>(fit["errors"]["per_joint"].size()), 0};
  }
  constexpr double kAbsent = std::numeric_limits<double>::quiet_NaN();
  file.residuals = NumberOr(fit, "residuals", kAbsent);
  file.effective_samples = NumberOr(fit, "effective_samples", kAbsent);
  file.residual_variance = NumberOr(fit, "residual_variance", kAbsent);
  if (fit.contains("experiments") && fit["experiments"].is_array()) {
    for (const json& e : fit["experiments"]) {
      if (!file.capture_placement) {
        file.capture_placement = PlacementOf(e, path, file.noise_deg.size());
      }
      std::vector<double>& noise = file.noise_deg.emplace_back();
      if (!e.is_object() || !e.contains("noise_deg") || !e["noise_deg"].is_array()) continue;
      for (const json& v : e["noise_deg"]) {
        if (v.is_number() && v.get<double>() > 0.0) noise.push_back(v.get<double>());
      }
    }
  }
  return file;
}

FitFile ReadFitFile(const std::string& path) {
  const json fit = json::parse(ReadTextFile(path), nullptr, /*allow_exceptions=*/false);
  if (fit.is_discarded() || !fit.is_object()) {
    ThrowInputError(path, "",
                    std::filesystem::path(path).extension() == ".json"
                        ? "is not a JSON object (expected a fit.json, ccsrm-fit/1)"
                        : "is not JSON: expected a fit.json (ccsrm-fit/1)");
  }
  const std::string schema =
      fit.contains("schema") && fit["schema"].is_string() ? fit["schema"].get<std::string>() : "";
  if (schema != kFitSchema) {
    ThrowInputError(path, "key 'schema'",
                    "is '" + schema + "', expected " + kFitSchema +
                        " (the fit.json of ccsrm identify, or final/fit.json of ccsrm loop)");
  }
  return FitFileFromJson(fit, path);
}

RecordingNoise RecordingNoiseOf(const FitFile& fit) {
  const auto number = [&fit](double value, const char* key) {
    if (!std::isfinite(value)) ThrowInputError(fit.path, key, "missing or not a finite number");
    return value;
  };
  const double residuals = number(fit.residuals, "residuals");
  const double effective = number(fit.effective_samples, "effective_samples");
  const double variance = number(fit.residual_variance, "residual_variance");
  if (!(residuals > 0.0) || !(effective > 0.0) || effective > residuals || !(variance > 0.0)) {
    ThrowInputError(fit.path, "effective_samples",
                    "needs 0 < effective_samples <= residuals and residual_variance > 0");
  }
  double sum = 0.0;
  int count = 0;
  for (const std::vector<double>& experiment : fit.noise_deg) {
    for (const double v : experiment) {
      sum += v * v;
      ++count;
    }
  }
  if (count == 0) ThrowInputError(fit.path, "experiments[].noise_deg", "no noise recorded");
  return {std::sqrt(sum / count * variance), effective / residuals};
}

}  // namespace ccsrm::identify
