#include "ccsrm/identify/adequacy.h"

#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>

#include "ccsrm/identify/diagnostics.h"
#include "statistics.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

double Ratio(const ChannelAboveNoise& c) { return c.rms_deg / c.noise_deg; }

}  // namespace

std::string Describe(const ChannelAboveNoise& c) {
  const std::string name = ChannelName(c.joint, c.axis, c.point);
  if (!c.point.empty()) {
    return name + Format(", %.3f mm RMS against %.3f mm of noise", c.rms_deg, c.noise_deg);
  }
  return name + Format(", %.4f deg RMS against %.4f deg of noise", c.rms_deg, c.noise_deg);
}

namespace {

// The channel's test as noise: its weighted residuals' mean square against
// the noise's F (or chi-square without a noise estimate's own samples).
void TestAsNoise(const std::vector<double>& weighted, double above_noise_ratio,
                 ChannelAboveNoise* c, ModelAdequacy* out, std::vector<bool>* large) {
  double sum = 0.0;
  for (const double w : weighted) sum += w * w;
  const double n = static_cast<double>(weighted.size());
  c->rms_deg = std::sqrt(sum / n) * c->noise_deg;
  c->effective_samples = internal::EffectiveSampleSize({weighted});
  // A run that ended early leaves NaN: never noise.
  c->p_value = !std::isfinite(sum) ? 0.0
               : std::isfinite(c->noise_effective_samples)
                   ? gsl_cdf_fdist_Q(sum / n, c->effective_samples, c->noise_effective_samples)
                   : gsl_cdf_chisq_Q(sum * c->effective_samples / n, c->effective_samples);
  out->worst_ratio = std::isfinite(sum) ? std::max(out->worst_ratio, Ratio(*c)) : INFINITY;
  large->push_back(!(c->rms_deg <= above_noise_ratio * c->noise_deg));
}

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
        "the model explains the data: no %s stands above its noise (%zu tested, the "
        "largest RMS residual %.2fx its noise; above means beyond %gx and beyond chance)",
        point_channels > 0 ? "measured axis" : "joint axis", channels, worst_ratio,
        above_noise_ratio);
  }
  const ChannelAboveNoise& w = *Worst();
  return Format(
      "the model does NOT explain the data: %zu of %zu %s stand above their noise "
      "(worst: %s %s, %.2fx)",
      above_noise.size(), channels, point_channels > 0 ? "measured axes" : "joint axes",
      w.recording.c_str(), Describe(w).c_str(), Ratio(w));
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
    if (sim.rows() != x.measured.rows() || sim.cols() != x.measured.cols()) continue;
    const auto weighted_column = [&](Eigen::Index column) {
      std::vector<double> weighted;
      for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
        if (std::isfinite(x.measured(f, column))) {
          weighted.push_back(x.WeightedResidual(f, column, sim(f, column)));
        }
      }
      return weighted;
    };
    for (int j = 0; j < x.joints; ++j) {
      const std::size_t jj = static_cast<std::size_t>(j);
      for (int a = 0; a < 2; ++a) {
        const std::vector<double> weighted = weighted_column(2 * j + a);
        if (weighted.empty()) continue;
        ChannelAboveNoise c;
        c.recording = x.name;
        c.joint = j + 1;
        c.axis = a;
        c.noise_deg = x.noise_deg[jj];
        c.noise_effective_samples =
            jj < x.noise_effective_samples.size() ? x.noise_effective_samples[jj] : INFINITY;
        TestAsNoise(weighted, above_noise_ratio, &c, &out, &large);
        tested.push_back(c);
      }
    }
    for (std::size_t p = 0; p < x.tracked_points.size(); ++p) {
      for (int a = 0; a < 3; ++a) {
        const std::vector<double> weighted =
            weighted_column(2 * x.joints + 3 * static_cast<Eigen::Index>(p) + a);
        if (weighted.empty()) continue;
        ChannelAboveNoise c;
        c.recording = x.name;
        c.point = x.tracked_points[p].name;
        c.axis = a;
        c.noise_deg = x.point_noise_mm;
        c.noise_effective_samples = INFINITY;  // a stated noise
        TestAsNoise(weighted, above_noise_ratio, &c, &out, &large);
        tested.push_back(c);
      }
    }
  }
  out.assessed = !tested.empty();
  out.channels = tested.size();
  out.point_channels = static_cast<std::size_t>(std::count_if(
      tested.begin(), tested.end(), [](const ChannelAboveNoise& c) { return !c.point.empty(); }));
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
                     {"point", c.point},
                     {"axis", std::string(1, "xyz"[c.axis])},
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
