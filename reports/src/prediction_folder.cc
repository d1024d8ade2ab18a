#include "prediction_folder.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "angles_csv.h"
#include "ccsrm/common/error.h"
#include "fit_folder.h"

namespace ccsrm::reports::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

PredictionErrors ReadErrors(const JsonReader& in, const json& object, const std::string& key) {
  PredictionErrors errors;
  errors.rms_deg = in.NumberAt(object, key, "rms_deg", true);
  errors.max_abs_deg = in.NumberAt(object, key, "max_abs_deg", true);
  errors.weighted_rms = in.NumberAt(object, key, "weighted_rms", true);
  errors.fit_percent = in.NumberAt(object, key, "fit_percent", true);
  const json& joints = in.List(object, key, "per_joint");
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const std::string at = key + ".per_joint[" + std::to_string(j) + "]";
    PredictionErrors::Joint joint;
    joint.joint = static_cast<int>(in.NumberAt(joints[j], at, "joint"));
    if (joint.joint != static_cast<int>(j) + 1) in.Fail(at + ".joint", "expected joints 1, 2, ...");
    joint.rms_deg = in.Pair(in.At(joints[j], at, "rms_deg"), at + ".rms_deg", true);
    joint.max_abs_deg = in.Pair(in.At(joints[j], at, "max_abs_deg"), at + ".max_abs_deg", true);
    joint.noise_deg = in.NumberAt(joints[j], at, "noise_deg", true);
    joint.rms_over_noise =
        in.Pair(in.At(joints[j], at, "rms_over_noise"), at + ".rms_over_noise", true);
    joint.fit_percent = in.Pair(in.At(joints[j], at, "fit_percent"), at + ".fit_percent", true);
    joint.motion_rms_deg =
        in.Pair(in.At(joints[j], at, "motion_rms_deg"), at + ".motion_rms_deg", true);
    joint.samples = in.Pair(in.At(joints[j], at, "samples"), at + ".samples", false);
    errors.per_joint.push_back(joint);
  }
  return errors;
}

// A recording of tracked points: its errors and placement from pred.json,
// its positions from the points file it names.
void ReadTrackedPoints(const JsonReader& in, const json& entry, const std::string& at,
                       const fs::path& folder, PredictionRecording* r) {
  r->points_file = in.Text(entry, at, "points_file");
  if (r->points_file.find('/') != std::string::npos || r->points_file == ".." ||
      r->points_file == ".") {
    in.Fail(at + ".points_file",
            "expected a file name in the prediction folder, not '" + r->points_file + "'");
  }
  PointsCsv points =
      ReadPointsCsv((folder / r->points_file).string(), {"measured", "predicted", "residual"},
                    "the points file pred.json names");
  r->time_s = std::move(points.time_s);
  r->points = std::move(points.points);
  r->labels = std::move(points.labels);
  r->measured_mm = std::move(points.series[0]);
  r->predicted_mm = std::move(points.series[1]);
  r->residual_mm = std::move(points.series[2]);
  const std::string key = at + ".tracked_points";
  const json& tracked = in.Object(entry, at, "tracked_points");
  const json& errors = in.List(tracked, key, "errors");
  if (errors.size() != r->points.size()) {
    in.Fail(key + ".errors", "must have one entry per point of " + r->points_file + " (" +
                                 std::to_string(r->points.size()) + ")");
  }
  for (std::size_t p = 0; p < errors.size(); ++p) {
    const std::string e = key + ".errors[" + std::to_string(p) + "]";
    r->point_rms_mm.push_back(in.NumberAt(errors[p], e, "rms_mm", true));
    r->point_rms_mean_removed_mm.push_back(
        in.NumberAt(errors[p], e, "rms_mean_offset_removed_mm", true));
  }
  const json& placement = in.At(tracked, key, "capture_placement");
  if (!placement.is_null())
    r->placement_from = in.Text(placement, key + ".capture_placement", "from");
}

PredictionRecording ReadRecording(const JsonReader& in, const json& entry, std::size_t index,
                                  const fs::path& folder) {
  const std::string at = "recordings[" + std::to_string(index) + "]";
  PredictionRecording r;
  r.name = in.Text(entry, at, "name");
  r.path = in.Text(entry, at, "path");
  r.angles_from_pipeline = in.Flag(entry, at, "angles_from_pipeline");
  r.noise_deg = in.Numbers(entry, at, "noise_deg");
  r.noise_source = in.Text(entry, at, "noise_source");
  r.errors = ReadErrors(in, in.At(entry, at, "errors"), at + ".errors");
  const json& run = in.At(entry, at, "run");
  r.run_status = in.Text(run, at + ".run", "status");
  r.run_message = in.Text(run, at + ".run", "message");
  const json& run_file = in.At(entry, at, "run_file");
  if (!run_file.is_null() && !run_file.is_string()) {
    in.Fail(at + ".run_file", "expected a file name or null");
  }
  if (run_file.is_string()) r.run_file = run_file.get<std::string>();
  if (in.At(entry, at, "angles_file").is_null()) {
    ReadTrackedPoints(in, entry, at, folder, &r);
    return r;
  }
  r.angles_file = in.Text(entry, at, "angles_file");
  // Both files sit in the folder: a name with a folder in it is not one
  // ccsrm predict writes.
  for (const std::string* name : {&r.angles_file, &r.run_file}) {
    if (name->find('/') != std::string::npos || *name == ".." || *name == ".") {
      in.Fail(at + (name == &r.angles_file ? ".angles_file" : ".run_file"),
              "expected a file name in the prediction folder, not '" + *name + "'");
    }
  }
  AnglesCsv angles =
      ReadAnglesCsv((folder / r.angles_file).string(), {"measured", "predicted", "residual"},
                    "the angles file pred.json names");
  r.time_s = std::move(angles.time_s);
  r.measured_deg = std::move(angles.series[0]);
  r.predicted_deg = std::move(angles.series[1]);
  r.residual_deg = std::move(angles.series[2]);
  const std::size_t joints = r.measured_deg.shape[1];
  if (r.noise_deg.size() != joints || r.errors.per_joint.size() != joints) {
    in.Fail(at, "noise_deg and errors must have one entry per joint of " + r.angles_file + " (" +
                    std::to_string(joints) + ")");
  }
  r.segments = SegmentsOfRun(folder.string(), r.run_file, joints, "Recording " + r.name,
                             "pred.json", "predicted", &r.problems);
  return r;
}

}  // namespace

bool LooksLikePredictionFolder(const std::string& folder) {
  std::error_code ec;
  return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "pred.json", ec);
}

PredictionFolder ReadPredictionFolder(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) ThrowInputError(folder, "", "not a folder");
  const fs::path path = fs::path(folder) / "pred.json";
  if (!fs::is_regular_file(path, ec)) {
    ThrowInputError(folder, "", "not a prediction folder (no pred.json)");
  }
  const std::string file = path.string();
  const json root = ReadSchemaFile(file, kPredictionSchema, "ccsrm predict");
  const JsonReader in(file);
  PredictionFolder p;
  p.folder = folder;
  const json& model = in.Object(root, "", "model");
  p.model_source = in.Text(model, "model", "source");
  p.model_kind = in.Text(model, "model", "kind");
  p.free = in.Texts(model, "model", "free");
  const json& values = in.Object(model, "model", "values");
  for (const auto& [name, value] : values.items()) {
    p.values.emplace_back(name, in.Number(value, "model.values." + name));
  }
  p.effects_files = in.Texts(model, "model", "effects_files");
  p.effects = in.Texts(root, "", "effects");
  p.completed = in.Flag(root, "", "completed");
  p.message = in.Text(root, "", "message");
  p.errors = ReadErrors(in, in.At(root, "", "errors"), "errors");
  p.above_noise_ratio = in.NumberAt(root, "", "above_noise_ratio");
  p.significance = in.NumberAt(root, "", "significance");
  p.channels = in.NumberAt(root, "", "channels");
  if (root.contains("verdict")) p.verdict = in.Text(root, "", "verdict");
  const json& above = in.List(root, "", "above_noise");
  for (std::size_t i = 0; i < above.size(); ++i) {
    const std::string at = "above_noise[" + std::to_string(i) + "]";
    PredictionChannel c;
    c.recording = in.Text(above[i], at, "recording");
    c.joint = static_cast<int>(in.NumberAt(above[i], at, "joint"));
    if (above[i].contains("point")) c.point = in.Text(above[i], at, "point");
    const std::string axis = in.Text(above[i], at, "axis");
    if (axis != "x" && axis != "y" && !(axis == "z" && !c.point.empty()))
      in.Fail(at + ".axis",
              c.point.empty() ? "expected \"x\" or \"y\"" : "expected \"x\", \"y\" or \"z\"");
    c.axis = axis[0] - 'x';
    c.rms_deg = in.NumberAt(above[i], at, "rms_deg", true);
    c.noise_deg = in.NumberAt(above[i], at, "noise_deg", true);
    c.effective_samples = in.NumberAt(above[i], at, "effective_samples", true);
    c.p_value = in.NumberAt(above[i], at, "p_value", true);
    p.above_noise.push_back(c);
  }
  p.threads = in.NumberAt(root, "", "threads");
  p.simulations = in.NumberAt(root, "", "simulations");
  p.wall_time_s = in.NumberAt(root, "", "wall_time_s", true);
  const json& recordings = in.List(root, "", "recordings");
  if (recordings.empty()) in.Fail("recordings", "is empty");
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    p.recordings.push_back(ReadRecording(in, recordings[e], e, fs::path(folder)));
  }
  return p;
}

}  // namespace ccsrm::reports::internal
