#pragma once
// Calibrated cameras: OpenCV's pinhole model with lens distortion, placed in
// the world frame W of SPEC 2, and the camera file that stores a rig of them
// (OpenCV FileStorage YAML, schema "ccsrm-cameras/1").
//
// Frames follow docs/conventions.md. C is a camera frame in OpenCV's
// convention (x right, y down in the image, z along the optical axis). A world
// point maps into C as p_CM = R_CW p_WM + p_CW, where p_CW is the position of
// W's origin in C (OpenCV's tvec) and R_CW is OpenCV's rotation (Rodrigues of
// rvec).
#include <Eigen/Core>

#include <string>
#include <vector>

namespace ccsrm::cameras {

// "ccsrm-cameras/1": the schema of the camera files this ccsrm writes and reads.
inline constexpr const char* kCameraSchema = "ccsrm-cameras/1";

struct Camera {
  // Unique within a rig; names the camera in messages and reports ("cam1").
  std::string name;
  int image_width_px = 0;
  int image_height_px = 0;
  // Intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], pixels.
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  // OpenCV distortion coefficients (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4
  // [, tau_x, tau_y]]]]): 0, 4, 5, 8, 12 or 14 values; empty means none.
  std::vector<double> distortion;
  // Extrinsics: world to camera (see the file comment).
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_CW = Eigen::Vector3d::Zero();  // m

  double fx() const { return K(0, 0); }
  double fy() const { return K(1, 1); }
  // Centre of projection in W [m].
  Eigen::Vector3d p_WC() const { return -R_CW.transpose() * p_CW; }
  // Sets the extrinsics from the camera's pose in W.
  void SetPose(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC);
};

// A set of cameras recording the same scene with synchronised frames.
struct CameraRig {
  std::vector<Camera> cameras;
  // Frame rate of the synchronised videos [Hz] (> 0).
  double frame_rate_hz = 100.0;
};

// Pixel coordinates (distorted, as in the image) of world points; uses
// cv::projectPoints. in_front[i] (when not null) is true where the point lies
// in front of the camera (positive depth): only those pixels are meaningful.
std::vector<Eigen::Vector2d> ProjectPoints(const Camera& camera,
                                           const std::vector<Eigen::Vector3d>& p_WM,
                                           std::vector<bool>* in_front = nullptr);

// Normalized, undistorted image coordinates (x/z, y/z in C) of pixel
// observations; cv::undistortPoints iterated to convergence (20 iterations or
// 1e-12), so strong distortion near the corners is removed as well as the
// centre.
std::vector<Eigen::Vector2d> UndistortToNormalized(const Camera& camera,
                                                   const std::vector<Eigen::Vector2d>& uv_px);

// Checks one camera: positive image size, finite values, fx and fy > 0,
// K(2, :) = (0, 0, 1), principal point inside the image, a supported number of
// distortion coefficients, R_CW orthonormal with determinant +1 (to 1e-6).
// Throws InputError "<file>: <where>.<node>: <problem>".
void ValidateCamera(const Camera& camera, const std::string& file, const std::string& where);

// Checks a rig: at least one camera, unique non-empty names, frame rate > 0,
// every camera valid. Throws InputError naming `file` and the node.
void ValidateCameraRig(const CameraRig& rig, const std::string& file);

// Parses a camera file's text (OpenCV FileStorage YAML):
//
//   %YAML:1.0
//   ---
//   schema: "ccsrm-cameras/1"
//   frame_rate_hz: 100.
//   cameras:
//     - name: cam1
//       image_width: 1280
//       image_height: 1024
//       camera_matrix: !!opencv-matrix {rows: 3, cols: 3, dt: d, data: [...]}
//       distortion_coefficients: !!opencv-matrix {rows: 1, cols: 5, ...}
//       R_CW: !!opencv-matrix {rows: 3, cols: 3, ...}
//       p_CW: !!opencv-matrix {rows: 3, cols: 1, ...}   (metres)
//
// `file` names the source in errors. Throws InputError with one line naming
// the file and the node ("cams.yaml: cameras[1].R_CW: not a rotation (...)").
CameraRig ParseCameraRig(const std::string& text, const std::string& file);

// Reads and validates a camera file (read-only). Throws InputError.
CameraRig LoadCameraRig(const std::string& path);

// The rig as camera-file text (validated first; throws InputError).
std::string CameraRigToYaml(const CameraRig& rig);

// Writes the camera file atomically (temporary, then rename). Throws InputError.
void SaveCameraRig(const std::string& path, const CameraRig& rig);

}  // namespace ccsrm::cameras
