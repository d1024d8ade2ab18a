// The prediction summary as text, JSON (ccsrm-prediction/1) and a folder.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "angles_table.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/identify/prediction.h"
#include "ccsrm/sim_io/run_file.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

// JSON has no NaN: unknown numbers are null.
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json Pair(const std::array<double, 2>& v) { return {Number(v[0]), Number(v[1])}; }

nlohmann::json ErrorsJson(const PredictionErrors& e) {
  const ChannelErrors& c = e.channels;
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < c.rms_deg.size(); ++j) {
    const double noise = e.noise_deg[j];
    joints.push_back(
        {{"joint", j + 1},
         {"rms_deg", Pair(c.rms_deg[j])},
         {"max_abs_deg", Pair(e.max_abs_deg[j])},
         {"noise_deg", Number(noise)},
         {"rms_over_noise", {Number(c.rms_deg[j][0] / noise), Number(c.rms_deg[j][1] / noise)}},
         {"fit_percent", Pair(c.fit_percent[j])},
         {"motion_rms_deg", Pair(c.motion_rms_deg[j])},
         {"samples", {c.samples[j][0], c.samples[j][1]}}});
  }
  return {{"rms_deg", Number(c.rms_deg_overall)},
          {"max_abs_deg", Number(e.max_abs_deg_overall)},
          {"weighted_rms", Number(e.weighted_rms)},
          {"fit_percent", Number(c.fit_percent_overall)},
          {"per_joint", joints},
          {"axes", {"theta_x", "theta_y"}}};
}

std::string EffectList(const std::vector<std::string>& effects) {
  return effects.empty() ? "none" : Join(effects);
}

}  // namespace

std::string PredictionSummary::BriefReport() const {
  // Without measured angles: the first recording's first tracked point.
  std::string size = "RMS " + Cell("%.4f", errors.channels.rms_deg_overall) + " deg, max " +
                     Cell("%.4f", errors.max_abs_deg_overall) + " deg";
  if (!std::isfinite(errors.channels.rms_deg_overall) && !recordings.empty() &&
      !recordings.front().points.rms_mm.empty()) {
    const RecordingPrediction& r = recordings.front();
    size = r.tracked_points[0].name + " RMS " + Cell("%.3f", r.points.rms_mm[0]) +
           " mm (mean offset removed " + Cell("%.3f", r.points.rms_mean_removed_mm[0]) + " mm)";
  }
  char text[640];
  std::snprintf(text, sizeof(text),
                "prediction of %zu recording%s with %s (effects: %s): %s, "
                "weighted RMS %s (1 = the noise floor); %zu of %zu channels above the noise%s",
                recordings.size(), recordings.size() == 1 ? "" : "s", model.source.c_str(),
                EffectList(effects).c_str(), size.c_str(),
                Cell("%.3f", errors.weighted_rms).c_str(), adequacy.above_noise.size(),
                adequacy.channels,
                completed ? "" : (" (a run did not complete: " + message + ")").c_str());
  return text;
}

std::string PredictionSummary::FullReport() const {
  std::ostringstream out;
  out << adequacy.Verdict()
      << (adequacy.assessed && !adequacy.adequate() ? "; `ccsrm loop` looks for what it lacks" : "")
      << "\n";
  out << BriefReport() << "\n";
  out << "  model: " << model.source << " (" << model.kind << "), " << model.values.size()
      << " parameter values";
  if (!model.free.empty()) {
    out << ", fitted:";
    for (const std::string& name : model.free) out << " " << name;
  }
  for (const PredictionModel::Effects& e : model.effects) out << "; effects from " << e.file;
  out << "\n  " << simulations << " simulations on " << threads << " thread"
      << (threads == 1 ? "" : "s") << ", " << Cell("%.1f", wall_time_s) << " s\n\n";
  const PredictionErrors& e = errors;
  const bool angles = std::isfinite(e.channels.rms_deg_overall);
  if (angles) {
    out << "  joint   RMS θx [deg]   RMS θy [deg]   max θx [deg]   max θy [deg]   noise [deg]   "
           "RMS/noise θx  RMS/noise θy\n";
  }
  for (std::size_t j = 0; angles && j < e.channels.rms_deg.size(); ++j) {
    char line[256];
    std::snprintf(line, sizeof(line), "  %5zu   %-14s %-14s %-14s %-14s %-13s %-13s %s\n", j + 1,
                  Cell("%.4f", e.channels.rms_deg[j][0]).c_str(),
                  Cell("%.4f", e.channels.rms_deg[j][1]).c_str(),
                  Cell("%.4f", e.max_abs_deg[j][0]).c_str(),
                  Cell("%.4f", e.max_abs_deg[j][1]).c_str(), Cell("%.4f", e.noise_deg[j]).c_str(),
                  Cell("%.2f", e.channels.rms_deg[j][0] / e.noise_deg[j]).c_str(),
                  Cell("%.2f", e.channels.rms_deg[j][1] / e.noise_deg[j]).c_str());
    out << line;
  }
  out << "\n";
  for (const RecordingPrediction& r : recordings) {
    if (!r.points.rms_mm.empty()) {
      out << "  " << r.name << ": weighted RMS " << Cell("%.3f", r.errors.weighted_rms) << ", "
          << r.noise_source << (r.run.summary.completed() ? "" : ", run: " + r.run.summary.message)
          << "\n"
          << internal::TrackedPointsText(r.tracked_points, nullptr, r.points,
                                         r.placed_in_capture_frame ? &r.placement : nullptr,
                                         r.placement_from_fit);
      continue;
    }
    double noise = 0.0;
    for (double s : r.errors.noise_deg) noise += s / static_cast<double>(r.errors.noise_deg.size());
    out << "  " << r.name << ": RMS " << Cell("%.4f", r.errors.channels.rms_deg_overall)
        << " deg, max " << Cell("%.4f", r.errors.max_abs_deg_overall) << " deg, weighted RMS "
        << Cell("%.3f", r.errors.weighted_rms) << ", noise " << Cell("%.4f", noise) << " deg ("
        << r.noise_source << ")"
        << (r.angles_from_pipeline ? ", angles from the mocap pipeline" : "")
        << (r.run.summary.completed() ? "" : ", run: " + r.run.summary.message) << "\n";
  }
  char rule[200];
  std::snprintf(rule, sizeof(rule),
                "RMS above %.3g times its noise, and beyond chance: p < %.3g over the %zu channels",
                adequacy.above_noise_ratio, adequacy.significance, adequacy.channels);
  const std::vector<ChannelAboveNoise>& above_noise = adequacy.above_noise;
  if (above_noise.empty()) {
    out << "  no channel stands above the noise (" << rule
        << "): the model predicts these recordings to the noise floor\n";
  } else {
    out << "  above the noise (" << rule << "):";
    for (std::size_t k = 0; k < above_noise.size(); ++k) {
      const ChannelAboveNoise& c = above_noise[k];
      if (k == 16) {
        out << " ... and " << above_noise.size() - 16 << " more";
        break;
      }
      out << (k == 0 ? " " : "; ") << c.recording << " " << Describe(c) << " ("
          << Cell("%.1f", c.rms_deg / c.noise_deg) << "x)";
    }
    out << "\n";
  }
  return out.str();
}

nlohmann::json ToJson(const PredictionSummary& s) {
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [name, value] : s.model.values) values[name] = value;
  nlohmann::json recordings = nlohmann::json::array();
  for (const RecordingPrediction& r : s.recordings) {
    recordings.push_back(
        {{"name", r.name},
         {"path", r.path},
         {"angles_from_pipeline", r.angles_from_pipeline},
         {"noise_deg", r.errors.noise_deg},
         {"noise_source", r.noise_source},
         {"errors", ErrorsJson(r.errors)},
         {"tracked_points",
          r.tracked_points.empty()
              ? nlohmann::json(nullptr)
              : internal::TrackedPointsJson(r.tracked_points, nullptr, r.points,
                                            r.placed_in_capture_frame ? &r.placement : nullptr,
                                            r.placement_from_fit)},
         {"run",
          {{"status", r.run.summary.completed() ? "completed" : "failed"},
           {"message", r.run.summary.message},
           {"wall_time_s", r.run.summary.wall_time_s},
           {"real_time_factor", r.run.summary.real_time_factor}}}});
  }
  nlohmann::json effects_files = nlohmann::json::array();
  for (const PredictionModel::Effects& e : s.model.effects) effects_files.push_back(e.file);
  const nlohmann::json adequacy = ToJson(s.adequacy);
  return {{"schema", "ccsrm-prediction/1"},
          {"model",
           {{"source", s.model.source},
            {"kind", s.model.kind},
            {"free", s.model.free},
            {"values", values},
            {"effects_files", effects_files}}},
          {"effects", s.effects},
          {"completed", s.completed},
          {"message", s.message},
          {"rms_deg", Number(s.errors.channels.rms_deg_overall)},
          {"max_abs_deg", Number(s.errors.max_abs_deg_overall)},
          {"weighted_rms", Number(s.errors.weighted_rms)},
          {"errors", ErrorsJson(s.errors)},
          {"verdict", adequacy["verdict"]},
          {"adequate", adequacy["adequate"]},
          {"above_noise_ratio", s.adequacy.above_noise_ratio},
          {"significance", s.adequacy.significance},
          {"channels", s.adequacy.channels},
          {"worst_ratio", adequacy["worst_ratio"]},
          {"above_noise", adequacy["above_noise"]},
          {"threads", s.threads},
          {"simulations", s.simulations},
          {"wall_time_s", Number(s.wall_time_s)},
          {"recordings", recordings}};
}

std::vector<std::string> WritePredictionDirectory(const PredictionSummary& summary,
                                                  const std::vector<Experiment>& recordings,
                                                  const std::string& directory) {
  CCSRM_CHECK(summary.recordings.size() == recordings.size());
  namespace fs = std::filesystem;
  AtomicOutputDirectory out(directory);
  const fs::path tmp(out.temp_path());
  std::vector<std::string> written;
  std::vector<std::string> names;
  for (const RecordingPrediction& r : summary.recordings) names.push_back(r.name);
  const std::vector<std::string> stems = internal::OutputStems(names);
  nlohmann::json json = ToJson(summary);
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    const RecordingPrediction& r = summary.recordings[e];
    internal::WriteRecordingOutputs(recordings[e], r.name, r.run, r.parameters, r.predicted_rad,
                                    "predicted", stems[e], ".pred.h5", out.temp_path(), directory,
                                    &json["recordings"][e], &written);
  }
  WriteTextFileAtomically((tmp / "pred.json").string(), json.dump(2) + "\n");
  written.insert(written.begin(), (fs::path(directory) / "pred.json").string());
  out.Commit();
  return written;
}

}  // namespace ccsrm::identify
