#include "ccsrm/identify/adequacy.h"

#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>

#include "statistics.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

double Ratio(const ChannelAboveNoise& c) { return c.rms_deg / c.noise_deg; }

}  // namespace

const ChannelAboveNoise* ModelAdequacy::Worst() const {
  const ChannelAboveNoise* worst = nullptr;
  for (const ChannelAboveNoise& c : above_noise) {
    if (worst == nullptr || Ratio(c) > Ratio(*worst)) worst = &c;
  }
  return worst;
}

double ModelAdequacy::misfit_scale() const {
  const ChannelAboveNoise* worst = Worst();
  return worst != nullptr ? std::max(1.0, Ratio(*worst)) : 1.0;
}

std::string ModelAdequacy::Verdict() const {
  if (!assessed) return "the model was not judged: no complete run to compare with the data";
  if (above_noise.empty()) {
    return Format(
        "the model explains the data: no joint axis stands above its noise (%zu tested, the "
        "largest RMS residual %.2fx its noise; above means beyond %gx and beyond chance)",
        channels, worst_ratio, above_noise_ratio);
  }
  const ChannelAboveNoise& w = *Worst();
  return Format(
      "the model does NOT explain the data: %zu of %zu joint axes stand above their noise "
      "(worst: %s joint %d %s, %.4f deg RMS against %.4f deg of noise, %.2fx)",
      above_noise.size(), channels, w.recording.c_str(), w.joint, w.axis == 0 ? "θx" : "θy",
      w.rms_deg, w.noise_deg, Ratio(w));
}

ModelAdequacy AssessModelAdequacy(const std::vector<const Experiment*>& recordings,
                                  const std::vector<const Eigen::MatrixXd*>& simulated,
                                  double above_noise_ratio, double significance) {
  ModelAdequacy out;
  out.above_noise_ratio = above_noise_ratio;
  out.significance = significance;
  std::vector<ChannelAboveNoise> tested;
  std::vector<bool> large;
  for (std::size_t e = 0; e < recordings.size() && e < simulated.size(); ++e) {
    const Experiment& x = *recordings[e];
    const Eigen::MatrixXd& sim = *simulated[e];
    if (sim.rows() != x.measured_rad.rows() || sim.cols() != x.measured_rad.cols()) continue;
    for (int j = 0; j < x.joints; ++j) {
      const std::size_t jj = static_cast<std::size_t>(j);
      for (int a = 0; a < 2; ++a) {
        std::vector<double> weighted;
        double sum = 0.0;
        for (Eigen::Index f = 0; f < x.measured_rad.rows(); ++f) {
          const double m = x.measured_rad(f, 2 * j + a);
          if (!std::isfinite(m)) continue;
          const double w = (sim(f, 2 * j + a) - m) * kDeg / x.NoiseDeg(f, 2 * j + a);
          weighted.push_back(w);
          sum += w * w;
        }
        if (weighted.empty()) continue;
        ChannelAboveNoise c;
        c.recording = x.name;
        c.joint = j + 1;
        c.axis = a;
        const double n = static_cast<double>(weighted.size());
        c.noise_deg = x.noise_deg[jj];
        c.rms_deg = std::sqrt(sum / n) * c.noise_deg;
        c.effective_samples = internal::EffectiveSampleSize({weighted});
        c.noise_effective_samples =
            jj < x.noise_effective_samples.size() ? x.noise_effective_samples[jj] : INFINITY;
        // A run that ended early leaves NaN: never noise.
        c.p_value = !std::isfinite(sum) ? 0.0
                    : std::isfinite(c.noise_effective_samples)
                        ? gsl_cdf_fdist_Q(sum / n, c.effective_samples, c.noise_effective_samples)
                        : gsl_cdf_chisq_Q(sum * c.effective_samples / n, c.effective_samples);
        out.worst_ratio = std::isfinite(sum) ? std::max(out.worst_ratio, Ratio(c)) : INFINITY;
        large.push_back(!(c.rms_deg <= above_noise_ratio * c.noise_deg));
        tested.push_back(c);
      }
    }
  }
  out.assessed = !tested.empty();
  out.channels = tested.size();
  for (std::size_t k = 0; k < tested.size(); ++k) {
    if (large[k] && tested[k].p_value < significance / static_cast<double>(tested.size())) {
      out.above_noise.push_back(tested[k]);
    }
  }
  return out;
}

nlohmann::json ToJson(const ModelAdequacy& a) {
  nlohmann::json above = nlohmann::json::array();
  for (const ChannelAboveNoise& c : a.above_noise) {
    above.push_back({{"recording", c.recording},
                     {"joint", c.joint},
                     {"axis", c.axis == 0 ? "x" : "y"},
                     {"rms_deg", c.rms_deg},
                     {"noise_deg", c.noise_deg},
                     {"effective_samples", c.effective_samples},
                     {"noise_effective_samples", std::isfinite(c.noise_effective_samples)
                                                     ? nlohmann::json(c.noise_effective_samples)
                                                     : nlohmann::json(nullptr)},
                     {"p_value", c.p_value}});
  }
  return {{"assessed", a.assessed},
          {"adequate", a.adequate()},
          {"verdict", a.Verdict()},
          {"above_noise_ratio", a.above_noise_ratio},
          {"significance", a.significance},
          {"channels", a.channels},
          {"worst_ratio", std::isfinite(a.worst_ratio) ? nlohmann::json(a.worst_ratio) : nullptr},
          {"misfit_scale", a.misfit_scale()},
          {"above_noise", above}};
}

}  // namespace ccsrm::identify
