#include "ccsrm/identify/diagnostics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "statistics.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr double kBand = 1.96;  // two-sided 95 % of a normal

// The longest lag of the whiteness check and of Bartlett's sum [frames]: a
// 1 Hz low-pass on 100 Hz frames correlates about 50 frames.
constexpr int kMaxLag = 200;

// One channel's series over its measured frames (NaN gaps skipped); a
// tracked point's in mm where a joint's are in deg, with no heading.
struct Series {
  std::vector<double> time, residual_deg, angle_deg, rate_degps, heading_deg, input_rate;
  std::vector<double> hold_time;  // time from the middle of the hold, NaN outside holds
  std::vector<int> phase;
};

double Mean(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  return x.empty() ? 0.0 : s / static_cast<double>(x.size());
}

// Autocorrelation of x at lags 1..max_lag (NaN-free, demeaned inside).
std::vector<double> Autocorrelation(const std::vector<double>& x, int max_lag) {
  const double m = Mean(x);
  double c0 = 0.0;
  for (double v : x) c0 += (v - m) * (v - m);
  std::vector<double> rho;
  const std::size_t n = x.size();
  for (int lag = 1; lag <= max_lag && static_cast<std::size_t>(lag) < n; ++lag) {
    double c = 0.0;
    for (std::size_t i = 0; i + static_cast<std::size_t>(lag) < n; ++i) {
      c += (x[i] - m) * (x[i + static_cast<std::size_t>(lag)] - m);
    }
    rho.push_back(c0 > 0.0 ? c / c0 : 0.0);
  }
  return rho;
}

// Correlation of r and s and the number of independent pairs behind it
// (Bartlett: n / (1 + 2 Σ_k ρ_r(k) ρ_s(k)), summed while ρ_r stays positive).
SignalEvidence Correlate(const std::string& name, const std::vector<double>& r,
                         const std::vector<double>& s, const std::vector<double>& rho_r) {
  SignalEvidence out;
  out.signal = name;
  const std::size_t n = r.size();
  if (n < 3 || s.size() != n) return out;
  const double mr = Mean(r), ms = Mean(s);
  double rr = 0.0, ss = 0.0, rs = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    rr += (r[i] - mr) * (r[i] - mr);
    ss += (s[i] - ms) * (s[i] - ms);
    rs += (r[i] - mr) * (s[i] - ms);
  }
  out.value = rr > 0.0 && ss > 0.0 ? rs / std::sqrt(rr * ss) : 0.0;
  const std::vector<double> rho_s = Autocorrelation(s, static_cast<int>(rho_r.size()));
  double sum = 0.0;
  for (std::size_t k = 0; k < rho_r.size() && k < rho_s.size(); ++k) {
    if (!(rho_r[k] > 0.0)) break;
    sum += rho_r[k] * rho_s[k];
  }
  const double pairs = static_cast<double>(n) / std::max(1.0 + 2.0 * sum, 1.0);
  out.band = kBand / std::sqrt(std::max(pairs, 1.0));
  return out;
}

// Central difference of y over t (one-sided at the ends).
std::vector<double> Rate(const std::vector<double>& t, const std::vector<double>& y) {
  const std::size_t n = y.size();
  std::vector<double> d(n, 0.0);
  if (n < 2) return d;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 < n ? i + 1 : n - 1;
    d[i] = t[b] > t[a] ? (y[b] - y[a]) / (t[b] - t[a]) : 0.0;
  }
  return d;
}

double InputRate(const Experiment& e, int cable, double t) {
  double value = 0.0, rate = 0.0, accel = 0.0;
  e.inputs->Evaluate(cable, t, &value, &rate, &accel);
  return rate;
}

}  // namespace

const std::vector<std::string>& ResidualSignalNames() {
  static const std::vector<std::string> names = {
      "rate_sign",  "rate",     "angle",      "heading",    "time",
      "input_rate", "constant", "hold_drift", "hysteresis", "lag"};
  return names;
}

std::string ChannelName(int joint, int axis, const std::string& point) {
  if (!point.empty()) return "point " + point + " " + std::string(1, "xyz"[axis]);
  return "joint " + std::to_string(joint) + (axis == 0 ? " θx" : " θy");
}

const SignalEvidence* ResidualDiagnostics::Pooled(const std::string& signal) const {
  for (const SignalEvidence& s : pooled) {
    if (s.signal == signal) return &s;
  }
  return nullptr;
}

std::vector<ProtocolPhase> ProtocolPhases(const Experiment& e) {
  const std::vector<double>& t = e.sample_time_s;
  std::vector<ProtocolPhase> phases;
  if (t.empty()) return phases;
  std::vector<double> speed(t.size(), 0.0);
  double top = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (int c = 0; c < e.inputs->num_cables(); ++c) {
      speed[i] = std::max(speed[i], std::abs(InputRate(e, c, t[i])));
    }
    top = std::max(top, speed[i]);
  }
  // Runs of still frames at least 0.3 s long are holds; the rest is motion.
  std::vector<bool> still(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) still[i] = !(speed[i] > 0.02 * top);
  std::vector<bool> hold(t.size(), false);
  for (std::size_t i = 0; i < t.size();) {
    std::size_t j = i;
    while (j < t.size() && still[j] == still[i]) ++j;
    if (still[i] && t[j - 1] - t[i] >= 0.3) {
      for (std::size_t k = i; k < j; ++k) hold[k] = true;
    }
    i = j;
  }
  int motions = 0, holds = 0;
  for (std::size_t i = 0; i < t.size();) {
    std::size_t j = i;
    while (j < t.size() && hold[j] == hold[i]) ++j;
    ProtocolPhase p;
    p.name = hold[i] ? "hold " + std::to_string(++holds) : "motion " + std::to_string(++motions);
    p.start_s = t[i] + e.start_time_s;
    p.end_s = t[j - 1] + e.start_time_s;
    phases.push_back(p);
    i = j;
  }
  return phases;
}

namespace {

constexpr int kPlotLags = 20;  // ±20 frames for the cross-correlation plots

// What each frame of an experiment is besides its angles: the input rate of
// the cable that moves most, its protocol phase, and the time from the
// middle of its hold (NaN outside holds).
struct FrameContext {
  std::vector<double> input_rate;
  std::vector<int> phase_of;
  std::vector<double> hold_time;
};

FrameContext FrameContextOf(const Experiment& x, const std::vector<ProtocolPhase>& phases) {
  const std::vector<double>& t = x.sample_time_s;
  const std::size_t frames = t.size();
  int main_cable = 0;
  double widest = -1.0;
  for (int c = 0; c < x.inputs->num_cables(); ++c) {
    const double w =
        x.inputs->length_change().col(c).maxCoeff() - x.inputs->length_change().col(c).minCoeff();
    if (w > widest) widest = w, main_cable = c;
  }
  FrameContext out;
  out.input_rate.resize(frames);
  for (std::size_t f = 0; f < frames; ++f) out.input_rate[f] = InputRate(x, main_cable, t[f]);
  out.phase_of.assign(frames, 0);
  out.hold_time.assign(frames, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t p = 0; p < phases.size(); ++p) {
    const ProtocolPhase& ph = phases[p];
    const double mid = 0.5 * (ph.start_s + ph.end_s);
    for (std::size_t f = 0; f < frames; ++f) {
      const double te = t[f] + x.start_time_s;
      if (te >= ph.start_s - 1e-9 && te <= ph.end_s + 1e-9) {
        out.phase_of[f] = static_cast<int>(p);
        if (ph.name.rfind("hold", 0) == 0) out.hold_time[f] = te - mid;
      }
    }
  }
  return out;
}

// Lag: the shift of the simulated motion that best matches the measured
// (within ±max_shift frames), and the share of the residual it removes.
void DiagnoseLag(const Experiment& x, const Eigen::MatrixXd& sim, ExperimentDiagnostics* ed) {
  const int max_shift = 50;  // ±0.5 s at 100 Hz, in frames
  const std::vector<double>& t = x.sample_time_s;
  const std::size_t frames = t.size();
  double best = std::numeric_limits<double>::infinity(), at_zero = 0.0;
  int best_shift = 0;
  for (int s = -max_shift; s <= max_shift; ++s) {
    double sq = 0.0;
    std::size_t n = 0;
    for (std::size_t f = static_cast<std::size_t>(max_shift);
         f + static_cast<std::size_t>(max_shift) < frames; ++f) {
      const std::size_t g = static_cast<std::size_t>(static_cast<long>(f) - s);
      for (Eigen::Index c = 0; c < sim.cols(); ++c) {
        const double m = x.measured(static_cast<Eigen::Index>(f), c);
        const double v = sim(static_cast<Eigen::Index>(g), c);
        if (!std::isfinite(m) || !std::isfinite(v)) continue;
        sq += (m - v) * (m - v);
        ++n;
      }
    }
    if (n == 0) continue;
    if (s == 0) at_zero = sq;
    if (sq < best) best = sq, best_shift = s;
  }
  const double dt = frames > 1 ? (t.back() - t.front()) / static_cast<double>(frames - 1) : 0.0;
  ed->lag_s = best_shift * dt;
  ed->lag_explained = at_zero > 0.0 ? 1.0 - best / at_zero : 0.0;
}

// Column `col` of the experiment where both the measured and the simulated
// value are finite: the residual, the simulated value and the frame's
// context; of a joint's angle in deg (the residual over the frame's relative
// noise) with the heading (the angles of its axis summed up to the joint), of
// a tracked point's coordinate in mm (its noise is the same at every frame)
// with no heading.
Series ChannelSeries(const Experiment& x, const Eigen::MatrixXd& sim, Eigen::Index col,
                     const FrameContext& context) {
  const bool point = x.IsPointColumn(col);
  const int j = static_cast<int>(col / 2), a = static_cast<int>(col % 2);
  Series s;
  for (std::size_t f = 0; f < x.sample_time_s.size(); ++f) {
    const Eigen::Index row = static_cast<Eigen::Index>(f);
    const double m = x.measured(row, col);
    const double v = sim(row, col);
    if (!std::isfinite(m) || !std::isfinite(v)) continue;
    s.time.push_back(x.sample_time_s[f]);
    s.input_rate.push_back(context.input_rate[f]);
    s.hold_time.push_back(context.hold_time[f]);
    s.phase.push_back(context.phase_of[f]);
    if (point) {
      s.residual_deg.push_back((v - m) * 1e3);
      s.angle_deg.push_back(v * 1e3);
      continue;
    }
    double heading = 0.0;
    bool ok = true;
    for (int k = 0; k <= j; ++k) {
      const double hk = sim(row, 2 * k + a);
      if (!std::isfinite(hk)) ok = false;
      heading += hk;
    }
    // Simulated - measured, over the frame's relative noise: a recording's
    // ends, where the low-pass leaves more noise, weigh what they know.
    s.residual_deg.push_back((v - m) * kDeg * x.noise_deg[static_cast<std::size_t>(j)] /
                             x.NoiseDeg(row, col));
    s.angle_deg.push_back(v * kDeg);
    s.heading_deg.push_back(ok ? heading * kDeg : v * kDeg);
  }
  return s;
}

// The channel's RMS, mean and whiteness (n >= 3 samples). Returns the sum of
// squared residuals [deg^2].
double ChannelStatistics(const Series& s, ChannelDiagnostics* ch) {
  const std::size_t n = s.residual_deg.size();
  double sq = 0.0;
  for (double r : s.residual_deg) sq += r * r;
  ch->rms_deg = std::sqrt(sq / static_cast<double>(n));
  ch->mean_deg = Mean(s.residual_deg);
  ch->autocorrelation = Autocorrelation(s.residual_deg, kMaxLag);
  ch->whiteness_band = kBand / std::sqrt(static_cast<double>(n));
  int outside = 0;
  for (double r : ch->autocorrelation) outside += std::abs(r) > ch->whiteness_band ? 1 : 0;
  ch->lags_outside_band =
      ch->autocorrelation.empty() ? 0.0 : outside / static_cast<double>(ch->autocorrelation.size());
  ch->autocorrelation_time = internal::AutocorrelationTime(s.residual_deg);
  ch->effective_samples = static_cast<double>(n) / ch->autocorrelation_time;
  return sq;
}

// The evidence of one named signal that is not a series (constant, hold
// drift, hysteresis, lag) in the channel.
SignalEvidence StructureEvidence(const std::string& name, const Series& s,
                                 const ExperimentDiagnostics& ed, ChannelDiagnostics* ch) {
  const std::size_t n = s.residual_deg.size();
  SignalEvidence ev;
  ev.signal = name;
  if (name == "constant") {
    ev.value = ch->rms_deg > 0.0 ? ch->mean_deg / ch->rms_deg : 0.0;
    // mean / rms against the mean's standard error sd / sqrt(n_eff).
    ev.band = kBand / std::sqrt(std::max(ch->effective_samples, 1.0));
  } else if (name == "hold_drift") {
    std::vector<double> r, h;
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isfinite(s.hold_time[i]))
        r.push_back(s.residual_deg[i]), h.push_back(s.hold_time[i]);
    }
    ev = Correlate(name, r, h, Autocorrelation(r, kMaxLag));
    ev.signal = name;
    double hh = 0.0, rh = 0.0;
    const double mr = Mean(r);
    for (std::size_t i = 0; i < r.size(); ++i) hh += h[i] * h[i], rh += h[i] * (r[i] - mr);
    ch->hold_drift_degps = hh > 0.0 ? rh / hh : 0.0;
  } else if (name == "hysteresis") {
    double area = 0.0, path = 0.0;
    for (std::size_t i = 1; i < n; ++i) {
      const double d = s.angle_deg[i] - s.angle_deg[i - 1];
      area += 0.5 * (s.residual_deg[i] + s.residual_deg[i - 1]) * d;
      path += std::abs(d);
    }
    ch->hysteresis_deg2 = area;
    // Over the loop, a residual unrelated to the motion's direction
    // averages out; the band is that of a correlation with a ±1 signal.
    ev.value = ch->rms_deg > 0.0 && path > 0.0 ? area / (ch->rms_deg * path) : 0.0;
    ev.band = kBand / std::sqrt(std::max(ch->effective_samples, 1.0));
  } else if (name == "lag") {
    ev.value = ed.lag_explained;
    // A shift explains part of any residual by chance; count it when it
    // removes more than the noise can (a chi-square of one degree of
    // freedom over the channel's independent samples).
    ev.band = 4.0 / std::max(ch->effective_samples, 1.0);
  }
  return ev;
}

// The channel's cross-correlation with each series signal at ±kPlotLags
// frames, as a correlation weighted by the channel's residual energy `sq`,
// added to *curves.
void AddCrossCorrelation(const std::map<std::string, const std::vector<double>*>& signals,
                         const Series& s, double mean_deg, double sq,
                         std::map<std::string, std::vector<double>>* curves) {
  const std::size_t n = s.residual_deg.size();
  std::vector<double> num(2 * kPlotLags + 1);
  for (const auto& [name, sig] : signals) {
    std::fill(num.begin(), num.end(), 0.0);
    const double ms = Mean(*sig), mr = mean_deg;
    for (int k = -kPlotLags; k <= kPlotLags; ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const long jdx = static_cast<long>(i) + k;
        if (jdx < 0 || jdx >= static_cast<long>(n)) continue;
        num[static_cast<std::size_t>(k + kPlotLags)] +=
            (s.residual_deg[i] - mr) * ((*sig)[static_cast<std::size_t>(jdx)] - ms);
      }
    }
    double ss = 0.0;
    for (double v : *sig) ss += (v - ms) * (v - ms);
    double rr = 0.0;
    for (double v : s.residual_deg) rr += (v - mr) * (v - mr);
    const double norm = ss > 0.0 && rr > 0.0 ? sq / std::sqrt(ss * rr) : 0.0;
    std::vector<double>& weighted = (*curves)[name];
    weighted.resize(2 * kPlotLags + 1, 0.0);
    for (std::size_t k = 0; k < weighted.size(); ++k) weighted[k] += num[k] * norm;
  }
}

// The channel's RMS in each protocol phase (NaN where it has no sample).
void PhaseRms(const Series& s, std::size_t phases, ChannelDiagnostics* ch) {
  ch->phase_rms_deg.assign(phases, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> psq(phases, 0.0), pn(phases, 0.0);
  for (std::size_t i = 0; i < s.residual_deg.size(); ++i) {
    psq[static_cast<std::size_t>(s.phase[i])] += s.residual_deg[i] * s.residual_deg[i];
    pn[static_cast<std::size_t>(s.phase[i])] += 1.0;
  }
  for (std::size_t p = 0; p < phases; ++p) {
    if (pn[p] > 0) ch->phase_rms_deg[p] = std::sqrt(psq[p] / pn[p]);
  }
}

// Pooled sums per signal: Σ value·energy, Σ energy, Σ effective pairs.
using EvidencePool = std::map<std::string, std::array<double, 3>>;

// Column `col` of experiment `e`: its statistics and evidence, pooled and
// cross-correlated. Returns the sum of squared residuals [deg^2, or mm^2 of
// a tracked point] (0 for a channel of fewer than 3 samples, which is listed
// without statistics).
double DiagnoseChannel(const Experiment& x, std::size_t e, const Eigen::MatrixXd& sim,
                       Eigen::Index col, const FrameContext& context,
                       const ExperimentDiagnostics& ed, EvidencePool* pool,
                       ResidualDiagnostics* out) {
  Series s = ChannelSeries(x, sim, col, context);
  ChannelDiagnostics ch;
  ch.experiment = e;
  if (x.IsPointColumn(col)) {
    const Eigen::Index k = col - 2 * x.joints;
    ch.point = x.tracked_points[static_cast<std::size_t>(k / 3)].name;
    ch.axis = static_cast<int>(k % 3);
    ch.noise_deg = x.point_noise_mm;
  } else {
    ch.joint = static_cast<int>(col / 2) + 1;
    ch.axis = static_cast<int>(col % 2);
    ch.noise_deg = x.noise_deg[static_cast<std::size_t>(col / 2)];
  }
  ch.samples = s.residual_deg.size();
  const std::size_t n = ch.samples;
  if (n < 3) {
    out->channels.push_back(ch);
    return 0.0;
  }
  s.rate_degps = Rate(s.time, s.angle_deg);
  const double sq = ChannelStatistics(s, &ch);
  double rate_top = 0.0;
  for (double r : s.rate_degps) rate_top = std::max(rate_top, std::abs(r));
  std::vector<double> rate_sign(n);
  for (std::size_t i = 0; i < n; ++i) {
    rate_sign[i] =
        std::abs(s.rate_degps[i]) > 0.05 * rate_top ? (s.rate_degps[i] > 0 ? 1.0 : -1.0) : 0.0;
  }
  std::map<std::string, const std::vector<double>*> signals = {{"rate_sign", &rate_sign},
                                                               {"rate", &s.rate_degps},
                                                               {"angle", &s.angle_deg},
                                                               {"time", &s.time},
                                                               {"input_rate", &s.input_rate}};
  if (!s.heading_deg.empty()) signals["heading"] = &s.heading_deg;
  for (const std::string& name : ResidualSignalNames()) {
    const auto series = signals.find(name);
    SignalEvidence ev;
    ev.signal = name;  // a tracked point has no heading: no evidence, never significant
    if (series != signals.end()) {
      ev = Correlate(name, s.residual_deg, *series->second, ch.autocorrelation);
    } else if (name != "heading") {
      ev = StructureEvidence(name, s, ed, &ch);
    }
    ch.evidence.push_back(ev);
    auto& acc = (*pool)[name];
    acc[0] += ev.value * sq;
    acc[1] += sq;
    const double pairs = ev.band > 0.0 ? std::pow(kBand / ev.band, 2) : 0.0;
    acc[2] += name == "lag" ? ch.effective_samples : pairs;
  }
  AddCrossCorrelation(signals, s, ch.mean_deg, sq, &out->cross_correlation);
  PhaseRms(s, ed.phases.size(), &ch);
  out->channels.push_back(std::move(ch));
  return sq;
}

}  // namespace

ResidualDiagnostics DiagnoseResidual(const std::vector<Experiment>& experiments,
                                     const std::vector<Eigen::MatrixXd>& simulated_rad) {
  ResidualDiagnostics out;
  EvidencePool pool;
  double energy = 0.0;  // Σ squared residuals of the channels with statistics
  double total_sq = 0.0, total_n = 0.0;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Experiment& x = experiments[e];
    ExperimentDiagnostics ed;
    ed.name = x.name;
    ed.phases = ProtocolPhases(x);
    const std::vector<double>& t = x.sample_time_s;
    if (e == 0 && t.size() > 1) {
      const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
      for (int k = -kPlotLags; k <= kPlotLags; ++k) out.lags_s.push_back(k * dt);
    }
    const FrameContext context = FrameContextOf(x, ed.phases);
    DiagnoseLag(x, simulated_rad[e], &ed);
    double exp_sq = 0.0, exp_n = 0.0;
    // Every joint axis, then every tracked point's coordinates (an
    // experiment of tracked points measures no angle: its joint axes have no
    // sample and are left out).
    for (Eigen::Index col = 0; col < x.measured.cols(); ++col) {
      if (!x.tracked_points.empty() && !x.IsPointColumn(col)) continue;
      const double sq = DiagnoseChannel(x, e, simulated_rad[e], col, context, ed, &pool, &out);
      const ChannelDiagnostics& ch = out.channels.back();
      if (ch.samples < 3) continue;
      energy += sq;
      exp_sq += sq;
      exp_n += static_cast<double>(ch.samples);
    }
    ed.rms_deg = exp_n > 0 ? std::sqrt(exp_sq / exp_n) : 0.0;
    total_sq += exp_sq;
    total_n += exp_n;
    out.experiments.push_back(ed);
  }
  for (auto& [name, curve] : out.cross_correlation) {
    for (double& v : curve) v = energy > 0.0 ? v / energy : 0.0;
  }
  for (const std::string& name : ResidualSignalNames()) {
    const auto& acc = pool[name];
    SignalEvidence ev;
    ev.signal = name;
    ev.value = acc[1] > 0.0 ? acc[0] / acc[1] : 0.0;
    ev.band =
        name == "lag" ? 4.0 / std::max(acc[2], 1.0) : kBand / std::sqrt(std::max(acc[2], 1.0));
    out.pooled.push_back(ev);
  }
  for (const ChannelDiagnostics& ch : out.channels) out.effective_samples += ch.effective_samples;
  out.rms_deg = total_n > 0 ? std::sqrt(total_sq / total_n) : 0.0;
  return out;
}

nlohmann::json ToJson(const ResidualDiagnostics& d) {
  using nlohmann::json;
  json j;
  j["rms_deg"] = d.rms_deg;
  j["effective_samples"] = d.effective_samples;
  json pooled = json::object();
  for (const SignalEvidence& s : d.pooled) {
    pooled[s.signal] = {{"value", s.value}, {"band", s.band}, {"significant", s.significant()}};
  }
  j["pooled"] = pooled;
  j["lags_s"] = d.lags_s;
  j["cross_correlation"] = d.cross_correlation;
  json exps = json::array();
  for (const ExperimentDiagnostics& e : d.experiments) {
    json phases = json::array();
    for (const ProtocolPhase& p : e.phases) {
      phases.push_back({{"name", p.name}, {"start_s", p.start_s}, {"end_s", p.end_s}});
    }
    exps.push_back({{"name", e.name},
                    {"rms_deg", e.rms_deg},
                    {"lag_s", e.lag_s},
                    {"lag_explained", e.lag_explained},
                    {"phases", phases}});
  }
  j["experiments"] = exps;
  json channels = json::array();
  for (const ChannelDiagnostics& c : d.channels) {
    json ev = json::object();
    for (const SignalEvidence& s : c.evidence)
      ev[s.signal] = {{"value", s.value}, {"band", s.band}};
    json acf = json::array();
    // The first 50 lags (0.5 s at 100 Hz) are what a whiteness plot shows.
    for (std::size_t k = 0; k < c.autocorrelation.size() && k < 50; ++k) {
      acf.push_back(c.autocorrelation[k]);
    }
    channels.push_back({{"experiment", d.experiments.at(c.experiment).name},
                        {"joint", c.joint},
                        {"point", c.point},
                        {"axis", std::string(1, "xyz"[c.axis])},
                        {"samples", c.samples},
                        {"rms_deg", c.rms_deg},
                        {"mean_deg", c.mean_deg},
                        {"noise_deg", c.noise_deg},
                        {"autocorrelation", acf},
                        {"whiteness_band", c.whiteness_band},
                        {"lags_outside_band", c.lags_outside_band},
                        {"autocorrelation_time", c.autocorrelation_time},
                        {"effective_samples", c.effective_samples},
                        {"hold_drift_degps", c.hold_drift_degps},
                        {"hysteresis_deg2", c.hysteresis_deg2},
                        {"phase_rms_deg", c.phase_rms_deg},
                        {"evidence", ev}});
  }
  j["channels"] = channels;
  return j;
}

}  // namespace ccsrm::identify
