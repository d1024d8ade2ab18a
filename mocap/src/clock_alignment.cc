#include "ccsrm/mocap/clock_alignment.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/kinematics.h"

namespace ccsrm::mocap {
namespace {

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

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
      rejected = "best rejected pairing: residual " + Format("%.3g", fit.rms * 1e3) +
                 " ms, drift " + Format("%.4g", fit.drift * 1e6) + " ppm";
    }
  }
  if (plausible.empty()) {
    ThrowInputError(source, "trigger",
                    "no pairing of the " + std::to_string(m) + " C3D edge(s) with the " +
                        std::to_string(l) +
                        " log edge(s) fits within 5 × the edge timing and a drift below " +
                        Format("%.4g", options.max_drift * 1e6) + " ppm (" + rejected + ")");
  }
  if (plausible.size() > 1) {
    ThrowInputError(
        source, "trigger",
        "ambiguous alignment: " + std::to_string(plausible.size()) +
            " pairings of the edges fit equally well (offsets " +
            Format("%.6g", plausible[0].fit.offset) + " s and " +
            Format("%.6g", plausible[1].fit.offset) +
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
             std::to_string(l) + " in the log), residual RMS " + Format("%.3g", fit.rms * 1e3) +
             " ms" + (with_drift ? "" : ", drift not estimated");
  return out;
}

namespace {

// Per-cable affine misfit of the kinematic lengths `q` (frames × cables)
// against the log at t_log = offset_s + (1 + drift) t: the sum over cables
// of the residual sum of squares of q_k ≈ a_k + b_k · l_k.
double Misfit(const Eigen::MatrixXd& q, const std::vector<double>& t_mocap, double offset_s,
              const Eigen::VectorXd& log_time, const Eigen::MatrixXd& log_length,
              double drift = 0.0) {
  const Eigen::Index frames = q.rows();
  double total = 0.0;
  for (Eigen::Index c = 0; c < q.cols(); ++c) {
    Eigen::Index hint = 0;
    double sl = 0, sq = 0, sll = 0, slq = 0, sqq = 0;
    for (Eigen::Index f = 0; f < frames; ++f) {
      const double l =
          Interpolate(log_time, log_length, c, offset_s + (1.0 + drift) * t_mocap[f], &hint);
      const double y = q(f, c);
      sl += l;
      sq += y;
      sll += l * l;
      slq += l * y;
      sqq += y * y;
    }
    const double n = static_cast<double>(frames);
    const double var_l = sll - sl * sl / n;
    const double cov = slq - sl * sq / n;
    const double var_q = sqq - sq * sq / n;
    // Residual of the best line; a cable the log holds still explains
    // nothing (its residual is var_q).
    total += var_l > 0.0 ? std::max(0.0, var_q - cov * cov / var_l) : var_q;
  }
  return total;
}

}  // namespace

ClockFit AlignByKinematics(const sim::ArmModel& model, const std::vector<double>& mocap_time_s,
                           const std::vector<double>& angles, const Eigen::VectorXd& log_time_s,
                           const Eigen::MatrixXd& log_length_change_m,
                           const KinematicAlignmentOptions& options, const std::string& source) {
  const int joints = model.num_joints();
  const int cables = model.num_cables();
  if (log_length_change_m.cols() != cables) {
    ThrowInputError(source, "cables",
                    "the log has " + std::to_string(log_length_change_m.cols()) +
                        " cable column(s), the arm " + std::to_string(cables));
  }
  CCSRM_CHECK(angles.size() == mocap_time_s.size() * static_cast<std::size_t>(joints) * 2);
  // Kinematic pulled-in lengths of the frames with every angle measured.
  const std::vector<sim::LinkPose> straight =
      sim::ForwardKinematics(model, sim::JointAngles(joints, Eigen::Vector2d::Zero()));
  std::vector<double> rest(cables);
  for (int c = 0; c < cables; ++c) rest[c] = sim::CablePathLength(model, c, straight);
  std::vector<double> times;
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
    times.push_back(mocap_time_s[f]);
    for (int c = 0; c < cables; ++c)
      rows.push_back(rest[c] - sim::CablePathLength(model, c, poses));
  }
  const Eigen::Index frames = static_cast<Eigen::Index>(times.size());
  if (frames < 10) {
    ThrowInputError(source, "/measured/joint_angles",
                    "only " + std::to_string(frames) +
                        " frame(s) with every joint angle measured: too few to align the clocks");
  }
  const Eigen::MatrixXd q =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          rows.data(), frames, cables);
  // The motion must move the cables by more than measurement noise; 0.1 mm
  // is below the marker noise's effect on path lengths.
  const double motion = (q.colwise().maxCoeff() - q.colwise().minCoeff()).maxCoeff();
  if (!(motion > 1e-4)) {
    ThrowInputError(source, "/measured/joint_angles",
                    "the measured motion changes no cable path by more than 0.1 mm: nothing to "
                    "align the clocks on (give --sync offset=S or a trigger)");
  }
  // Offsets that keep every frame inside the log, then inside the window
  // asked for.
  double lo = log_time_s[0] - times.front();
  double hi = log_time_s[log_time_s.size() - 1] - times.back();
  if (!(hi >= lo)) {
    ThrowInputError(source, "actuator log",
                    "covers " + Format("%.6g", log_time_s[log_time_s.size() - 1] - log_time_s[0]) +
                        " s, shorter than the mocap recording (" +
                        Format("%.6g", times.back() - times.front()) + " s)");
  }
  if (std::isfinite(options.search_center_s) && std::isfinite(options.search_half_width_s)) {
    lo = std::max(lo, options.search_center_s - options.search_half_width_s);
    hi = std::min(hi, options.search_center_s + options.search_half_width_s);
    if (!(hi >= lo)) {
      ThrowInputError(source, "actuator log",
                      "no offset within " + Format("%.6g", options.search_half_width_s) + " s of " +
                          Format("%.6g", options.search_center_s) +
                          " s keeps the recording inside the log");
    }
  }
  const double frame_step = (times.back() - times.front()) / static_cast<double>(frames - 1);
  const double step = options.grid_step_s > 0.0 ? options.grid_step_s : frame_step;
  const std::size_t grid = static_cast<std::size_t>(std::floor((hi - lo) / step)) + 1;
  std::vector<double> misfit(grid);
  for (std::size_t i = 0; i < grid; ++i) {
    misfit[i] =
        Misfit(q, times, lo + static_cast<double>(i) * step, log_time_s, log_length_change_m);
  }
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(misfit.begin(), misfit.end()) - misfit.begin());
  // Refine by a parabola through the best grid point and its neighbours.
  double offset = lo + static_cast<double>(best) * step;
  double curvature = 0.0;  // d²misfit/doffset²
  if (best > 0 && best + 1 < grid) {
    const double a = misfit[best - 1], b = misfit[best], c = misfit[best + 1];
    curvature = (a - 2.0 * b + c) / (step * step);
    if (curvature > 0.0) offset += 0.5 * step * (a - c) / (a - 2.0 * b + c);
  }
  const double best_misfit = Misfit(q, times, offset, log_time_s, log_length_change_m);
  // Residual variance: frames × cables values, 2 per cable and the offset fitted.
  const double dof = static_cast<double>(frames * cables - 2 * cables - 1);
  const double variance = std::max(best_misfit, 1e-30) / dof;
  // Ambiguity: another local minimum, far enough away, statistically as good.
  for (std::size_t i = 0; i < grid; ++i) {
    const double t = lo + static_cast<double>(i) * step;
    if (std::abs(t - offset) <= options.ambiguity_separation_s) continue;
    // A local minimum (at the ends of the range, against its one neighbour).
    const bool below_left = i == 0 || misfit[i] <= misfit[i - 1];
    const bool below_right = i + 1 == grid || misfit[i] <= misfit[i + 1];
    if (below_left && below_right &&
        (misfit[i] - best_misfit) / variance < options.ambiguity_chi2) {
      ThrowInputError(source, "--sync estimate",
                      "ambiguous alignment: log offsets " + Format("%.6g", offset) + " s and " +
                          Format("%.6g", t) +
                          " s explain the measured angles equally well (a periodic motion?); "
                          "give a trigger or --sync offset=S");
    }
  }
  ClockFit out;
  out.method = "estimate";
  out.offset_s = offset;
  // Gauss-Newton: misfit ≈ misfit_min + ½ H δ², var(δ) = variance / (½ H).
  out.offset_sigma_s = curvature > 0.0 ? std::sqrt(2.0 * variance / curvature) : step;
  const std::string head = std::to_string(frames) + " frames, " + std::to_string(cables) +
                           " cables; kinematic path change vs log, residual RMS " +
                           Format("%.3g", std::sqrt(variance) * 1e3) + " mm";
  out.note = head + "; drift not estimated";
  if (!options.estimate_drift) return out;

  // Drift: profile the misfit over a grid of drifts, each at its best log
  // time at the recording's middle (where offset and drift are least
  // correlated), found by a parabola through three points half a frame apart
  // around the drift-free one.
  const double t_mid = 0.5 * (times.front() + times.back());
  const double mid0 = offset + t_mid;  // log time at t_mid without drift
  const double h = 0.5 * frame_step;
  struct Profile {
    double misfit = 0.0;
    double mid = 0.0;
    double curvature = 0.0;  // d²misfit/dmid²
  };
  auto profile = [&](double drift) {
    auto at = [&](double mid) {
      return Misfit(q, times, mid - (1.0 + drift) * t_mid, log_time_s, log_length_change_m, drift);
    };
    const double a = at(mid0 - h), b = at(mid0), c = at(mid0 + h);
    Profile p;
    p.curvature = (a - 2.0 * b + c) / (h * h);
    p.mid = mid0;
    if (p.curvature > 0.0) p.mid += std::clamp(0.5 * h * (a - c) / (a - 2.0 * b + c), -h, h);
    p.misfit = at(p.mid);
    return p;
  };
  const int half = static_cast<int>(std::ceil(options.max_drift / options.drift_step));
  std::vector<Profile> profiles;
  for (int k = -half; k <= half; ++k) profiles.push_back(profile(k * options.drift_step));
  std::size_t k_best = 0;
  for (std::size_t k = 1; k < profiles.size(); ++k) {
    if (profiles[k].misfit < profiles[k_best].misfit) k_best = k;
  }
  double drift = (static_cast<int>(k_best) - half) * options.drift_step;
  double drift_curvature = 0.0;
  if (k_best > 0 && k_best + 1 < profiles.size()) {
    const double a = profiles[k_best - 1].misfit, b = profiles[k_best].misfit,
                 c = profiles[k_best + 1].misfit;
    drift_curvature = (a - 2.0 * b + c) / (options.drift_step * options.drift_step);
    if (drift_curvature > 0.0) drift += 0.5 * options.drift_step * (a - c) / (a - 2.0 * b + c);
  }
  const Profile at_best = profile(drift);
  out.drift = drift;
  out.offset_s = at_best.mid - (1.0 + drift) * t_mid;
  // The profile's curvature gives the drift's marginal variance; the offset
  // at t = 0 carries the drift's uncertainty over t_mid.
  out.drift_sigma =
      drift_curvature > 0.0 ? std::sqrt(2.0 * variance / drift_curvature) : options.drift_step;
  const double mid_sigma =
      at_best.curvature > 0.0 ? std::sqrt(2.0 * variance / at_best.curvature) : h;
  out.offset_sigma_s = std::hypot(mid_sigma, t_mid * out.drift_sigma);
  out.note = head + "; drift profiled over ±" + Format("%.4g", options.max_drift * 1e6) + " ppm";
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
                    "covers mocap time " + Format("%.6g", first) + " to " + Format("%.6g", last) +
                        " s after alignment (offset " + Format("%.6g", fit.offset_s) +
                        " s), the markers " + Format("%.6g", mocap_time_s.front()) + " to " +
                        Format("%.6g", mocap_time_s.back()) +
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
