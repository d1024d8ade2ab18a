#include "ccsrm/cameras/camera_model.h"

#include <gtest/gtest.h>

#include <fstream>

#include "camera_test_util.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

using testing::ScratchDir;

// The error message of parsing `text`, or "" when it parses.
std::string ParseError(const std::string& text) {
  try {
    ParseCameraRig(text, "cams.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "fixture text lacks '" << from << "'";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(CameraFile, RigRoundTripsThroughTheFile) {
  const ScratchDir dir("camera_file_round_trip");
  const CameraRig rig = MakeVirtualRig();
  SaveCameraRig(dir / "cams.yaml", rig);
  const CameraRig back = LoadCameraRig(dir / "cams.yaml");
  ASSERT_EQ(back.cameras.size(), 4u);
  EXPECT_DOUBLE_EQ(back.frame_rate_hz, rig.frame_rate_hz);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(back.cameras[c].name, rig.cameras[c].name);
    EXPECT_EQ(back.cameras[c].image_width_px, 1280);
    EXPECT_EQ(back.cameras[c].image_height_px, 1024);
    EXPECT_TRUE(back.cameras[c].K.isApprox(rig.cameras[c].K, 1e-15));
    EXPECT_TRUE(back.cameras[c].R_CW.isApprox(rig.cameras[c].R_CW, 1e-15));
    EXPECT_TRUE(back.cameras[c].p_CW.isApprox(rig.cameras[c].p_CW, 1e-15));
    EXPECT_EQ(back.cameras[c].distortion, rig.cameras[c].distortion);
  }
}

TEST(CameraFile, ProjectionAndUndistortionInvertEachOther) {
  const Camera camera = MakeVirtualRig().cameras[0];
  const std::vector<Eigen::Vector3d> p_W = {{0.03, 0.2, 0.3}, {0.03, -0.6, 1.0}, {0.0, 0.5, -0.1}};
  std::vector<bool> in_front;
  const std::vector<Eigen::Vector2d> uv = ProjectPoints(camera, p_W, &in_front);
  const std::vector<Eigen::Vector2d> xy = UndistortToNormalized(camera, uv);
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    ASSERT_TRUE(in_front[i]);
    const Eigen::Vector3d p_C = camera.R_CW * p_W[i] + camera.p_CW;
    EXPECT_NEAR((xy[i] - p_C.hnormalized()).norm() * camera.fx(), 0.0, 1e-6) << "point " << i;
  }
}

class BadCameraFile : public ::testing::Test {
 protected:
  std::string good_ = CameraRigToYaml(MakeVirtualRig());
};

TEST_F(BadCameraFile, GoodFixtureParses) { EXPECT_EQ(ParseError(good_), ""); }

TEST_F(BadCameraFile, MissingNodeIsNamed) {
  const std::string text = Replace(good_, "R_CW:", "R_XX:");
  EXPECT_EQ(ParseError(text), "cams.yaml: cameras[0].R_CW: missing");
}

TEST_F(BadCameraFile, WrongMatrixSizeIsNamed) {
  // Turn camera 1's 1x5 distortion into a 3x3 camera matrix's place: swap node names.
  std::string text = Replace(good_, "p_CW: !!opencv-matrix\n         rows: 3",
                             "p_CW: !!opencv-matrix\n         rows: 1");
  text = Replace(text, "cols: 1\n         dt: d\n         data: [",
                 "cols: 3\n         dt: d\n         data: [");
  const std::string error = ParseError(text);
  EXPECT_EQ(error, "cams.yaml: cameras[0].p_CW: expected a 3x1 matrix, got 1x3");
}

TEST_F(BadCameraFile, NonPositiveFocalLengthIsRejected) {
  const std::string fx = std::to_string(1600);
  const std::string text = Replace(good_, "data: [ 1700.,", "data: [ -1700.,");
  EXPECT_NE(
      ParseError(text).find("cams.yaml: cameras[0].camera_matrix: focal lengths must be positive"),
      std::string::npos)
      << ParseError(text);
}

TEST_F(BadCameraFile, NonFiniteValueIsRejected) {
  const std::string text = Replace(good_, "data: [ 1700.,", "data: [ .nan,");
  EXPECT_EQ(ParseError(text), "cams.yaml: cameras[0].camera_matrix: non-finite value");
}

// One camera's entry written by hand, with replaceable matrices.
std::string HandWrittenFile(const std::string& rotation_data, const std::string& distortion) {
  return "%YAML:1.0\n---\nschema: \"ccsrm-cameras/1\"\nframe_rate_hz: 100.\ncameras:\n"
         "  - name: cam1\n    image_width: 1280\n    image_height: 1024\n"
         "    camera_matrix: !!opencv-matrix\n      rows: 3\n      cols: 3\n      dt: d\n"
         "      data: [ 1600., 0., 640., 0., 1600., 512., 0., 0., 1. ]\n"
         "    distortion_coefficients: " +
         distortion +
         "\n"
         "    R_CW: !!opencv-matrix\n      rows: 3\n      cols: 3\n      dt: d\n"
         "      data: [ " +
         rotation_data +
         " ]\n"
         "    p_CW: !!opencv-matrix\n      rows: 3\n      cols: 1\n      dt: d\n"
         "      data: [ 0., 0., 2. ]\n";
}

const char* kFiveCoefficients =
    "!!opencv-matrix\n      rows: 1\n      cols: 5\n      dt: d\n      data: [ -0.1, 0.05, 0., 0., "
    "0. ]";

TEST_F(BadCameraFile, HandWrittenFileParses) {
  EXPECT_EQ(ParseError(HandWrittenFile("1., 0., 0., 0., 1., 0., 0., 0., 1.", kFiveCoefficients)),
            "");
}

TEST_F(BadCameraFile, RotationThatIsNotOrthonormalIsRejected) {
  const std::string error =
      ParseError(HandWrittenFile("1., 0., 0., 0., 1.1, 0., 0., 0., 1.", kFiveCoefficients));
  EXPECT_NE(error.find("cams.yaml: cameras[0].R_CW: not a rotation"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST_F(BadCameraFile, ReflectionIsNotARotation) {
  const std::string error =
      ParseError(HandWrittenFile("-1., 0., 0., 0., 1., 0., 0., 0., 1.", kFiveCoefficients));
  EXPECT_NE(error.find("cams.yaml: cameras[0].R_CW: not a rotation"), std::string::npos) << error;
}

TEST_F(BadCameraFile, UnsupportedDistortionCountIsRejected) {
  const std::string three =
      "!!opencv-matrix\n      rows: 1\n      cols: 3\n      dt: d\n      data: [ -0.1, 0.05, 0. ]";
  EXPECT_EQ(ParseError(HandWrittenFile("1., 0., 0., 0., 1., 0., 0., 0., 1.", three)),
            "cams.yaml: cameras[0].distortion_coefficients: expected 4, 5, 8, 12 or 14 "
            "coefficients, got 3");
}

TEST_F(BadCameraFile, MatrixWithTooFewValuesIsRejected) {
  const std::string error =
      ParseError(HandWrittenFile("1., 0., 0., 0., 1., 0.", kFiveCoefficients));
  EXPECT_EQ(error.rfind("cams.yaml: cameras[0].R_CW: ", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST_F(BadCameraFile, ScalarWhereAMatrixBelongsIsRejected) {
  EXPECT_EQ(ParseError(HandWrittenFile("1., 0., 0., 0., 1., 0., 0., 0., 1.", "0.1")),
            "cams.yaml: cameras[0].distortion_coefficients: expected an !!opencv-matrix");
}

TEST_F(BadCameraFile, DuplicateCameraNamesAreRejected) {
  const std::string text = Replace(good_, "name: cam2", "name: cam1");
  EXPECT_EQ(ParseError(text), "cams.yaml: cameras[1].name: duplicate camera name 'cam1'");
}

TEST_F(BadCameraFile, WrongSchemaIsRejected) {
  const std::string text = Replace(good_, "ccsrm-cameras/1", "ccsrm-cameras/9");
  EXPECT_EQ(ParseError(text),
            "cams.yaml: schema: unsupported schema 'ccsrm-cameras/9' (expected 'ccsrm-cameras/1')");
}

TEST_F(BadCameraFile, TruncatedFileGivesOneLine) {
  const std::string text = good_.substr(0, good_.size() / 2) + "\n  - [ {";
  const std::string error = ParseError(text);
  EXPECT_EQ(error.rfind("cams.yaml: ", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST_F(BadCameraFile, NotYamlAtAllIsRejected) {
  const std::string error = ParseError("\x89PNG\r\n\x1a\n binary junk");
  EXPECT_EQ(error.rfind("cams.yaml: ", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

TEST(CameraFile, MissingFileIsNamed) {
  try {
    LoadCameraRig("/nonexistent/cams.yaml");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/cams.yaml: cannot open for reading");
  }
}

TEST(CameraFile, SavingAnInvalidRigWritesNothing) {
  const ScratchDir dir("camera_file_invalid");
  CameraRig rig = MakeVirtualRig();
  rig.cameras[2].K(0, 0) = 0.0;
  EXPECT_THROW(SaveCameraRig(dir / "cams.yaml", rig), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "cams.yaml"));
}

}  // namespace
}  // namespace ccsrm::cameras
