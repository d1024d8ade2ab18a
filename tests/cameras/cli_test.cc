// The ccsrm cameras commands: exit codes, one-line errors, files written.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <string>

#include "camera_test_util.h"

namespace ccsrm::cameras {
namespace {

using testing::ScratchDir;

struct CommandRun {
  int status = 0;
  std::string output;  // stdout and stderr
};

CommandRun Ccsrm(const std::string& arguments) {
  const std::string command = std::string(CCSRM_BINARY_DIR) + "/app/ccsrm " + arguments + " 2>&1";
  CommandRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.output += buffer.data();
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

TEST(CamerasCli, RigWritesALoadableCameraFile) {
  const ScratchDir dir("cli_rig");
  const CommandRun run = Ccsrm("cameras rig --out " + dir / "rig.yaml");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(LoadCameraRig(dir / "rig.yaml").cameras.size(), 4u);
}

TEST(CamerasCli, CorruptCameraFileExitsTwoWithOneLine) {
  const ScratchDir dir("cli_bad_cameras");
  std::ofstream(dir / "cams.yaml")
      << "%YAML:1.0\n---\nschema: \"ccsrm-cameras/1\"\nframe_rate_hz: 100.\n";
  const CommandRun run =
      Ccsrm("cameras reconstruct --cameras " + dir / "cams.yaml" + " --video a.avi --config " +
            CCSRM_SOURCE_DIR "/configs/paper.yaml --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.output, "ccsrm: " + dir / "cams.yaml" + ": cameras: missing\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "m.c3d"));
}

TEST(CamerasCli, ReconstructWithoutALayoutIsRefused) {
  const ScratchDir dir("cli_no_layout");
  ASSERT_EQ(Ccsrm("cameras rig --out " + dir / "rig.yaml").status, 0);
  const CommandRun run = Ccsrm("cameras reconstruct --cameras " + dir / "rig.yaml" +
                               " --video a.avi --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.output.find("give --config or --rigid-bodies"), std::string::npos) << run.output;
}

TEST(CamerasCli, UnreadableVideoExitsTwoWithOneLine) {
  const ScratchDir dir("cli_bad_video");
  ASSERT_EQ(Ccsrm("cameras rig --out " + dir / "rig.yaml").status, 0);
  std::ofstream(dir / "junk.avi") << "junk";
  const CommandRun run = Ccsrm(
      "cameras reconstruct --cameras " + dir / "rig.yaml" + " --video " + dir / "junk.avi" +
      " b.avi c.avi d.avi --config " CCSRM_SOURCE_DIR "/configs/paper.yaml --out " + dir / "m.c3d");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.output.rfind("ccsrm: " + dir / "junk.avi" + ": cannot open video", 0), 0u)
      << run.output;
  EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
}

TEST(CamerasCli, BadBoardSizeIsNamed) {
  const ScratchDir dir("cli_bad_board");
  const CommandRun run = Ccsrm("cameras render-board --board 9by6 --out " + dir / "boards");
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.output,
            "ccsrm: --board: expected inner corners as COLSxROWS (e.g. 9x6), got '9by6'\n");
}

}  // namespace
}  // namespace ccsrm::cameras
