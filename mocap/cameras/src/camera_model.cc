#include "ccsrm/cameras/camera_model.h"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include <cmath>
#include <set>
#include <sstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

bool IsSupportedDistortionCount(std::size_t n) {
  return n == 0 || n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

std::string Describe(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// cv::Exception carries a multi-line message; its `err` field is the short reason.
std::string OneLine(const cv::Exception& e) {
  std::string text = e.err.empty() ? e.what() : e.err;
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

cv::Mat ToCvMat(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

// Reads one node of a camera entry with the file and node named in errors.
class CameraNodeReader {
 public:
  CameraNodeReader(const cv::FileNode& entry, std::string file, std::string where)
      : entry_(entry), file_(std::move(file)), where_(std::move(where)) {}

  cv::FileNode Required(const std::string& key) const {
    const cv::FileNode node = entry_[key];
    if (node.empty() || node.isNone()) Fail(key, "missing");
    return node;
  }

  std::string String(const std::string& key) const {
    const cv::FileNode node = Required(key);
    if (!node.isString()) Fail(key, "expected a string");
    return node.string();
  }

  int Int(const std::string& key) const {
    const cv::FileNode node = Required(key);
    if (!node.isInt()) Fail(key, "expected an integer");
    return static_cast<int>(node);
  }

  // A matrix of the given shape (rows, cols); cols < 0 accepts a row or a
  // column vector of any length in `allowed_lengths`.
  Eigen::MatrixXd Matrix(const std::string& key, int rows, int cols) const {
    const cv::FileNode node = Required(key);
    cv::Mat mat;
    try {
      if (!node.isMap()) Fail(key, "expected an !!opencv-matrix");
      node >> mat;
    } catch (const cv::Exception& e) {
      Fail(key, "not a readable !!opencv-matrix (" + OneLine(e) + ")");
    }
    if (mat.empty() && rows * cols != 0) Fail(key, "expected an !!opencv-matrix");
    if (mat.channels() != 1) Fail(key, "expected a single-channel matrix");
    if (rows >= 0 && (mat.rows != rows || mat.cols != cols)) {
      Fail(key, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) +
                    " matrix, got " + std::to_string(mat.rows) + "x" + std::to_string(mat.cols));
    }
    cv::Mat as_double;
    mat.convertTo(as_double, CV_64F);
    Eigen::MatrixXd out;
    cv::cv2eigen(as_double, out);
    for (Eigen::Index i = 0; i < out.size(); ++i) {
      if (!std::isfinite(out.data()[i])) Fail(key, "non-finite value");
    }
    return out;
  }

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    ThrowInputError(file_, where_ + "." + key, what);
  }

 private:
  cv::FileNode entry_;
  std::string file_;
  std::string where_;
};

}  // namespace

void Camera::SetPose(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC_in) {
  R_CW = R_WC.transpose();
  p_CW = -R_CW * p_WC_in;
}

std::vector<Eigen::Vector2d> ProjectPoints(const Camera& camera,
                                           const std::vector<Eigen::Vector3d>& p_WM,
                                           std::vector<bool>* in_front) {
  std::vector<Eigen::Vector2d> uv(p_WM.size(), Eigen::Vector2d::Zero());
  if (in_front != nullptr) in_front->assign(p_WM.size(), false);
  if (p_WM.empty()) return uv;
  std::vector<cv::Point3d> object(p_WM.size());
  for (std::size_t i = 0; i < p_WM.size(); ++i) {
    object[i] = cv::Point3d(p_WM[i].x(), p_WM[i].y(), p_WM[i].z());
    if (in_front != nullptr) {
      (*in_front)[i] = (camera.R_CW * p_WM[i] + camera.p_CW).z() > 0.0;
    }
  }
  cv::Mat rvec;
  cv::Rodrigues(ToCvMat(camera.R_CW), rvec);
  const cv::Mat tvec = ToCvMat(camera.p_CW);
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, rvec, tvec, ToCvMat(camera.K), camera.distortion, image);
  for (std::size_t i = 0; i < image.size(); ++i) uv[i] = Eigen::Vector2d(image[i].x, image[i].y);
  return uv;
}

std::vector<Eigen::Vector2d> UndistortToNormalized(const Camera& camera,
                                                   const std::vector<Eigen::Vector2d>& uv_px) {
  std::vector<Eigen::Vector2d> xy(uv_px.size());
  if (uv_px.empty()) return xy;
  std::vector<cv::Point2d> src(uv_px.size());
  for (std::size_t i = 0; i < uv_px.size(); ++i) src[i] = cv::Point2d(uv_px[i].x(), uv_px[i].y());
  std::vector<cv::Point2d> dst;
  // OpenCV's default stops after 5 fixed-point iterations, which leaves a
  // visible error where the distortion is strong; iterate to convergence.
  cv::undistortPoints(src, dst, ToCvMat(camera.K), camera.distortion, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 20, 1e-12));
  for (std::size_t i = 0; i < dst.size(); ++i) xy[i] = Eigen::Vector2d(dst[i].x, dst[i].y);
  return xy;
}

void ValidateCamera(const Camera& camera, const std::string& file, const std::string& where) {
  auto fail = [&](const std::string& node, const std::string& what) {
    ThrowInputError(file, where + "." + node, what);
  };
  if (camera.name.empty()) fail("name", "empty camera name");
  if (camera.image_width_px <= 0) fail("image_width", "must be positive");
  if (camera.image_height_px <= 0) fail("image_height", "must be positive");
  if (!camera.K.allFinite()) fail("camera_matrix", "non-finite value");
  if (!(camera.fx() > 0.0) || !(camera.fy() > 0.0)) {
    fail("camera_matrix", "focal lengths must be positive (fx = " + Describe(camera.fx()) +
                              ", fy = " + Describe(camera.fy()) + ")");
  }
  if (camera.K(1, 0) != 0.0 || camera.K(2, 0) != 0.0 || camera.K(2, 1) != 0.0 ||
      camera.K(2, 2) != 1.0) {
    fail("camera_matrix", "expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]]");
  }
  const double cx = camera.K(0, 2);
  const double cy = camera.K(1, 2);
  if (cx < 0.0 || cx > camera.image_width_px || cy < 0.0 || cy > camera.image_height_px) {
    fail("camera_matrix", "principal point (" + Describe(cx) + ", " + Describe(cy) +
                              ") lies outside the " + std::to_string(camera.image_width_px) + "x" +
                              std::to_string(camera.image_height_px) + " image");
  }
  if (!IsSupportedDistortionCount(camera.distortion.size())) {
    fail("distortion_coefficients", "expected 4, 5, 8, 12 or 14 coefficients, got " +
                                        std::to_string(camera.distortion.size()));
  }
  for (double d : camera.distortion) {
    if (!std::isfinite(d)) fail("distortion_coefficients", "non-finite value");
  }
  if (!camera.R_CW.allFinite()) fail("R_CW", "non-finite value");
  const double orthogonality =
      (camera.R_CW.transpose() * camera.R_CW - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-6 || std::abs(camera.R_CW.determinant() - 1.0) > 1e-6) {
    fail("R_CW", "not a rotation (|R^T R - I| = " + Describe(orthogonality) +
                     ", det = " + Describe(camera.R_CW.determinant()) + ")");
  }
  if (!camera.p_CW.allFinite()) fail("p_CW", "non-finite value");
}

void ValidateCameraRig(const CameraRig& rig, const std::string& file) {
  if (!(rig.frame_rate_hz > 0.0) || !std::isfinite(rig.frame_rate_hz)) {
    ThrowInputError(file, "frame_rate_hz", "must be a positive number");
  }
  if (rig.cameras.empty()) ThrowInputError(file, "cameras", "no camera");
  std::set<std::string> names;
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const std::string where = "cameras[" + std::to_string(i) + "]";
    ValidateCamera(rig.cameras[i], file, where);
    if (!names.insert(rig.cameras[i].name).second) {
      ThrowInputError(file, where + ".name", "duplicate camera name '" + rig.cameras[i].name + "'");
    }
  }
}

CameraRig ParseCameraRig(const std::string& text, const std::string& file) {
  cv::FileStorage storage;
  try {
    storage.open(text,
                 cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    ThrowInputError(file, "", "not an OpenCV FileStorage YAML file (" + OneLine(e) + ")");
  }
  if (!storage.isOpened()) {
    ThrowInputError(file, "",
                    "not an OpenCV FileStorage YAML file (expected a '%YAML:1.0' header)");
  }
  const cv::FileNode root = storage.root();
  CameraNodeReader top(root, file, "");
  auto fail_top = [&](const std::string& node, const std::string& what) {
    ThrowInputError(file, node, what);
  };
  const cv::FileNode schema = root["schema"];
  if (schema.empty() || !schema.isString())
    fail_top("schema", "missing (expected \"" + std::string(kCameraSchema) + "\")");
  if (schema.string() != kCameraSchema) {
    fail_top("schema",
             "unsupported schema '" + schema.string() + "' (expected '" + kCameraSchema + "')");
  }
  CameraRig rig;
  const cv::FileNode rate = root["frame_rate_hz"];
  if (rate.empty()) fail_top("frame_rate_hz", "missing");
  if (!rate.isReal() && !rate.isInt()) fail_top("frame_rate_hz", "expected a number");
  rig.frame_rate_hz = static_cast<double>(rate);
  const cv::FileNode list = root["cameras"];
  if (list.empty()) fail_top("cameras", "missing");
  if (!list.isSeq()) fail_top("cameras", "expected a sequence of cameras");
  for (int i = 0; i < static_cast<int>(list.size()); ++i) {
    const std::string where = "cameras[" + std::to_string(i) + "]";
    const cv::FileNode entry = list[i];
    if (!entry.isMap()) fail_top(where, "expected a map");
    const CameraNodeReader reader(entry, file, where);
    Camera camera;
    camera.name = reader.String("name");
    camera.image_width_px = reader.Int("image_width");
    camera.image_height_px = reader.Int("image_height");
    camera.K = reader.Matrix("camera_matrix", 3, 3);
    const Eigen::MatrixXd distortion = reader.Matrix("distortion_coefficients", -1, -1);
    if (distortion.size() > 0 && distortion.rows() != 1 && distortion.cols() != 1) {
      reader.Fail("distortion_coefficients", "expected a row or column vector");
    }
    camera.distortion.assign(distortion.data(), distortion.data() + distortion.size());
    camera.R_CW = reader.Matrix("R_CW", 3, 3);
    camera.p_CW = reader.Matrix("p_CW", 3, 1);
    rig.cameras.push_back(std::move(camera));
  }
  ValidateCameraRig(rig, file);
  return rig;
}

CameraRig LoadCameraRig(const std::string& path) {
  return ParseCameraRig(ReadTextFile(path), path);
}

std::string CameraRigToYaml(const CameraRig& rig) {
  ValidateCameraRig(rig, "(camera rig)");
  cv::FileStorage storage(
      ".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  storage.writeComment(
      " ccsrm camera file. p_C = R_CW p_W + p_CW (OpenCV's rvec/tvec), W = world frame of "
      "SPEC 2, metres; camera_matrix in pixels; distortion in OpenCV's order "
      "(k1, k2, p1, p2, k3, ...).");
  storage << "schema" << kCameraSchema;
  storage << "frame_rate_hz" << rig.frame_rate_hz;
  storage << "cameras"
          << "[";
  for (const Camera& camera : rig.cameras) {
    storage << "{";
    storage << "name" << camera.name;
    storage << "image_width" << camera.image_width_px;
    storage << "image_height" << camera.image_height_px;
    storage << "camera_matrix" << ToCvMat(camera.K);
    storage << "distortion_coefficients" << cv::Mat(camera.distortion, true).reshape(1, 1);
    storage << "R_CW" << ToCvMat(camera.R_CW);
    storage << "p_CW" << ToCvMat(camera.p_CW);
    storage << "}";
  }
  storage << "]";
  return storage.releaseAndGetString();
}

void SaveCameraRig(const std::string& path, const CameraRig& rig) {
  WriteTextFileAtomically(path, CameraRigToYaml(rig));
}

}  // namespace ccsrm::cameras
