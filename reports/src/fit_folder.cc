#include "fit_folder.h"

#include <exception>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "angles_csv.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"

namespace ccsrm::reports::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

FitErrors ReadErrors(const JsonReader& in, const json& object, const std::string& key) {
  FitErrors errors;
  errors.rms_deg = in.NumberAt(object, key, "rms_deg", true);
  errors.fit_percent = in.NumberAt(object, key, "fit_percent", true);
  const json& joints = in.List(object, key, "per_joint");
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const std::string at = key + ".per_joint[" + std::to_string(j) + "]";
    FitErrors::Joint joint;
    joint.joint = static_cast<int>(in.NumberAt(joints[j], at, "joint"));
    if (joint.joint != static_cast<int>(j) + 1) in.Fail(at + ".joint", "expected joints 1, 2, ...");
    joint.rms_deg = in.Pair(in.At(joints[j], at, "rms_deg"), at + ".rms_deg", true);
    joint.fit_percent = in.Pair(in.At(joints[j], at, "fit_percent"), at + ".fit_percent", true);
    if (joints[j].contains("motion_rms_deg")) {  // absent from older fit.json files
      joint.motion_rms_deg =
          in.Pair(in.At(joints[j], at, "motion_rms_deg"), at + ".motion_rms_deg", true);
    }
    joint.samples = in.Pair(in.At(joints[j], at, "samples"), at + ".samples", false);
    errors.per_joint.push_back(joint);
  }
  return errors;
}

FitParameter ReadParameter(const JsonReader& in, const json& entry, const std::string& name) {
  const std::string at = "parameters." + name;
  FitParameter p;
  p.name = name;
  p.units = in.Text(entry, at, "units");
  p.free = in.Flag(entry, at, "free");
  p.start = in.NumberAt(entry, at, "start");
  p.value = in.NumberAt(entry, at, "value");
  if (!p.free) return p;
  p.identifiable = in.Flag(entry, at, "identifiable");
  p.at_bound = in.Flag(entry, at, "at_bound");
  p.std_error = in.NumberAt(entry, at, "std_error", true);
  const json& ci = in.At(entry, at, "ci95");
  if (!ci.is_null()) {
    const std::array<double, 2> interval = in.Pair(ci, at + ".ci95", true);
    p.ci95_lower = interval[0];
    p.ci95_upper = interval[1];
  }
  if (entry.contains("ci95_scaled_by_misfit") && !entry["ci95_scaled_by_misfit"].is_null()) {
    const std::array<double, 2> interval =
        in.Pair(entry["ci95_scaled_by_misfit"], at + ".ci95_scaled_by_misfit", true);
    p.ci95_misfit_lower = interval[0];
    p.ci95_misfit_upper = interval[1];
  }
  if (entry.contains("derivative_step_disagreement")) {
    p.derivative_step_disagreement = in.NumberAt(entry, at, "derivative_step_disagreement", true);
  }
  const std::array<double, 2> bounds = in.Pair(in.At(entry, at, "bounds"), at + ".bounds", false);
  p.lower = bounds[0];
  p.upper = bounds[1];
  return p;
}

// <name>.angles.csv: measured, fitted and residual angles of every joint.
void ReadAnglesFile(const std::string& file, FitExperiment* e) {
  AnglesCsv angles =
      ReadAnglesCsv(file, {"measured", "fitted", "residual"}, "the angles file fit.json names");
  e->time_s = std::move(angles.time_s);
  e->measured_deg = std::move(angles.series[0]);
  e->fitted_deg = std::move(angles.series[1]);
  e->residual_deg = std::move(angles.series[2]);
}

// An experiment of tracked points: its errors from fit.json, its positions
// from the points file it names.
void ReadTrackedPoints(const JsonReader& in, const json& entry, const std::string& at,
                       const fs::path& folder, FitExperiment* e) {
  e->points_file = in.Text(entry, at, "points_file");
  if (e->points_file.find('/') != std::string::npos || e->points_file == ".." ||
      e->points_file == ".") {
    in.Fail(at + ".points_file",
            "expected a file name in the fit folder, not '" + e->points_file + "'");
  }
  PointsCsv points =
      ReadPointsCsv((folder / e->points_file).string(), {"measured", "fitted", "residual"},
                    "the points file fit.json names");
  e->time_s = std::move(points.time_s);
  e->points = std::move(points.points);
  e->labels = std::move(points.labels);
  e->measured_mm = std::move(points.series[0]);
  e->fitted_mm = std::move(points.series[1]);
  e->residual_mm = std::move(points.series[2]);
  const std::string key = at + ".tracked_points";
  const json& tracked = in.Object(entry, at, "tracked_points");
  for (const char* which : {"start_errors", "errors"}) {
    const json& errors = in.List(tracked, key, which);
    if (errors.size() != e->points.size()) {
      in.Fail(key + "." + which, "must have one entry per point of " + e->points_file + " (" +
                                     std::to_string(e->points.size()) + ")");
    }
    for (std::size_t p = 0; p < errors.size(); ++p) {
      const std::string item = key + "." + which + "[" + std::to_string(p) + "]";
      const double rms = in.NumberAt(errors[p], item, "rms_mm", true);
      if (std::string(which) == "start_errors") {
        e->point_start_rms_mm.push_back(rms);
      } else {
        e->point_rms_mm.push_back(rms);
        e->point_rms_mean_removed_mm.push_back(
            in.NumberAt(errors[p], item, "rms_mean_offset_removed_mm", true));
      }
    }
  }
}

FitExperiment ReadExperiment(const JsonReader& in, const json& entry, std::size_t index,
                             const fs::path& folder) {
  const std::string at = "experiments[" + std::to_string(index) + "]";
  FitExperiment e;
  e.name = in.Text(entry, at, "name");
  e.path = in.Text(entry, at, "path");
  e.angles_from_pipeline = in.Flag(entry, at, "angles_from_pipeline");
  e.noise_deg = in.Numbers(entry, at, "noise_deg");
  e.noise_source = in.Text(entry, at, "noise_source");
  e.start = ReadErrors(in, in.At(entry, at, "start"), at + ".start");
  e.fitted = ReadErrors(in, in.At(entry, at, "fitted"), at + ".fitted");
  const json& run = in.At(entry, at, "run");
  e.run_status = in.Text(run, at + ".run", "status");
  e.run_message = in.Text(run, at + ".run", "message");
  const json& run_file = in.At(entry, at, "run_file");
  if (!run_file.is_null() && !run_file.is_string()) {
    in.Fail(at + ".run_file", "expected a file name or null");
  }
  if (run_file.is_string()) e.run_file = run_file.get<std::string>();
  if (in.At(entry, at, "angles_file").is_null()) {
    ReadTrackedPoints(in, entry, at, folder, &e);
    return e;
  }
  e.angles_file = in.Text(entry, at, "angles_file");
  // Both files sit in the fit folder: a name with a folder in it is not one
  // identify writes.
  for (const std::string* name : {&e.angles_file, &e.run_file}) {
    if (name->find('/') != std::string::npos || *name == ".." || *name == ".") {
      in.Fail(at + (name == &e.angles_file ? ".angles_file" : ".run_file"),
              "expected a file name in the fit folder, not '" + *name + "'");
    }
  }
  ReadAnglesFile((folder / e.angles_file).string(), &e);
  const std::size_t joints = e.measured_deg.shape[1];
  if (e.noise_deg.size() != joints || e.fitted.per_joint.size() != joints ||
      e.start.per_joint.size() != joints) {
    in.Fail(at, "noise_deg, start and fitted must have one entry per joint of " + e.angles_file +
                    " (" + std::to_string(joints) + ")");
  }
  e.segments = SegmentsOfRun(folder.string(), e.run_file, joints, "Experiment " + e.name,
                             "fit.json", "fitted", &e.problems);
  return e;
}

}  // namespace

std::vector<JointGroup> SegmentsOfRun(const std::string& folder, const std::string& run_file,
                                      std::size_t joints, const std::string& subject,
                                      const std::string& json_name, const std::string& run_word,
                                      std::vector<std::string>* problems) {
  const std::string path = (fs::path(folder) / run_file).string();
  std::string config_yaml;
  if (run_file.empty()) {
    problems->push_back(subject + ": " + json_name + " names no " + run_word + " run file (the " +
                        run_word +
                        " run failed), so the arm's segments are unknown: its joints are shown "
                        "in one panel.");
  } else {
    try {
      config_yaml = datasets::ReadRunFile(path).config_yaml;
    } catch (const std::exception& error) {
      problems->push_back(subject + ": the " + run_word + " run file cannot be read (" +
                          error.what() + "): its joints are shown in one panel.");
    }
  }
  if (config_yaml.empty()) {
    return {{"All joints (1–" + std::to_string(joints) + ")", 1, static_cast<int>(joints)}};
  }
  ArmFacts facts =
      ReadArmFacts(config_yaml, path + ": attribute 'config_yaml'", joints, 0, nullptr);
  for (std::string& problem : facts.problems) problems->push_back(subject + ": " + problem);
  return std::move(facts.segments);
}

bool LooksLikeFitFolder(const std::string& folder) {
  std::error_code ec;
  return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "fit.json", ec);
}

FitFolder ReadFitFolder(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) ThrowInputError(folder, "", "not a folder");
  const fs::path path = fs::path(folder) / "fit.json";
  if (!fs::is_regular_file(path, ec)) ThrowInputError(folder, "", "not a fit folder (no fit.json)");
  const std::string file = path.string();
  const json root = ReadSchemaFile(file, kFitSchema, "ccsrm identify");
  const JsonReader in(file);
  FitFolder fit;
  fit.folder = folder;
  fit.converged = in.Flag(root, "", "converged");
  if (root.contains("adequacy")) {
    const json& adequacy = in.Object(root, "", "adequacy");
    fit.adequacy_known = in.Flag(adequacy, "adequacy", "assessed");
    fit.adequate = in.Flag(adequacy, "adequacy", "adequate");
    fit.verdict = in.Text(adequacy, "adequacy", "verdict");
    fit.misfit_scale = in.NumberAt(adequacy, "adequacy", "misfit_scale");
  }
  fit.termination = in.Text(root, "", "termination");
  fit.message = in.Text(root, "", "message");
  fit.iterations = in.NumberAt(root, "", "iterations");
  fit.simulations = in.NumberAt(root, "", "simulations");
  fit.threads = in.NumberAt(root, "", "threads");
  fit.wall_time_s = in.NumberAt(root, "", "wall_time_s");
  const json& free = in.List(root, "", "free");
  for (std::size_t i = 0; i < free.size(); ++i) {
    if (!free[i].is_string()) in.Fail("free[" + std::to_string(i) + "]", "expected a name");
    fit.free.push_back(free[i].get<std::string>());
  }
  const json& parameters = in.At(root, "", "parameters");
  if (!parameters.is_object()) in.Fail("parameters", "expected an object");
  for (const std::string& name : fit.free) {
    const FitParameter p = ReadParameter(in, in.At(parameters, "parameters", name), name);
    if (!p.free) in.Fail("parameters." + name + ".free", "is false, but 'free' lists " + name);
    fit.parameters.push_back(p);
  }
  for (const auto& [name, entry] : parameters.items()) {
    const FitParameter p = ReadParameter(in, entry, name);
    if (p.free) {
      bool listed = false;
      for (const std::string& f : fit.free) listed = listed || f == name;
      if (!listed) in.Fail("parameters." + name + ".free", "is true, but 'free' does not list it");
      continue;
    }
    fit.parameters.push_back(p);
  }
  const json& correlation = in.List(root, "", "correlation");
  if (correlation.size() != fit.free.size()) {
    in.Fail("correlation",
            "expected " + std::to_string(fit.free.size()) + " rows (one per free parameter)");
  }
  for (std::size_t i = 0; i < correlation.size(); ++i) {
    const std::string at = "correlation[" + std::to_string(i) + "]";
    if (!correlation[i].is_array() || correlation[i].size() != fit.free.size()) {
      in.Fail(at, "expected " + std::to_string(fit.free.size()) + " numbers or nulls");
    }
    std::vector<double> row;
    for (std::size_t j = 0; j < correlation[i].size(); ++j) {
      row.push_back(in.Number(correlation[i][j], at + "[" + std::to_string(j) + "]", true));
    }
    fit.correlation.push_back(std::move(row));
  }
  fit.singular_values = in.Numbers(root, "", "singular_values");
  const json& directions = in.List(root, "", "unidentifiable");
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const std::string at = "unidentifiable[" + std::to_string(i) + "]";
    FitDirection d;
    d.combination = in.Text(directions[i], at, "combination");
    d.singular_value = in.NumberAt(directions[i], at, "singular_value");
    d.relative_std_error = in.NumberAt(directions[i], at, "relative_std_error", true);
    const json& components = in.At(directions[i], at, "components");
    if (!components.is_object()) in.Fail(at + ".components", "expected an object");
    for (const auto& [name, c] : components.items()) {
      d.components.push_back({name, in.Number(c, at + ".components." + name)});
    }
    fit.unidentifiable.push_back(std::move(d));
  }
  fit.rms_deg = in.NumberAt(root, "", "rms_deg", true);
  fit.rms_deg_start = in.NumberAt(root, "", "rms_deg_start", true);
  fit.fit_percent = in.NumberAt(root, "", "fit_percent", true);
  fit.errors = ReadErrors(in, in.At(root, "", "errors"), "errors");
  fit.start_errors = ReadErrors(in, in.At(root, "", "start_errors"), "start_errors");
  if (fit.errors.per_joint.size() != fit.start_errors.per_joint.size()) {
    in.Fail("start_errors.per_joint", "has not as many joints as errors.per_joint");
  }
  fit.cost_history = in.Numbers(root, "", "cost_history");
  fit.residuals = in.NumberAt(root, "", "residuals");
  fit.effective_samples = in.NumberAt(root, "", "effective_samples", true);
  fit.residual_variance = in.NumberAt(root, "", "residual_variance", true);
  const json& experiments = in.List(root, "", "experiments");
  if (experiments.empty()) in.Fail("experiments", "is empty");
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    fit.experiments.push_back(ReadExperiment(in, experiments[e], e, fs::path(folder)));
  }
  return fit;
}

}  // namespace ccsrm::reports::internal
