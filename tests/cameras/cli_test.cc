// The ccsrm cameras commands: exit codes, one-line errors, files written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include "camera_test_util.h"
#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "run_ccsrm.h"

namespace ccsrm::cameras {
namespace {

using ccsrm::testing::CommandOutcome;
using ccsrm::testing::RunCcsrm;
using testing::ScratchDir;

TEST(CamerasCli, RigWritesALoadableCameraFile) {
  const ScratchDir dir("cli_rig");
  const CommandOutcome run = RunCcsrm("cameras rig --out " + dir / "rig.yaml");
  ASSERT_EQ(run.status, 0) << run.all();
  EXPECT_EQ(LoadCameraRig(dir / "rig.yaml").cameras.size(), 4u);
}

TEST(CamerasCli, CorruptCameraFileExitsTwoWithOneLine) {
  const ScratchDir dir("cli_bad_cameras");
  std::ofstream(dir / "cams.yaml")
      << "%YAML:1.0\n---\nschema: \"ccsrm-cameras/1\"\nframe_rate_hz: 100.\n";
  const CommandOutcome run =
      RunCcsrm("cameras reconstruct --cameras " + dir / "cams.yaml" + " --video a.avi --config " +
               CCSRM_SOURCE_DIR "/configs/paper.yaml --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.all(), "ccsrm: " + dir / "cams.yaml" + ": cameras: missing\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "m.c3d"));
}

TEST(CamerasCli, ReconstructWithoutALayoutIsRefused) {
  const ScratchDir dir("cli_no_layout");
  ASSERT_EQ(RunCcsrm("cameras rig --out " + dir / "rig.yaml").status, 0);
  const CommandOutcome run = RunCcsrm("cameras reconstruct --cameras " + dir / "rig.yaml" +
                                      " --video a.avi --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.all().find("give --config or --rigid-bodies"), std::string::npos) << run.all();
}

TEST(CamerasCli, UnreadableVideoExitsTwoWithOneLine) {
  const ScratchDir dir("cli_bad_video");
  ASSERT_EQ(RunCcsrm("cameras rig --out " + dir / "rig.yaml").status, 0);
  std::ofstream(dir / "junk.avi") << "junk";
  const CommandOutcome run = RunCcsrm(
      "cameras reconstruct --cameras " + dir / "rig.yaml" + " --video " + dir / "junk.avi" +
      " b.avi c.avi d.avi --config " CCSRM_SOURCE_DIR "/configs/paper.yaml --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(run.err.rfind("ccsrm: " + dir / "junk.avi" + ": cannot open video", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST(CamerasCli, BadBoardSizeIsNamed) {
  const ScratchDir dir("cli_bad_board");
  const CommandOutcome run = RunCcsrm("cameras render-board --board 9by6 --out " + dir / "boards");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.all(),
            "ccsrm: --board: expected inner corners as COLSxROWS (e.g. 9x6), got '9by6'\n");
}

}  // namespace
}  // namespace ccsrm::cameras

namespace ccsrm::cameras {
namespace {

TEST(CamerasCli, SimulatedRunRendersAndReconstructsIntoC3dNearTheTruth) {
  const ScratchDir dir("cli_end_to_end");
  const std::string run_file = dir / "run.h5";
  CommandOutcome run = RunCcsrm("simulate --config " CCSRM_SOURCE_DIR
                                "/configs/paper.yaml --case 1 --duration 0.05 --out " +
                                run_file);
  ASSERT_EQ(run.status, 0) << run.all();
  run = RunCcsrm("cameras render --in " + run_file + " --noise-px 0.2 --seed 4 --out " +
                 dir / "vids");
  ASSERT_EQ(run.status, 0) << run.all();
  EXPECT_NE(run.all().find("seen by two or more cameras: 100.0 %"), std::string::npos) << run.all();
  const std::string videos = dir / "vids/cam1.avi" + " " + dir / "vids/cam2.avi" + " " +
                             dir / "vids/cam3.avi" + " " + dir / "vids/cam4.avi";
  run = RunCcsrm("cameras reconstruct --quiet --cameras " + dir / "vids/cameras.yaml" +
                 " --video " + videos + " --config " CCSRM_SOURCE_DIR "/configs/paper.yaml --out " +
                 dir / "markers.c3d");
  ASSERT_EQ(run.status, 0) << run.all();
  EXPECT_NE(run.all().find("reprojection RMS"), std::string::npos) << run.all();
  const mocap::MarkerTable table = mocap::ReadC3d(dir / "markers.c3d");
  const MarkerMotion truth = ReadMarkerMotion(run_file);
  ASSERT_EQ(table.frames(), truth.p_WM.size());
  ASSERT_EQ(table.labels, truth.marker_names);
  double sum = 0.0;
  std::size_t valid = 0;
  for (std::size_t f = 0; f < table.frames(); ++f) {
    for (std::size_t m = 0; m < table.markers(); ++m) {
      ASSERT_TRUE(table.is_valid(f, m)) << table.labels[m] << " frame " << f;
      sum += (table.position(f, m) - truth.p_WM[f][m]).squaredNorm();
      ++valid;
    }
  }
  EXPECT_LT(std::sqrt(sum / valid), 0.3e-3);
}

TEST(CamerasCli, MocapProcessTakesVideosToJointAnglesNearTheSimulation) {
  // The end-to-end check: case 2 motion, 4 cameras at 1280x1024,
  // 0.2 px noise, through `ccsrm mocap process --cameras ... --video ...`.
  const ScratchDir dir("cli_mocap_process");
  const std::string run_file = dir / "run.h5";
  CommandOutcome run = RunCcsrm("simulate --config " CCSRM_SOURCE_DIR
                                "/configs/paper.yaml --case 2 --duration 1 --quiet --out " +
                                run_file);
  ASSERT_EQ(run.status, 0) << run.all();
  run = RunCcsrm("cameras render --in " + run_file + " --noise-px 0.2 --seed 7 --out " +
                 dir / "vids");
  ASSERT_EQ(run.status, 0) << run.all();
  const std::string videos = dir / "vids/cam1.avi" + " " + dir / "vids/cam2.avi" + " " +
                             dir / "vids/cam3.avi" + " " + dir / "vids/cam4.avi";
  run = RunCcsrm("mocap process --quiet --cameras " + dir / "vids/cameras.yaml" + " --video " +
                 videos + " --config " CCSRM_SOURCE_DIR "/configs/paper.yaml --out " +
                 dir / "exp.h5");
  ASSERT_EQ(run.status, 0) << run.all();
  const datasets::ExperimentFile experiment = datasets::ReadExperimentFile(dir / "exp.h5");
  const datasets::RunFile truth = datasets::ReadRunFile(run_file);
  ASSERT_TRUE(experiment.measured_joint_angles.has_value());
  ASSERT_EQ(experiment.measured_joint_angles->values.size(), truth.joint_angles.values.size());
  double worst_rms_deg = 0.0;
  for (std::size_t j = 0; j < 12; ++j) {
    for (std::size_t axis = 0; axis < 2; ++axis) {
      double sum = 0.0;
      for (std::size_t f = 0; f < truth.frames(); ++f) {
        const double e =
            experiment.measured_joint_angles->at(f, j, axis) - truth.joint_angles.at(f, j, axis);
        ASSERT_TRUE(std::isfinite(e)) << "joint " << j + 1 << " frame " << f;
        sum += e * e;
      }
      worst_rms_deg = std::max(worst_rms_deg, std::sqrt(sum / truth.frames()) * 180.0 / M_PI);
    }
  }
  std::printf("videos -> mocap process: worst joint-angle RMS %.4f deg\n", worst_rms_deg);
  EXPECT_LT(worst_rms_deg, 0.05);
}

TEST(ReadMarkerMotion, ExperimentMarkersAreRenderedAsRecorded) {
  const ScratchDir dir("experiment_motion");
  datasets::ExperimentFile experiment;
  experiment.name = "tiny";
  experiment.input_time = datasets::Array({2}, 0.0);
  experiment.input_time.values = {0.0, 0.01};
  experiment.input_length_change = datasets::Array({2, 6}, 0.0);
  const MarkerMotion planned = testing::PlannedMotion({0.0, 0.01, 0.02}, 6.0);
  experiment.mocap_time = datasets::Array({3}, 0.0);
  experiment.mocap_time.values = {0.0, 0.01, 0.02};
  experiment.marker_names = planned.marker_names;
  experiment.mocap_markers = datasets::Array({3, planned.marker_names.size(), 3}, 0.0);
  for (std::size_t f = 0; f < 3; ++f) {
    for (std::size_t m = 0; m < planned.marker_names.size(); ++m) {
      for (int a = 0; a < 3; ++a) experiment.mocap_markers.at(f, m, a) = planned.p_WM[f][m][a];
    }
  }
  experiment.mocap_markers.at(1, 7, 0) = std::numeric_limits<double>::quiet_NaN();  // not seen
  experiment.mocap_markers.at(1, 7, 1) = std::numeric_limits<double>::quiet_NaN();
  experiment.mocap_markers.at(1, 7, 2) = std::numeric_limits<double>::quiet_NaN();
  datasets::WriteExperimentFile(dir / "exp.h5", experiment);
  try {
    ReadMarkerMotion(dir / "exp.h5", {3, 1, 0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              dir / "exp.h5" + ": first frame 3 is past the last frame (3 frames)");
  }
  const MarkerMotion motion = ReadMarkerMotion(dir / "exp.h5", {1, 1, 2});
  ASSERT_EQ(motion.p_WM.size(), 2u);
  EXPECT_NEAR(motion.rate_hz, 100.0, 1e-9);
  EXPECT_FALSE(motion.p_WM[0][7].allFinite());
  EXPECT_EQ(motion.p_WM[1][3], planned.p_WM[2][3]);
  const RenderSummary summary = RenderVideos(MakeVirtualRig(), motion, {}, dir / "vids");
  EXPECT_EQ(summary.frames, 2u);
  const ReconstructionResult result = ReconstructMarkers(
      LoadCameraRig(summary.camera_file), summary.video_paths, testing::PaperLayout());
  EXPECT_FALSE(
      result.markers.is_valid(0, 7));  // a marker the experiment did not see is not invented
  EXPECT_TRUE(result.markers.is_valid(1, 7));
}

TEST(ReadMarkerMotion, MissingFileIsNamed) {
  try {
    ReadMarkerMotion("/nonexistent/run.h5");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/run.h5: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace ccsrm::cameras
