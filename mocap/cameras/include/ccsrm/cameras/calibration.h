#pragma once
// Camera calibration with OpenCV: intrinsics from checkerboard images
// (cv::calibrateCamera), extrinsics in the world frame W of SPEC 2 from a
// checkerboard lying at a known place on the table, or from markers at
// known world positions (the layout's ground markers, optionally the
// straight arm) with cv::solvePnP.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/cameras/virtual_rig.h"

namespace ccsrm::cameras {

// The inner corners of `board` in an 8-bit gray image (sub-pixel refined),
// in CheckerboardTarget::CornerPositions() order, or nothing when the board
// is not found. The board's orientation is told by its colours: the square
// diagonally outside corner (0, 0) is black (a board with one odd and one
// even count looks different turned by 180 deg).
std::optional<std::vector<Eigen::Vector2d>> DetectCheckerboard(const cv::Mat& gray,
                                                               const CheckerboardTarget& board);

struct IntrinsicCalibrationOptions {
  // Fewest images in which the board must be found.
  int min_views = 4;
  // Fit k3 too (OpenCV's 5-coefficient model); false fixes it at 0, which is
  // safer with few views or a narrow lens.
  bool fit_k3 = true;

  bool IsValid(std::string* error) const;
};

struct IntrinsicCalibration {
  // Intrinsics and distortion; extrinsics left at the identity.
  Camera camera;
  // RMS reprojection error over every corner of every used view [px].
  double rms_reprojection_px = 0.0;
  // Names of the images where the board was found, and their RMS errors.
  std::vector<std::string> used_images;
  std::vector<double> per_view_rms_px;
  std::vector<std::string> rejected_images;  // board not found
};

// Calibrates one camera's intrinsics from images of `board` (names label the
// images in the result and in errors). Throws InputError when the images
// differ in size, are not 8-bit gray, or show the board fewer than
// min_views times.
IntrinsicCalibration CalibrateIntrinsics(const std::vector<cv::Mat>& images,
                                         const std::vector<std::string>& names,
                                         const CheckerboardTarget& board,
                                         const std::string& camera_name,
                                         const IntrinsicCalibrationOptions& options = {});

struct ExtrinsicCalibration {
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_CW = Eigen::Vector3d::Zero();
  double rms_reprojection_px = 0.0;
  std::size_t correspondences = 0;
};

// A checkerboard at a known pose in W, seen in one image.
struct WorldBoardView {
  cv::Mat image;  // 8-bit gray
  std::string name;
  CheckerboardTarget board;
  Eigen::Matrix3d R_WG = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WG = Eigen::Vector3d::Zero();
};

// Intrinsics and pose in W together: the world board is one more view of
// cv::calibrateCamera, so the focal length and the pose agree (a focal
// length 0.05 % off moves a camera 2 m away by 1 mm along its axis when the
// two are fitted apart). The camera of the result carries the pose; the
// extrinsic result gives the world board's reprojection error. Throws
// InputError when the world board is not found (naming its image) or as
// CalibrateIntrinsics does.
std::pair<IntrinsicCalibration, ExtrinsicCalibration> CalibrateCameraInWorld(
    const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
    const CheckerboardTarget& board, const WorldBoardView& world, const std::string& camera_name,
    const IntrinsicCalibrationOptions& options = {});

// Pose of `camera` (intrinsics known) from one image of `board` lying at the
// known pose R_WG, p_WG. Throws InputError (naming `image_name`) when the
// board is not found.
ExtrinsicCalibration CalibrateExtrinsicsFromBoard(const Camera& camera, const cv::Mat& image,
                                                  const std::string& image_name,
                                                  const CheckerboardTarget& board,
                                                  const Eigen::Matrix3d& R_WG,
                                                  const Eigen::Vector3d& p_WG);

struct MarkerExtrinsicsOptions {
  // Largest image shift between the starting pose and the truth [px]: the
  // shift that lines up the most markers is found first (a vote).
  double max_shift_px = 300.0;
  // Gates of the successive matching rounds [px]: detections are matched to
  // the reference points projected with the current pose estimate (the
  // first round after the shift).
  std::vector<double> match_gates_px = {4.0, 3.0, 2.0};
  // Fewest matched reference points (solvePnP needs 4; more is safer).
  int min_points = 6;
};

// Pose of `camera` from marker detections of a static scene whose world
// positions are known (p_W_reference; NaN entries are skipped), over one or
// more frames: detections_px[frame] are the blob centroids of one frame.
// The camera's current extrinsics are the starting guess (a tape-measure
// placement: a few centimetres and degrees off, which mostly shifts the
// image; the roll about the optical axis should be within about 0.5 deg). Throws
// InputError naming `camera.name` when too few points match.
ExtrinsicCalibration CalibrateExtrinsicsFromMarkers(
    const Camera& camera, const std::vector<Eigen::Vector3d>& p_W_reference,
    const std::vector<std::vector<Eigen::Vector2d>>& detections_px,
    const MarkerExtrinsicsOptions& options = {});

}  // namespace ccsrm::cameras
