// The reconstruction pipeline: frames -> blobs -> 3D points -> labelled markers.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <sstream>
#include <utility>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/cameras/video_io.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {

double MaxLinkSpacing(const sim::ArmModel& model) {
  double shortest = 1e9, longest = 0.0;
  for (const sim::LinkModel& link : model.links()) {
    shortest = std::min(shortest, link.length_m);
    longest = std::max(longest, link.length_m);
  }
  return 0.5 * (longest + 2.0 * shortest);
}
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void CheckInputs(const CameraRig& rig, const mocap::MarkerLayout& layout,
                 const ReconstructionOptions& options) {
  std::string reason;
  if (!options.IsValid(&reason)) ThrowInputError("(reconstruction options)", "", reason);
  ValidateCameraRig(rig, "(camera rig)");
  if (rig.cameras.size() < 2) {
    ThrowInputError("(camera rig)", "cameras", "reconstruction needs at least two cameras");
  }
  if (layout.marker_count() == 0) ThrowInputError("(marker layout)", "", "no marker to label");
}

// Turns the detections of successive frames into rows of the marker table
// and the quality figures.
class FrameProcessor {
 public:
  FrameProcessor(const CameraRig& rig, const mocap::MarkerLayout& layout,
                 const ReconstructionOptions& options)
      : rig_(rig), options_(options), labeller_(layout, options.labelling) {
    labels_ = layout.MarkerNames();
    const std::size_t markers = labels_.size();
    quality_.cameras.resize(rig.cameras.size());
    for (std::size_t c = 0; c < rig.cameras.size(); ++c)
      quality_.cameras[c].name = rig.cameras[c].name;
    seen_.assign(markers, 0);
    views_.assign(markers, 0.0);
    residual_.assign(markers, 0.0);
    squared_reprojection_.assign(rig.cameras.size(), 0.0);
  }

  // detections[c]: pixel centroids of camera c; frame_read[c] is false when
  // the camera delivered no frame.
  void Process(const std::vector<std::vector<Eigen::Vector2d>>& detections,
               const std::vector<bool>& frame_read) {
    for (std::size_t c = 0; c < detections.size(); ++c) {
      CameraQuality& camera = quality_.cameras[c];
      if (frame_read[c]) ++camera.frames_read;
      if (detections[c].empty()) ++camera.empty_frames;
      camera.detections += detections[c].size();
    }
    const std::vector<TriangulatedPoint> points =
        TriangulateFrame(rig_, detections, options_.triangulation);
    std::vector<Eigen::Vector3d> p_W(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) p_W[i] = points[i].p_W;
    std::vector<int> label_of_point;
    labeller_.LabelFrame(p_W, &label_of_point);
    const std::size_t markers = labels_.size();
    std::vector<double> row(markers * 3, kNaN);
    std::vector<double> residual_row(markers, -1.0);
    std::vector<std::uint8_t> mask_row(markers, 0);
    quality_.triangulated_points += points.size();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const int marker = label_of_point[i];
      if (marker < 0) {
        ++quality_.unlabelled_points;
        continue;
      }
      const TriangulatedPoint& point = points[i];
      for (int axis = 0; axis < 3; ++axis) row[marker * 3 + axis] = point.p_W[axis];
      residual_row[marker] = point.ray_residual_m;
      ++seen_[marker];
      views_[marker] += point.views.size();
      residual_[marker] += point.ray_residual_m;
      for (const View& view : point.views) {
        // The C3D residual word has room for 7 cameras.
        if (view.camera < 7) mask_row[marker] |= static_cast<std::uint8_t>(1u << view.camera);
        const Camera& camera = rig_.cameras[view.camera];
        const Eigen::Vector2d uv = ProjectPoints(camera, {point.p_W})[0];
        squared_reprojection_[view.camera] +=
            (uv - detections[view.camera][view.blob]).squaredNorm();
        ++quality_.cameras[view.camera].used_detections;
      }
    }
    positions_.insert(positions_.end(), row.begin(), row.end());
    residuals_.insert(residuals_.end(), residual_row.begin(), residual_row.end());
    masks_.insert(masks_.end(), mask_row.begin(), mask_row.end());
    ++quality_.frames;
  }

  void Warn(std::string warning) { quality_.warnings.push_back(std::move(warning)); }

  ReconstructionResult Finish(double wall_time_s) {
    ReconstructionResult result;
    mocap::MarkerTable& table = result.markers;
    table.Reset(quality_.frames, labels_, true);
    table.positions_m = std::move(positions_);
    table.residual_m = std::move(residuals_);
    table.camera_mask = std::move(masks_);
    table.rate_hz = rig_.frame_rate_hz;
    table.first_frame_number = static_cast<std::int64_t>(options_.first_frame) + 1;
    table.format = "cameras";
    table.units_in_file = "m";
    table.warnings = quality_.warnings;
    CCSRM_CHECK(table.IsConsistent(nullptr));
    for (std::size_t c = 0; c < quality_.cameras.size(); ++c) {
      CameraQuality& camera = quality_.cameras[c];
      camera.reprojection_rms_px =
          camera.used_detections > 0 ? std::sqrt(squared_reprojection_[c] / camera.used_detections)
                                     : 0.0;
    }
    for (std::size_t m = 0; m < labels_.size(); ++m) {
      MarkerQuality marker;
      marker.label = labels_[m];
      marker.visibility =
          quality_.frames > 0 ? static_cast<double>(seen_[m]) / quality_.frames : 0.0;
      marker.mean_views = seen_[m] > 0 ? views_[m] / seen_[m] : 0.0;
      marker.mean_ray_residual_m = seen_[m] > 0 ? residual_[m] / seen_[m] : 0.0;
      quality_.markers.push_back(marker);
    }
    quality_.wall_time_s = wall_time_s;
    quality_.frames_per_second = wall_time_s > 0.0 ? quality_.frames / wall_time_s : 0.0;
    result.quality = std::move(quality_);
    return result;
  }

 private:
  const CameraRig& rig_;
  const ReconstructionOptions& options_;
  MarkerLabeller labeller_;
  std::vector<std::string> labels_;
  ReconstructionQuality quality_;
  std::vector<double> positions_;
  std::vector<double> residuals_;
  std::vector<std::uint8_t> masks_;
  std::vector<std::size_t> seen_;
  std::vector<double> views_;
  std::vector<double> residual_;
  std::vector<double> squared_reprojection_;
};

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

bool ReconstructionOptions::IsValid(std::string* error) const {
  return detection.IsValid(error) && triangulation.IsValid(error) && labelling.IsValid(error);
}

ReconstructionResult ReconstructMarkersFromDetections(
    const CameraRig& rig, const std::vector<std::vector<std::vector<Eigen::Vector2d>>>& detections,
    const mocap::MarkerLayout& layout, const ReconstructionOptions& options) {
  CheckInputs(rig, layout, options);
  const auto start = std::chrono::steady_clock::now();
  FrameProcessor processor(rig, layout, options);
  const std::size_t end =
      options.max_frames > 0 ? std::min(detections.size(), options.first_frame + options.max_frames)
                             : detections.size();
  for (std::size_t f = options.first_frame; f < end; ++f) {
    if (detections[f].size() != rig.cameras.size()) {
      ThrowInputError(
          "(detections)", "frame " + std::to_string(f),
          "expected one detection list per camera (" + std::to_string(rig.cameras.size()) + ")");
    }
    processor.Process(detections[f], std::vector<bool>(rig.cameras.size(), true));
    if (options.progress) options.progress(f + 1 - options.first_frame, end - options.first_frame);
  }
  return processor.Finish(Seconds(start));
}

ReconstructionResult ReconstructMarkers(const CameraRig& rig,
                                        const std::vector<std::string>& videos,
                                        const mocap::MarkerLayout& layout,
                                        const ReconstructionOptions& options) {
  CheckInputs(rig, layout, options);
  if (videos.size() != rig.cameras.size()) {
    ThrowInputError("(videos)", "",
                    "got " + std::to_string(videos.size()) + " videos for " +
                        std::to_string(rig.cameras.size()) +
                        " cameras (one video per camera, in camera-file order)");
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<VideoFrameReader> readers;
  long expected = 0;
  for (std::size_t c = 0; c < videos.size(); ++c) {
    readers.emplace_back(videos[c]);
    const Camera& camera = rig.cameras[c];
    if (readers[c].width_px() != camera.image_width_px ||
        readers[c].height_px() != camera.image_height_px) {
      ThrowInputError(videos[c], "",
                      "frame size " + std::to_string(readers[c].width_px()) + "x" +
                          std::to_string(readers[c].height_px()) + " does not match camera '" +
                          camera.name + "' (" + std::to_string(camera.image_width_px) + "x" +
                          std::to_string(camera.image_height_px) + ")");
    }
    expected = std::max(expected, readers[c].reported_frames());
  }
  FrameProcessor processor(rig, layout, options);
  const std::size_t cameras = rig.cameras.size();
  std::vector<bool> ended(cameras, false);
  std::vector<std::size_t> frames_of(cameras, 0);
  std::vector<std::vector<Eigen::Vector2d>> detections(cameras);
  std::vector<bool> frame_read(cameras, false);
  std::size_t index = 0;
  std::size_t processed = 0;
  const std::size_t to_process = expected > static_cast<long>(options.first_frame)
                                     ? static_cast<std::size_t>(expected) - options.first_frame
                                     : 0;
  for (;; ++index) {
    if (options.max_frames > 0 && processed >= options.max_frames) break;
    // Decoding dominates the cost of a frame: each camera reads and detects
    // on its own thread (the readers are independent).
    std::vector<std::future<bool>> reads;
    for (std::size_t c = 0; c < cameras; ++c) {
      detections[c].clear();
      frame_read[c] = false;
      if (ended[c]) continue;
      reads.push_back(std::async(std::launch::async, [&, c] {
        cv::Mat gray;
        if (!readers[c].Read(&gray)) return false;
        if (index >= options.first_frame) {
          for (const Blob& blob : DetectBlobs(gray, options.detection)) {
            detections[c].push_back(blob.uv_px);
          }
        }
        return true;
      }));
    }
    bool any = false;
    std::size_t next = 0;
    for (std::size_t c = 0; c < cameras; ++c) {
      if (ended[c]) continue;
      if (!reads[next++].get()) {
        ended[c] = true;
        continue;
      }
      any = true;
      frame_read[c] = true;
      ++frames_of[c];
    }
    if (!any) break;
    if (index < options.first_frame) continue;
    processor.Process(detections, frame_read);
    ++processed;
    if (options.progress) {
      options.progress(processed, options.max_frames > 0 ? std::min(options.max_frames, to_process)
                                                         : to_process);
    }
  }
  const std::size_t longest = *std::max_element(frames_of.begin(), frames_of.end());
  for (std::size_t c = 0; c < cameras; ++c) {
    if (frames_of[c] < longest) {
      processor.Warn(videos[c] + ": " + std::to_string(frames_of[c]) + " frames, " +
                     std::to_string(longest - frames_of[c]) +
                     " fewer than the longest video; the missing frames count as empty");
    }
  }
  if (processed == 0) {
    ThrowInputError(videos[0], "",
                    "no frame to reconstruct (first frame " + std::to_string(options.first_frame) +
                        " of " + std::to_string(longest) + ")");
  }
  return processor.Finish(Seconds(start));
}

std::string ReconstructionQuality::BriefReport() const {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "frames: %zu in %.2f s (%.1f frames/s)\n", frames, wall_time_s,
                frames_per_second);
  out << line;
  for (const CameraQuality& camera : cameras) {
    std::snprintf(line, sizeof line,
                  "  %-10s reprojection RMS %.3f px, %zu detections (%zu used), %zu empty frames\n",
                  camera.name.c_str(), camera.reprojection_rms_px, camera.detections,
                  camera.used_detections, camera.empty_frames);
    out << line;
  }
  if (!markers.empty()) {
    double min_visibility = 1.0, max_residual = 0.0, sum_visibility = 0.0;
    std::string least_seen;
    for (const MarkerQuality& marker : markers) {
      sum_visibility += marker.visibility;
      if (marker.visibility <= min_visibility) {
        min_visibility = marker.visibility;
        least_seen = marker.label;
      }
      max_residual = std::max(max_residual, marker.mean_ray_residual_m);
    }
    std::snprintf(line, sizeof line,
                  "markers: %zu, mean visibility %.1f %%, least seen %s (%.1f %%), largest mean "
                  "ray residual %.3f mm\n",
                  markers.size(), 100.0 * sum_visibility / markers.size(), least_seen.c_str(),
                  100.0 * min_visibility, 1e3 * max_residual);
    out << line;
  }
  std::snprintf(line, sizeof line, "points: %zu triangulated, %zu unlabelled\n",
                triangulated_points, unlabelled_points);
  out << line;
  for (const std::string& warning : warnings) out << "warning: " << warning << "\n";
  return out.str();
}

mocap::MarkerReconstruction VideoMarkerSource(std::string cameras_file,
                                              std::vector<std::string> videos,
                                              ReconstructionOptions options) {
  return [cameras_file = std::move(cameras_file), videos = std::move(videos),
          options = std::move(options)](const mocap::MarkerLayout& layout,
                                        const sim::ArmModel* model) {
    const CameraRig rig = LoadCameraRig(cameras_file);
    ReconstructionOptions used = options;
    if (model != nullptr) used.labelling.max_link_spacing_m = MaxLinkSpacing(*model);
    ReconstructionResult reconstruction = ReconstructMarkers(rig, videos, layout, used);
    return mocap::ReconstructedMarkers{std::move(reconstruction.markers),
                                       reconstruction.quality.BriefReport()};
  };
}

}  // namespace ccsrm::cameras
