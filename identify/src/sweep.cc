// ParameterSweep: the joint angles along one parameter, and how far they are
// from a cubic in it.
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/runs.h"
#include "ccsrm/identify/sensitivity.h"
#include "finite_difference.h"
#include "run_pool.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

double RowRms(const Eigen::MatrixXd& m, Eigen::Index row) {
  return m.cols() == 0 ? 0.0 : std::sqrt(m.row(row).squaredNorm() / static_cast<double>(m.cols()));
}

}  // namespace

bool SweepOptions::IsValid(std::string* error) const {
  try {
    sim::FindParameter(parameter, "parameter");
  } catch (const InputError& e) {
    *error = e.what();
    return false;
  }
  if (points < 5) {
    *error = "points: must be >= 5 (a cubic has 4 coefficients), found " + std::to_string(points);
    return false;
  }
  if (!(span > 0.0 && span < 1.0)) {
    *error = "span: " + Format("%g", span) + " is outside (0, 1)";
    return false;
  }
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    *error = problem + ", found " + std::to_string(threads);
    return false;
  }
  return true;
}

Eigen::MatrixXd CubicFitResiduals(const std::vector<double>& x, const Eigen::MatrixXd& y) {
  CCSRM_CHECK(static_cast<Eigen::Index>(x.size()) == y.rows());
  CCSRM_CHECK(x.size() >= 4);
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  const double centre = 0.5 * (*lo + *hi), half_width = 0.5 * (*hi - *lo);
  CCSRM_CHECK(half_width > 0.0);
  // Powers of t in [-1, 1]: the Vandermonde matrix stays well conditioned
  // (in raw x = 100 +- 5 its columns would agree to 1e-6).
  const Eigen::Index n = y.rows();
  Eigen::MatrixXd v(n, 4);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = (x[k] - centre) / half_width;
    v(k, 0) = 1.0;
    v(k, 1) = t;
    v(k, 2) = t * t;
    v(k, 3) = t * t * t;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(v);
  CCSRM_CHECK(qr.rank() == 4);  // at least 4 distinct values of x
  return y - v * qr.solve(y);
}

bool SweepSummary::all_runs_completed() const {
  for (const sim::SimulationSummary& r : runs) {
    if (!r.completed()) return false;
  }
  return !runs.empty();
}

SweepSummary ParameterSweep(const sim::ArmModel& model, const sim::ArmParameters& base,
                            const sim::CableInputs& inputs,
                            const sim::SimulationOptions& simulation, const SweepOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("SweepOptions", "", error);
  if (!base.IsValid(&error)) ThrowInputError("base parameters", "", error);
  if (!simulation.IsValid(&error)) ThrowInputError("SimulationOptions", "", error);

  const sim::ParameterInfo& info = sim::FindParameter(options.parameter, "parameter");
  SweepSummary s;
  s.parameter = info.name;
  s.units = info.units;
  s.value = sim::GetParameter(base, info.name);
  s.scale = internal::ParameterScale(info, s.value, options.scale_at_zero);
  s.span = options.span;
  s.threads = options.backend ? options.backend->parallelism() : options.threads;
  if (s.scale == 0.0) {
    ThrowInputError(info.name, "",
                    "value 0 and no scale at zero: a relative span does not move it");
  }
  std::vector<internal::RunRequest> requests;
  for (int k = 0; k < options.points; ++k) {
    // x = -1 + 2k/(N-1) is exactly 0 in the middle of an odd N: the base value.
    const double x = -1.0 + 2.0 * k / (options.points - 1);
    const double value = s.value + options.span * s.scale * x;
    const std::string problem = sim::ParameterValueProblem(info, value);
    if (!problem.empty()) {
      ThrowInputError(info.name, "",
                      "the sweep over +-" + Format("%g", 100.0 * options.span) +
                          " % leaves the bounds: " + problem);
    }
    s.values.push_back(value);
    sim::ArmParameters p = base;
    sim::SetParameter(info.name, value, "sweep", &p);
    requests.push_back({p, info.name + " = " + Format("%.6g", value)});
  }
  const std::vector<internal::RunOutcome> outcomes =
      internal::RunAll(model, inputs, simulation, requests, options.threads, options.progress,
                       options.backend.get());
  for (const internal::RunOutcome& o : outcomes) s.runs.push_back(o.summary);
  s.sampled_angles = outcomes[0].angles_deg.size();

  const double nan = std::nan("");
  if (!s.all_runs_completed()) {
    s.residual_rms = s.residual_max = s.variation_rms = s.variation_max = nan;
  } else {
    const Eigen::Index n = options.points, m = static_cast<Eigen::Index>(s.sampled_angles);
    Eigen::MatrixXd y(n, m);
    for (Eigen::Index k = 0; k < n; ++k) {
      CCSRM_CHECK(outcomes[k].angles_deg.size() == s.sampled_angles);
      y.row(k) = Eigen::Map<const Eigen::RowVectorXd>(outcomes[k].angles_deg.data(), m);
    }
    const Eigen::MatrixXd residual = CubicFitResiduals(s.values, y);
    s.angles_deg = y;
    for (Eigen::Index k = 0; k < n; ++k) {
      s.residual_rms_deg.push_back(RowRms(residual, k));
      s.change_rms_deg.push_back(
          m == 0 ? 0.0 : std::sqrt((y.row(k) - y.row(0)).squaredNorm() / static_cast<double>(m)));
    }
    const double count = static_cast<double>(std::max<Eigen::Index>(1, n * m));
    s.residual_rms = std::sqrt(residual.squaredNorm() / count);
    s.residual_max = m == 0 ? 0.0 : residual.cwiseAbs().maxCoeff();
    const Eigen::RowVectorXd range = y.colwise().maxCoeff() - y.colwise().minCoeff();
    s.variation_rms = m == 0 ? 0.0 : std::sqrt(range.squaredNorm() / static_cast<double>(m));
    s.variation_max = m == 0 ? 0.0 : range.maxCoeff();
  }
  s.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

std::string SweepSummary::BriefReport() const {
  char text[320];
  if (!all_runs_completed()) {
    std::snprintf(text, sizeof(text), "sweep of %s: a run did not complete (%zu runs, %.1f s wall)",
                  parameter.c_str(), runs.size(), wall_time_s);
  } else {
    std::snprintf(text, sizeof(text),
                  "sweep of %s over +-%g %%: residual to a cubic %.3g deg RMS, %.3g deg max; "
                  "variation %.3g deg RMS, %.3g deg max (%zu runs, %.1f s wall)",
                  parameter.c_str(), 100.0 * span, residual_rms, residual_max, variation_rms,
                  variation_max, runs.size(), wall_time_s);
  }
  return text;
}

std::string SweepSummary::FullReport() const {
  std::ostringstream out;
  char line[320];
  std::snprintf(line, sizeof(line),
                "sweep of %s [%s]: %zu values from %.6g to %.6g (+-%g %% of s = %g around %.6g)\n",
                parameter.c_str(), units.c_str(), values.size(),
                values.empty() ? 0.0 : values.front(), values.empty() ? 0.0 : values.back(),
                100.0 * span, scale, value);
  out << line;
  std::snprintf(line, sizeof(line),
                "  %zu runs on %d threads, %.1f s wall; %zu sampled angles per run; a "
                "least-squares cubic in %s fitted to each angle\n\n",
                runs.size(), threads, wall_time_s, sampled_angles, parameter.c_str());
  out << line;
  out << "  point  value        offset    RMS change from first [deg]  RMS residual [deg]  run\n";
  for (std::size_t k = 0; k < values.size(); ++k) {
    const bool fitted = k < residual_rms_deg.size();
    const sim::SimulationSummary& run = runs[k];
    std::snprintf(line, sizeof(line), "  %5zu  %-11.6g  %+6.2f %%  %27s  %18s  %s, %lld steps\n",
                  k + 1, values[k], 100.0 * (values[k] - value) / scale,
                  fitted ? Format("%.6g", change_rms_deg[k]).c_str() : "-",
                  fitted ? Format("%.3g", residual_rms_deg[k]).c_str() : "-",
                  sim::SimulationStatusName(run.status), static_cast<long long>(run.steps));
    out << line;
  }
  if (all_runs_completed()) {
    std::snprintf(line, sizeof(line),
                  "\n  residual to the cubics: %.3g deg RMS, %.3g deg max\n"
                  "  total variation across the sweep: %.3g deg RMS, %.3g deg max (residual / "
                  "variation: %.3g RMS, %.3g max)\n",
                  residual_rms, residual_max, variation_rms, variation_max,
                  variation_rms > 0 ? residual_rms / variation_rms : 0.0,
                  variation_max > 0 ? residual_max / variation_max : 0.0);
    out << line;
  } else {
    for (std::size_t k = 0; k < runs.size(); ++k) {
      if (!runs[k].completed()) out << "  run " << k + 1 << ": " << runs[k].message << "\n";
    }
  }
  out << "\n" << BriefReport() << "\n";
  return out.str();
}

nlohmann::json ToJson(const SweepSummary& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (const sim::SimulationSummary& r : s.runs) runs.push_back(internal::RunJson(r));
  return {{"schema", "ccsrm-sweep/1"},
          {"parameter", s.parameter},
          {"units", s.units},
          {"value", s.value},
          {"scale", s.scale},
          {"span", s.span},
          {"values", s.values},
          {"sampled_angles", s.sampled_angles},
          {"point_change_rms_deg", s.change_rms_deg},
          {"point_residual_rms_deg", s.residual_rms_deg},
          {"residual_rms_deg", s.residual_rms},
          {"residual_max_deg", s.residual_max},
          {"variation_rms_deg", s.variation_rms},
          {"variation_max_deg", s.variation_max},
          {"threads", s.threads},
          {"wall_time_s", s.wall_time_s},
          {"runs", runs}};
}

}  // namespace ccsrm::identify
