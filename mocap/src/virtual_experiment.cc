#include "ccsrm/mocap/virtual_experiment.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/rigid_bodies.h"

namespace ccsrm::mocap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Start frames of a Poisson process with `per_frame` expected events per
// frame over [0, frames).
std::vector<std::size_t> PoissonStarts(double per_frame, std::size_t frames, std::mt19937_64& rng) {
  std::vector<std::size_t> starts;
  if (!(per_frame > 0.0)) return starts;
  std::exponential_distribution<double> wait(per_frame);
  double t = wait(rng);
  while (t < static_cast<double>(frames)) {
    starts.push_back(static_cast<std::size_t>(t));
    t += wait(rng);
  }
  return starts;
}

}  // namespace

bool OcclusionOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(marker_gap_rate_per_s >= 0.0) || !std::isfinite(marker_gap_rate_per_s)) {
    return fail("marker_gap_rate_per_s must be >= 0");
  }
  if (min_gap_frames < 1 || max_gap_frames < min_gap_frames) {
    return fail("gap lengths must satisfy 1 <= min_gap_frames <= max_gap_frames");
  }
  if (!(link_loss_rate_per_s >= 0.0) || !std::isfinite(link_loss_rate_per_s)) {
    return fail("link_loss_rate_per_s must be >= 0");
  }
  if (min_link_loss_frames < 1 || max_link_loss_frames < min_link_loss_frames) {
    return fail("link-loss lengths must satisfy 1 <= min_link_loss_frames <= max_link_loss_frames");
  }
  return true;
}

bool VirtualRecordingOptions::IsValid(std::string* error) const {
  if (!(noise_sigma_m >= 0.0) || !std::isfinite(noise_sigma_m)) {
    if (error != nullptr) *error = "noise_sigma_m must be >= 0";
    return false;
  }
  if (!(resolution_m >= 0.0 && resolution_m <= 1e-3)) {
    if (error != nullptr) *error = "resolution_m must be in [0, 1e-3] m";
    return false;
  }
  return occlusions.IsValid(error);
}

datasets::Array MarkersFromLinkPoses(const MarkerLayout& layout, const datasets::Array& link_pose) {
  CCSRM_CHECK(link_pose.rank() == 3 && link_pose.shape[2] == 7);
  const std::size_t F = link_pose.shape[0];
  const std::size_t L = link_pose.shape[1];
  const std::size_t K = layout.marker_count();
  datasets::Array markers({F, K, 3});
  std::vector<sim::LinkPose> poses(L);
  for (std::size_t f = 0; f < F; ++f) {
    for (std::size_t l = 0; l < L; ++l) {
      poses[l].p_WB =
          Eigen::Vector3d(link_pose.at(f, l, 0), link_pose.at(f, l, 1), link_pose.at(f, l, 2));
      Eigen::Quaterniond q(link_pose.at(f, l, 3), link_pose.at(f, l, 4), link_pose.at(f, l, 5),
                           link_pose.at(f, l, 6));
      poses[l].R_WB = q.normalized().toRotationMatrix();
    }
    const std::vector<Eigen::Vector3d> p_WM = PlaceMarkers(layout, poses);
    for (std::size_t k = 0; k < K; ++k) {
      for (std::size_t axis = 0; axis < 3; ++axis) {
        markers.at(f, k, axis) = p_WM[k][static_cast<int>(axis)];
      }
    }
  }
  return markers;
}

datasets::Array RecordMarkers(const datasets::Array& clean, const MarkerLayout& layout,
                              double rate_hz, const VirtualRecordingOptions& options,
                              VirtualRecordingSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("virtual recording", "options", error);
  if (!(rate_hz > 0.0)) ThrowInputError("virtual recording", "rate", "must be > 0 Hz");
  CCSRM_CHECK(clean.rank() == 3 && clean.shape[1] == layout.marker_count() && clean.shape[2] == 3);
  const std::size_t F = clean.shape[0];
  const std::size_t K = clean.shape[1];
  std::mt19937_64 rng(options.seed);
  datasets::Array recorded = clean;
  // Noise first, for every sample in a fixed order, so the noise of a sample
  // does not depend on the occlusion settings.
  std::normal_distribution<double> noise(0.0, 1.0);
  for (double& value : recorded.values) value += options.noise_sigma_m * noise(rng);
  if (options.resolution_m > 0.0) {
    const int exponent = static_cast<int>(std::floor(std::log2(options.resolution_m)));
    for (double& value : recorded.values) {
      value = std::ldexp(std::nearbyint(std::ldexp(value, -exponent)), exponent);
    }
  }

  VirtualRecordingSummary s;
  const OcclusionOptions& o = options.occlusions;
  if (o.enabled) {
    auto hide = [&](std::size_t first, std::size_t length, std::size_t k) {
      for (std::size_t f = first; f < std::min(F, first + length); ++f) {
        for (std::size_t axis = 0; axis < 3; ++axis) recorded.at(f, k, axis) = kNaN;
      }
    };
    std::uniform_int_distribution<int> gap_length(o.min_gap_frames, o.max_gap_frames);
    for (std::size_t k = 0; k < K; ++k) {
      for (const std::size_t start : PoissonStarts(o.marker_gap_rate_per_s / rate_hz, F, rng)) {
        hide(start, static_cast<std::size_t>(gap_length(rng)), k);
        ++s.marker_gaps;
      }
    }
    std::uniform_int_distribution<int> loss_length(o.min_link_loss_frames, o.max_link_loss_frames);
    std::size_t k0 = 0;
    for (const RigidBody& body : layout.bodies) {
      const std::size_t n = body.marker_names.size();
      if (body.link != 0) {
        std::vector<bool> lost(F, false);
        for (const std::size_t start : PoissonStarts(o.link_loss_rate_per_s / rate_hz, F, rng)) {
          const std::size_t length = static_cast<std::size_t>(loss_length(rng));
          for (std::size_t m = 0; m < n; ++m) hide(start, length, k0 + m);
          for (std::size_t f = start; f < std::min(F, start + length); ++f) lost[f] = true;
          ++s.link_losses;
        }
        s.link_loss_frames += static_cast<std::size_t>(std::count(lost.begin(), lost.end(), true));
      }
      k0 += n;
    }
    for (std::size_t i = 0; i < recorded.values.size(); i += 3) {
      s.hidden_samples += std::isnan(recorded.values[i]);
    }
    s.hidden_fraction = F * K > 0 ? static_cast<double>(s.hidden_samples) / double(F * K) : 0.0;
  }
  if (summary != nullptr) *summary = s;
  return recorded;
}

VirtualExperiment MakeVirtualExperiment(const datasets::RunFile& run, const MarkerLayout& layout,
                                        const VirtualExperimentOptions& options) {
  ValidateMarkerLayout(layout, "marker layout");
  const std::size_t F = run.frames();
  if (F < 2) ThrowInputError("virtual experiment", "run", "needs at least two frames");
  const double rate_hz =
      static_cast<double>(F - 1) / (run.time.values.back() - run.time.values.front());
  VirtualExperiment out;
  out.truth = run;
  const datasets::Array clean = MarkersFromLinkPoses(layout, run.link_pose);
  out.truth.markers = clean;
  out.truth.marker_names = layout.MarkerNames();

  datasets::ExperimentFile& e = out.experiment;
  e.name = options.name;
  e.description = options.description;
  e.source = datasets::ExperimentSource::kGenerated;
  e.config_yaml = options.nominal_config_yaml;
  e.input_time = run.time;
  e.input_length_change = run.input_length_change;
  e.mocap_time = run.time;
  e.mocap_markers = RecordMarkers(clean, layout, rate_hz, options.recording, &out.recording);
  e.marker_names = layout.MarkerNames();
  e.rigid_bodies = ToExperimentRigidBodies(layout);
  return out;
}

}  // namespace ccsrm::mocap
