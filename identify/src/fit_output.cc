// The identification summary as text, JSON and a fit directory.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "angles_table.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim_io/run_file.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

// JSON has no NaN: unknown numbers are null.
nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json ChannelJson(const ChannelErrors& e) {
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < e.rms_deg.size(); ++j) {
    joints.push_back(
        {{"joint", j + 1},
         {"rms_deg", {Number(e.rms_deg[j][0]), Number(e.rms_deg[j][1])}},
         {"fit_percent", {Number(e.fit_percent[j][0]), Number(e.fit_percent[j][1])}},
         {"motion_rms_deg", {Number(e.motion_rms_deg[j][0]), Number(e.motion_rms_deg[j][1])}},
         {"samples", {e.samples[j][0], e.samples[j][1]}}});
  }
  return {{"rms_deg", Number(e.rms_deg_overall)},
          {"fit_percent", Number(e.fit_percent_overall)},
          {"per_joint", joints},
          {"axes", {"theta_x", "theta_y"}}};
}

// The per-joint table of RMS, motion and fit.
std::string JointTable(const ChannelErrors& errors) {
  std::ostringstream out;
  out << "\n  joint   RMS θx [deg]   RMS θy [deg]   motion θx [deg]  motion θy [deg]  fit θx [%]   "
         "fit θy [%]\n";
  bool barely_moves = false;
  for (std::size_t j = 0; j < errors.rms_deg.size(); ++j) {
    char line[256];
    std::snprintf(line, sizeof(line), "  %5zu   %-14s %-14s %-16s %-16s %-12s %s\n", j + 1,
                  Cell("%.4f", errors.rms_deg[j][0]).c_str(),
                  Cell("%.4f", errors.rms_deg[j][1]).c_str(),
                  Cell("%.4f", errors.motion_rms_deg[j][0]).c_str(),
                  Cell("%.4f", errors.motion_rms_deg[j][1]).c_str(),
                  Cell("%.1f", errors.fit_percent[j][0]).c_str(),
                  Cell("%.1f", errors.fit_percent[j][1]).c_str());
    out << line;
    for (int a = 0; a < 2; ++a)
      barely_moves = barely_moves || !std::isfinite(errors.fit_percent[j][a]);
  }
  if (barely_moves) {
    out << "  fit -: the axis barely moves (its motion, RMS about its mean, is under a tenth of "
           "the "
           "joint's larger or three times its noise); read its RMS error against its motion\n";
  }
  return out.str();
}

}  // namespace

std::string UnidentifiableDirection::Describe() const {
  std::string out;
  for (const auto& [name, c] : components) {
    // A small component (a parameter leaking into another's undetermined
    // direction) keeps two significant digits instead of printing as 0.00.
    char text[64];
    std::snprintf(text, sizeof(text), std::abs(c) < 0.005 ? "%s%.1e %s" : "%s%.2f %s",
                  out.empty() ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + "), std::abs(c),
                  name.c_str());
    out += text;
  }
  return out.empty() ? "(no dominant parameter)" : out;
}

std::string IdentificationSummary::BriefReport() const {
  std::string rough;
  for (const ParameterEstimate& p : parameters) {
    if (p.free && p.derivative_step_disagreement > kDerivativeStepLimit) {
      rough += (rough.empty() ? "" : ", ") + p.name;
    }
  }
  // Tracked points: the first experiment's first point, as the tip.
  std::string points;
  for (const ExperimentFit& e : experiments) {
    if (e.fitted_points.rms_mm.empty()) continue;
    points =
        Format("%s RMS %s -> %s mm (mean offset removed %s mm)", e.points[0].name.c_str(),
               Cell("%.3f", e.start_points.rms_mm.empty() ? NAN : e.start_points.rms_mm[0]).c_str(),
               Cell("%.3f", e.fitted_points.rms_mm[0]).c_str(),
               Cell("%.3f", e.fitted_points.rms_mean_removed_mm[0]).c_str());
    break;
  }
  char text[512];
  std::snprintf(text, sizeof(text),
                "identification %s after %d iterations (%lld simulations, %d threads, %.1f s): "
                "%s%s",
                TerminationName(termination), iterations, static_cast<long long>(simulations),
                threads, wall_time_s,
                !points.empty() && !std::isfinite(errors.rms_deg_overall)
                    ? points.c_str()
                    : Format("RMS %s -> %s deg, fit %s %%",
                             Cell("%.4f", start_errors.rms_deg_overall).c_str(),
                             Cell("%.4f", errors.rms_deg_overall).c_str(),
                             Cell("%.1f", errors.fit_percent_overall).c_str())
                          .c_str(),
                !adequacy.assessed ? ""
                : adequacy.adequate()
                    ? "; the model explains the data"
                    : Format("; the model does NOT explain the data (%zu %s above their noise)",
                             adequacy.above_noise.size(),
                             adequacy.point_channels > 0 ? "measured axes" : "joint axes")
                          .c_str());
  if (!rough.empty()) return text + ("; derivatives NOT smooth in " + rough);
  return text;
}

std::array<double, 2> IdentificationSummary::MisfitInterval(const ParameterEstimate& p) const {
  const double scale = adequacy.misfit_scale();
  return {p.value - scale * (p.value - p.ci95_lower), p.value + scale * (p.ci95_upper - p.value)};
}

namespace {

// Whether the angles were smooth in each free parameter at the final point:
// its derivatives at the fit's step and a third of it agree, or at a third
// and a ninth where the fit took the finer one.
std::string DerivativeCheckLine(const IdentificationSummary& s) {
  std::string rough, largest, finer;
  double worst = -1.0;
  for (const ParameterEstimate& p : s.parameters) {
    const double d = p.derivative_step_disagreement;
    if (!p.free || !std::isfinite(d)) continue;
    if (d > kDerivativeStepLimit)
      rough += (rough.empty() ? "" : ", ") + p.name + Format(" %.1f %%", 100.0 * d);
    if (d > worst) worst = d, largest = p.name + Format(" %.2f %%", 100.0 * d);
    if (p.derivative_step < 0.5 * s.relative_step) {
      finer += (finer.empty() ? "" : ", ") + p.name + Format(" %.1f %%", 100.0 * d);
    }
  }
  const std::string steps =
      Format("relative steps %g and %.3g", s.relative_step, s.relative_step / 3.0);
  const std::string or_finer =
      finer.empty() ? ""
                    : Format(
                          " or, where the angles bend between the two, at %.3g and %.3g, "
                          "whose derivative the intervals take (",
                          s.relative_step / 3.0, s.relative_step / 9.0) +
                          finer + ")";
  if (worst < 0.0) return "  derivative check: not made";
  if (rough.empty()) {
    return "  derivative check: the derivatives at " + steps + or_finer +
           " agree for every free parameter (largest difference: " + largest + ")";
  }
  return "  derivative check: NOT smooth: the derivatives at " + steps + " differ for " + rough +
         Format(" (more than %.0f %%): ", 100.0 * kDerivativeStepLimit) +
         "the angles jump with these parameters here (a breakaway that happens or not, a "
         "stick-slip cycle that gains or loses a slip); their estimates and intervals are not "
         "to be trusted from these data" +
         (finer.empty() ? ""
                        : "; at a third and a ninth of the step they agree for " + finer +
                              ", whose derivative the intervals take");
}

}  // namespace

std::string IdentificationSummary::FullReport() const {
  std::ostringstream out;
  // The answer first: whether the model explains the data at all.
  out << "model: " << adequacy.Verdict()
      << (adequacy.assessed && !adequacy.adequate()
              ? "; its intervals assume a right model; `ccsrm loop` looks for what it lacks"
              : "")
      << "\n";
  out << BriefReport() << "\n";
  out << "  termination: " << TerminationName(termination) << " (" << message << ")\n";
  out << "  residuals: " << residuals << " (effective " << Cell("%.0f", effective_samples)
      << "), residual variance " << Cell("%.3g", residual_variance)
      << " (1 = at the measurement noise), cost " << Cell("%.6g", initial_cost) << " -> "
      << Cell("%.6g", final_cost) << "\n";
  out << "  finite differences: relative step " << relative_step
      << (central_differences_throughout
              ? ", second order (central, or one-sided inside the bounds) throughout\n\n"
              : ", first-order forward while descending, second order (central, or "
                "one-sided inside the bounds) at the final point\n");
  out << DerivativeCheckLine(*this) << "\n";
  // When the model misses, the intervals assume what is false; beside
  // them, the interval widened by the misfit.
  const bool misfit = adequacy.assessed && !adequacy.adequate();
  out << "  parameter      start          estimate       std error      95 % interval"
         "                 "
      << (misfit ? Format(" 95 %% x misfit %.2f             ", adequacy.misfit_scale()) : "")
      << " units\n";
  for (const ParameterEstimate& p : parameters) {
    if (!p.free) continue;
    char line[640];
    const auto bracket = [](double lo, double hi) {
      return "[" + Cell("%.6g", lo) + ", " + Cell("%.6g", hi) + "]";
    };
    const std::string interval =
        p.identifiable ? bracket(p.ci95_lower, p.ci95_upper) : "not identifiable";
    const std::array<double, 2> wide = MisfitInterval(p);
    const std::string widened = !misfit ? "" : p.identifiable ? bracket(wide[0], wide[1]) : "-";
    std::snprintf(line, sizeof(line), "  %-14s %-14s %-14s %-14s %-30s %s%s%s\n", p.name.c_str(),
                  Cell("%.6g", p.start).c_str(), Cell("%.6g", p.value).c_str(),
                  p.identifiable ? Cell("%.3g", p.std_error).c_str() : "-", interval.c_str(),
                  misfit ? Format("%-30s ", widened.c_str()).c_str() : "", p.units.c_str(),
                  p.at_bound ? "  (at a bound)" : "");
    out << line;
  }
  if (!covariance_available) out << "  no covariance: " << covariance_message << "\n";
  if (misfit) {
    out << "  x misfit: the interval widened by the worst axis's RMS over its noise; it allows "
           "for the misfit's size, not for a bias (an effect the model lacks can move an "
           "estimate beyond both intervals)\n";
  }
  out << "\n  singular values of the scaled Jacobian:";
  for (double s : singular_values) out << " " << Cell("%.3g", s);
  out << "\n";
  if (unidentifiable.empty()) {
    out << "  every free parameter is identifiable from these data\n";
  } else {
    for (const UnidentifiableDirection& d : unidentifiable) {
      out << "  not pinned down by the data: " << d.Describe() << " (singular value "
          << Cell("%.3g", d.singular_value) << ", relative std error "
          << Cell("%.3g", d.relative_std_error) << ")\n";
    }
  }
  if (std::isfinite(errors.rms_deg_overall)) out << JointTable(errors);
  out << "\n";
  for (const ExperimentFit& e : experiments) {
    if (!e.fitted_points.rms_mm.empty()) {
      out << "  " << e.name << ": " << e.noise_source << "\n";
      out << internal::TrackedPointsText(e.points, &e.start_points, e.fitted_points,
                                         e.placed_in_capture_frame ? &e.placement : nullptr);
      continue;
    }
    char line[512];
    double noise = 0.0;
    for (double s : e.noise_deg) noise += s / static_cast<double>(e.noise_deg.size());
    std::snprintf(line, sizeof(line), "  %s: RMS %s -> %s deg, fit %s %%, noise %.4f deg (%s)%s\n",
                  e.name.c_str(), Cell("%.4f", e.start.rms_deg_overall).c_str(),
                  Cell("%.4f", e.fitted.rms_deg_overall).c_str(),
                  Cell("%.1f", e.fitted.fit_percent_overall).c_str(), noise, e.noise_source.c_str(),
                  e.angles_from_pipeline ? ", angles from the mocap pipeline" : "");
    out << line;
  }
  return out.str();
}

nlohmann::json ToJson(const IdentificationSummary& s) {
  nlohmann::json parameters = nlohmann::json::object();
  for (const ParameterEstimate& p : s.parameters) {
    nlohmann::json entry = {
        {"value", p.value}, {"units", p.units}, {"free", p.free}, {"start", p.start}};
    if (p.free) {
      entry["std_error"] = p.identifiable ? Number(p.std_error) : nullptr;
      entry["derivative_step_disagreement"] = Number(p.derivative_step_disagreement);
      entry["derivative_step"] = Number(p.derivative_step);
      entry["ci95"] = p.identifiable ? nlohmann::json{Number(p.ci95_lower), Number(p.ci95_upper)}
                                     : nlohmann::json(nullptr);
      const std::array<double, 2> wide = s.MisfitInterval(p);
      entry["ci95_scaled_by_misfit"] = p.identifiable
                                           ? nlohmann::json{Number(wide[0]), Number(wide[1])}
                                           : nlohmann::json(nullptr);
      entry["identifiable"] = p.identifiable;
      entry["bounds"] = {p.lower, p.upper};
      entry["scale"] = p.scale;
      entry["at_bound"] = p.at_bound;
    }
    parameters[p.name] = entry;
  }
  nlohmann::json correlation = nlohmann::json::array();
  for (Eigen::Index i = 0; i < s.correlation.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < s.correlation.cols(); ++j)
      row.push_back(Number(s.correlation(i, j)));
    correlation.push_back(row);
  }
  nlohmann::json unidentifiable = nlohmann::json::array();
  for (const UnidentifiableDirection& d : s.unidentifiable) {
    nlohmann::json parts = nlohmann::json::object();
    for (const auto& [name, c] : d.components) parts[name] = c;
    unidentifiable.push_back({{"combination", d.Describe()},
                              {"components", parts},
                              {"singular_value", d.singular_value},
                              {"relative_std_error", Number(d.relative_std_error)}});
  }
  nlohmann::json experiments = nlohmann::json::array();
  for (const ExperimentFit& e : s.experiments) {
    experiments.push_back(
        {{"name", e.name},
         {"path", e.path},
         {"angles_from_pipeline", e.angles_from_pipeline},
         {"noise_deg", e.noise_deg},
         {"noise_source", e.noise_source},
         {"start", ChannelJson(e.start)},
         {"fitted", ChannelJson(e.fitted)},
         {"tracked_points",
          e.points.empty()
              ? nlohmann::json(nullptr)
              : internal::TrackedPointsJson(e.points, &e.start_points, e.fitted_points,
                                            e.placed_in_capture_frame ? &e.placement : nullptr)},
         {"run",
          {{"status", e.run.summary.completed() ? "completed" : "failed"},
           {"message", e.run.summary.message},
           {"wall_time_s", e.run.summary.wall_time_s},
           {"real_time_factor", e.run.summary.real_time_factor}}}});
  }
  nlohmann::json arm = nullptr;
  if (!s.experiments.empty()) {
    // The arm the values were fitted on: a prediction refuses another one.
    const sim::ArmSize& size = s.experiments.front().parameters.arm;
    arm = {{"joints", size.joints}, {"driving_cables", size.cables}};
  }
  return {{"schema", "ccsrm-fit/1"},
          {"arm", arm},
          {"converged", s.converged()},
          {"adequacy", ToJson(s.adequacy)},
          {"termination", TerminationName(s.termination)},
          {"message", s.message},
          {"iterations", s.iterations},
          {"simulations", s.simulations},
          {"threads", s.threads},
          {"wall_time_s", s.wall_time_s},
          {"relative_step", s.relative_step},
          {"descent_differences", s.central_differences_throughout ? "second_order" : "forward"},
          {"free", s.free_names},
          {"parameters", parameters},
          {"rms_deg", Number(s.errors.rms_deg_overall)},
          {"fit_percent", Number(s.errors.fit_percent_overall)},
          {"rms_deg_start", Number(s.start_errors.rms_deg_overall)},
          {"errors", ChannelJson(s.errors)},
          {"start_errors", ChannelJson(s.start_errors)},
          {"cost_history", s.cost_history},
          {"initial_cost", Number(s.initial_cost)},
          {"final_cost", Number(s.final_cost)},
          {"residuals", s.residuals},
          {"effective_samples", Number(s.effective_samples)},
          {"residual_variance", Number(s.residual_variance)},
          {"covariance_available", s.covariance_available},
          {"covariance_message", s.covariance_message},
          {"correlation", correlation},
          {"singular_values", s.singular_values},
          {"unidentifiable", unidentifiable},
          {"experiments", experiments}};
}

std::vector<std::string> WriteFitDirectory(const IdentificationSummary& summary,
                                           const std::vector<Experiment>& experiments,
                                           const std::string& directory) {
  CCSRM_CHECK(summary.experiments.size() == experiments.size());
  namespace fs = std::filesystem;
  AtomicOutputDirectory out(directory);
  const fs::path tmp(out.temp_path());
  std::vector<std::string> written;
  std::vector<std::string> names;
  for (const ExperimentFit& fit : summary.experiments) names.push_back(fit.name);
  const std::vector<std::string> stems = internal::OutputStems(names);
  nlohmann::json json = ToJson(summary);
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const ExperimentFit& fit = summary.experiments[e];
    internal::WriteRecordingOutputs(experiments[e], fit.name, fit.run, fit.parameters,
                                    fit.simulated, "fitted", stems[e], ".fit.h5", out.temp_path(),
                                    directory, &json["experiments"][e], &written);
  }
  WriteTextFileAtomically((tmp / "fit.json").string(), json.dump(2) + "\n");
  written.insert(written.begin(), (fs::path(directory) / "fit.json").string());
  out.Commit();
  return written;
}

}  // namespace ccsrm::identify
