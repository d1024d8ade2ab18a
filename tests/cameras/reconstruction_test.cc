// Detection, triangulation and labelling on synthetic data (no video files).
#include "ccsrm/cameras/reconstruction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "camera_test_util.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

using testing::EvenTimes;
using testing::PaperLayout;
using testing::PlannedMotion;

// Detections of every finite marker inside each camera's image, with
// Gaussian pixel noise; drop(camera, marker) removes single observations.
std::vector<std::vector<Eigen::Vector2d>> Detect(
    const CameraRig& rig, const std::vector<Eigen::Vector3d>& p_WM, double noise_px,
    std::mt19937_64* rng, const std::function<bool(int, int)>& drop = nullptr) {
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<std::vector<Eigen::Vector2d>> detections(rig.cameras.size());
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const Camera& camera = rig.cameras[c];
    std::vector<bool> in_front;
    const std::vector<Eigen::Vector2d> uv = ProjectPoints(camera, p_WM, &in_front);
    for (std::size_t m = 0; m < p_WM.size(); ++m) {
      if (!in_front[m] || !p_WM[m].allFinite()) continue;
      if (uv[m].x() < 5 || uv[m].y() < 5 || uv[m].x() > camera.image_width_px - 5 ||
          uv[m].y() > camera.image_height_px - 5) {
        continue;
      }
      if (drop && drop(static_cast<int>(c), static_cast<int>(m))) continue;
      detections[c].push_back(uv[m] + Eigen::Vector2d(noise(*rng), noise(*rng)));
    }
    std::shuffle(detections[c].begin(), detections[c].end(), *rng);  // no order to lean on
  }
  return detections;
}

struct Errors {
  double rms_m = 0.0;
  double worst_m = 0.0;
  std::size_t valid = 0;
  std::size_t samples = 0;
};

Errors Compare(const mocap::MarkerTable& table, const MarkerMotion& truth) {
  Errors errors;
  double sum = 0.0;
  for (std::size_t f = 0; f < table.frames(); ++f) {
    for (std::size_t m = 0; m < table.markers(); ++m) {
      ++errors.samples;
      if (!table.is_valid(f, m)) continue;
      const double e = (table.position(f, m) - truth.p_WM[f][m]).norm();
      sum += e * e;
      errors.worst_m = std::max(errors.worst_m, e);
      ++errors.valid;
    }
  }
  errors.rms_m = errors.valid > 0 ? std::sqrt(sum / errors.valid) : 0.0;
  return errors;
}

TEST(DetectBlobs, CentroidOfARenderedSpotIsSubPixel) {
  Camera camera = MakeVirtualRig().cameras[0];
  MarkerRenderOptions render;
  render.position_noise_px = 0.0;
  render.intensity_noise_level = 1.5;
  // Points in front of the camera placed at fractional pixel positions.
  std::vector<Eigen::Vector3d> p_W;
  const Eigen::Matrix3d R_WC = camera.R_CW.transpose();
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d p_C(-0.4 + 0.041 * k, -0.3 + 0.029 * k, 1.6);
    p_W.push_back(R_WC * (p_C - camera.p_CW));
  }
  const std::vector<Eigen::Vector2d> truth = ProjectPoints(camera, p_W);
  const std::vector<Blob> blobs = DetectBlobs(RenderMarkerFrame(camera, p_W, render, 7));
  ASSERT_EQ(blobs.size(), p_W.size());
  for (const Eigen::Vector2d& t : truth) {
    double nearest = 1e9;
    for (const Blob& b : blobs) nearest = std::min(nearest, (b.uv_px - t).norm());
    EXPECT_LT(nearest, 0.05) << "at " << t.transpose();
  }
}

TEST(DetectBlobs, MergedSpotsAndBorderSpotsAreDropped) {
  Camera camera = MakeVirtualRig().cameras[0];
  camera.distortion.clear();
  MarkerRenderOptions render;
  render.position_noise_px = 0.0;
  const Eigen::Matrix3d R_WC = camera.R_CW.transpose();
  auto at_pixel = [&](double u, double v) {
    const Eigen::Vector3d p_C((u - camera.K(0, 2)) / camera.fx() * 1.5,
                              (v - camera.K(1, 2)) / camera.fy() * 1.5, 1.5);
    return Eigen::Vector3d(R_WC * (p_C - camera.p_CW));
  };
  // Two spots 2.5 px apart merge; one spot straddles the left border; one is alone.
  const std::vector<Eigen::Vector3d> p_W = {at_pixel(400.0, 300.0), at_pixel(402.5, 300.0),
                                            at_pixel(0.7, 500.0), at_pixel(800.3, 700.6)};
  const std::vector<Blob> blobs = DetectBlobs(RenderMarkerFrame(camera, p_W, render, 3));
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].uv_px.x(), 800.3, 0.05);
  EXPECT_NEAR(blobs[0].uv_px.y(), 700.6, 0.05);
}

TEST(Triangulation, DltAndRefinementRecoverAPointExactly) {
  const CameraRig rig = MakeVirtualRig();
  const Eigen::Vector3d p_W(0.03, 0.25, 0.7);
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::Vector3d> t;
  std::vector<Eigen::Vector2d> xy;
  std::vector<const Camera*> cameras;
  for (const Camera& camera : rig.cameras) {
    R.push_back(camera.R_CW);
    t.push_back(camera.p_CW);
    xy.push_back((camera.R_CW * p_W + camera.p_CW).hnormalized());
    cameras.push_back(&camera);
  }
  EXPECT_LT((TriangulateDlt(R, t, xy) - p_W).norm(), 1e-9);
  const Eigen::Vector3d start = p_W + Eigen::Vector3d(0.004, -0.003, 0.005);
  EXPECT_LT((RefineTriangulation(cameras, xy, start, 8) - p_W).norm(), 1e-10);
}

TEST(Triangulation, RefinementReducesTheReprojectionErrorOfNoisyViews) {
  const CameraRig rig = MakeVirtualRig();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.5 / 1600.0);
  const Eigen::Vector3d p_W(0.03, -0.2, 0.4);
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::Vector3d> t;
  std::vector<Eigen::Vector2d> xy;
  std::vector<const Camera*> cameras;
  for (const Camera& camera : rig.cameras) {
    R.push_back(camera.R_CW);
    t.push_back(camera.p_CW);
    xy.push_back((camera.R_CW * p_W + camera.p_CW).hnormalized() +
                 Eigen::Vector2d(noise(rng), noise(rng)));
    cameras.push_back(&camera);
  }
  auto cost = [&](const Eigen::Vector3d& p) {
    double sum = 0.0;
    for (std::size_t i = 0; i < xy.size(); ++i) {
      sum += (1600.0 * ((R[i] * p + t[i]).hnormalized() - xy[i])).squaredNorm();
    }
    return sum;
  };
  const Eigen::Vector3d dlt = TriangulateDlt(R, t, xy);
  const Eigen::Vector3d refined = RefineTriangulation(cameras, xy, dlt, 8);
  EXPECT_LE(cost(refined), cost(dlt) + 1e-12);
  // At the optimum a small step in any direction costs more.
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(cost(refined + 1e-5 * Eigen::Vector3d::Unit(axis)), cost(refined));
    EXPECT_GT(cost(refined - 1e-5 * Eigen::Vector3d::Unit(axis)), cost(refined));
  }
}

TEST(VirtualRig, EveryMarkerIsSeenByTwoCamerasOverTheProtocol) {
  const CameraRig rig = MakeVirtualRig();
  for (double amplitude : {-6.0, 6.0}) {
    const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 20.0, 11), amplitude / 1.25);
    for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
      for (std::size_t m = 0; m < motion.p_WM[f].size(); ++m) {
        int views = 0;
        for (const Camera& camera : rig.cameras) {
          std::vector<bool> in_front;
          const Eigen::Vector2d uv = ProjectPoints(camera, {motion.p_WM[f][m]}, &in_front)[0];
          views += in_front[0] && uv.x() > 10 && uv.y() > 10 &&
                   uv.x() < camera.image_width_px - 10 && uv.y() < camera.image_height_px - 10;
        }
        EXPECT_GE(views, 2) << motion.marker_names[m] << " at frame " << f << ", amplitude "
                            << amplitude;
      }
    }
  }
}

TEST(ReconstructFromDetections, NoisyDetectionsGiveSubMillimetreMarkersWithTheRightLabels) {
  const CameraRig rig = MakeVirtualRig();
  const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 22.0, 40), 6.0);
  std::mt19937_64 rng(11);
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> detections;
  for (const auto& frame : motion.p_WM) detections.push_back(Detect(rig, frame, 0.2, &rng));
  const ReconstructionResult result =
      ReconstructMarkersFromDetections(rig, detections, PaperLayout());
  ASSERT_EQ(result.markers.frames(), motion.p_WM.size());
  EXPECT_EQ(result.markers.labels, PaperLayout().MarkerNames());
  const Errors errors = Compare(result.markers, motion);
  EXPECT_EQ(errors.valid, errors.samples) << result.quality.BriefReport();
  EXPECT_LT(errors.rms_m, 0.3e-3);
  EXPECT_LT(errors.worst_m, 1.5e-3);
  EXPECT_EQ(result.quality.unlabelled_points, 0u);
}

TEST(ReconstructFromDetections, MarkerSeenByOneCameraIsNaNNotAWrongPoint) {
  const CameraRig rig = MakeVirtualRig();
  const MarkerMotion motion = PlannedMotion(EvenTimes(5.0, 10.0, 12), 6.0);
  const std::size_t lonely = 4 * 6 + 2;  // L06_C: only camera 2 sees it in frames 4-7
  std::mt19937_64 rng(3);
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> detections;
  for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
    detections.push_back(Detect(rig, motion.p_WM[f], 0.2, &rng, [&](int c, int m) {
      return f >= 4 && f <= 7 && m == static_cast<int>(lonely) && c != 1;
    }));
  }
  const ReconstructionResult result =
      ReconstructMarkersFromDetections(rig, detections, PaperLayout());
  for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
    EXPECT_EQ(result.markers.is_valid(f, lonely), f < 4 || f > 7) << "frame " << f;
  }
  const Errors errors = Compare(result.markers, motion);
  EXPECT_LT(errors.worst_m, 1.5e-3);
  EXPECT_EQ(errors.valid, errors.samples - 4);
}

TEST(ReconstructFromDetections, CameraDroppingFramesStillGivesTheMarkersFromTheOthers) {
  const CameraRig rig = MakeVirtualRig();
  const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 12.0, 16), -6.0);
  std::mt19937_64 rng(8);
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> detections;
  for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
    detections.push_back(Detect(rig, motion.p_WM[f], 0.2, &rng));
    if (f % 3 == 1) detections.back()[2].clear();  // camera 3 drops every third frame
  }
  const ReconstructionResult result =
      ReconstructMarkersFromDetections(rig, detections, PaperLayout());
  const Errors errors = Compare(result.markers, motion);
  EXPECT_LT(errors.worst_m, 1.5e-3);
  EXPECT_GT(static_cast<double>(errors.valid) / errors.samples, 0.97)
      << result.quality.BriefReport();
  EXPECT_EQ(result.quality.cameras[2].empty_frames, 5u);
}

TEST(ReconstructFromDetections, TwoCameraRigLosingOneCameraGivesNaNEverywhere) {
  CameraRig rig = MakeVirtualRig();
  rig.cameras.resize(2);
  const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 4.0, 6), 6.0);
  std::mt19937_64 rng(9);
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> detections;
  for (std::size_t f = 0; f < motion.p_WM.size(); ++f) {
    detections.push_back(Detect(rig, motion.p_WM[f], 0.2, &rng));
    if (f == 3) detections.back()[0].clear();
  }
  const ReconstructionResult result =
      ReconstructMarkersFromDetections(rig, detections, PaperLayout());
  for (std::size_t m = 0; m < result.markers.markers(); ++m) {
    EXPECT_FALSE(result.markers.is_valid(3, m)) << result.markers.labels[m];
  }
  EXPECT_LT(Compare(result.markers, motion).worst_m, 2e-3);
}

TEST(ReconstructFromDetections, SpuriousBlobsDoNotBecomeMarkers) {
  const CameraRig rig = MakeVirtualRig();
  const MarkerMotion motion = PlannedMotion(EvenTimes(2.0, 8.0, 8), 6.0);
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(20.0, 1260.0), v(20.0, 1000.0);
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> detections;
  for (const auto& frame : motion.p_WM) {
    detections.push_back(Detect(rig, frame, 0.2, &rng));
    for (auto& camera : detections.back()) {
      for (int k = 0; k < 10; ++k) camera.emplace_back(u(rng), v(rng));  // reflections, noise
    }
  }
  const ReconstructionResult result =
      ReconstructMarkersFromDetections(rig, detections, PaperLayout());
  const Errors errors = Compare(result.markers, motion);
  EXPECT_LT(errors.worst_m, 1.5e-3);
  EXPECT_GT(static_cast<double>(errors.valid) / errors.samples, 0.95);
}

TEST(ReconstructionOptions, InvalidOptionsAreRejected) {
  ReconstructionOptions options;
  options.triangulation.min_views = 1;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error, "min_views must be at least 2");
  EXPECT_THROW(ReconstructMarkersFromDetections(MakeVirtualRig(), {}, PaperLayout(), options),
               InputError);
}

}  // namespace
}  // namespace ccsrm::cameras
