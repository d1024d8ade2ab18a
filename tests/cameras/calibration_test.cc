// Calibration from rendered checkerboards and from rendered markers.
#include "ccsrm/cameras/calibration.h"

#include <gtest/gtest.h>

#include <chrono>

#include "camera_test_util.h"
#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

using testing::PaperLayout;

const CheckerboardTarget& Board() {
  static const CheckerboardTarget board{9, 6, 0.04};
  return board;
}

// 16 rendered views of the hand-held board per camera of the default rig,
// made once for the suite.
const std::vector<cv::Mat>& BoardImages(std::size_t c) {
  static const std::vector<std::vector<cv::Mat>> images = [] {
    std::vector<std::vector<cv::Mat>> out;
    const CameraRig rig = MakeVirtualRig();
    for (std::size_t k = 0; k < rig.cameras.size(); ++k) {
      out.emplace_back();
      CheckerboardRenderOptions render;
      int view = 0;
      for (const auto& [R_CG, p_CG] : CalibrationBoardPoses(rig.cameras[k], Board(), 16, 100 + k)) {
        render.seed = 1000 * k + view++;
        out.back().push_back(RenderCheckerboard(rig.cameras[k], Board(), R_CG, p_CG, render));
      }
    }
    return out;
  }();
  return images[c];
}

// Intrinsics of every camera of the default rig from its 16 views.
const std::vector<IntrinsicCalibration>& CalibratedRig() {
  static const std::vector<IntrinsicCalibration> calibrations = [] {
    std::vector<IntrinsicCalibration> out;
    const CameraRig rig = MakeVirtualRig();
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      const Camera& camera = rig.cameras[c];
      const std::vector<cv::Mat>& images = BoardImages(c);
      std::vector<std::string> names;
      for (std::size_t i = 0; i < images.size(); ++i)
        names.push_back(camera.name + "_view" + std::to_string(i));
      IntrinsicCalibrationOptions options;
      options.fit_k3 = false;  // the lens has k3 = 0; fitting it costs focal accuracy
      out.push_back(CalibrateIntrinsics(images, names, Board(), camera.name, options));
    }
    return out;
  }();
  return calibrations;
}

TEST(DetectCheckerboard, FindsTheCornersInOrderWhicheverWayTheBoardIsTurned) {
  const Camera camera = MakeVirtualRig().cameras[1];
  const auto poses = CalibrationBoardPoses(camera, Board(), 1, 3);
  ASSERT_EQ(poses.size(), 1u);
  for (double turn : {0.0, M_PI}) {
    // Turning the board by 180 deg about its centre keeps it in view.
    const Eigen::Vector3d centre((Board().inner_corners_x - 1) * 0.5 * Board().square_m,
                                 (Board().inner_corners_y - 1) * 0.5 * Board().square_m, 0.0);
    const Eigen::Matrix3d R_turn =
        Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d R_CG = poses[0].first * R_turn;
    const Eigen::Vector3d p_CG = poses[0].second + poses[0].first * (centre - R_turn * centre);
    const cv::Mat image = RenderCheckerboard(camera, Board(), R_CG, p_CG, {});
    const auto corners = DetectCheckerboard(image, Board());
    ASSERT_TRUE(corners.has_value()) << "turn " << turn;
    Camera at_origin = camera;
    at_origin.R_CW = R_CG;
    at_origin.p_CW = p_CG;
    const std::vector<Eigen::Vector2d> truth = ProjectPoints(at_origin, Board().CornerPositions());
    double worst = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i)
      worst = std::max(worst, ((*corners)[i] - truth[i]).norm());
    EXPECT_LT(worst, 0.35) << "turn " << turn;
  }
}

TEST(CalibrateIntrinsics, RenderedCheckerboardsGiveFocalLengthsWithinHalfAPercent) {
  const CameraRig truth = MakeVirtualRig();
  for (std::size_t c = 0; c < truth.cameras.size(); ++c) {
    const IntrinsicCalibration& calibration = CalibratedRig()[c];
    const Camera& camera = calibration.camera;
    std::printf("%s: RMS %.3f px over %zu views, fx %.2f fy %.2f (true %.2f), cx %.2f cy %.2f\n",
                camera.name.c_str(), calibration.rms_reprojection_px,
                calibration.used_images.size(), camera.fx(), camera.fy(), truth.cameras[c].fx(),
                camera.K(0, 2), camera.K(1, 2));
    EXPECT_EQ(calibration.used_images.size(), 16u);
    EXPECT_LT(calibration.rms_reprojection_px, 0.2);
    EXPECT_LT(std::abs(camera.fx() / truth.cameras[c].fx() - 1.0), 0.005);
    EXPECT_LT(std::abs(camera.fy() / truth.cameras[c].fy() - 1.0), 0.005);
    EXPECT_LT((camera.K.col(2) - truth.cameras[c].K.col(2)).norm(), 3.0);
  }
}

TEST(CalibrateCameraInWorld, BoardOnTheTableGivesCameraCentresWithinAMillimetre) {
  const CameraRig truth = MakeVirtualRig();
  const CheckerboardTarget world_board{11, 8, 0.08};
  const auto [R_WG, p_WG] = DefaultWorldBoardPose(world_board);
  for (std::size_t c = 0; c < truth.cameras.size(); ++c) {
    const Camera& true_camera = truth.cameras[c];
    CheckerboardRenderOptions render;
    render.seed = 77 + c;
    WorldBoardView world;
    world.image = RenderCheckerboard(true_camera, world_board, true_camera.R_CW * R_WG,
                                     true_camera.R_CW * p_WG + true_camera.p_CW, render);
    world.name = true_camera.name + "_world.png";
    world.board = world_board;
    world.R_WG = R_WG;
    world.p_WG = p_WG;
    const std::vector<cv::Mat>& images = BoardImages(c);
    std::vector<std::string> names;
    for (std::size_t i = 0; i < images.size(); ++i) names.push_back("view" + std::to_string(i));
    IntrinsicCalibrationOptions options;
    options.fit_k3 = false;
    const auto [intrinsics, pose] =
        CalibrateCameraInWorld(images, names, Board(), world, true_camera.name, options);
    const Camera& camera = intrinsics.camera;
    const double centre_error = (camera.p_WC() - true_camera.p_WC()).norm();
    std::printf("%s: fx %.2f, world board RMS %.3f px, camera centre error %.3f mm\n",
                camera.name.c_str(), camera.fx(), pose.rms_reprojection_px, 1e3 * centre_error);
    EXPECT_LT(std::abs(camera.fx() / true_camera.fx() - 1.0), 0.005);
    EXPECT_LT(pose.rms_reprojection_px, 0.2);
    EXPECT_LT(centre_error, 1e-3);
    // What matters for triangulation: the rays. Points of the workspace
    // project where the true camera sees them.
    double worst_px = 0.0;
    for (const Eigen::Vector3d& p_W :
         {Eigen::Vector3d(0.03, 0.0, 0.0), Eigen::Vector3d(0.03, 0.5, 0.9),
          Eigen::Vector3d(0.03, -0.5, 0.9), Eigen::Vector3d(0.03, 0.0, 1.1)}) {
      worst_px =
          std::max(worst_px,
                   (ProjectPoints(camera, {p_W})[0] - ProjectPoints(true_camera, {p_W})[0]).norm());
    }
    EXPECT_LT(worst_px, 0.5);
  }
}

TEST(CalibrateExtrinsics, BoardOnTheTableGivesThePoseOfACalibratedCamera) {
  const Camera true_camera = MakeVirtualRig().cameras[2];
  const CheckerboardTarget world_board{11, 8, 0.08};
  const auto [R_WG, p_WG] = DefaultWorldBoardPose(world_board);
  const cv::Mat image = RenderCheckerboard(true_camera, world_board, true_camera.R_CW * R_WG,
                                           true_camera.R_CW * p_WG + true_camera.p_CW, {});
  Camera camera = true_camera;
  camera.SetPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const ExtrinsicCalibration pose =
      CalibrateExtrinsicsFromBoard(camera, image, "world.png", world_board, R_WG, p_WG);
  camera.R_CW = pose.R_CW;
  camera.p_CW = pose.p_CW;
  EXPECT_LT((camera.p_WC() - true_camera.p_WC()).norm(), 1e-3);
  EXPECT_LT(pose.rms_reprojection_px, 0.2);
}

TEST(CalibrateExtrinsics, MarkersOfTheStraightArmRefineARoughPose) {
  // The arm at rest (the first frames of every protocol) and its ground
  // markers are known in W; a camera placed within 3 cm and 2 deg finds its pose.
  const CameraRig truth = MakeVirtualRig();
  const sim::JointAngles straight(testing::PaperModel().num_joints(), Eigen::Vector2d::Zero());
  const std::vector<Eigen::Vector3d> p_WM =
      mocap::PlaceMarkers(PaperLayout(), sim::ForwardKinematics(testing::PaperModel(), straight));
  MarkerRenderOptions render;
  render.position_noise_px = 0.2;
  for (std::size_t c = 0; c < truth.cameras.size(); ++c) {
    std::vector<std::vector<Eigen::Vector2d>> frames;
    for (int f = 0; f < 10; ++f) {
      std::vector<Eigen::Vector2d> uv;
      for (const Blob& blob :
           DetectBlobs(RenderMarkerFrame(truth.cameras[c], p_WM, render, 40 * c + f))) {
        uv.push_back(blob.uv_px);
      }
      frames.push_back(uv);
    }
    Camera rough = truth.cameras[c];
    rough.SetPose(
        truth.cameras[c].R_CW.transpose() *
            Eigen::AngleAxisd(0.035, Eigen::Vector3d(1, 2, 0.2).normalized()).toRotationMatrix(),
        truth.cameras[c].p_WC() + Eigen::Vector3d(0.03, -0.02, 0.015));
    const ExtrinsicCalibration pose = CalibrateExtrinsicsFromMarkers(rough, p_WM, frames);
    Camera found = truth.cameras[c];
    found.R_CW = pose.R_CW;
    found.p_CW = pose.p_CW;
    const double centre_error = (found.p_WC() - truth.cameras[c].p_WC()).norm();
    std::printf("%s: markers RMS %.3f px over %zu matches, camera centre error %.3f mm\n",
                found.name.c_str(), pose.rms_reprojection_px, pose.correspondences,
                1e3 * centre_error);
    EXPECT_EQ(pose.correspondences, 10 * p_WM.size());
    EXPECT_LT(centre_error, 3e-3);
  }
}

TEST(CalibrateExtrinsics, WrongStartingPoseIsAClearError) {
  const CameraRig truth = MakeVirtualRig();
  std::vector<Eigen::Vector3d> p_W = {{0.02, -0.045, -0.06}, {0.045, 0.04, -0.065}};
  Camera far_off = truth.cameras[0];
  far_off.SetPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(5.0, 5.0, 5.0));
  try {
    CalibrateExtrinsicsFromMarkers(far_off, p_W, {{{100.0, 100.0}}});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cam1: only 0 detections match"), std::string::npos)
        << e.what();
  }
}

TEST(CalibrateIntrinsics, TooFewBoardViewsIsAClearError) {
  const Camera camera = MakeVirtualRig().cameras[0];
  const cv::Mat blank(camera.image_height_px, camera.image_width_px, CV_8U, cv::Scalar(20));
  try {
    CalibrateIntrinsics({blank, blank.clone()}, {"a.png", "b.png"}, Board(), "cam1");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "a.png: checkerboard 9x6 found in only 0 of 2 images (need 4)");
  }
}

}  // namespace
}  // namespace ccsrm::cameras
