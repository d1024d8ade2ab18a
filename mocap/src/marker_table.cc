#include "ccsrm/mocap/marker_table.h"

#include <cmath>
#include <limits>
#include <utility>

#include "ccsrm/common/error.h"

namespace ccsrm::mocap {

Eigen::Vector3d MarkerTable::position(std::size_t frame, std::size_t marker) const {
  CCSRM_CHECK(frame < frames() && marker < markers());
  const std::size_t i = (frame * markers() + marker) * 3;
  return Eigen::Vector3d(positions_m[i], positions_m[i + 1], positions_m[i + 2]);
}

bool MarkerTable::is_valid(std::size_t frame, std::size_t marker) const {
  CCSRM_CHECK(frame < frames() && marker < markers());
  const std::size_t i = (frame * markers() + marker) * 3;
  return std::isfinite(positions_m[i]) && std::isfinite(positions_m[i + 1]) &&
         std::isfinite(positions_m[i + 2]);
}

std::optional<std::size_t> MarkerTable::index_of(const std::string& label) const {
  for (std::size_t m = 0; m < labels.size(); ++m) {
    if (labels[m] == label) return m;
  }
  return std::nullopt;
}

void MarkerTable::Reset(std::size_t frames, std::vector<std::string> marker_labels,
                        bool with_residual) {
  labels = std::move(marker_labels);
  frame_count = frames;
  const std::size_t samples = frames * labels.size();
  positions_m.assign(samples * 3, std::numeric_limits<double>::quiet_NaN());
  has_residual = with_residual;
  if (with_residual) {
    residual_m.assign(samples, -1.0);
    camera_mask.assign(samples, 0);
  } else {
    residual_m.clear();
    camera_mask.clear();
  }
}

void MarkerTable::set_position(std::size_t frame, std::size_t marker, const Eigen::Vector3d& p_m) {
  CCSRM_CHECK(frame < frames() && marker < markers());
  const std::size_t i = (frame * markers() + marker) * 3;
  positions_m[i] = p_m.x();
  positions_m[i + 1] = p_m.y();
  positions_m[i + 2] = p_m.z();
}

bool MarkerTable::IsConsistent(std::string* error) const {
  auto fail = [error](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  const std::size_t samples = frame_count * labels.size();
  if (positions_m.size() != samples * 3) {
    return fail("positions_m has " + std::to_string(positions_m.size()) + " values, expected " +
                std::to_string(samples * 3) + " (frames × markers × 3)");
  }
  if (has_residual && (residual_m.size() != samples || camera_mask.size() != samples)) {
    return fail("residual_m / camera_mask must have frames × markers = " + std::to_string(samples) +
                " values");
  }
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    return fail("rate_hz must be positive and finite");
  }
  return true;
}

MarkerStatistics Summarize(const MarkerTable& table) {
  MarkerStatistics stats;
  stats.frames = table.frames();
  stats.markers = table.markers();
  stats.visibility.assign(stats.markers, 0.0);
  for (std::size_t m = 0; m < stats.markers; ++m) {
    std::size_t seen = 0;
    std::size_t run = 0;
    for (std::size_t f = 0; f < stats.frames; ++f) {
      if (table.is_valid(f, m)) {
        ++seen;
        run = 0;
        continue;
      }
      ++run;
      if (run > stats.longest_gap_frames) {
        stats.longest_gap_frames = run;
        stats.longest_gap_marker = table.labels[m];
        stats.longest_gap_first_frame = f + 1 - run;
      }
    }
    stats.invalid_points += stats.frames - seen;
    stats.visibility[m] =
        stats.frames == 0 ? 0.0 : static_cast<double>(seen) / static_cast<double>(stats.frames);
  }
  const std::size_t samples = stats.frames * stats.markers;
  stats.invalid_fraction =
      samples == 0 ? 0.0 : static_cast<double>(stats.invalid_points) / static_cast<double>(samples);
  return stats;
}

}  // namespace ccsrm::mocap
