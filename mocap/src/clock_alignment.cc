#include "ccsrm/mocap/clock_alignment.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "ccsrm/common/autocorrelation.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "ccsrm/sim/simulator.h"
#include "text_table.h"

namespace ccsrm::mocap {
namespace {

using internal::FormatNumber;

// Linear interpolation of column `c` of `values` (rows at `time`, increasing)
// at t; requires time[0] <= t <= time[n-1]. `hint` speeds up increasing t.
double Interpolate(const Eigen::VectorXd& time, const Eigen::MatrixXd& values, Eigen::Index c,
                   double t, Eigen::Index* hint) {
  const Eigen::Index n = time.size();
  Eigen::Index k = std::clamp<Eigen::Index>(*hint, 0, n - 2);
  while (k > 0 && time[k] > t) --k;
  while (k + 2 < n && time[k + 1] <= t) ++k;
  *hint = k;
  const double u = std::clamp((t - time[k]) / (time[k + 1] - time[k]), 0.0, 1.0);
  return (1.0 - u) * values(k, c) + u * values(k + 1, c);
}

// Least-squares line log = offset + (1 + drift) × mocap through paired
// edges; residual RMS in *rms.
struct LineFit {
  double offset = 0.0;
  double drift = 0.0;
  double rms = 0.0;
  Eigen::Matrix2d inverse_normal = Eigen::Matrix2d::Zero();  // (XᵀX)⁻¹, for offset and slope
};

LineFit FitLine(const std::vector<double>& mocap, const std::vector<double>& log,
                std::size_t mocap_first, std::size_t log_first, std::size_t count,
                bool with_drift) {
  LineFit fit;
  if (!with_drift || count < 2) {
    double sum = 0.0;
    for (std::size_t i = 0; i < count; ++i) sum += log[log_first + i] - mocap[mocap_first + i];
    fit.offset = sum / static_cast<double>(count);
    double squares = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const double r = log[log_first + i] - mocap[mocap_first + i] - fit.offset;
      squares += r * r;
    }
    fit.rms = std::sqrt(squares / static_cast<double>(count));
    fit.inverse_normal(0, 0) = 1.0 / static_cast<double>(count);
    return fit;
  }
  Eigen::MatrixXd x(count, 2);
  Eigen::VectorXd y(count);
  for (std::size_t i = 0; i < count; ++i) {
    x(i, 0) = 1.0;
    x(i, 1) = mocap[mocap_first + i];
    y(i) = log[log_first + i];
  }
  const Eigen::Matrix2d normal = x.transpose() * x;
  const Eigen::Vector2d beta = normal.ldlt().solve(x.transpose() * y);
  fit.offset = beta(0);
  fit.drift = beta(1) - 1.0;
  fit.rms = std::sqrt((y - x * beta).squaredNorm() / static_cast<double>(count));
  fit.inverse_normal = normal.inverse();
  return fit;
}

}  // namespace

std::vector<double> FindEdges(const Eigen::VectorXd& time_s, const Eigen::VectorXd& values,
                              const EdgeOptions& options) {
  CCSRM_CHECK(time_s.size() == values.size());
  double threshold = options.threshold;
  if (std::isnan(threshold)) {
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) continue;
      lo = std::min(lo, values[i]);
      hi = std::max(hi, values[i]);
    }
    if (!(hi > lo)) return {};  // a flat signal has no edge
    threshold = 0.5 * (lo + hi);
  }
  // True on the far side of an edge of the chosen polarity: at or above the
  // level for rising edges, at or below it for falling ones.
  auto past = [&](double v) { return options.rising ? v >= threshold : v <= threshold; };
  std::vector<double> edges;
  bool armed = false;  // has been on the near side long enough
  double near_since = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!std::isfinite(v)) {
      armed = false;
      near_since = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    if (!past(v)) {
      if (std::isnan(near_since)) near_since = time_s[i];
      if (time_s[i] - near_since >= options.min_separation_s || edges.empty()) armed = true;
      continue;
    }
    if (armed && i > 0 && std::isfinite(values[i - 1]) && !past(values[i - 1])) {
      double t = time_s[i];
      if (options.interpolate) {
        const double u = (threshold - values[i - 1]) / (v - values[i - 1]);
        t = time_s[i - 1] + std::clamp(u, 0.0, 1.0) * (time_s[i] - time_s[i - 1]);
      }
      edges.push_back(t);
      armed = false;
    }
    near_since = std::numeric_limits<double>::quiet_NaN();
  }
  return edges;
}

ClockFit AlignByTrigger(const std::vector<double>& mocap_edges_s,
                        const std::vector<double>& log_edges_s,
                        const TriggerAlignmentOptions& options, const std::string& source) {
  if (mocap_edges_s.empty() || log_edges_s.empty()) {
    ThrowInputError(
        source, "trigger",
        "no edge in the " +
            std::string(mocap_edges_s.empty() ? "C3D analog channel" : "log's trigger column") +
            " (check the channel, threshold and polarity)");
  }
  const std::size_t m = mocap_edges_s.size();
  const std::size_t l = log_edges_s.size();
  const std::size_t pairs = std::min(m, l);
  const bool with_drift = options.estimate_drift && pairs >= 2;
  // One edge's timing uncertainty, both clocks together.
  const double edge_sigma =
      std::max(1e-9, std::hypot(options.mocap_edge_sigma_s, options.log_edge_sigma_s));
  struct Candidate {
    long shift;  // log index = mocap index + shift
    LineFit fit;
  };
  std::vector<Candidate> plausible;
  std::string rejected;
  // Shifts that pair the shorter sequence whole.
  const long first_shift = m <= l ? 0 : -static_cast<long>(m - l);
  const long last_shift = m <= l ? static_cast<long>(l - m) : 0;
  for (long shift = first_shift; shift <= last_shift; ++shift) {
    const std::size_t mocap_first = shift >= 0 ? 0 : static_cast<std::size_t>(-shift);
    const std::size_t log_first = shift >= 0 ? static_cast<std::size_t>(shift) : 0;
    const LineFit fit =
        FitLine(mocap_edges_s, log_edges_s, mocap_first, log_first, pairs, with_drift);
    // A true pairing leaves residuals of the edge timing; 5 σ (RMS over the
    // pairs) leaves room for an outlying edge without admitting a wrong one.
    const bool fits = fit.rms <= 5.0 * edge_sigma;
    const bool drift_ok = std::abs(fit.drift) <= options.max_drift;
    if (fits && drift_ok) {
      plausible.push_back({shift, fit});
    } else if (rejected.empty()) {
      rejected = "best rejected pairing: residual " + FormatNumber("%.3g", fit.rms * 1e3) +
                 " ms, drift " + FormatNumber("%.4g", fit.drift * 1e6) + " ppm";
    }
  }
  if (plausible.empty()) {
    ThrowInputError(source, "trigger",
                    "no pairing of the " + std::to_string(m) + " C3D edge(s) with the " +
                        std::to_string(l) +
                        " log edge(s) fits within 5 × the edge timing and a drift below " +
                        FormatNumber("%.4g", options.max_drift * 1e6) + " ppm (" + rejected + ")");
  }
  if (plausible.size() > 1) {
    ThrowInputError(
        source, "trigger",
        "ambiguous alignment: " + std::to_string(plausible.size()) +
            " pairings of the edges fit equally well (offsets " +
            FormatNumber("%.6g", plausible[0].fit.offset) + " s and " +
            FormatNumber("%.6g", plausible[1].fit.offset) +
            " s); use pulses at irregular intervals, --sync offset=S or --sync estimate");
  }
  const LineFit& fit = plausible.front().fit;
  ClockFit out;
  out.method = "trigger";
  out.offset_s = fit.offset;
  out.drift = fit.drift;
  // Timing scatter: the larger of what the sampling implies and what the
  // residuals show (when there are more pairs than parameters).
  const std::size_t parameters = with_drift ? 2 : 1;
  double sigma = edge_sigma;
  if (pairs > parameters) {
    sigma = std::max(sigma, fit.rms * std::sqrt(static_cast<double>(pairs) /
                                                static_cast<double>(pairs - parameters)));
  }
  out.offset_sigma_s = sigma * std::sqrt(fit.inverse_normal(0, 0));
  out.drift_sigma = with_drift ? sigma * std::sqrt(fit.inverse_normal(1, 1)) : 0.0;
  out.note = std::to_string(pairs) + " edge pair(s) (" + std::to_string(m) + " in the C3D, " +
             std::to_string(l) + " in the log), residual RMS " +
             FormatNumber("%.3g", fit.rms * 1e3) + " ms" +
             (with_drift ? "" : ", drift not estimated");
  return out;
}

namespace {

// One log column per driving cable, angles F × J × 2.
void CheckLogAgainstArm(const sim::ArmModel& model, const std::vector<double>& mocap_time_s,
                        const std::vector<double>& angles,
                        const Eigen::MatrixXd& log_length_change_m, const std::string& source) {
  if (log_length_change_m.cols() != model.num_cables()) {
    ThrowInputError(source, "cables",
                    "the log has " + std::to_string(log_length_change_m.cols()) +
                        " cable column(s), the arm " + std::to_string(model.num_cables()));
  }
  CCSRM_CHECK(angles.size() ==
              mocap_time_s.size() * static_cast<std::size_t>(model.num_joints()) * 2);
}

// Frames with every joint angle measured: at least 10 to align on.
void CheckFramesToAlign(Eigen::Index frames, const std::string& source) {
  if (frames < 10) {
    ThrowInputError(source, "/measured/joint_angles",
                    "only " + std::to_string(frames) +
                        " frame(s) with every joint angle measured: too few to align the clocks");
  }
}

// Channels measured at mocap frames against a reference on the log's clock:
// the kinematic path changes against the logged lengths, or the measured
// joint angles against the simulated ones.
struct AlignmentData {
  std::vector<double> times;       // mocap times of the frames used [s]
  Eigen::MatrixXd measured;        // frames × channels
  Eigen::VectorXd reference_time;  // log clock [s], increasing
  Eigen::MatrixXd reference;       // rows at reference_time, same channels
  // Per channel measured ≈ a + b · reference (true: the kinematic lengths,
  // where cable stretch and the log's zero are unknown), or ≈ a + reference
  // (false: simulated angles, whose scale is the model's).
  bool affine = true;
  int parameters_per_channel() const { return affine ? 2 : 1; }
};

// Residual sum of squares over the channels at t_log = offset_s + (1 +
// drift) t, on every `stride`-th frame; the residuals per channel in
// *residuals when given (stride 1).
double Misfit(const AlignmentData& d, double offset_s, double drift, Eigen::Index stride = 1,
              std::vector<std::vector<double>>* residuals = nullptr) {
  const Eigen::Index frames = d.measured.rows();
  double total = 0.0;
  std::vector<double> r(static_cast<std::size_t>(frames));
  // The reference sample before the first frame, by bisection: walking
  // there from the start cost most of a long log's search.
  const double first = offset_s + (1.0 + drift) * d.times.front();
  const Eigen::Index start = std::max<Eigen::Index>(
      0, static_cast<Eigen::Index>(
             std::upper_bound(d.reference_time.data(),
                              d.reference_time.data() + d.reference_time.size(), first) -
             d.reference_time.data()) -
             1);
  for (Eigen::Index c = 0; c < d.measured.cols(); ++c) {
    Eigen::Index hint = start;
    double sl = 0, sq = 0, sll = 0, slq = 0, sqq = 0, n = 0;
    for (Eigen::Index f = 0; f < frames; f += stride) {
      const double l = Interpolate(d.reference_time, d.reference, c,
                                   offset_s + (1.0 + drift) * d.times[f], &hint);
      r[f] = l;
      const double y = d.affine ? d.measured(f, c) : d.measured(f, c) - l;
      sl += l;
      sq += y;
      sll += l * l;
      slq += l * y;
      sqq += y * y;
      n += 1.0;
    }
    const double var_l = sll - sl * sl / n;
    const double cov = slq - sl * sq / n;
    const double var_q = sqq - sq * sq / n;
    // Affine: the residual of the best line; a cable the log holds still
    // explains nothing (its residual is var_q). Else: about the mean.
    const bool line = d.affine && var_l > 0.0;
    total += line ? std::max(0.0, var_q - cov * cov / var_l) : var_q;
    if (residuals != nullptr) {
      const double b = line ? cov / var_l : 0.0;
      const double a = (sq - b * sl) / n;
      std::vector<double> channel;
      for (Eigen::Index f = 0; f < frames; f += stride) {
        const double y = d.affine ? d.measured(f, c) : d.measured(f, c) - r[f];
        channel.push_back(y - a - b * r[f]);
      }
      residuals->push_back(std::move(channel));
    }
  }
  return total;
}

struct Minimum {
  double offset_s = 0.0;
  double misfit = 0.0;
  double curvature = 0.0;  // d²misfit/doffset², 0 when unknown
};

// The best offset on a grid of `step` over [lo, hi] (drift 0, every frame),
// refined by a parabola through the best point and its neighbours.
Minimum FineMinimum(const AlignmentData& d, double lo, double hi, double step) {
  const std::size_t grid = static_cast<std::size_t>(std::floor((hi - lo) / step)) + 1;
  std::vector<double> misfit(grid);
  for (std::size_t i = 0; i < grid; ++i)
    misfit[i] = Misfit(d, lo + static_cast<double>(i) * step, 0.0);
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(misfit.begin(), misfit.end()) - misfit.begin());
  Minimum m;
  m.offset_s = lo + static_cast<double>(best) * step;
  if (best > 0 && best + 1 < grid) {
    const double a = misfit[best - 1], b = misfit[best], c = misfit[best + 1];
    m.curvature = (a - 2.0 * b + c) / (step * step);
    if (m.curvature > 0.0) m.offset_s += 0.5 * step * (a - c) / (a - 2.0 * b + c);
  }
  m.misfit = Misfit(d, m.offset_s, 0.0);
  return m;
}

// The local minima of the misfit over [lo, hi], coarse to fine: a grid of
// options.coarse_step_s on every k-th frame (k frames ≈ one coarse step:
// the misfit of a motion slower than that changes little between them),
// then its lowest local minima refined on every frame within one coarse
// step. Best first.
std::vector<Minimum> FindMinima(const AlignmentData& d, double lo, double hi, double fine_step,
                                double frame_step, const KinematicAlignmentOptions& options) {
  const double coarse = std::max(options.coarse_step_s, fine_step);
  if (hi - lo <= 4.0 * coarse) return {FineMinimum(d, lo, hi, fine_step)};
  const Eigen::Index stride =
      std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::floor(coarse / frame_step)));
  const std::size_t grid = static_cast<std::size_t>(std::floor((hi - lo) / coarse)) + 1;
  std::vector<double> misfit(grid);
  for (std::size_t i = 0; i < grid; ++i) {
    misfit[i] = Misfit(d, lo + static_cast<double>(i) * coarse, 0.0, stride);
  }
  std::vector<std::size_t> local;  // at the ends, against the one neighbour
  for (std::size_t i = 0; i < grid; ++i) {
    if ((i == 0 || misfit[i] <= misfit[i - 1]) && (i + 1 == grid || misfit[i] <= misfit[i + 1]))
      local.push_back(i);
  }
  std::sort(local.begin(), local.end(),
            [&](std::size_t a, std::size_t b) { return misfit[a] < misfit[b]; });
  // The best few: a wrong one among them is what the ambiguity test needs
  // to see; one further down the coarse ranking is worse still.
  constexpr std::size_t kRefined = 5;
  std::vector<Minimum> out;
  for (std::size_t k = 0; k < std::min(kRefined, local.size()); ++k) {
    const double t = lo + static_cast<double>(local[k]) * coarse;
    out.push_back(FineMinimum(d, std::max(lo, t - coarse), std::min(hi, t + coarse), fine_step));
  }
  std::sort(out.begin(), out.end(),
            [](const Minimum& a, const Minimum& b) { return a.misfit < b.misfit; });
  return out;
}

// The offset (and drift) that best maps `d.measured` onto `d.reference`,
// with uncertainties; see AlignByKinematics.
ClockFit AlignToReference(const AlignmentData& d, const KinematicAlignmentOptions& options,
                          const std::string& head, const std::string& source) {
  const std::vector<double>& times = d.times;
  const Eigen::Index frames = d.measured.rows();
  const Eigen::Index channels = d.measured.cols();
  const Eigen::VectorXd& log_time_s = d.reference_time;
  // Offsets that keep every frame inside the log, then inside the window
  // asked for.
  double lo = log_time_s[0] - times.front();
  double hi = log_time_s[log_time_s.size() - 1] - times.back();
  if (!(hi >= lo)) {
    ThrowInputError(source, "actuator log",
                    "covers " +
                        FormatNumber("%.6g", log_time_s[log_time_s.size() - 1] - log_time_s[0]) +
                        " s, shorter than the mocap recording (" +
                        FormatNumber("%.6g", times.back() - times.front()) + " s)");
  }
  if (std::isfinite(options.search_center_s) && std::isfinite(options.search_half_width_s)) {
    lo = std::max(lo, options.search_center_s - options.search_half_width_s);
    hi = std::min(hi, options.search_center_s + options.search_half_width_s);
    if (!(hi >= lo)) {
      ThrowInputError(source, "actuator log",
                      "no offset within " + FormatNumber("%.6g", options.search_half_width_s) +
                          " s of " + FormatNumber("%.6g", options.search_center_s) +
                          " s keeps the recording inside the log");
    }
  }
  const double frame_step = (times.back() - times.front()) / static_cast<double>(frames - 1);
  const double step = options.grid_step_s > 0.0 ? options.grid_step_s : frame_step;
  const std::vector<Minimum> minima = FindMinima(d, lo, hi, step, frame_step, options);
  const Minimum& best = minima.front();
  // Residual variance: frames × channels values, the per-channel fit and
  // the offset fitted. Correlated residuals (a model's misfit is smooth in
  // time) carry fewer independent samples: the variance of the offset is
  // scaled by N / N_eff, as identification scales its standard errors.
  std::vector<std::vector<double>> residuals;
  Misfit(d, best.offset_s, 0.0, 1, &residuals);
  const double n = static_cast<double>(frames * channels);
  const double dof = n - static_cast<double>(d.parameters_per_channel() * channels + 1);
  const double variance = std::max(best.misfit, 1e-30) / dof;
  const double n_eff = std::max(1.0, EffectiveSampleSize(residuals));
  const double inflation = std::max(1.0, n / n_eff);
  // Ambiguity: another local minimum, far enough away, statistically as
  // good (in effective chi-square units).
  for (std::size_t k = 1; k < minima.size(); ++k) {
    if (std::abs(minima[k].offset_s - best.offset_s) <= options.ambiguity_separation_s) continue;
    if ((minima[k].misfit - best.misfit) / (variance * inflation) < options.ambiguity_chi2) {
      ThrowInputError(source, "--sync estimate",
                      "ambiguous alignment: log offsets " + FormatNumber("%.6g", best.offset_s) +
                          " s and " + FormatNumber("%.6g", minima[k].offset_s) +
                          " s explain the measured angles equally well (a periodic motion?); "
                          "give a trigger or --sync offset=S");
    }
  }
  ClockFit out;
  out.method = "estimate";
  out.offset_s = best.offset_s;
  // Gauss-Newton: misfit ≈ misfit_min + ½ H δ², var(δ) = variance / (½ H).
  out.offset_sigma_s =
      best.curvature > 0.0 ? std::sqrt(2.0 * variance * inflation / best.curvature) : step;
  const std::string stats = head + ", residual RMS " + FormatNumber("%.3g", std::sqrt(variance)) +
                            " (N_eff " + FormatNumber("%.0f", n_eff) + " of " +
                            FormatNumber("%.0f", n) + ")";
  out.note = stats + "; drift not estimated";
  if (!options.estimate_drift) return out;

  // Drift: profile the misfit over a grid of drifts, each at its best log
  // time at the recording's middle (where offset and drift are least
  // correlated), found by a parabola through three points half a frame apart
  // around the drift-free one. The grid on every k-th frame as the offset's
  // coarse search, its best point and neighbours again on every frame.
  const double t_mid = 0.5 * (times.front() + times.back());
  const double mid0 = out.offset_s + t_mid;  // log time at t_mid without drift
  const double h = 0.5 * frame_step;
  const Eigen::Index stride = std::max<Eigen::Index>(
      1, static_cast<Eigen::Index>(std::floor(options.coarse_step_s / frame_step)));
  struct Profile {
    double misfit = 0.0;
    double mid = 0.0;
    double curvature = 0.0;  // d²misfit/dmid²
  };
  auto profile = [&](double drift, Eigen::Index every) {
    auto at = [&](double mid) { return Misfit(d, mid - (1.0 + drift) * t_mid, drift, every); };
    const double a = at(mid0 - h), b = at(mid0), c = at(mid0 + h);
    Profile p;
    p.curvature = (a - 2.0 * b + c) / (h * h);
    p.mid = mid0;
    if (p.curvature > 0.0) p.mid += std::clamp(0.5 * h * (a - c) / (a - 2.0 * b + c), -h, h);
    p.misfit = at(p.mid);
    return p;
  };
  const int half = static_cast<int>(std::ceil(options.max_drift / options.drift_step));
  int k_best = -half;
  double coarse_best = std::numeric_limits<double>::infinity();
  for (int k = -half; k <= half; ++k) {
    const double m = profile(k * options.drift_step, stride).misfit;
    if (m < coarse_best) coarse_best = m, k_best = k;
  }
  double drift = k_best * options.drift_step;
  double drift_curvature = 0.0;
  if (k_best > -half && k_best < half) {
    const double a = profile((k_best - 1) * options.drift_step, 1).misfit;
    const double b = profile(k_best * options.drift_step, 1).misfit;
    const double c = profile((k_best + 1) * options.drift_step, 1).misfit;
    drift_curvature = (a - 2.0 * b + c) / (options.drift_step * options.drift_step);
    if (drift_curvature > 0.0) drift += 0.5 * options.drift_step * (a - c) / (a - 2.0 * b + c);
  }
  const Profile at_best = profile(drift, 1);
  out.drift = drift;
  out.offset_s = at_best.mid - (1.0 + drift) * t_mid;
  // The profile's curvature gives the drift's marginal variance; the offset
  // at t = 0 carries the drift's uncertainty over t_mid.
  out.drift_sigma = drift_curvature > 0.0 ? std::sqrt(2.0 * variance * inflation / drift_curvature)
                                          : options.drift_step;
  const double mid_sigma =
      at_best.curvature > 0.0 ? std::sqrt(2.0 * variance * inflation / at_best.curvature) : h;
  out.offset_sigma_s = std::hypot(mid_sigma, t_mid * out.drift_sigma);
  out.note =
      stats + "; drift profiled over ±" + FormatNumber("%.4g", options.max_drift * 1e6) + " ppm";
  return out;
}

}  // namespace

ClockFit AlignByKinematics(const sim::ArmModel& model, const std::vector<double>& mocap_time_s,
                           const std::vector<double>& angles, const Eigen::VectorXd& log_time_s,
                           const Eigen::MatrixXd& log_length_change_m,
                           const KinematicAlignmentOptions& options, const std::string& source) {
  const int joints = model.num_joints();
  const int cables = model.num_cables();
  CheckLogAgainstArm(model, mocap_time_s, angles, log_length_change_m, source);
  // Kinematic pulled-in lengths of the frames with every angle measured.
  const std::vector<sim::LinkPose> straight =
      sim::ForwardKinematics(model, sim::JointAngles(joints, Eigen::Vector2d::Zero()));
  std::vector<double> rest(cables);
  for (int c = 0; c < cables; ++c) rest[c] = sim::CablePathLength(model, c, straight);
  AlignmentData d;
  std::vector<double> rows;
  for (std::size_t f = 0; f < mocap_time_s.size(); ++f) {
    sim::JointAngles theta(joints);
    bool finite = true;
    for (int j = 0; j < joints; ++j) {
      theta[j] = Eigen::Vector2d(angles[(f * joints + j) * 2], angles[(f * joints + j) * 2 + 1]);
      finite = finite && theta[j].allFinite();
    }
    if (!finite) continue;
    const std::vector<sim::LinkPose> poses = sim::ForwardKinematics(model, theta);
    d.times.push_back(mocap_time_s[f]);
    for (int c = 0; c < cables; ++c)
      rows.push_back(rest[c] - sim::CablePathLength(model, c, poses));
  }
  const Eigen::Index frames = static_cast<Eigen::Index>(d.times.size());
  CheckFramesToAlign(frames, source);
  d.measured =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          rows.data(), frames, cables);
  // The motion must move the cables by more than measurement noise; 0.1 mm
  // is below the marker noise's effect on path lengths.
  const double motion =
      (d.measured.colwise().maxCoeff() - d.measured.colwise().minCoeff()).maxCoeff();
  if (!(motion > 1e-4)) {
    ThrowInputError(source, "/measured/joint_angles",
                    "the measured motion changes no cable path by more than 0.1 mm: nothing to "
                    "align the clocks on (give --sync offset=S or a trigger)");
  }
  d.reference_time = log_time_s;
  d.reference = log_length_change_m;
  d.affine = true;
  ClockFit out =
      AlignToReference(d, options,
                       std::to_string(frames) + " frames, " + std::to_string(cables) +
                           " cables; kinematic path change vs log (quasi-static arm) [m]",
                       source);
  out.method = "estimate";
  return out;
}

ClockFit AlignBySimulation(const sim::ArmModel& model, const sim::ArmParameters& parameters,
                           const sim::SolverConfig& solver, const std::vector<double>& mocap_time_s,
                           const std::vector<double>& angles, const Eigen::VectorXd& log_time_s,
                           const Eigen::MatrixXd& log_length_change_m,
                           const KinematicAlignmentOptions& options, const std::string& source) {
  CheckLogAgainstArm(model, mocap_time_s, angles, log_length_change_m, source);
  const int joints = model.num_joints();
  AlignmentData d;
  std::vector<double> rows;
  for (std::size_t f = 0; f < mocap_time_s.size(); ++f) {
    const double* a = &angles[f * joints * 2];
    if (!std::all_of(a, a + joints * 2, [](double x) { return std::isfinite(x); })) continue;
    d.times.push_back(mocap_time_s[f]);
    rows.insert(rows.end(), a, a + joints * 2);
  }
  const Eigen::Index frames = static_cast<Eigen::Index>(d.times.size());
  CheckFramesToAlign(frames, source);
  d.measured =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          rows.data(), frames, joints * 2);
  // The motion must exceed the angles' noise (about 0.03°) many times over.
  const double motion =
      (d.measured.colwise().maxCoeff() - d.measured.colwise().minCoeff()).maxCoeff();
  if (!(motion > 1e-3 * M_PI / 180.0 * 100.0)) {
    ThrowInputError(source, "/measured/joint_angles",
                    "the measured motion moves no joint by more than 0.1 deg: nothing to align "
                    "the clocks on (give --sync offset=S or a trigger)");
  }
  // One run from rest at the log's first sample (its zero: the arm
  // straight), driven by the log on its own clock. The arm is
  // time-invariant, so the response to the inputs shifted by δ is this one
  // shifted by δ: one run serves every offset.
  const double t0 = log_time_s[0];
  const int cables = model.num_cables();
  sim::RecordedInputs record;
  record.source_name = source;
  record.time_name = "time";
  for (int c = 0; c < cables; ++c) record.cable_names.push_back("cable" + std::to_string(c + 1));
  record.time_s = log_time_s.array() - t0;
  record.length_change_m = log_length_change_m;
  // Frame step of the mocap, which the simulated angles are compared at.
  const double frame_step = (d.times.back() - d.times.front()) /
                            static_cast<double>(std::max<Eigen::Index>(1, frames - 1));
  // The log resampled onto a grid of one mocap frame (linear interpolation):
  // the spline through a fast log's jittered stamps would turn 0.1 ms of
  // jitter at 2 ms steps into accelerations of 0.1 m/s² (and the solver's
  // steps short); at 10 ms steps they are 25 times smaller, while the
  // motions the angles can show (below the arm's first mode, ~1 Hz) are
  // kept.
  sim::RecordedInputOptions resampling;
  resampling.resample_step_s = frame_step;
  resampling.regular_step_tolerance = 0.0;  // always resampled
  const sim::CableInputs inputs = sim::MakeRecordedCableInputs(record, cables, resampling);
  sim::SimulationOptions run;
  run.duration_s = inputs.end_time();
  run.solver = solver;
  // Simulated frames at half the mocap frame step: linear interpolation
  // between them errs by far less than the angles' noise for motions below
  // the arm's first mode.
  const double sample_step = 0.5 * frame_step;
  for (double t = 0.0; t <= run.duration_s; t += sample_step) run.sample_times.push_back(t);
  const sim::SimulationResult result = sim::Simulate(model, parameters, inputs, run);
  if (!result.summary.completed() || result.trajectory.size() < 2) {
    ThrowInputError(source, "--sync estimate",
                    "the simulation of the logged inputs did not complete (" +
                        result.summary.message +
                        "): use --sync estimate-kinematic, a trigger or --sync offset=S");
  }
  const sim::Trajectory& trajectory = result.trajectory;
  d.reference_time.resize(static_cast<Eigen::Index>(trajectory.size()));
  d.reference.resize(static_cast<Eigen::Index>(trajectory.size()), joints * 2);
  for (std::size_t s = 0; s < trajectory.size(); ++s) {
    d.reference_time[static_cast<Eigen::Index>(s)] = trajectory.time[s] + t0;
    for (int j = 0; j < joints; ++j) {
      d.reference(static_cast<Eigen::Index>(s), 2 * j) = trajectory.frames[s].joint_angles[j].x();
      d.reference(static_cast<Eigen::Index>(s), 2 * j + 1) =
          trajectory.frames[s].joint_angles[j].y();
    }
  }
  d.affine = false;
  ClockFit out =
      AlignToReference(d, options,
                       std::to_string(frames) + " frames, " + std::to_string(joints) +
                           " joints; measured vs simulated angles (one run of the log, " +
                           FormatNumber("%.3g", result.summary.wall_time_s) + " s) [rad]",
                       source);
  out.method = "estimate";
  return out;
}

Eigen::MatrixXd ResampleOntoMocapTimes(const ClockFit& fit, const std::vector<double>& mocap_time_s,
                                       const Eigen::VectorXd& log_time_s,
                                       const Eigen::MatrixXd& log_length_change_m,
                                       const std::string& source) {
  const Eigen::Index n = log_time_s.size();
  CCSRM_CHECK(n >= 2 && log_length_change_m.rows() == n);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(mocap_time_s.size()), log_length_change_m.cols());
  const double first = fit.MocapTime(log_time_s[0]);
  const double last = fit.MocapTime(log_time_s[n - 1]);
  if (!mocap_time_s.empty() &&
      (mocap_time_s.front() < first - 1e-9 || mocap_time_s.back() > last + 1e-9)) {
    ThrowInputError(source, "actuator log",
                    "covers mocap time " + FormatNumber("%.6g", first) + " to " +
                        FormatNumber("%.6g", last) + " s after alignment (offset " +
                        FormatNumber("%.6g", fit.offset_s) + " s), the markers " +
                        FormatNumber("%.6g", mocap_time_s.front()) + " to " +
                        FormatNumber("%.6g", mocap_time_s.back()) +
                        " s: the log must cover the whole recording");
  }
  for (Eigen::Index c = 0; c < log_length_change_m.cols(); ++c) {
    Eigen::Index hint = 0;
    for (std::size_t f = 0; f < mocap_time_s.size(); ++f) {
      const double t = std::clamp(fit.LogTime(mocap_time_s[f]), log_time_s[0], log_time_s[n - 1]);
      out(static_cast<Eigen::Index>(f), c) =
          Interpolate(log_time_s, log_length_change_m, c, t, &hint);
    }
  }
  return out;
}

}  // namespace ccsrm::mocap
