#include "loop_folder.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "angles_csv.h"
#include "ccsrm/common/error.h"

namespace ccsrm::reports::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// `pooled` of a diagnostics object: {signal: {value, band, significant}}.
std::vector<LoopSignal> ReadPooled(const JsonReader& in, const json& object,
                                   const std::string& key) {
  std::vector<LoopSignal> out;
  for (const auto& [name, entry] : in.Object(object, key, "pooled").items()) {
    const std::string at = key + ".pooled." + name;
    out.push_back({name, in.NumberAt(entry, at, "value", true),
                   in.NumberAt(entry, at, "band", true), in.Flag(entry, at, "significant")});
  }
  return out;
}

// A channel's axis: x or y of a joint, x, y or z of a tracked point.
int ReadAxis(const JsonReader& in, const json& object, const std::string& at, bool point) {
  const std::string axis = in.Text(object, at, "axis");
  const std::string allowed = point ? "xyz" : "xy";
  const std::size_t k = axis.size() == 1 ? allowed.find(axis[0]) : std::string::npos;
  if (k == std::string::npos) {
    in.Fail(at + ".axis", "is '" + axis + "', expected " + (point ? "x, y or z" : "x or y"));
  }
  return static_cast<int>(k);
}

// A channel's tracked point ('point', absent in files written before it):
// empty for a joint's axis.
std::string ReadPoint(const JsonReader& in, const json& object, const std::string& at) {
  return object.contains("point") ? in.Text(object, at, "point") : std::string();
}

// A diagnostics object (`object`, at `key`). Its numbers are written as
// computed, so a NaN comes out null: every number may be null.
LoopDiagnostics ReadDiagnostics(const JsonReader& in, const json& object, const std::string& key) {
  LoopDiagnostics d;
  d.rms_deg = in.NumberAt(object, key, "rms_deg", true);
  d.effective_samples = in.NumberAt(object, key, "effective_samples", true);
  d.pooled = ReadPooled(in, object, key);
  d.lags_s = in.Numbers(object, key, "lags_s", true);
  const std::string xc = key + ".cross_correlation";
  const json& curves = in.Object(object, key, "cross_correlation");
  for (const auto& item : curves.items()) {
    const std::string& signal = item.key();
    std::vector<double> values = in.Numbers(curves, xc, signal, true);
    if (values.size() != d.lags_s.size()) {
      in.Fail(xc + "." + signal, "has " + std::to_string(values.size()) +
                                     " values, expected one per lag (" +
                                     std::to_string(d.lags_s.size()) + ")");
    }
    d.cross_correlation.emplace_back(signal, std::move(values));
  }
  const json& experiments = in.List(object, key, "experiments");
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const std::string at = JsonReader::Index(key + ".experiments", e);
    LoopDiagnostics::Experiment x;
    x.name = in.Text(experiments[e], at, "name");
    x.rms_deg = in.NumberAt(experiments[e], at, "rms_deg", true);
    x.lag_s = in.NumberAt(experiments[e], at, "lag_s", true);
    x.lag_explained = in.NumberAt(experiments[e], at, "lag_explained", true);
    const json& phases = in.List(experiments[e], at, "phases");
    for (std::size_t p = 0; p < phases.size(); ++p) {
      const std::string pat = JsonReader::Index(at + ".phases", p);
      x.phases.push_back({in.Text(phases[p], pat, "name"),
                          in.NumberAt(phases[p], pat, "start_s", true),
                          in.NumberAt(phases[p], pat, "end_s", true)});
    }
    d.experiments.push_back(std::move(x));
  }
  const json& channels = in.List(object, key, "channels");
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const std::string at = JsonReader::Index(key + ".channels", c);
    const json& ch = channels[c];
    LoopDiagnostics::Channel x;
    x.experiment = in.Text(ch, at, "experiment");
    x.joint = static_cast<int>(in.NumberAt(ch, at, "joint"));
    x.point = ReadPoint(in, ch, at);
    x.axis = ReadAxis(in, ch, at, !x.point.empty());
    x.samples = in.NumberAt(ch, at, "samples", true);
    x.rms_deg = in.NumberAt(ch, at, "rms_deg", true);
    x.mean_deg = in.NumberAt(ch, at, "mean_deg", true);
    x.noise_deg = in.NumberAt(ch, at, "noise_deg", true);
    x.lags_outside_band = in.NumberAt(ch, at, "lags_outside_band", true);
    x.autocorrelation_time = in.NumberAt(ch, at, "autocorrelation_time", true);
    x.effective_samples = in.NumberAt(ch, at, "effective_samples", true);
    x.hold_drift_degps = in.NumberAt(ch, at, "hold_drift_degps", true);
    x.hysteresis_deg2 = in.NumberAt(ch, at, "hysteresis_deg2", true);
    d.channels.push_back(std::move(x));
  }
  return d;
}

// One estimate ({value, std_error, ci95, identifiable, free, units}).
LoopEstimate ReadEstimate(const JsonReader& in, const json& entry, const std::string& at,
                          const std::string& name) {
  LoopEstimate e;
  e.name = name;
  e.value = in.NumberAt(entry, at, "value", true);
  e.std_error = in.NumberAt(entry, at, "std_error", true);
  const std::array<double, 2> ci = in.Pair(in.At(entry, at, "ci95"), at + ".ci95", true);
  e.ci95_lower = ci[0];
  e.ci95_upper = ci[1];
  e.identifiable = in.Flag(entry, at, "identifiable");
  e.free = in.Flag(entry, at, "free");
  e.units = in.Text(entry, at, "units");
  return e;
}

// Estimates by name.
std::vector<LoopEstimate> ReadEstimates(const JsonReader& in, const json& parent,
                                        const std::string& parent_key, const std::string& key) {
  std::vector<LoopEstimate> out;
  const std::string path = JsonReader::Join(parent_key, key);
  for (const auto& [name, entry] : in.Object(parent, parent_key, key).items()) {
    out.push_back(ReadEstimate(in, entry, path + "." + name, name));
  }
  return out;
}

std::vector<LoopSignal> ReadEvidenceList(const JsonReader& in, const json& object,
                                         const std::string& at) {
  std::vector<LoopSignal> out;
  const json& list = in.List(object, at, "evidence");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string e = JsonReader::Index(at + ".evidence", i);
    out.push_back({in.Text(list[i], e, "signal"), in.NumberAt(list[i], e, "value", true),
                   in.NumberAt(list[i], e, "band", true), in.Flag(list[i], e, "significant")});
  }
  return out;
}

LoopCandidate ReadCandidate(const JsonReader& in, const json& c, const std::string& at) {
  LoopCandidate x;
  x.name = in.Text(c, at, "name");
  x.score = in.NumberAt(c, at, "score", true);
  x.p_value = in.NumberAt(c, at, "p_value", true);
  x.significant = in.Flag(c, at, "significant");
  x.parameters = in.Texts(c, at, "parameters");
  for (const auto& [name, value] : in.Object(c, at, "linearised").items()) {
    x.linearised.emplace_back(name, in.Number(value, at + ".linearised." + name, true));
  }
  x.evidence = ReadEvidenceList(in, c, at);
  x.refitted = in.Flag(c, at, "refitted");
  x.delta_bic = in.NumberAt(c, at, "delta_bic", true);
  x.rms_deg = in.NumberAt(c, at, "rms_deg", true);
  x.holdout_rms_deg = in.NumberAt(c, at, "holdout_rms_deg", true);
  x.holdout_improved = in.Flag(c, at, "holdout_improved");
  x.size_significant = in.Flag(c, at, "size_significant");
  x.termination = in.Text(c, at, "termination");
  x.estimates = ReadEstimates(in, c, at, "estimates");
  x.accepted = in.Flag(c, at, "accepted");
  x.reason = in.Text(c, at, "reason");
  return x;
}

LoopRound ReadRound(const JsonReader& in, const json& r, std::size_t index) {
  const std::string at = JsonReader::Index("rounds", index);
  LoopRound x;
  x.index = static_cast<int>(in.NumberAt(r, at, "round"));
  if (x.index != static_cast<int>(index) + 1) in.Fail(at + ".round", "expected rounds 1, 2, ...");
  x.effects_on = in.Texts(r, at, "effects_on");
  x.rms_deg = in.NumberAt(r, at, "rms_deg", true);
  x.holdout_rms_deg = in.NumberAt(r, at, "holdout_rms_deg", true);
  x.evidence = ReadDiagnostics(in, in.Object(r, at, "evidence"), at + ".evidence");
  const json& candidates = in.List(r, at, "candidates");
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    x.candidates.push_back(
        ReadCandidate(in, candidates[c], JsonReader::Index(at + ".candidates", c)));
  }
  const json& winner = in.At(r, at, "winner");
  if (!winner.is_null() && !winner.is_string()) in.Fail(at + ".winner", "expected a name or null");
  if (winner.is_string()) x.winner = winner.get<std::string>();
  x.tie = in.Texts(r, at, "tie");
  x.decision = in.Text(r, at, "decision");
  if (r.contains("backward")) {
    const json& backward = in.List(r, at, "backward");
    for (std::size_t k = 0; k < backward.size(); ++k) {
      const std::string bat = JsonReader::Index(at + ".backward", k);
      const json& b = backward[k];
      LoopBackwardCheck c;
      c.name = in.Text(b, bat, "name");
      c.parameters = in.Texts(b, bat, "parameters");
      c.size_significant = in.Flag(b, bat, "size_significant");
      c.delta_chi2_zeroed = in.NumberAt(b, bat, "delta_chi2_zeroed", true);
      c.refitted = in.Flag(b, bat, "refitted");
      c.delta_bic_keep = in.NumberAt(b, bat, "delta_bic_keep", true);
      c.rms_deg_without = in.NumberAt(b, bat, "rms_deg_without", true);
      c.holdout_rms_deg_without = in.NumberAt(b, bat, "holdout_rms_deg_without", true);
      c.taken_back = in.Flag(b, bat, "taken_back");
      c.reason = in.Text(b, bat, "reason");
      x.backward.push_back(std::move(c));
    }
  }
  return x;
}

// {rms_deg, joints: [{joint, rms_deg: [x, y]}]}, or null where `nullable`.
std::optional<LoopErrors> ReadErrors(const JsonReader& in, const json& root, const std::string& key,
                                     bool nullable) {
  const json& object = in.At(root, "", key);
  if (object.is_null() && nullable) return std::nullopt;
  if (!object.is_object())
    in.Fail(key, nullable ? "expected an object or null" : "expected an object");
  LoopErrors errors;
  errors.rms_deg = in.NumberAt(object, key, "rms_deg", true);
  const json& joints = in.List(object, key, "joints");
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const std::string at = JsonReader::Index(key + ".joints", j);
    if (static_cast<int>(in.NumberAt(joints[j], at, "joint")) != static_cast<int>(j) + 1) {
      in.Fail(at + ".joint", "expected joints 1, 2, ...");
    }
    errors.joint_rms_deg.push_back(in.Pair(in.At(joints[j], at, "rms_deg"), at + ".rms_deg", true));
  }
  return errors;
}

LoopFitRun ReadFitRun(const JsonReader& in, const json& root, const std::string& key) {
  const json& object = in.Object(root, "", key);
  return {in.Text(object, key, "termination"), in.NumberAt(object, key, "iterations")};
}

// declared/ or final/, when the loop wrote it.
std::optional<FitFolder> ReadModelFolder(const fs::path& folder, const std::string& which,
                                         std::vector<std::string>* problems) {
  std::error_code ec;
  if (!fs::exists(folder, ec)) {
    problems->push_back("The loop folder holds no " + folder.filename().string() + "/ (the " +
                        which + " model's fit folder): its residuals are not shown.");
    return std::nullopt;
  }
  return ReadFitFolder(folder.string());
}

// A held-out experiment's points of a loop over tracked points: the
// declared and the final model's residuals, from their two files.
void ReadHoldoutPoints(const std::string& folder, const std::string& stem, LoopHoldout* h,
                       std::vector<std::string>* problems) {
  std::error_code ec;
  std::vector<PointsCsv> read;
  for (const char* kind : {"declared", "final"}) {
    const fs::path csv = fs::path(folder) / "holdout" / (stem + "." + kind + ".points.csv");
    if (!fs::exists(csv, ec)) {
      problems->push_back("The loop folder holds no holdout/" + stem + "." + kind +
                          ".points.csv: the residuals of held-out experiment " + h->name +
                          " are not shown.");
      return;
    }
    read.push_back(ReadPointsCsv(csv.string(), {"measured", kind, "residual"},
                                 "the held-out points of experiment " + h->name));
  }
  if (read[0].time_s != read[1].time_s || read[0].points != read[1].points) {
    problems->push_back("holdout/" + stem +
                        ".declared.points.csv and .final.points.csv hold "
                        "other frames or points: the residuals of held-out experiment " +
                        h->name + " are not shown.");
    return;
  }
  h->file = (fs::path(folder) / "holdout" / (stem + ".declared.points.csv")).string();
  h->time_s = std::move(read[0].time_s);
  h->points = std::move(read[0].points);
  h->declared_residual_mm = std::move(read[0].series[2]);
  h->final_residual_mm = std::move(read[1].series[2]);
}

}  // namespace

bool LooksLikeLoopFolder(const std::string& folder) {
  std::error_code ec;
  return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "loop.json", ec);
}

LoopFolder ReadLoopFolder(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) ThrowInputError(folder, "", "not a folder");
  const fs::path path = fs::path(folder) / "loop.json";
  if (!fs::is_regular_file(path, ec)) {
    ThrowInputError(folder, "", "not a loop folder (no loop.json)");
  }
  const std::string file = path.string();
  const json root = ReadSchemaFile(file, kLoopSchema, "ccsrm loop");
  const JsonReader in(file);
  LoopFolder loop;
  loop.folder = folder;
  const json& data = in.List(root, "", "data");
  for (std::size_t i = 0; i < data.size(); ++i) {
    const std::string at = JsonReader::Index("data", i);
    LoopFolder::Data d;
    d.name = in.Text(data[i], at, "name");
    d.path = in.Text(data[i], at, "path");
    const std::string role = in.Text(data[i], at, "role");
    if (role != "training" && role != "holdout") {
      in.Fail(at + ".role", "is '" + role + "', expected training or holdout");
    }
    d.holdout = role == "holdout";
    // The name is a file name in holdout/.
    if (d.name.find('/') != std::string::npos || d.name == "." || d.name == "..") {
      in.Fail(at + ".name", "expected an experiment name, not '" + d.name + "'");
    }
    loop.data.push_back(std::move(d));
  }
  loop.declared_free = in.Texts(root, "", "declared_free");
  const json& rounds = in.List(root, "", "rounds");
  for (std::size_t r = 0; r < rounds.size(); ++r)
    loop.rounds.push_back(ReadRound(in, rounds[r], r));
  loop.added_effects = in.Texts(root, "", "added_effects");
  if (root.contains("declared_corrections")) {
    const json& corrections = in.List(root, "", "declared_corrections");
    for (std::size_t k = 0; k < corrections.size(); ++k) {
      const std::string at = JsonReader::Index("declared_corrections", k);
      const json& c = corrections[k];
      LoopDeclaredCorrection d;
      d.parameter = in.Text(c, at, "parameter");
      d.config_key = in.Text(c, at, "config_key");
      d.sentence = in.Text(c, at, "sentence");
      d.declared = in.NumberAt(c, at, "declared", true);
      d.corrected = in.NumberAt(c, at, "corrected", true);
      d.relative = in.NumberAt(c, at, "relative", true);
      d.relative_std_error = in.NumberAt(c, at, "relative_std_error", true);
      d.relative_ci95 = in.Pair(in.At(c, at, "relative_ci95"), at + ".relative_ci95", true);
      d.indistinguishable = in.Texts(c, at, "indistinguishable");
      loop.declared_corrections.push_back(std::move(d));
    }
  }
  if (root.contains("discovered_terms")) {
    const json& moments = in.List(root, "", "discovered_terms");
    for (std::size_t k = 0; k < moments.size(); ++k) {
      const std::string at = JsonReader::Index("discovered_terms", k);
      const json& m = moments[k];
      LoopDiscoveredMoment d;
      d.segment = static_cast<int>(in.NumberAt(m, at, "segment", false));
      d.joints = in.Pair(in.At(m, at, "joints"), at + ".joints", false);
      d.axis = in.Text(m, at, "axis");
      d.formula = in.Text(m, at, "formula");
      const json& terms = in.List(m, at, "terms");
      for (std::size_t t = 0; t < terms.size(); ++t) {
        const std::string tat = JsonReader::Index(at + ".terms", t);
        LoopDiscoveredMoment::Term term;
        term.term = in.Text(terms[t], tat, "term");
        term.formula = in.Text(terms[t], tat, "formula");
        term.units = in.Text(terms[t], tat, "units");
        term.estimate = ReadEstimate(in, in.At(terms[t], tat, "estimate"), tat + ".estimate",
                                     in.Text(terms[t], tat, "parameter"));
        d.terms.push_back(std::move(term));
      }
      loop.discovered_terms.push_back(std::move(d));
    }
  }
  loop.parameters = ReadEstimates(in, root, "", "parameters");
  if (root.contains("unit")) {
    loop.unit = in.Text(root, "", "unit");
    if (loop.unit != "deg" && loop.unit != "mm") {
      in.Fail("unit", "is '" + loop.unit + "', expected deg or mm");
    }
  }
  loop.rms_before_deg = in.NumberAt(root, "", "rms_before_deg", true);
  loop.rms_after_deg = in.NumberAt(root, "", "rms_after_deg", true);
  loop.holdout_rms_before_deg = in.NumberAt(root, "", "holdout_rms_before_deg", true);
  loop.holdout_rms_after_deg = in.NumberAt(root, "", "holdout_rms_after_deg", true);
  loop.before = *ReadErrors(in, root, "before", false);
  loop.after = *ReadErrors(in, root, "after", false);
  loop.holdout_before = ReadErrors(in, root, "holdout_before", true);
  loop.holdout_after = ReadErrors(in, root, "holdout_after", true);
  loop.noise_floor_deg = in.NumberAt(root, "", "noise_floor_deg", true);
  const json& unexplained = in.List(root, "", "unexplained");
  for (std::size_t u = 0; u < unexplained.size(); ++u) {
    const std::string at = JsonReader::Index("unexplained", u);
    const json& entry = unexplained[u];
    const std::string point = ReadPoint(in, entry, at);
    loop.unexplained.push_back(
        {in.Text(entry, at, "experiment"), static_cast<int>(in.NumberAt(entry, at, "joint")),
         ReadAxis(in, entry, at, !point.empty()), point, in.NumberAt(entry, at, "rms_deg", true),
         in.NumberAt(entry, at, "noise_deg", true), in.Text(entry, at, "worst_phase"),
         in.NumberAt(entry, at, "worst_phase_rms_deg", true)});
  }
  loop.final_evidence =
      ReadDiagnostics(in, in.Object(root, "", "final_evidence"), "final_evidence");
  loop.conclusion = in.Text(root, "", "conclusion");
  loop.simulations = in.NumberAt(root, "", "simulations");
  loop.wall_time_s = in.NumberAt(root, "", "wall_time_s", true);
  loop.threads = in.NumberAt(root, "", "threads");
  loop.declared_fit = ReadFitRun(in, root, "declared_fit");
  loop.final_fit = ReadFitRun(in, root, "final_fit");

  loop.declared = ReadModelFolder(fs::path(folder) / "declared", "declared", &loop.problems);
  loop.final_model = ReadModelFolder(fs::path(folder) / "final", "final", &loop.problems);
  std::size_t k = 0;
  for (const LoopFolder::Data& d : loop.data) {
    if (!d.holdout) continue;
    ++k;
    LoopHoldout h;
    h.name = d.name;
    h.path = d.path;
    // ccsrm loop names an unnamed experiment by its place among the held-out.
    const std::string stem = d.name.empty() ? "holdout" + std::to_string(k) : d.name;
    if (loop.unit == "mm") {
      ReadHoldoutPoints(folder, stem, &h, &loop.problems);
      if (!h.file.empty()) loop.holdout.push_back(std::move(h));
      continue;
    }
    const fs::path csv = fs::path(folder) / "holdout" / (stem + ".angles.csv");
    if (!fs::exists(csv, ec)) {
      loop.problems.push_back("The loop folder holds no holdout/" + stem +
                              ".angles.csv: the residuals of held-out experiment " + d.name +
                              " are not shown.");
      continue;
    }
    h.file = csv.string();
    AnglesCsv angles = ReadAnglesCsv(h.file, {"measured", "declared", "final"},
                                     "the held-out angles of experiment " + d.name);
    h.time_s = std::move(angles.time_s);
    h.measured_deg = std::move(angles.series[0]);
    h.declared_deg = std::move(angles.series[1]);
    h.final_deg = std::move(angles.series[2]);
    loop.holdout.push_back(std::move(h));
  }
  return loop;
}

}  // namespace ccsrm::reports::internal
