// The loop's summary as text, JSON (ccsrm-loop/1) and a loop folder.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "angles_table.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/identify/loop.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / M_PI;

nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json Optional(const std::optional<double>& value) {
  return value ? Number(*value) : nlohmann::json(nullptr);
}

nlohmann::json PerJoint(const ChannelErrors& e) {
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < e.rms_deg.size(); ++j) {
    joints.push_back(
        {{"joint", j + 1}, {"rms_deg", {Number(e.rms_deg[j][0]), Number(e.rms_deg[j][1])}}});
  }
  return {{"rms_deg", Number(e.rms_deg_overall)}, {"joints", joints}};
}

nlohmann::json Estimate(const ParameterEstimate& p) {
  return {{"value", Number(p.value)},
          {"std_error", Number(p.std_error)},
          {"ci95", {Number(p.ci95_lower), Number(p.ci95_upper)}},
          {"identifiable", p.identifiable},
          {"free", p.free},
          {"units", p.units}};
}

nlohmann::json Evidence(const std::vector<SignalEvidence>& evidence) {
  nlohmann::json out = nlohmann::json::array();
  for (const SignalEvidence& s : evidence) {
    out.push_back({{"signal", s.signal},
                   {"value", Number(s.value)},
                   {"band", Number(s.band)},
                   {"significant", s.significant()}});
  }
  return out;
}

// A value in SI units with its unit, the wrap angle in degrees.
std::string WithUnit(double value, const std::string& key) {
  const bool angle = key.find("_deg") != std::string::npos;
  const std::string unit = key.substr(key.rfind('_') + 1);
  return Cell("%.4g", angle ? value * kDeg : value) + " " + unit;
}

// The backward step's check of an earlier addition (loop.json rounds[].backward).
nlohmann::json Backward(const BackwardCheck& b, int round) {
  return {{"round", round},
          {"name", b.name},
          {"parameters", b.parameters},
          {"size_significant", b.size_significant},
          {"delta_chi2_zeroed", Number(b.delta_chi2_zeroed)},
          {"refitted", b.refitted},
          {"delta_bic_keep", Number(b.delta_bic_keep)},
          {"rms_deg_without", Number(b.rms_deg_without)},
          {"holdout_rms_deg_without", Optional(b.holdout_rms_deg_without)},
          {"taken_back", b.taken_back},
          {"reason", b.reason}};
}

}  // namespace

std::string DeclaredCorrection::Sentence() const {
  std::string out = "the declared " + label + " (" + config_key + " = " +
                    WithUnit(declared, config_key) + ") is off by " + (delta() >= 0.0 ? "+" : "") +
                    WithUnit(delta(), config_key);
  if (identifiable && std::isfinite(relative_std_error)) {
    out += " ± " + WithUnit(std::abs(declared) * relative_std_error, config_key);
  } else {
    out += " (its error not identifiable)";
  }
  out += " (" + Cell("%+.2f", 100.0 * relative) + " %)";
  if (!indistinguishable.empty()) {
    out +=
        ", or a combination with " + Join(indistinguishable) + " that the data cannot tell apart";
  }
  return out;
}

namespace {

nlohmann::json CandidateJson(const CandidateResult& c) {
  using nlohmann::json;
  json est = json::object();
  for (const auto& [name, e] : c.estimates) est[name] = Estimate(e);
  json path = json::array();
  for (const CandidateResult::TermSupport& t : c.term_path) {
    path.push_back({{"parameters", t.parameters},
                    {"delta_chi2_eff", Number(t.delta_chi2_eff)},
                    {"delta_bic", Number(t.delta_bic)}});
  }
  json out = {{"name", c.name},
              {"kind", c.kind},
              {"indistinguishable", c.indistinguishable},
              {"excess_share", c.refitted ? Number(c.excess_share) : json(nullptr)},
              {"mean_square_after", c.refitted ? Number(c.mean_square_after) : json(nullptr)},
              {"partial", c.partial},
              {"score", Number(c.score)},
              {"p_value", Number(c.p_value)},
              {"significant", c.significant},
              {"parameters", c.parameters},
              {"linearised", c.linearised},
              {"evidence", Evidence(c.evidence)},
              {"refitted", c.refitted},
              {"cost_without", c.refitted ? Number(c.cost_without) : json(nullptr)},
              {"delta_bic", c.refitted ? Number(c.delta_bic) : json(nullptr)},
              {"holdout_rms_without_deg", Optional(c.holdout_rms_without_deg)},
              {"rms_deg", c.refitted ? Number(c.rms_deg) : json(nullptr)},
              {"holdout_rms_deg", Optional(c.holdout_rms_deg)},
              {"holdout_improved", c.holdout_improved},
              {"size_significant", c.size_significant},
              {"termination", c.termination},
              {"estimates", est},
              {"simulations", c.simulations},
              {"accepted", c.accepted},
              {"reason", c.reason}};
  if (!c.term_path.empty()) out["term_path"] = path;
  return out;
}

nlohmann::json RoundJson(const LoopRound& r) {
  using nlohmann::json;
  json cands = json::array();
  for (const CandidateResult& c : r.candidates) cands.push_back(CandidateJson(c));
  json out = {{"round", r.index},
              {"effects_on", r.effects_on},
              {"rms_deg", Number(r.rms_deg)},
              {"holdout_rms_deg", Optional(r.holdout_rms_deg)},
              {"evidence", ToJson(r.evidence)},
              {"candidates", cands},
              {"winner", r.winner.empty() ? json(nullptr) : json(r.winner)},
              {"tie", r.tie},
              {"decision", r.decision}};
  if (!r.discovery.empty()) out["discovery"] = r.discovery;
  // The backward step (issue 28): every earlier addition checked, and the
  // one taken back (null: none).
  json backward = json::array();
  json taken = nullptr;
  for (const BackwardCheck& b : r.backward) {
    backward.push_back(Backward(b, r.index));
    if (b.taken_back) taken = backward.back();
  }
  out["backward"] = backward;
  out["taken_back"] = taken;
  return out;
}

nlohmann::json CorrectionJson(const DeclaredCorrection& d) {
  return {{"parameter", d.parameter},
          {"config_key", d.config_key},
          {"declared", Number(d.declared)},
          {"corrected", Number(d.corrected())},
          {"delta", Number(d.delta())},
          {"relative", Number(d.relative)},
          {"relative_std_error", Number(d.relative_std_error)},
          {"relative_ci95", {Number(d.relative_ci95_lower), Number(d.relative_ci95_upper)}},
          {"identifiable", d.identifiable},
          {"indistinguishable", d.indistinguishable},
          {"sentence", d.Sentence()}};
}

nlohmann::json DiscoveredJson(const DiscoveredMoment& m) {
  using nlohmann::json;
  json terms = json::array();
  for (const DiscoveredMoment::Term& t : m.terms) {
    terms.push_back({{"term", t.name},
                     {"formula", t.formula},
                     {"parameter", t.estimate.name},
                     {"units", t.units},
                     {"estimate", Estimate(t.estimate)}});
  }
  return {{"segment", m.segment},
          {"joints", {m.first_joint, m.last_joint}},
          {"axis", m.axis == 0 ? "x" : "y"},
          {"terms", terms},
          {"formula", m.Formula()}};
}

}  // namespace

nlohmann::json ToJson(const LoopSummary& s, const std::vector<Experiment>& training,
                      const std::vector<Experiment>& holdout) {
  using nlohmann::json;
  json j;
  j["schema"] = "ccsrm-loop/1";
  json data = json::array();
  for (const Experiment& e : training) {
    data.push_back({{"name", e.name}, {"path", e.path}, {"role", "training"}});
  }
  for (const Experiment& e : holdout) {
    data.push_back({{"name", e.name}, {"path", e.path}, {"role", "holdout"}});
  }
  j["data"] = data;
  j["declared_free"] = s.declared.free_names;
  const LoopOptions& o = s.options;
  j["criteria"] = {{"score_significance", o.score_significance},
                   {"refits_per_round", o.refits_per_round},
                   {"max_rounds", o.max_rounds},
                   {"min_delta_bic", o.min_delta_bic},
                   {"declared_refits_per_round", o.declared_refits_per_round},
                   {"min_excess_share", o.min_excess_share},
                   {"holdout_z", o.holdout_z},
                   {"tie_delta_bic", o.tie_delta_bic},
                   {"unexplained_noise_ratio", o.unexplained_noise_ratio}};
  json rounds = json::array();
  for (const LoopRound& r : s.rounds) rounds.push_back(RoundJson(r));
  j["rounds"] = rounds;
  j["added_effects"] = s.added_effects;
  json taken_back = json::array();
  for (const LoopRound& r : s.rounds) {
    for (const BackwardCheck& b : r.backward) {
      if (b.taken_back) taken_back.push_back(Backward(b, r.index));
    }
  }
  j["taken_back"] = taken_back;
  json corrections = json::array();
  for (const DeclaredCorrection& d : s.declared_corrections)
    corrections.push_back(CorrectionJson(d));
  j["declared_corrections"] = corrections;
  json discovered = json::array();
  for (const DiscoveredMoment& m : s.discovered_terms) discovered.push_back(DiscoveredJson(m));
  j["discovered_terms"] = discovered;
  json params = json::object();
  for (const ParameterEstimate& p : s.final_fit.parameters) {
    if (p.free) params[p.name] = Estimate(p);
  }
  j["parameters"] = params;
  // Every RMS figure below (the keys named _deg) is in this unit: mm over
  // experiments of tracked points.
  j["unit"] = s.unit;
  j["rms_before_deg"] = Number(s.rms_before_deg);
  j["rms_after_deg"] = Number(s.rms_after_deg);
  j["holdout_rms_before_deg"] = Optional(s.holdout_rms_before_deg);
  j["holdout_rms_after_deg"] = Optional(s.holdout_rms_after_deg);
  j["before"] = PerJoint(s.before);
  j["after"] = PerJoint(s.after);
  j["holdout_before"] = s.holdout_before ? PerJoint(*s.holdout_before) : json(nullptr);
  j["holdout_after"] = s.holdout_after ? PerJoint(*s.holdout_after) : json(nullptr);
  double floor = 0.0;
  std::size_t count = 0;
  for (const Experiment& e : training) {
    if (!e.tracked_points.empty()) {
      floor += e.point_noise_mm * e.point_noise_mm, ++count;
      continue;
    }
    for (double v : e.noise_deg) floor += v * v, ++count;
  }
  j["noise_floor_deg"] =
      count ? Number(std::sqrt(floor / static_cast<double>(count))) : json(nullptr);
  json unexplained = json::array();
  for (const UnexplainedChannel& u : s.unexplained) {
    unexplained.push_back({{"experiment", u.experiment},
                           {"joint", u.joint},
                           {"point", u.point},
                           {"axis", std::string(1, "xyz"[u.axis])},
                           {"rms_deg", Number(u.rms_deg)},
                           {"noise_deg", Number(u.noise_deg)},
                           {"worst_phase", u.worst_phase},
                           {"worst_phase_rms_deg", Number(u.worst_phase_rms_deg)}});
  }
  j["unexplained"] = unexplained;
  j["final_evidence"] = ToJson(s.final_evidence);
  j["conclusion"] = s.conclusion;
  j["simulations"] = s.simulations;
  j["wall_time_s"] = Number(s.wall_time_s);
  j["threads"] = s.threads;
  j["declared_fit"] = {{"termination", TerminationName(s.declared.termination)},
                       {"iterations", s.declared.iterations},
                       {"simulations", s.declared.simulations}};
  j["final_fit"] = {{"termination", TerminationName(s.final_fit.termination)},
                    {"iterations", s.final_fit.iterations},
                    {"simulations", s.final_fit.simulations}};
  return j;
}

std::string LoopSummary::FullReport() const {
  std::ostringstream out;
  out << "Declared model: training RMS " << Cell("%.4f", rms_before_deg) << " " << unit;
  if (holdout_rms_before_deg) out << ", held out " << Cell("%.4f", *holdout_rms_before_deg);
  out << "\n";
  for (const LoopRound& r : rounds) {
    out << "\nRound " << r.index << " (training RMS " << Cell("%.4f", r.rms_deg) << " " << unit
        << ")\n";
    out << "  candidate                                  score     p        refit  dBIC     RMS    "
           "  "
           "held-out  accepted\n";
    for (const CandidateResult& c : r.candidates) {
      char line[256];
      std::snprintf(line, sizeof(line), "  %-41s %9s %8s  %-5s %8s %8s %9s  %s\n", c.name.c_str(),
                    Cell("%.1f", c.score).c_str(), Cell("%.2g", c.p_value).c_str(),
                    c.refitted ? "yes" : "no", c.refitted ? Cell("%.1f", c.delta_bic).c_str() : "-",
                    c.refitted ? Cell("%.4f", c.rms_deg).c_str() : "-",
                    c.holdout_rms_deg ? Cell("%.4f", *c.holdout_rms_deg).c_str() : "-",
                    c.accepted ? "yes" : "no");
      out << line;
    }
    out << "  decision: " << r.decision << "\n";
    for (const BackwardCheck& b : r.backward) {
      out << "  backward step: " << (b.taken_back ? b.reason : b.name + ": " + b.reason) << "\n";
    }
  }
  out << "\nParameters of the final model:\n";
  for (const ParameterEstimate& p : final_fit.parameters) {
    if (!p.free) continue;
    out << "  " << p.name << " = " << Cell("%.6g", p.value);
    if (p.identifiable) {
      out << " ± " << Cell("%.2g", p.std_error) << " " << p.units << "  (95 % ["
          << Cell("%.6g", p.ci95_lower) << ", " << Cell("%.6g", p.ci95_upper) << "])";
    } else {
      out << " " << p.units << "  (not identifiable)";
    }
    out << "\n";
  }
  if (!declared_corrections.empty()) {
    out << "\nDeclared values corrected (calibrated.yaml):\n";
    for (const DeclaredCorrection& d : declared_corrections) out << "  " << d.Sentence() << "\n";
  }
  if (!discovered_terms.empty()) {
    out << "\nTerms found in the data (joint_moment):\n";
    for (const DiscoveredMoment& m : discovered_terms) out << "  " << m.Formula() << "\n";
  }
  out << "\nRMS error [" << unit << "]      before    after\n";
  out << "  training          " << Cell("%.4f", rms_before_deg) << "   "
      << Cell("%.4f", rms_after_deg) << "\n";
  if (holdout_rms_before_deg && holdout_rms_after_deg) {
    out << "  held out          " << Cell("%.4f", *holdout_rms_before_deg) << "   "
        << Cell("%.4f", *holdout_rms_after_deg) << "\n";
  }
  if (!unexplained.empty()) {
    out << "\nUnexplained (RMS above the noise):\n";
    for (std::size_t k = 0; k < unexplained.size() && k < 12; ++k) {
      const UnexplainedChannel& u = unexplained[k];
      out << "  " << u.experiment << " " << ChannelName(u.joint, u.axis, u.point) << " "
          << Cell("%.4f", u.rms_deg) << " " << unit << " (noise " << Cell("%.4f", u.noise_deg)
          << "), worst in " << u.worst_phase << "\n";
    }
    if (unexplained.size() > 12) out << "  ... and " << unexplained.size() - 12 << " more\n";
  }
  out << "\n" << conclusion << "\n";
  out << simulations << " simulations, " << Cell("%.0f", wall_time_s) << " s wall on " << threads
      << " threads\n";
  return out.str();
}

std::vector<std::string> WriteLoopDirectory(const LoopSummary& summary,
                                            const std::vector<Experiment>& training,
                                            const std::vector<Experiment>& holdout,
                                            const std::string& directory) {
  namespace fs = std::filesystem;
  AtomicOutputDirectory out(directory);
  const fs::path tmp(out.temp_path());
  std::vector<std::string> written = {(fs::path(directory) / "loop.json").string()};
  const auto relocate = [&](const std::vector<std::string>& paths) {
    for (const std::string& p : paths) {
      written.push_back((fs::path(directory) / fs::relative(p, tmp)).string());
    }
  };
  if (!summary.declared.experiments.empty()) {
    relocate(WriteFitDirectory(summary.declared, training, (tmp / "declared").string()));
  }
  if (!summary.final_fit.experiments.empty()) {
    relocate(WriteFitDirectory(summary.final_fit, training, (tmp / "final").string()));
  }
  if (!holdout.empty() && summary.holdout_declared_rad.size() == holdout.size() &&
      summary.holdout_final_rad.size() == holdout.size()) {
    fs::create_directory(tmp / "holdout");
    for (std::size_t e = 0; e < holdout.size(); ++e) {
      const Experiment& x = holdout[e];
      const std::string name = x.name.empty() ? "holdout" + std::to_string(e + 1) : x.name;
      if (!x.tracked_points.empty()) {
        // The declared model's and the final model's points, each with the
        // measured ones and its residual.
        for (const auto& [kind, run] : {std::pair{"declared", &summary.holdout_declared_rad[e]},
                                        std::pair{"final", &summary.holdout_final_rad[e]}}) {
          const std::string file = name + "." + kind + ".points.csv";
          WriteTextFileAtomically((tmp / "holdout" / file).string(),
                                  internal::PointsCsvText(x, *run, x.name, kind));
          written.push_back((fs::path(directory) / "holdout" / file).string());
        }
        continue;
      }
      const auto degrees = [](const Eigen::MatrixXd& m) {
        return [&m](Eigen::Index f, Eigen::Index c) { return f < m.rows() ? m(f, c) * kDeg : NAN; };
      };
      const std::string csv = internal::AnglesCsvText(
          x.name +
              ": held-out joint angles [deg]: measured, the declared model's and the final "
              "model's; empty where not measured",
          x.frame_time_s, x.joints,
          {{"measured", degrees(x.measured)},
           {"declared", degrees(summary.holdout_declared_rad[e])},
           {"final", degrees(summary.holdout_final_rad[e])}});
      WriteTextFileAtomically((tmp / "holdout" / (name + ".angles.csv")).string(), csv);
      written.push_back((fs::path(directory) / "holdout" / (name + ".angles.csv")).string());
    }
  }
  if (summary.calibrated) {
    WriteTextFileAtomically((tmp / "calibrated.yaml").string(),
                            "# The declared configuration with the loop's corrections of declared "
                            "values and the final model's fitted values (loop.json: "
                            "declared_corrections).\n" +
                                sim::ToYaml(*summary.calibrated));
    written.push_back((fs::path(directory) / "calibrated.yaml").string());
  }
  WriteTextFileAtomically((tmp / "loop.json").string(),
                          ToJson(summary, training, holdout).dump(2) + "\n");
  out.Commit();
  return written;
}

}  // namespace ccsrm::identify
