#include "ccsrm/cameras/virtual_rig.h"

#include <Eigen/Geometry>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Deg(double degrees) { return degrees * kPi / 180.0; }

// Mass of a unit Gaussian of std sigma over [a, b].
double GaussianMass(double a, double b, double sigma) {
  const double scale = 1.0 / (std::sqrt(2.0) * sigma);
  return 0.5 * (std::erf(b * scale) - std::erf(a * scale));
}

}  // namespace

CameraRig MakeVirtualRig(const VirtualRigOptions& options) {
  CCSRM_CHECK(options.image_width_px > 0 && options.image_height_px > 0);
  CCSRM_CHECK(options.focal_length_px > 0.0 && options.aim_distance_m > 0.0);
  CameraRig rig;
  rig.frame_rate_hz = options.frame_rate_hz;
  const Eigen::Vector3d x_W = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y_W = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d z_W = Eigen::Vector3d::UnitZ();
  for (std::size_t i = 0; i < options.azimuths_deg.size(); ++i) {
    const double azimuth = Deg(options.azimuths_deg[i]);
    const double tilt = Deg(options.tilt_deg);
    const Eigen::Vector3d in_plane = std::cos(azimuth) * z_W + std::sin(azimuth) * y_W;
    const Eigen::Vector3d p_WC =
        options.p_W_aim +
        options.aim_distance_m * (std::cos(tilt) * x_W + std::sin(tilt) * in_plane);
    // Optical axis through the aim point; image x along the table's y.
    const Eigen::Vector3d axis_z = (options.p_W_aim - p_WC).normalized();
    const Eigen::Vector3d axis_x = (y_W - y_W.dot(axis_z) * axis_z).normalized();
    const Eigen::Vector3d axis_y = axis_z.cross(axis_x);
    Eigen::Matrix3d R_WC;
    R_WC.col(0) = axis_x;
    R_WC.col(1) = axis_y;
    R_WC.col(2) = axis_z;
    Camera camera;
    camera.name = "cam" + std::to_string(i + 1);
    camera.image_width_px = options.image_width_px;
    camera.image_height_px = options.image_height_px;
    camera.K << options.focal_length_px, 0.0, 0.5 * (options.image_width_px - 1), 0.0,
        options.focal_length_px, 0.5 * (options.image_height_px - 1), 0.0, 0.0, 1.0;
    camera.distortion = options.distortion;
    camera.SetPose(R_WC, p_WC);
    rig.cameras.push_back(std::move(camera));
  }
  return rig;
}

bool MarkerRenderOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(spot_sigma_px >= 0.3 && spot_sigma_px <= 20.0))
    return fail("spot_sigma_px must be in [0.3, 20]");
  if (!(spot_peak_level > 0.0)) return fail("spot_peak_level must be positive");
  if (!(background_level >= 0.0 && background_level < 255.0))
    return fail("background_level must be in [0, 255)");
  if (!(intensity_noise_level >= 0.0)) return fail("intensity_noise_level must be >= 0");
  if (!(position_noise_px >= 0.0)) return fail("position_noise_px must be >= 0");
  if (!(dropped_frame_probability >= 0.0 && dropped_frame_probability <= 1.0)) {
    return fail("dropped_frame_probability must be in [0, 1]");
  }
  return true;
}

cv::Mat RenderMarkerFrame(const Camera& camera, const std::vector<Eigen::Vector3d>& p_WM,
                          const MarkerRenderOptions& options, std::uint64_t frame_seed) {
  const int width = camera.image_width_px;
  const int height = camera.image_height_px;
  cv::Mat image(height, width, CV_32F, cv::Scalar(options.background_level));
  cv::RNG rng(frame_seed);
  std::vector<Eigen::Vector3d> finite;
  for (const Eigen::Vector3d& p : p_WM) {
    if (p.allFinite()) finite.push_back(p);
  }
  std::vector<bool> in_front;
  const std::vector<Eigen::Vector2d> uv = ProjectPoints(camera, finite, &in_front);
  const double sigma = options.spot_sigma_px;
  // A spot's volume is peak * 2 pi sigma^2; the pixel masses below sum to it.
  const double volume = options.spot_peak_level * 2.0 * kPi * sigma * sigma;
  const int radius = static_cast<int>(std::ceil(4.0 * sigma)) + 1;
  std::vector<double> mass_u(2 * radius + 1);
  std::vector<double> mass_v(2 * radius + 1);
  for (std::size_t m = 0; m < uv.size(); ++m) {
    if (!in_front[m]) continue;
    const double u = uv[m].x() + rng.gaussian(options.position_noise_px);
    const double v = uv[m].y() + rng.gaussian(options.position_noise_px);
    if (!std::isfinite(u) || !std::isfinite(v)) continue;
    const int u0 = static_cast<int>(std::lround(u));
    const int v0 = static_cast<int>(std::lround(v));
    if (u0 + radius < 0 || u0 - radius >= width || v0 + radius < 0 || v0 - radius >= height) {
      continue;  // wholly outside the image
    }
    // Pixel (c, r) covers [c - 0.5, c + 0.5] x [r - 0.5, r + 0.5] (OpenCV's
    // pixel-centre convention), so the Gaussian separates into two 1D masses.
    for (int k = -radius; k <= radius; ++k) {
      mass_u[k + radius] = GaussianMass(u0 + k - 0.5 - u, u0 + k + 0.5 - u, sigma);
      mass_v[k + radius] = GaussianMass(v0 + k - 0.5 - v, v0 + k + 0.5 - v, sigma);
    }
    for (int dv = -radius; dv <= radius; ++dv) {
      const int row = v0 + dv;
      if (row < 0 || row >= height) continue;
      float* pixels = image.ptr<float>(row);
      for (int du = -radius; du <= radius; ++du) {
        const int col = u0 + du;
        if (col < 0 || col >= width) continue;
        pixels[col] += static_cast<float>(volume * mass_u[du + radius] * mass_v[dv + radius]);
      }
    }
  }
  if (options.intensity_noise_level > 0.0) {
    cv::Mat noise(height, width, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.intensity_noise_level);
    image += noise;
  }
  cv::Mat gray;
  image.convertTo(gray, CV_8U);  // rounds and saturates to [0, 255]
  return gray;
}

// ---- Checkerboards -----------------------------------------------------------

bool CheckerboardTarget::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (inner_corners_x < 3 || inner_corners_y < 3)
    return fail("a board needs at least 3x3 inner corners");
  if (!(square_m > 0.0) || !std::isfinite(square_m))
    return fail("the square size must be positive");
  return true;
}

std::vector<Eigen::Vector3d> CheckerboardTarget::CornerPositions() const {
  std::vector<Eigen::Vector3d> corners;
  corners.reserve(static_cast<std::size_t>(inner_corners_x) * inner_corners_y);
  for (int j = 0; j < inner_corners_y; ++j) {
    for (int i = 0; i < inner_corners_x; ++i) corners.emplace_back(i * square_m, j * square_m, 0.0);
  }
  return corners;
}

namespace {

// Gray level of the board at (X, Y) in G [m]: squares alternate, the square
// just outside corner (0, 0) is black, a white margin of one square surrounds
// the pattern, and the world around the board is `surround`.
double BoardLevel(const CheckerboardTarget& board, const CheckerboardRenderOptions& options,
                  double X, double Y) {
  const double s = board.square_m;
  const double a = std::floor(X / s);
  const double b = std::floor(Y / s);
  if (a < -2 || b < -2 || a > board.inner_corners_x || b > board.inner_corners_y) {
    return options.surround_level;
  }
  if (a < -1 || b < -1 || a > board.inner_corners_x - 1 || b > board.inner_corners_y - 1) {
    return options.white_level;  // margin
  }
  const long parity = (static_cast<long>(a) + static_cast<long>(b)) & 1L;
  return parity == 0 ? options.black_level : options.white_level;
}

}  // namespace

cv::Mat RenderCheckerboard(const Camera& camera, const CheckerboardTarget& board,
                           const Eigen::Matrix3d& R_CG, const Eigen::Vector3d& p_CG,
                           const CheckerboardRenderOptions& options) {
  const int width = camera.image_width_px;
  const int height = camera.image_height_px;
  // Where each pixel of the distorted image looks in the ideal pinhole
  // image: the costly part (an iterative undistortion of every pixel), kept
  // for the last camera rendered since calibration renders many views of one.
  static std::mutex cache_mutex;
  static Camera cached_camera;
  static std::shared_ptr<const std::vector<Eigen::Vector2d>> cached_ideal;
  std::shared_ptr<const std::vector<Eigen::Vector2d>> ideal_ptr;
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    if (cached_ideal && cached_camera.K == camera.K &&
        cached_camera.distortion == camera.distortion && cached_camera.image_width_px == width &&
        cached_camera.image_height_px == height) {
      ideal_ptr = cached_ideal;
    }
  }
  if (!ideal_ptr) {
    std::vector<Eigen::Vector2d> pixels;
    pixels.reserve(static_cast<std::size_t>(width) * height);
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) pixels.emplace_back(c, r);
    }
    const std::vector<Eigen::Vector2d> normalized = UndistortToNormalized(camera, pixels);
    auto ideal_new = std::make_shared<std::vector<Eigen::Vector2d>>(normalized.size());
    for (std::size_t i = 0; i < normalized.size(); ++i) {
      (*ideal_new)[i] = Eigen::Vector2d(
          camera.fx() * normalized[i].x() + camera.K(0, 1) * normalized[i].y() + camera.K(0, 2),
          camera.fy() * normalized[i].y() + camera.K(1, 2));
    }
    ideal_ptr = ideal_new;
    std::lock_guard<std::mutex> lock(cache_mutex);
    cached_camera = camera;
    cached_ideal = ideal_ptr;
  }
  const std::vector<Eigen::Vector2d>& ideal = *ideal_ptr;
  double min_u = 0, min_v = 0, max_u = width - 1, max_v = height - 1;
  for (const Eigen::Vector2d& p : ideal) {
    min_u = std::min(min_u, p.x());
    min_v = std::min(min_v, p.y());
    max_u = std::max(max_u, p.x());
    max_v = std::max(max_v, p.y());
  }
  // The ideal image, rendered on a canvas that covers every lookup.
  const int offset_u = static_cast<int>(std::floor(min_u)) - 2;
  const int offset_v = static_cast<int>(std::floor(min_v)) - 2;
  const int canvas_w = static_cast<int>(std::ceil(max_u)) + 3 - offset_u;
  const int canvas_h = static_cast<int>(std::ceil(max_v)) + 3 - offset_v;
  const int ss = std::max(1, options.supersampling);
  // Homography board (X, Y, 1) -> ideal pixel; its inverse maps sub-pixel
  // sample centres back onto the board.
  Eigen::Matrix3d H;
  H.col(0) = camera.K * R_CG.col(0);
  H.col(1) = camera.K * R_CG.col(1);
  H.col(2) = camera.K * p_CG;
  const Eigen::Matrix3d H_inv = H.inverse();
  cv::Mat fine(canvas_h * ss, canvas_w * ss, CV_32F);
  for (int r = 0; r < fine.rows; ++r) {
    float* row = fine.ptr<float>(r);
    const double v = offset_v - 0.5 + (r + 0.5) / ss;
    for (int c = 0; c < fine.cols; ++c) {
      const double u = offset_u - 0.5 + (c + 0.5) / ss;
      const Eigen::Vector3d g = H_inv * Eigen::Vector3d(u, v, 1.0);
      // A ray that meets the board plane behind the camera sees the surround.
      row[c] =
          static_cast<float>(g.z() > 0.0 ? BoardLevel(board, options, g.x() / g.z(), g.y() / g.z())
                                         : options.surround_level);
    }
  }
  cv::Mat canvas;
  cv::resize(fine, canvas, cv::Size(canvas_w, canvas_h), 0, 0, cv::INTER_AREA);
  cv::Mat map_u(height, width, CV_32F);
  cv::Mat map_v(height, width, CV_32F);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const Eigen::Vector2d& p = ideal[static_cast<std::size_t>(r) * width + c];
      map_u.at<float>(r, c) = static_cast<float>(p.x() - offset_u);
      map_v.at<float>(r, c) = static_cast<float>(p.y() - offset_v);
    }
  }
  cv::Mat image;
  cv::remap(canvas, image, map_u, map_v, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  if (options.intensity_noise_level > 0.0) {
    cv::RNG rng(options.seed);
    cv::Mat noise(height, width, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.intensity_noise_level);
    image += noise;
  }
  cv::Mat gray;
  image.convertTo(gray, CV_8U);
  return gray;
}

std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> CalibrationBoardPoses(
    const Camera& camera, const CheckerboardTarget& board, int views, std::uint64_t seed) {
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> poses;
  cv::RNG rng(seed);
  const std::vector<Eigen::Vector3d> corners = board.CornerPositions();
  const Eigen::Vector3d centre_G((board.inner_corners_x - 1) * 0.5 * board.square_m,
                                 (board.inner_corners_y - 1) * 0.5 * board.square_m, 0.0);
  const double board_width = (board.inner_corners_x + 1) * board.square_m;
  const int margin_px = 20;
  int attempts = 0;
  while (static_cast<int>(poses.size()) < views && attempts < 1000 * std::max(views, 1)) {
    ++attempts;
    // The board fills 35-60 % of the image width, centred somewhere on a
    // grid over the image so that the corners see the lens distortion.
    const double fill = rng.uniform(0.35, 0.6);
    const double depth = camera.fx() * board_width / (fill * camera.image_width_px);
    const double u = rng.uniform(0.2, 0.8) * camera.image_width_px;
    const double v = rng.uniform(0.2, 0.8) * camera.image_height_px;
    const Eigen::Vector3d centre_C =
        depth * Eigen::Vector3d((u - camera.K(0, 2)) / camera.fx(),
                                (v - camera.K(1, 2)) / camera.fy(), 1.0);
    const double tilt = Deg(rng.uniform(20.0, 50.0));
    const double tilt_axis = rng.uniform(0.0, 2.0 * kPi);
    const double spin = Deg(rng.uniform(-30.0, 30.0));
    const Eigen::Matrix3d R_CG =
        Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(tilt_axis), std::sin(tilt_axis), 0.0))
            .toRotationMatrix() *
        Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d p_CG = centre_C - R_CG * centre_G;
    // Keep the pose only when the whole board (with its margin) is in view.
    std::vector<Eigen::Vector3d> outline;
    for (const Eigen::Vector3d& corner : corners) outline.push_back(R_CG * corner + p_CG);
    const double s = board.square_m;
    for (double X : {-2 * s, (board.inner_corners_x + 1) * s}) {
      for (double Y : {-2 * s, (board.inner_corners_y + 1) * s}) {
        outline.push_back(R_CG * Eigen::Vector3d(X, Y, 0.0) + p_CG);
      }
    }
    Camera at_origin = camera;
    at_origin.R_CW.setIdentity();
    at_origin.p_CW.setZero();
    std::vector<bool> in_front;
    const std::vector<Eigen::Vector2d> uv = ProjectPoints(at_origin, outline, &in_front);
    bool inside = true;
    for (std::size_t i = 0; i < uv.size(); ++i) {
      inside = inside && in_front[i] && uv[i].x() > margin_px && uv[i].y() > margin_px &&
               uv[i].x() < camera.image_width_px - margin_px &&
               uv[i].y() < camera.image_height_px - margin_px;
    }
    if (inside) poses.emplace_back(R_CG, p_CG);
  }
  return poses;
}

std::pair<Eigen::Matrix3d, Eigen::Vector3d> DefaultWorldBoardPose(const CheckerboardTarget& board) {
  Eigen::Matrix3d R_WG;
  R_WG.col(0) = Eigen::Vector3d::UnitZ();
  R_WG.col(1) = Eigen::Vector3d::UnitY();
  R_WG.col(2) = -Eigen::Vector3d::UnitX();  // into the table, away from the cameras
  // Centred on the default rig's aim point, on the table 3 cm below the
  // link axes.
  const Eigen::Vector3d centre_G((board.inner_corners_x - 1) * 0.5 * board.square_m,
                                 (board.inner_corners_y - 1) * 0.5 * board.square_m, 0.0);
  const Eigen::Vector3d p_W_centre(-0.03, 0.0, 0.50);
  return {R_WG, p_W_centre - R_WG * centre_G};
}

}  // namespace ccsrm::cameras
