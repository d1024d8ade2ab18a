// The whole front end through real files: markers rendered into FFV1 videos
// by the virtual rig, read back and reconstructed.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <fstream>

#include "camera_test_util.h"
#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/cameras/video_io.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

using testing::EvenTimes;
using testing::PaperLayout;
using testing::PaperModel;
using testing::PlannedMotion;
using testing::ScratchDir;

std::string ErrorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Rendered once for the suite: 30 frames of a case-2-like +6 deg ramp and
// hold through the default rig with 0.2 px noise.
class RenderedCaseTwo : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("pipeline_case_two");
    motion_ = new MarkerMotion(PlannedMotion(EvenTimes(0.0, 23.2, 30), 6.0, &angles_));
    MarkerRenderOptions render;
    render.position_noise_px = 0.2;
    render.seed = 17;
    summary_ = new RenderSummary(RenderVideos(MakeVirtualRig(), *motion_, render, dir_->str()));
    result_ = new ReconstructionResult(ReconstructMarkers(LoadCameraRig(summary_->camera_file),
                                                          summary_->video_paths, PaperLayout()));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete summary_;
    delete motion_;
    delete dir_;
  }

  static ScratchDir* dir_;
  static MarkerMotion* motion_;
  static std::vector<sim::JointAngles> angles_;
  static RenderSummary* summary_;
  static ReconstructionResult* result_;
};

ScratchDir* RenderedCaseTwo::dir_ = nullptr;
MarkerMotion* RenderedCaseTwo::motion_ = nullptr;
std::vector<sim::JointAngles> RenderedCaseTwo::angles_;
RenderSummary* RenderedCaseTwo::summary_ = nullptr;
ReconstructionResult* RenderedCaseTwo::result_ = nullptr;

TEST_F(RenderedCaseTwo, RenderWritesOneLosslessVideoPerCameraAndTheCameraFile) {
  ASSERT_EQ(summary_->video_paths.size(), 4u);
  for (const std::string& path : summary_->video_paths) {
    VideoFrameReader reader(path);
    EXPECT_EQ(reader.width_px(), 1280);
    EXPECT_EQ(reader.height_px(), 1024);
    int frames = 0;
    cv::Mat gray;
    while (reader.Read(&gray)) ++frames;
    EXPECT_EQ(frames, 30) << path;
  }
  // Lossless: frame 0 of camera 1 reads back exactly as rendered.
  VideoFrameReader reader(summary_->video_paths[0]);
  cv::Mat gray;
  ASSERT_TRUE(reader.Read(&gray));
  MarkerRenderOptions render;
  render.position_noise_px = 0.2;
  render.seed = 17;
  const CameraRig rig = LoadCameraRig(summary_->camera_file);
  // The camera file carries the motion's frame rate.
  EXPECT_NEAR(rig.frame_rate_hz, 29.0 / 23.2, 1e-9);
  EXPECT_EQ(summary_->seen_by_two_fraction, 1.0);
  for (const char* name : {"cam1.avi", "cam4.avi", "cameras.yaml"}) {
    EXPECT_TRUE(std::filesystem::exists(*dir_ / name)) << name;
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir_->str())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos)
        << "left-over temporary " << entry.path();
  }
}

TEST_F(RenderedCaseTwo, MarkersAreWithinAFractionOfAMillimetreOfTheTruth) {
  const mocap::MarkerTable& table = result_->markers;
  ASSERT_EQ(table.frames(), 30u);
  ASSERT_EQ(table.labels, PaperLayout().MarkerNames());
  double sum = 0.0, worst = 0.0;
  std::size_t valid = 0;
  for (std::size_t f = 0; f < table.frames(); ++f) {
    for (std::size_t m = 0; m < table.markers(); ++m) {
      if (!table.is_valid(f, m)) continue;
      const double e = (table.position(f, m) - motion_->p_WM[f][m]).norm();
      sum += e * e;
      worst = std::max(worst, e);
      ++valid;
    }
  }
  const double rms = std::sqrt(sum / valid);
  std::printf("3D marker error: RMS %.3f mm, worst %.3f mm, %zu of %zu samples\n%s", 1e3 * rms,
              1e3 * worst, valid, table.frames() * table.markers(),
              result_->quality.BriefReport().c_str());
  EXPECT_LT(rms, 0.3e-3);
  EXPECT_LT(worst, 1.5e-3);  // no wrong labels
  EXPECT_GT(static_cast<double>(valid) / (table.frames() * table.markers()), 0.99);
  for (const CameraQuality& camera : result_->quality.cameras) {
    EXPECT_LT(camera.reprojection_rms_px, 0.35) << camera.name;
  }
}

TEST_F(RenderedCaseTwo, TableLooksLikeWhatTheFileReadersGive) {
  const mocap::MarkerTable& table = result_->markers;
  std::string why;
  EXPECT_TRUE(table.IsConsistent(&why)) << why;
  EXPECT_EQ(table.units_in_file, "m");
  EXPECT_NEAR(table.rate_hz, 29.0 / 23.2, 1e-9);
  ASSERT_TRUE(table.has_residual);
  for (std::size_t f = 0; f < table.frames(); ++f) {
    for (std::size_t m = 0; m < table.markers(); ++m) {
      const std::size_t k = f * table.markers() + m;
      if (table.is_valid(f, m)) {
        EXPECT_GE(table.residual_m[k], 0.0);
        EXPECT_LT(table.residual_m[k], 1e-3);
        EXPECT_GE(__builtin_popcount(table.camera_mask[k]), 2);
      } else {
        EXPECT_EQ(table.residual_m[k], -1.0);
      }
    }
  }
}

TEST_F(RenderedCaseTwo, JointAnglesFromUmeyamaFitsFollowThePlan) {
  // Link poses by rigid fits of each plate (what mocap processing will do),
  // joint angles from relative rotations (SPEC 2).
  const mocap::MarkerTable& table = result_->markers;
  const mocap::MarkerLayout& layout = PaperLayout();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  std::size_t count = 0;
  for (std::size_t f = 0; f < table.frames(); ++f) {
    std::vector<Eigen::Matrix3d> R_WL(layout.bodies.size(), Eigen::Matrix3d::Identity());
    std::vector<bool> ok(layout.bodies.size(), false);
    std::size_t first = 0;
    for (std::size_t b = 0; b < layout.bodies.size(); ++b) {
      const mocap::RigidBody& body = layout.bodies[b];
      std::vector<int> seen;
      for (std::size_t m = 0; m < body.p_BM.size(); ++m) {
        if (table.is_valid(f, first + m)) seen.push_back(static_cast<int>(m));
      }
      if (body.link > 0 && seen.size() >= 3) {
        Eigen::Matrix3Xd src(3, seen.size()), dst(3, seen.size());
        for (std::size_t k = 0; k < seen.size(); ++k) {
          src.col(k) = body.p_BM[seen[k]];
          dst.col(k) = table.position(f, first + seen[k]);
        }
        R_WL[b] = Eigen::umeyama(src, dst, false).topLeftCorner<3, 3>();
        ok[b] = true;
      }
      first += body.p_BM.size();
    }
    for (std::size_t b = 1; b < layout.bodies.size(); ++b) {
      const int joint = layout.bodies[b].link;  // joint i joins link i-1 and link i
      const bool parent_ok = joint == 1 || ok[b - 1];
      if (!ok[b] || !parent_ok) continue;
      const Eigen::Matrix3d R_WP = joint == 1 ? Eigen::Matrix3d::Identity() : R_WL[b - 1];
      const Eigen::Vector2d measured = sim::UniversalJointAngles(R_WP.transpose() * R_WL[b]);
      const Eigen::Vector2d error = measured - angles_[f][joint - 1];
      sum += error.cwiseAbs2();
      ++count;
    }
  }
  const Eigen::Vector2d rms_deg = (sum / count).cwiseSqrt() * 180.0 / M_PI;
  const double overall_deg = std::sqrt(sum.sum() / (2.0 * count)) * 180.0 / M_PI;
  std::printf(
      "joint angles from per-frame umeyama fits (no filtering): RMS error %.3f deg (theta_x "
      "%.3f, theta_y %.3f) over %zu joints x frames\n",
      overall_deg, rms_deg.x(), rms_deg.y(), count);
  EXPECT_GT(count, 30u * 12u * 95u / 100u);
  // A single frame's plate fit turns 0.25 mm of marker noise into about
  // 0.2 deg per joint; the 0.05 deg target of the issue needs the low-pass
  // filtering of mocap processing over 100 Hz frames.
  EXPECT_LT(overall_deg, 0.35);
}

TEST(RenderVideos, DroppedFramesNeverGiveWrongPoints) {
  const ScratchDir dir("pipeline_dropped_frames");
  const MarkerMotion motion = PlannedMotion(EvenTimes(4.0, 12.0, 12), -6.0);
  MarkerRenderOptions render;
  render.dropped_frame_probability = 0.25;
  render.seed = 5;
  const RenderSummary summary = RenderVideos(MakeVirtualRig(), motion, render, dir.str());
  std::size_t dropped = 0;
  for (std::size_t n : summary.dropped_frames) dropped += n;
  ASSERT_GT(dropped, 5u);
  const ReconstructionResult result =
      ReconstructMarkers(LoadCameraRig(summary.camera_file), summary.video_paths, PaperLayout());
  std::size_t valid = 0;
  for (std::size_t f = 0; f < result.markers.frames(); ++f) {
    for (std::size_t m = 0; m < result.markers.markers(); ++m) {
      if (!result.markers.is_valid(f, m)) continue;
      ++valid;
      EXPECT_LT((result.markers.position(f, m) - motion.p_WM[f][m]).norm(), 1.5e-3)
          << result.markers.labels[m] << " frame " << f;
    }
  }
  EXPECT_GT(valid, result.markers.frames() * result.markers.markers() / 2);
  std::size_t empty = 0;
  for (const CameraQuality& camera : result.quality.cameras) empty += camera.empty_frames;
  EXPECT_EQ(empty, dropped);
}

class BadVideos : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("pipeline_bad_videos");
    const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 1.0, 3), 6.0);
    summary_ = new RenderSummary(RenderVideos(MakeVirtualRig(), motion, {}, dir_->str()));
  }
  static void TearDownTestSuite() {
    delete summary_;
    delete dir_;
  }
  static ScratchDir* dir_;
  static RenderSummary* summary_;
};

ScratchDir* BadVideos::dir_ = nullptr;
RenderSummary* BadVideos::summary_ = nullptr;

TEST_F(BadVideos, MissingVideoIsNamed) {
  std::vector<std::string> videos = summary_->video_paths;
  videos[2] = *dir_ / "nope.avi";
  EXPECT_EQ(ErrorOf([&] { ReconstructMarkers(MakeVirtualRig(), videos, PaperLayout()); }),
            *dir_ / "nope.avi" + ": cannot open video (no such file)");
}

TEST_F(BadVideos, TextFileIsNotAVideo) {
  const std::string fake = *dir_ / "fake.avi";
  std::ofstream(fake) << "this is not a video\n";
  std::vector<std::string> videos = summary_->video_paths;
  videos[1] = fake;
  const std::string error =
      ErrorOf([&] { ReconstructMarkers(MakeVirtualRig(), videos, PaperLayout()); });
  EXPECT_EQ(error.rfind(fake + ": cannot open video", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST_F(BadVideos, WrongNumberOfVideosIsRejected) {
  std::vector<std::string> videos = summary_->video_paths;
  videos.pop_back();
  EXPECT_EQ(ErrorOf([&] { ReconstructMarkers(MakeVirtualRig(), videos, PaperLayout()); }),
            "(videos): got 3 videos for 4 cameras (one video per camera, in camera-file order)");
}

TEST_F(BadVideos, VideoOfAnotherSizeThanItsCameraIsRejected) {
  CameraRig rig = MakeVirtualRig();
  rig.cameras[3].image_width_px = 640;
  rig.cameras[3].K(0, 2) = 320.0;
  const std::string error =
      ErrorOf([&] { ReconstructMarkers(rig, summary_->video_paths, PaperLayout()); });
  EXPECT_EQ(error, summary_->video_paths[3] +
                       ": frame size 1280x1024 does not match camera 'cam4' (640x1024)");
}

TEST_F(BadVideos, ShorterVideoCountsAsACameraThatStopped) {
  const ScratchDir dir("pipeline_short_video");
  const MarkerMotion motion = PlannedMotion(EvenTimes(0.0, 0.5, 2), 6.0);
  const RenderSummary shorter = RenderVideos(MakeVirtualRig(), motion, {}, dir.str());
  std::vector<std::string> videos = summary_->video_paths;
  videos[0] = shorter.video_paths[0];
  const ReconstructionResult result = ReconstructMarkers(MakeVirtualRig(), videos, PaperLayout());
  EXPECT_EQ(result.markers.frames(), 3u);
  ASSERT_EQ(result.quality.warnings.size(), 1u);
  EXPECT_NE(result.quality.warnings[0].find("1 fewer than the longest video"), std::string::npos);
  EXPECT_EQ(result.quality.cameras[0].empty_frames, 1u);
}

}  // namespace
}  // namespace ccsrm::cameras
