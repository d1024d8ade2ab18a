#pragma once
// Whether a model explains recorded joint angles (issue 44): each channel's
// residual (recording, joint, axis) against the noise measured independently
// of the model, the mocap pipeline's estimate (Experiment::noise_deg: the
// loop's noise floor). A fit can converge on a wrong model and give tight
// intervals around a biased value; this is what says so. Identification,
// prediction and the loop judge by the same rule.
#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"

namespace ccsrm::identify {

// A channel stands above its noise when both hold: its RMS residual exceeds
// kAboveNoiseRatio times its measurement noise (a size worth naming: the
// noise estimate itself is good to a fifth or so), and the residual is not
// noise by chance. Mocap residuals are filtered, so a channel's N frames
// carry N_eff independent samples (N over the residual's integrated
// autocorrelation time: its whiteness), and Σ r² N_eff / N of the weighted
// residuals r is then a chi-square of N_eff degrees of freedom; its p-value
// must be below kAboveNoiseSignificance over the number of channels
// (Bonferroni, family-wise; the loop's score_significance). On a few
// seconds of 1 Hz-filtered mocap a channel has N_eff of about 7, and its RMS
// alone scatters by a quarter around the noise. A noise estimated from the
// recording (the twist's scatter, Experiment::noise_effective_samples) is
// itself uncertain: 10 s of filtered twist hold 15 or so independent
// samples, a noise known to a fifth. The mean square Σ r² / N is then the
// ratio of two estimated variances, an F of (N_eff, the noise's N_eff)
// degrees of freedom, and that is the test (a given noise: chi-square).
inline constexpr double kAboveNoiseRatio = 1.5;
inline constexpr double kAboveNoiseSignificance = 0.01;

// A channel whose residual stands above its noise.
struct ChannelAboveNoise {
  std::string recording;
  int joint = 0;  // 1-based; 0 for a tracked point's coordinate
  int axis = 0;   // 0 θx, 1 θy; of a tracked point 0 x, 1 y, 2 z
  // A tracked point's name (Experiment::tracked_points): rms_deg and
  // noise_deg are then in mm.
  std::string point;
  double rms_deg = 0.0;
  double noise_deg = 0.0;
  double effective_samples = 0.0;        // N_eff of its residual
  double noise_effective_samples = 0.0;  // of its noise estimate; inf: given
  double p_value = 0.0;                  // of its F (or chi-square) as noise
};

// "joint 3 θx, 0.0412 deg RMS against 0.0300 deg of noise", or the same of
// a tracked point's coordinate in mm.
std::string Describe(const ChannelAboveNoise& channel);

struct ModelAdequacy {
  bool assessed = false;  // false: no complete run to compare
  double above_noise_ratio = kAboveNoiseRatio;
  double significance = kAboveNoiseSignificance;  // family-wise, over `channels`
  // tested: recordings × joints × 2 with a measured sample, and of those
  // tracked points' coordinates
  std::size_t channels = 0;
  std::size_t point_channels = 0;
  std::vector<ChannelAboveNoise> above_noise;  // in channel order
  // The largest RMS residual over noise of any channel (1 at the noise).
  double worst_ratio = 0.0;

  bool adequate() const { return assessed && above_noise.empty(); }
  // The channel above the noise with the largest RMS over noise; null when
  // there is none.
  const ChannelAboveNoise* Worst() const;
  // The factor a fit's intervals widen by when the residual is not noise:
  // the worst channel's RMS over its noise (1 when the model is adequate).
  // The intervals of a fit assume the residual is the noise; where it is
  // not, a channel's excess is error the model makes, and counting it as
  // noise of that size is the least the intervals must allow.
  double misfit_scale() const;
  // One line: "the model explains the data: ..." or "the model does NOT
  // explain the data: N of M joint axes stand above their noise (worst:
  // ...)".
  std::string Verdict() const;
};

// Judges `simulated` (one matrix per recording, laid out and made comparable
// as Experiment::measured) against the recordings' measured angles.
ModelAdequacy AssessModelAdequacy(const std::vector<const Experiment*>& recordings,
                                  const std::vector<const Eigen::MatrixXd*>& simulated,
                                  double above_noise_ratio = kAboveNoiseRatio,
                                  double significance = kAboveNoiseSignificance);

// {"adequate", "verdict", "above_noise_ratio", "significance", "channels",
// "worst_ratio", "misfit_scale", "above_noise": [...]}.
nlohmann::json ToJson(const ModelAdequacy& adequacy);

}  // namespace ccsrm::identify
