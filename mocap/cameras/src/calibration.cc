#include "ccsrm/cameras/calibration.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

std::vector<cv::Point3f> ToCv3f(const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3f> out;
  for (const Eigen::Vector3d& p : points) out.emplace_back(p.x(), p.y(), p.z());
  return out;
}

std::vector<cv::Point2f> ToCv2f(const std::vector<Eigen::Vector2d>& points) {
  std::vector<cv::Point2f> out;
  for (const Eigen::Vector2d& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

cv::Mat ToCvMat(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

// Mean gray level of the image around the projection of board point (X, Y).
double SampleBoard(const cv::Mat& gray, const cv::Mat& H, double X, double Y) {
  std::vector<cv::Point2d> in{{X, Y}}, out;
  cv::perspectiveTransform(in, out, H);
  const int u = static_cast<int>(std::lround(out[0].x));
  const int v = static_cast<int>(std::lround(out[0].y));
  double sum = 0.0;
  int count = 0;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      if (u + du < 0 || v + dv < 0 || u + du >= gray.cols || v + dv >= gray.rows) continue;
      sum += gray.at<unsigned char>(v + dv, u + du);
      ++count;
    }
  }
  return count > 0 ? sum / count : 0.0;
}

ExtrinsicCalibration SolvePose(const Camera& camera, const std::vector<cv::Point3f>& object,
                               const std::vector<cv::Point2f>& image, bool use_guess) {
  cv::Mat rvec, tvec;
  if (use_guess) {
    cv::Rodrigues(ToCvMat(camera.R_CW), rvec);
    tvec = ToCvMat(camera.p_CW);
  }
  const cv::Mat K = ToCvMat(camera.K);
  cv::solvePnP(object, image, K, camera.distortion, rvec, tvec, use_guess, cv::SOLVEPNP_ITERATIVE);
  cv::solvePnPRefineLM(object, image, K, camera.distortion, rvec, tvec);
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  ExtrinsicCalibration result;
  Eigen::Matrix3d R_CW;
  Eigen::Vector3d p_CW;
  cv::cv2eigen(R, R_CW);
  cv::cv2eigen(tvec, p_CW);
  result.R_CW = R_CW;
  result.p_CW = p_CW;
  std::vector<cv::Point2f> projected;
  cv::projectPoints(object, rvec, tvec, K, camera.distortion, projected);
  double sum = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const cv::Point2f e = projected[i] - image[i];
    sum += e.dot(e);
  }
  result.rms_reprojection_px = image.empty() ? 0.0 : std::sqrt(sum / image.size());
  result.correspondences = image.size();
  return result;
}

}  // namespace

std::optional<std::vector<Eigen::Vector2d>> DetectCheckerboard(const cv::Mat& gray,
                                                               const CheckerboardTarget& board) {
  CCSRM_CHECK(gray.type() == CV_8UC1);
  const cv::Size pattern(board.inner_corners_x, board.inner_corners_y);
  std::vector<cv::Point2f> corners;
  const bool found = cv::findChessboardCorners(
      gray, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found || corners.size() != static_cast<std::size_t>(pattern.area())) return std::nullopt;
  cv::cornerSubPix(gray, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  // The detector may start from either end; the black square outside
  // corner (0, 0) tells which.
  std::vector<cv::Point2f> board_xy;
  for (const Eigen::Vector3d& p : board.CornerPositions()) board_xy.emplace_back(p.x(), p.y());
  const cv::Mat H = cv::findHomography(board_xy, corners);
  if (H.empty()) return std::nullopt;
  const double s = board.square_m;
  const double outside = SampleBoard(gray, H, -0.5 * s, -0.5 * s);  // black when in order
  const double beside = SampleBoard(gray, H, 0.5 * s, -0.5 * s);    // white when in order
  if (outside > beside) std::reverse(corners.begin(), corners.end());
  std::vector<Eigen::Vector2d> out;
  for (const cv::Point2f& c : corners) out.emplace_back(c.x, c.y);
  return out;
}

bool IntrinsicCalibrationOptions::IsValid(std::string* error) const {
  if (min_views < 3) {
    if (error != nullptr) *error = "min_views must be at least 3";
    return false;
  }
  return true;
}

namespace {

// Detects `board` in every image and calibrates; with `world` its board is
// the last view and its pose is returned in *world_pose.
IntrinsicCalibration Calibrate(const std::vector<cv::Mat>& images,
                               const std::vector<std::string>& names,
                               const CheckerboardTarget& board, const WorldBoardView* world,
                               const std::string& camera_name,
                               const IntrinsicCalibrationOptions& options,
                               ExtrinsicCalibration* world_pose) {
  CCSRM_CHECK(images.size() == names.size());
  std::string reason;
  if (!board.IsValid(&reason)) ThrowInputError("(checkerboard)", "", reason);
  if (!options.IsValid(&reason)) ThrowInputError("(calibration options)", "", reason);
  if (images.empty()) ThrowInputError("(calibration images)", "", "no image");
  IntrinsicCalibration result;
  const cv::Size size = images[0].size();
  auto check_image = [&](const cv::Mat& image, const std::string& name) {
    if (image.type() != CV_8UC1) ThrowInputError(name, "", "expected an 8-bit gray image");
    if (image.size() != size) {
      ThrowInputError(name, "",
                      "image size " + std::to_string(image.cols) + "x" +
                          std::to_string(image.rows) + " differs from the first image's " +
                          std::to_string(size.width) + "x" + std::to_string(size.height));
    }
  };
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  const std::vector<cv::Point3f> corners_G = ToCv3f(board.CornerPositions());
  for (std::size_t i = 0; i < images.size(); ++i) {
    check_image(images[i], names[i]);
    const auto corners = DetectCheckerboard(images[i], board);
    if (!corners) {
      result.rejected_images.push_back(names[i]);
      continue;
    }
    result.used_images.push_back(names[i]);
    object_points.push_back(corners_G);
    image_points.push_back(ToCv2f(*corners));
  }
  if (static_cast<int>(image_points.size()) < options.min_views) {
    ThrowInputError(names[0], "",
                    "checkerboard " + std::to_string(board.inner_corners_x) + "x" +
                        std::to_string(board.inner_corners_y) + " found in only " +
                        std::to_string(image_points.size()) + " of " +
                        std::to_string(images.size()) + " images (need " +
                        std::to_string(options.min_views) + ")");
  }
  if (world != nullptr) {
    if (!world->board.IsValid(&reason)) ThrowInputError(world->name, "", reason);
    check_image(world->image, world->name);
    const auto corners = DetectCheckerboard(world->image, world->board);
    if (!corners) {
      ThrowInputError(world->name, "",
                      "checkerboard " + std::to_string(world->board.inner_corners_x) + "x" +
                          std::to_string(world->board.inner_corners_y) + " not found");
    }
    object_points.push_back(ToCv3f(world->board.CornerPositions()));
    image_points.push_back(ToCv2f(*corners));
  }
  cv::Mat K, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat std_intrinsics, std_extrinsics, per_view_errors;
  const int flags = options.fit_k3 ? 0 : cv::CALIB_FIX_K3;
  result.rms_reprojection_px = cv::calibrateCamera(
      object_points, image_points, size, K, distortion, rvecs, tvecs, std_intrinsics,
      std_extrinsics, per_view_errors, flags,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  const int board_views = static_cast<int>(result.used_images.size());
  for (int i = 0; i < board_views; ++i) {
    result.per_view_rms_px.push_back(per_view_errors.at<double>(i, 0));
  }
  Camera& camera = result.camera;
  camera.name = camera_name;
  camera.image_width_px = size.width;
  camera.image_height_px = size.height;
  Eigen::Matrix3d K_eigen;
  cv::cv2eigen(K, K_eigen);
  camera.K = K_eigen;
  distortion = distortion.reshape(1, 1);
  for (int i = 0; i < distortion.cols; ++i)
    camera.distortion.push_back(distortion.at<double>(0, i));
  if (world != nullptr) {
    cv::Mat R;
    cv::Rodrigues(rvecs.back(), R);
    Eigen::Matrix3d R_CG;
    Eigen::Vector3d p_CG;
    cv::cv2eigen(R, R_CG);
    cv::cv2eigen(tvecs.back(), p_CG);
    // p_C = R_CG (R_WG^T (p_W - p_WG)) + p_CG
    world_pose->R_CW = R_CG * world->R_WG.transpose();
    world_pose->p_CW = p_CG - world_pose->R_CW * world->p_WG;
    world_pose->rms_reprojection_px = per_view_errors.at<double>(board_views, 0);
    world_pose->correspondences = image_points.back().size();
    camera.R_CW = world_pose->R_CW;
    camera.p_CW = world_pose->p_CW;
  }
  return result;
}

}  // namespace

IntrinsicCalibration CalibrateIntrinsics(const std::vector<cv::Mat>& images,
                                         const std::vector<std::string>& names,
                                         const CheckerboardTarget& board,
                                         const std::string& camera_name,
                                         const IntrinsicCalibrationOptions& options) {
  return Calibrate(images, names, board, nullptr, camera_name, options, nullptr);
}

std::pair<IntrinsicCalibration, ExtrinsicCalibration> CalibrateCameraInWorld(
    const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
    const CheckerboardTarget& board, const WorldBoardView& world, const std::string& camera_name,
    const IntrinsicCalibrationOptions& options) {
  ExtrinsicCalibration pose;
  IntrinsicCalibration intrinsics =
      Calibrate(images, names, board, &world, camera_name, options, &pose);
  return {std::move(intrinsics), pose};
}

ExtrinsicCalibration CalibrateExtrinsicsFromBoard(const Camera& camera, const cv::Mat& image,
                                                  const std::string& image_name,
                                                  const CheckerboardTarget& board,
                                                  const Eigen::Matrix3d& R_WG,
                                                  const Eigen::Vector3d& p_WG) {
  if (image.type() != CV_8UC1) ThrowInputError(image_name, "", "expected an 8-bit gray image");
  if (image.cols != camera.image_width_px || image.rows != camera.image_height_px) {
    ThrowInputError(image_name, "", "image size does not match camera '" + camera.name + "'");
  }
  const auto corners = DetectCheckerboard(image, board);
  if (!corners) {
    ThrowInputError(image_name, "",
                    "checkerboard " + std::to_string(board.inner_corners_x) + "x" +
                        std::to_string(board.inner_corners_y) + " not found");
  }
  std::vector<Eigen::Vector3d> corners_W;
  for (const Eigen::Vector3d& p_G : board.CornerPositions()) corners_W.push_back(R_WG * p_G + p_WG);
  return SolvePose(camera, ToCv3f(corners_W), ToCv2f(*corners), false);
}

ExtrinsicCalibration CalibrateExtrinsicsFromMarkers(
    const Camera& camera, const std::vector<Eigen::Vector3d>& p_W_reference,
    const std::vector<std::vector<Eigen::Vector2d>>& detections_px,
    const MarkerExtrinsicsOptions& options) {
  std::vector<Eigen::Vector3d> reference;
  for (const Eigen::Vector3d& p : p_W_reference) {
    if (p.allFinite()) reference.push_back(p);
  }
  Camera estimate = camera;
  ExtrinsicCalibration result;
  result.R_CW = camera.R_CW;
  result.p_CW = camera.p_CW;
  // A rough pose mostly shifts the whole image: first find the shift that
  // lines up the most detections of the first frame with projected markers
  // (a vote over every projection-detection pair).
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  {
    std::vector<bool> in_front;
    const std::vector<Eigen::Vector2d> uv = ProjectPoints(estimate, reference, &in_front);
    const std::vector<Eigen::Vector2d>& blobs =
        detections_px.empty() ? std::vector<Eigen::Vector2d>() : detections_px[0];
    constexpr double kVoteRadiusPx = 2.0;
    int best_votes = 0;
    for (std::size_t r = 0; r < reference.size(); ++r) {
      if (!in_front[r]) continue;
      for (const Eigen::Vector2d& blob : blobs) {
        const Eigen::Vector2d candidate = blob - uv[r];
        if (candidate.norm() > options.max_shift_px) continue;
        int votes = 0;
        for (std::size_t q = 0; q < reference.size(); ++q) {
          if (!in_front[q]) continue;
          for (const Eigen::Vector2d& other : blobs) {
            if ((other - uv[q] - candidate).squaredNorm() < kVoteRadiusPx * kVoteRadiusPx) {
              ++votes;
              break;
            }
          }
        }
        if (votes > best_votes) {
          best_votes = votes;
          shift = candidate;
        }
      }
    }
  }
  for (std::size_t round = 0; round < options.match_gates_px.size(); ++round) {
    const double gate = options.match_gates_px[round];
    std::vector<bool> in_front;
    std::vector<Eigen::Vector2d> uv = ProjectPoints(estimate, reference, &in_front);
    if (round == 0) {
      for (Eigen::Vector2d& p : uv) p += shift;
    }
    std::vector<cv::Point3f> object;
    std::vector<cv::Point2f> image;
    for (const std::vector<Eigen::Vector2d>& blobs : detections_px) {
      // Mutual nearest neighbours within the gate: a blob near two
      // projections (or a projection near two blobs) is left out.
      for (std::size_t r = 0; r < reference.size(); ++r) {
        if (!in_front[r]) continue;
        int best = -1;
        double best_d = gate;
        for (std::size_t b = 0; b < blobs.size(); ++b) {
          const double d = (blobs[b] - uv[r]).norm();
          if (d < best_d) {
            best_d = d;
            best = static_cast<int>(b);
          }
        }
        if (best < 0) continue;
        bool mutual = true;
        for (std::size_t other = 0; other < reference.size() && mutual; ++other) {
          if (other != r && in_front[other] && (blobs[best] - uv[other]).norm() < best_d) {
            mutual = false;
          }
        }
        if (!mutual) continue;
        object.emplace_back(reference[r].x(), reference[r].y(), reference[r].z());
        image.emplace_back(blobs[best].x(), blobs[best].y());
      }
    }
    if (static_cast<int>(image.size()) < std::max(4, options.min_points)) {
      ThrowInputError(camera.name, "",
                      "only " + std::to_string(image.size()) +
                          " detections match the reference markers within " +
                          std::to_string(static_cast<int>(gate)) +
                          " px of the starting pose (need " +
                          std::to_string(std::max(4, options.min_points)) +
                          "); is the camera's starting pose right?");
    }
    result = SolvePose(estimate, object, image, true);
    estimate.R_CW = result.R_CW;
    estimate.p_CW = result.p_CW;
  }
  return result;
}

}  // namespace ccsrm::cameras
