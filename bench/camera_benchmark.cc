// Camera front end: blob detection of one 1280x1024 frame, triangulation and
// labelling of one frame of the paper arm, and whole frames through video
// (decode + detect + triangulate + label, four cameras).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"

namespace {

using namespace ccsrm;

const sim::ArmModel& Model() {
  static const sim::ArmModel model(sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml").arm);
  return model;
}

std::vector<Eigen::Vector3d> BentArmMarkers(double angle_deg) {
  const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(Model());
  const sim::JointAngles angles(Model().num_joints(),
                                Eigen::Vector2d(angle_deg * M_PI / 180.0, 0.0));
  return mocap::PlaceMarkers(layout, sim::ForwardKinematics(Model(), angles));
}

void BM_DetectBlobs(benchmark::State& state) {
  const cameras::Camera camera = cameras::MakeVirtualRig().cameras[0];
  const cv::Mat image = cameras::RenderMarkerFrame(camera, BentArmMarkers(4.0), {}, 1);
  for (auto _ : state) benchmark::DoNotOptimize(cameras::DetectBlobs(image));
}
BENCHMARK(BM_DetectBlobs)->Unit(benchmark::kMillisecond);

void BM_TriangulateAndLabelFrame(benchmark::State& state) {
  const cameras::CameraRig rig = cameras::MakeVirtualRig();
  const std::vector<Eigen::Vector3d> p_WM = BentArmMarkers(4.0);
  std::vector<std::vector<Eigen::Vector2d>> detections;
  for (const cameras::Camera& camera : rig.cameras)
    detections.push_back(cameras::ProjectPoints(camera, p_WM));
  cameras::MarkerLabeller labeller(mocap::DefaultMarkerLayout(Model()), {});
  for (auto _ : state) {
    const std::vector<cameras::TriangulatedPoint> points =
        cameras::TriangulateFrame(rig, detections);
    std::vector<Eigen::Vector3d> p_W;
    for (const auto& point : points) p_W.push_back(point.p_W);
    benchmark::DoNotOptimize(labeller.LabelFrame(p_W));
  }
}
BENCHMARK(BM_TriangulateAndLabelFrame)->Unit(benchmark::kMillisecond);

// Frames per second of ReconstructMarkers on 20 rendered frames (4 FFV1
// videos); the rendering is set-up, not timed.
void BM_ReconstructFromVideo(benchmark::State& state) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / "ccsrm_camera_benchmark").string();
  std::filesystem::remove_all(dir);
  cameras::MarkerMotion motion;
  motion.marker_names = mocap::DefaultMarkerLayout(Model()).MarkerNames();
  for (int f = 0; f < 20; ++f) {
    motion.time_s.push_back(0.01 * f);
    motion.p_WM.push_back(BentArmMarkers(0.2 * f));
  }
  motion.rate_hz = 100.0;
  const cameras::RenderSummary summary =
      cameras::RenderVideos(cameras::MakeVirtualRig(), motion, {}, dir);
  const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(Model());
  std::size_t frames = 0;
  for (auto _ : state) {
    const cameras::ReconstructionResult result =
        cameras::ReconstructMarkers(cameras::MakeVirtualRig(), summary.video_paths, layout);
    frames += result.markers.frames();
  }
  state.counters["frames_per_second"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_ReconstructFromVideo)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
