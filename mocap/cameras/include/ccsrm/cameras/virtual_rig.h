#pragma once
// A virtual camera rig for tests and demos: four cameras above the
// air-floating table, the simulator's markers rendered as bright sub-pixel
// spots on a dark background, and rendered checkerboards for calibration.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "ccsrm/cameras/camera_model.h"

namespace ccsrm::cameras {

// Where the default rig's cameras stand. The arm lies in the table plane
// (y-z of W, markers at x ~ 0.03 m); over the +-6 deg protocol its markers
// cover about y in [-0.75, 0.75] m and z in [-0.15, 1.15] m. The cameras stand
// at the four diagonal directions around the aim point, tilted from the table
// normal (+x) by tilt_deg, far enough that each sees the whole workspace.
// With the defaults every marker of the paper arm is in view of all four
// cameras over the +-6 deg protocol (of three or more up to +-7.5 deg per
// joint), and 0.2 px of detection noise gives about 0.25 mm RMS of 3D error.
struct VirtualRigOptions {
  int image_width_px = 1280;
  int image_height_px = 1024;
  // Focal length [px] (fx = fy); 1700 px gives a 41 x 33 deg field of view.
  double focal_length_px = 1700.0;
  // Lens distortion of every camera (k1, k2, p1, p2, k3): mild barrel
  // distortion as of a wide-angle machine-vision lens.
  std::vector<double> distortion = {-0.08, 0.04, 3e-4, -2e-4, 0.0};
  // Point every optical axis goes through [m, in W].
  Eigen::Vector3d p_W_aim = Eigen::Vector3d(0.035, 0.0, 0.50);
  // Distance from each camera's centre to the aim point [m].
  double aim_distance_m = 2.0;
  // Angle between each optical axis and the table normal -x [deg]; steep
  // views triangulate the height above the table better.
  double tilt_deg = 50.0;
  // Directions of the cameras around the table normal, measured in the
  // table plane from +z toward +y [deg]; one camera per entry.
  std::vector<double> azimuths_deg = {45.0, 135.0, 225.0, 315.0};
  double frame_rate_hz = 100.0;
};

// The rig the options describe; cameras are named cam1, cam2, ... and each
// image's long side runs along the table's y direction.
CameraRig MakeVirtualRig(const VirtualRigOptions& options = VirtualRigOptions());

// How markers look in a rendered frame.
struct MarkerRenderOptions {
  // Standard deviation of a marker's Gaussian spot [px].
  double spot_sigma_px = 1.3;
  // Height of a spot's Gaussian above the background [gray levels of 255].
  double spot_peak_level = 200.0;
  // Dark background level [gray levels].
  double background_level = 12.0;
  // Standard deviation of the per-pixel sensor noise [gray levels].
  double intensity_noise_level = 1.5;
  // Standard deviation of the position noise of every spot centre, per image
  // axis [px]: the jitter a real detector shows (marker shape, flicker).
  double position_noise_px = 0.2;
  // Probability that a camera drops a frame (the frame comes out black).
  double dropped_frame_probability = 0.0;
  std::uint64_t seed = 1;

  bool IsValid(std::string* error) const;
};

// Renders one frame of `camera`: every finite marker in front of the camera
// becomes a spot whose intensity is integrated over each pixel's area
// (anti-aliased), centred at its distorted projection plus position noise;
// spots partly or wholly outside the image are clipped. 8-bit, one channel.
// `frame_seed` makes the noise of one frame reproducible.
cv::Mat RenderMarkerFrame(const Camera& camera, const std::vector<Eigen::Vector3d>& p_WM,
                          const MarkerRenderOptions& options, std::uint64_t frame_seed);

// Markers over time, as a run or an experiment gives them.
struct MarkerMotion {
  std::vector<std::string> marker_names;
  std::vector<double> time_s;
  // p_WM[frame][marker] [m]; NaN where a marker does not exist in that frame.
  std::vector<std::vector<Eigen::Vector3d>> p_WM;
  // Frame rate of the motion [Hz] (1 / the time step).
  double rate_hz = 0.0;
  // The arm configuration of the source (may be empty for an experiment
  // without one).
  std::string config_yaml;
};

// Which frames of a source to take.
struct FrameSelection {
  std::size_t first = 0;       // index of the first frame taken
  std::size_t stride = 1;      // take every stride-th frame (>= 1)
  std::size_t max_frames = 0;  // 0 = up to the end
};

// Markers of a ccsrm-run/1 file: the default marker layout of its
// config_yaml (mocap::DefaultMarkerLayout, ground markers included) placed on
// its /link_pose. Markers of a ccsrm-dataset/1 file: /mocap/markers. The kind
// is read from the file's schema. Throws InputError naming the file.
MarkerMotion ReadMarkerMotion(const std::string& path, const FrameSelection& selection = {});

// What RenderVideos wrote.
struct RenderSummary {
  std::vector<std::string> video_paths;  // one per camera, rig order
  std::string camera_file;               // <dir>/cameras.yaml
  std::size_t frames = 0;
  // Per camera: fraction of (frame, marker) samples whose spot centre lies
  // inside the image.
  std::vector<double> in_view_fraction;
  // Per camera: frames rendered black (dropped).
  std::vector<std::size_t> dropped_frames;
  // Markers seen by at least two cameras in every frame / in no frame.
  double seen_by_two_fraction = 0.0;
};

// Renders `motion` through every camera of `rig` into <out_dir>/<name>.avi
// (FFV1, lossless, 8-bit gray) and writes the rig as <out_dir>/cameras.yaml
// with the motion's frame rate. out_dir is created when missing (its parent
// must exist). Every file appears atomically. Throws InputError.
RenderSummary RenderVideos(const CameraRig& rig, const MarkerMotion& motion,
                           const MarkerRenderOptions& options, const std::string& out_dir);

// ---- Checkerboards ----------------------------------------------------------

// A checkerboard target. Board frame G: inner corner (i, j) sits at
// (i * square_m, j * square_m, 0), i < inner_corners_x, j < inner_corners_y;
// the squares cover [-1, n] squares around them, with a white margin of one
// square. Make one count odd and the other even: the board then looks
// different when turned by 180 deg, so its orientation can be told.
struct CheckerboardTarget {
  int inner_corners_x = 9;
  int inner_corners_y = 6;
  double square_m = 0.05;

  bool IsValid(std::string* error) const;
  // Inner-corner positions in G, row by row (i fastest), the order of
  // cv::findChessboardCorners.
  std::vector<Eigen::Vector3d> CornerPositions() const;
};

struct CheckerboardRenderOptions {
  double white_level = 210.0;
  double black_level = 35.0;
  // Gray of whatever lies around the board [gray levels].
  double surround_level = 110.0;
  double intensity_noise_level = 1.5;
  // Sub-samples per pixel side for anti-aliasing (area integration).
  int supersampling = 3;
  std::uint64_t seed = 1;
};

// Renders the board seen by `camera` with the board pose R_CG, p_CG (board in
// camera frame), with the camera's lens distortion. 8-bit, one channel.
cv::Mat RenderCheckerboard(const Camera& camera, const CheckerboardTarget& board,
                           const Eigen::Matrix3d& R_CG, const Eigen::Vector3d& p_CG,
                           const CheckerboardRenderOptions& options);

// `views` board poses (R_CG, p_CG) in front of `camera` for intrinsic
// calibration: tilted by 20-50 deg, spread over the image so lens
// distortion is seen, every corner inside the image. Deterministic in seed.
std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> CalibrationBoardPoses(
    const Camera& camera, const CheckerboardTarget& board, int views, std::uint64_t seed);

// A board lying on the table in W, seen by every camera of the default rig,
// for extrinsic calibration: G's x along +z of W, y along +y, its face toward
// +x (the cameras). Returns R_WG, p_WG.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> DefaultWorldBoardPose(const CheckerboardTarget& board);

}  // namespace ccsrm::cameras
