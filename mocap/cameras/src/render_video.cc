// Marker motion from run and experiment files, and its rendering into one
// lossless video per camera.
#include <sys/stat.h>
#include <unistd.h>
#include <Eigen/Geometry>
#include <opencv2/videoio.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "ccsrm/cameras/video_io.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::cameras {
namespace {

std::vector<std::size_t> SelectFrames(std::size_t available, const FrameSelection& selection,
                                      const std::string& path) {
  if (selection.stride < 1) ThrowInputError(path, "", "frame stride must be at least 1");
  if (selection.first >= available) {
    ThrowInputError(path, "",
                    "first frame " + std::to_string(selection.first) + " is past the last frame (" +
                        std::to_string(available) + " frames)");
  }
  std::vector<std::size_t> frames;
  for (std::size_t f = selection.first; f < available; f += selection.stride) {
    if (selection.max_frames > 0 && frames.size() >= selection.max_frames) break;
    frames.push_back(f);
  }
  return frames;
}

double RateOf(const std::vector<double>& time_s, double fallback) {
  if (time_s.size() < 2) return fallback;
  return (time_s.size() - 1) / (time_s.back() - time_s.front());
}

MarkerMotion MotionFromRun(const std::string& path, const FrameSelection& selection) {
  const datasets::RunFile run = datasets::ReadRunFile(path);
  const sim::Config config = sim::ParseConfig(run.config_yaml, path + ": config_yaml");
  const sim::ArmModel model(config.arm);
  const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(model);
  const std::size_t links = run.link_pose.shape[1];
  if (static_cast<int>(links) != model.num_links()) {
    ThrowInputError(path, "/link_pose",
                    "has " + std::to_string(links) + " links but config_yaml describes " +
                        std::to_string(model.num_links()));
  }
  MarkerMotion motion;
  motion.marker_names = layout.MarkerNames();
  motion.config_yaml = run.config_yaml;
  for (std::size_t f : SelectFrames(run.frames(), selection, path)) {
    std::vector<sim::LinkPose> poses(links);
    for (std::size_t l = 0; l < links; ++l) {
      poses[l].p_WB = Eigen::Vector3d(run.link_pose.at(f, l, 0), run.link_pose.at(f, l, 1),
                                      run.link_pose.at(f, l, 2));
      Eigen::Quaterniond e(run.link_pose.at(f, l, 3), run.link_pose.at(f, l, 4),
                           run.link_pose.at(f, l, 5), run.link_pose.at(f, l, 6));
      if (!(e.norm() > 0.5))
        ThrowInputError(
            path, "/link_pose",
            "quaternion of norm " + std::to_string(e.norm()) + " at frame " + std::to_string(f));
      poses[l].R_WB = e.normalized().toRotationMatrix();
    }
    motion.time_s.push_back(run.time.at(f));
    motion.p_WM.push_back(mocap::PlaceMarkers(layout, poses));
  }
  motion.rate_hz = RateOf(motion.time_s, 100.0);
  return motion;
}

MarkerMotion MotionFromExperiment(const std::string& path, const FrameSelection& selection) {
  const datasets::ExperimentFile experiment = datasets::ReadExperimentFile(path);
  MarkerMotion motion;
  motion.marker_names = experiment.marker_names;
  motion.config_yaml = experiment.config_yaml;
  const std::size_t markers = experiment.marker_names.size();
  for (std::size_t f : SelectFrames(experiment.mocap_time.rows(), selection, path)) {
    std::vector<Eigen::Vector3d> frame(markers);
    for (std::size_t m = 0; m < markers; ++m) {
      frame[m] = Eigen::Vector3d(experiment.mocap_markers.at(f, m, 0),
                                 experiment.mocap_markers.at(f, m, 1),
                                 experiment.mocap_markers.at(f, m, 2));
    }
    motion.time_s.push_back(experiment.mocap_time.at(f));
    motion.p_WM.push_back(std::move(frame));
  }
  motion.rate_hz = RateOf(motion.time_s, 100.0);
  return motion;
}

// splitmix64: independent, reproducible seeds per (camera, frame).
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t camera, std::uint64_t frame) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (1 + camera * 1000003ULL + frame * 7919ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

MarkerMotion ReadMarkerMotion(const std::string& path, const FrameSelection& selection) {
  const datasets::FileSummary summary = datasets::InspectFile(path);
  return summary.kind == datasets::FileKind::kRun ? MotionFromRun(path, selection)
                                                  : MotionFromExperiment(path, selection);
}

RenderSummary RenderVideos(const CameraRig& rig, const MarkerMotion& motion,
                           const MarkerRenderOptions& options, const std::string& out_dir) {
  std::string reason;
  if (!options.IsValid(&reason)) ThrowInputError("(render options)", "", reason);
  ValidateCameraRig(rig, "(camera rig)");
  if (motion.p_WM.empty()) ThrowInputError(out_dir, "", "no frame to render");
  namespace fs = std::filesystem;
  // The folder appears complete or not at all (an earlier one is replaced
  // whole): the videos are written into a temporary folder beside it.
  AtomicOutputDirectory folder(out_dir);
  const fs::path temp(folder.temp_path());
  const double rate = motion.rate_hz > 0.0 ? motion.rate_hz : rig.frame_rate_hz;
  RenderSummary summary;
  summary.frames = motion.p_WM.size();
  const std::size_t cameras = rig.cameras.size();
  summary.in_view_fraction.assign(cameras, 0.0);
  summary.dropped_frames.assign(cameras, 0);
  std::vector<VideoFileWriter> writers;
  for (const Camera& camera : rig.cameras) {
    const std::string name = camera.name + ".avi";
    writers.emplace_back((temp / name).string(), rate, camera.image_width_px,
                         camera.image_height_px);
    summary.video_paths.push_back((fs::path(out_dir) / name).string());
  }
  std::size_t samples = 0;
  std::size_t seen_by_two = 0;
  cv::RNG drop_rng(MixSeed(options.seed, 0xD209, 0));
  for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
    const std::vector<Eigen::Vector3d>& p_WM = motion.p_WM[f];
    std::vector<int> views(p_WM.size(), 0);
    for (std::size_t c = 0; c < cameras; ++c) {
      const Camera& camera = rig.cameras[c];
      std::vector<bool> in_front;
      const std::vector<Eigen::Vector2d> uv = ProjectPoints(camera, p_WM, &in_front);
      for (std::size_t m = 0; m < p_WM.size(); ++m) {
        if (!p_WM[m].allFinite()) continue;
        const bool inside = in_front[m] && uv[m].x() >= 0 && uv[m].y() >= 0 &&
                            uv[m].x() < camera.image_width_px && uv[m].y() < camera.image_height_px;
        if (inside) {
          ++views[m];
          summary.in_view_fraction[c] += 1.0;
        }
      }
      const bool dropped = options.dropped_frame_probability > 0.0 &&
                           drop_rng.uniform(0.0, 1.0) < options.dropped_frame_probability;
      if (dropped) {
        ++summary.dropped_frames[c];
        writers[c].Write(cv::Mat::zeros(camera.image_height_px, camera.image_width_px, CV_8U));
      } else {
        writers[c].Write(RenderMarkerFrame(camera, p_WM, options, MixSeed(options.seed, c, f)));
      }
    }
    for (std::size_t m = 0; m < p_WM.size(); ++m) {
      if (!p_WM[m].allFinite()) continue;
      ++samples;
      if (views[m] >= 2) ++seen_by_two;
    }
  }
  for (double& fraction : summary.in_view_fraction) fraction /= std::max<std::size_t>(samples, 1);
  summary.seen_by_two_fraction = samples > 0 ? static_cast<double>(seen_by_two) / samples : 0.0;
  for (VideoFileWriter& writer : writers) writer.Commit();
  CameraRig written = rig;
  written.frame_rate_hz = rate;
  SaveCameraRig((temp / "cameras.yaml").string(), written);
  folder.Commit();
  summary.camera_file = (fs::path(out_dir) / "cameras.yaml").string();
  return summary;
}

}  // namespace ccsrm::cameras
