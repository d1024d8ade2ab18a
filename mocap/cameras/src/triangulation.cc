#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Distance [normalized units] of x_j from the epipolar line of x_i in camera j,
// with E_ji the essential matrix taking camera i to camera j.
double EpipolarDistance(const Eigen::Matrix3d& E_ji, const Eigen::Vector2d& x_i,
                        const Eigen::Vector2d& x_j) {
  const Eigen::Vector3d line = E_ji * x_i.homogeneous();
  const double norm = std::hypot(line.x(), line.y());
  if (!(norm > 0.0)) return std::numeric_limits<double>::infinity();
  return std::abs(x_j.homogeneous().dot(line)) / norm;
}

// What a candidate point needs while the frame is matched.
struct Candidate {
  std::vector<View> views;  // sorted by camera
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double rms_px = 0.0;
  // Cameras that should have seen the point (in front, inside the image,
  // delivering detections this frame) but are not among its views.
  int unexplained_misses = 0;
};

class FrameMatcher {
 public:
  FrameMatcher(const CameraRig& rig, const std::vector<std::vector<Eigen::Vector2d>>& uv_px,
               const TriangulationOptions& options)
      : rig_(rig), options_(options) {
    const std::size_t n = rig.cameras.size();
    xy_.resize(n);
    for (std::size_t c = 0; c < n; ++c) {
      xy_[c] = UndistortToNormalized(rig.cameras[c], uv_px[c]);
      focal_.push_back(0.5 * (rig.cameras[c].fx() + rig.cameras[c].fy()));
    }
  }

  std::vector<TriangulatedPoint> Run() {
    GenerateCandidates();
    return Select();
  }

 private:
  // Reprojection error [px] of p_W in camera c against its detection `blob`.
  double ReprojectionError(int c, int blob, const Eigen::Vector3d& p_W) const {
    const Camera& camera = rig_.cameras[c];
    const Eigen::Vector3d p_C = camera.R_CW * p_W + camera.p_CW;
    if (p_C.z() < options_.min_depth_m) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d e = p_C.hnormalized() - xy_[c][blob];
    return std::hypot(camera.fx() * e.x(), camera.fy() * e.y());
  }

  // Triangulates the views (DLT + refinement) and fills p_W and rms_px.
  void Solve(Candidate* candidate) const {
    std::vector<Eigen::Matrix3d> R;
    std::vector<Eigen::Vector3d> t;
    std::vector<Eigen::Vector2d> xy;
    std::vector<const Camera*> cams;
    for (const View& view : candidate->views) {
      const Camera& camera = rig_.cameras[view.camera];
      R.push_back(camera.R_CW);
      t.push_back(camera.p_CW);
      xy.push_back(xy_[view.camera][view.blob]);
      cams.push_back(&camera);
    }
    const Eigen::Vector3d initial = TriangulateDlt(R, t, xy);
    candidate->p_W = RefineTriangulation(cams, xy, initial, options_.refinement_iterations);
    double sum = 0.0;
    for (const View& view : candidate->views) {
      const double e = ReprojectionError(view.camera, view.blob, candidate->p_W);
      sum += e * e;
    }
    candidate->rms_px = std::sqrt(sum / candidate->views.size());
  }

  // Grows a two-view seed with the best detection of every other camera,
  // then drops the worst views while any exceeds the tolerance.
  bool Grow(Candidate* candidate) const {
    Solve(candidate);
    if (!std::isfinite(candidate->rms_px)) return false;
    const int seed_a = candidate->views[0].camera;
    const int seed_b = candidate->views[1].camera;
    for (int c = 0; c < static_cast<int>(xy_.size()); ++c) {
      if (c == seed_a || c == seed_b) continue;
      int best = -1;
      double best_error = options_.reprojection_tolerance_px;
      for (int blob = 0; blob < static_cast<int>(xy_[c].size()); ++blob) {
        const double e = ReprojectionError(c, blob, candidate->p_W);
        if (e < best_error) {
          best_error = e;
          best = blob;
        }
      }
      if (best >= 0) candidate->views.push_back(View{c, best});
    }
    std::sort(candidate->views.begin(), candidate->views.end(),
              [](const View& a, const View& b) { return a.camera < b.camera; });
    for (;;) {
      Solve(candidate);
      std::size_t worst = 0;
      double worst_error = -1.0;
      for (std::size_t i = 0; i < candidate->views.size(); ++i) {
        const double e =
            ReprojectionError(candidate->views[i].camera, candidate->views[i].blob, candidate->p_W);
        if (!(e <= worst_error)) {
          worst_error = e;
          worst = i;
        }
      }
      if (worst_error <= options_.reprojection_tolerance_px) return true;
      if (candidate->views.size() <= static_cast<std::size_t>(options_.min_views)) return false;
      candidate->views.erase(candidate->views.begin() + static_cast<long>(worst));
    }
  }

  void GenerateCandidates() {
    const int n = static_cast<int>(xy_.size());
    std::map<std::vector<std::pair<int, int>>, std::size_t> seen;
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const Camera& ci = rig_.cameras[i];
        const Camera& cj = rig_.cameras[j];
        const Eigen::Matrix3d R_ji = cj.R_CW * ci.R_CW.transpose();
        const Eigen::Vector3d t_ji = cj.p_CW - R_ji * ci.p_CW;
        const Eigen::Matrix3d E_ji = Skew(t_ji) * R_ji;
        const Eigen::Matrix3d E_ij = E_ji.transpose();
        for (int a = 0; a < static_cast<int>(xy_[i].size()); ++a) {
          for (int b = 0; b < static_cast<int>(xy_[j].size()); ++b) {
            const double d_j = focal_[j] * EpipolarDistance(E_ji, xy_[i][a], xy_[j][b]);
            if (d_j > options_.epipolar_tolerance_px) continue;
            const double d_i = focal_[i] * EpipolarDistance(E_ij, xy_[j][b], xy_[i][a]);
            if (d_i > options_.epipolar_tolerance_px) continue;
            Candidate candidate;
            candidate.views = {View{i, a}, View{j, b}};
            if (!Grow(&candidate)) continue;
            candidate.unexplained_misses = UnexplainedMisses(candidate);
            std::vector<std::pair<int, int>> key;
            for (const View& v : candidate.views) key.emplace_back(v.camera, v.blob);
            if (seen.count(key) > 0) continue;
            seen[key] = candidates_.size();
            candidates_.push_back(std::move(candidate));
          }
        }
      }
    }
  }

  int UnexplainedMisses(const Candidate& candidate) const {
    constexpr double kMarginPx = 10.0;
    int misses = 0;
    for (int c = 0; c < static_cast<int>(xy_.size()); ++c) {
      if (xy_[c].empty()) continue;  // a dropped frame explains itself
      bool viewed = false;
      for (const View& v : candidate.views) viewed = viewed || v.camera == c;
      if (viewed) continue;
      const Camera& camera = rig_.cameras[c];
      std::vector<bool> in_front;
      const Eigen::Vector2d uv = ProjectPoints(camera, {candidate.p_W}, &in_front)[0];
      if (in_front[0] && uv.x() > kMarginPx && uv.y() > kMarginPx &&
          uv.x() < camera.image_width_px - kMarginPx &&
          uv.y() < camera.image_height_px - kMarginPx) {
        ++misses;
      }
    }
    return misses;
  }

  // True when candidate a wins its conflict with b: both are the same point
  // seen through different views (a fits better), or a explains every
  // camera's silence and b does not (a ghost from a wrong pairing lands where
  // other cameras should have seen it).
  bool Wins(const Candidate& a, const Candidate& b) const {
    constexpr double kSamePointM = 1e-3;
    if ((a.p_W - b.p_W).norm() < kSamePointM) return a.rms_px < b.rms_px;
    return a.unexplained_misses == 0 && b.unexplained_misses > 0;
  }

  bool Shares(const Candidate& a, const Candidate& b) const {
    for (const View& va : a.views) {
      for (const View& vb : b.views) {
        if (va.camera == vb.camera && va.blob == vb.blob) return true;
      }
    }
    return false;
  }

  // Accepts candidates from the most views down. Within one view count a
  // candidate that shares a detection with another still-available one must
  // win every such conflict (Wins); otherwise the match is ambiguous and
  // dropped rather than guessed.
  std::vector<TriangulatedPoint> Select() {
    std::vector<std::vector<bool>> used(xy_.size());
    for (std::size_t c = 0; c < xy_.size(); ++c) used[c].assign(xy_[c].size(), false);
    auto is_available = [&](const Candidate& candidate) {
      for (const View& v : candidate.views) {
        if (used[v.camera][v.blob]) return false;
      }
      return true;
    };
    std::vector<TriangulatedPoint> points;
    for (int views = static_cast<int>(xy_.size()); views >= options_.min_views; --views) {
      std::vector<std::size_t> level;
      for (std::size_t k = 0; k < candidates_.size(); ++k) {
        if (static_cast<int>(candidates_[k].views.size()) == views &&
            is_available(candidates_[k])) {
          level.push_back(k);
        }
      }
      std::vector<std::size_t> accepted;
      for (std::size_t a : level) {
        bool ambiguous = false;
        for (std::size_t b : level) {
          if (a != b && Shares(candidates_[a], candidates_[b]) &&
              !Wins(candidates_[a], candidates_[b])) {
            ambiguous = true;
            break;
          }
        }
        if (!ambiguous) accepted.push_back(a);
      }
      for (std::size_t k : accepted) {
        const Candidate& candidate = candidates_[k];
        for (const View& v : candidate.views) used[v.camera][v.blob] = true;
        TriangulatedPoint point;
        point.p_W = candidate.p_W;
        point.views = candidate.views;
        point.rms_reprojection_px = candidate.rms_px;
        double sum = 0.0;
        for (const View& v : candidate.views) {
          const Camera& camera = rig_.cameras[v.camera];
          const Eigen::Vector3d direction =
              (camera.R_CW.transpose() * xy_[v.camera][v.blob].homogeneous()).normalized();
          const double distance = (point.p_W - camera.p_WC()).cross(direction).norm();
          sum += distance * distance;
        }
        point.ray_residual_m = std::sqrt(sum / candidate.views.size());
        points.push_back(std::move(point));
      }
    }
    return points;
  }

  const CameraRig& rig_;
  const TriangulationOptions& options_;
  std::vector<std::vector<Eigen::Vector2d>> xy_;
  std::vector<double> focal_;
  std::vector<Candidate> candidates_;
};

}  // namespace

bool TriangulationOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(epipolar_tolerance_px > 0.0)) return fail("epipolar_tolerance_px must be positive");
  if (!(reprojection_tolerance_px > 0.0)) return fail("reprojection_tolerance_px must be positive");
  if (min_views < 2) return fail("min_views must be at least 2");
  if (refinement_iterations < 0) return fail("refinement_iterations must be >= 0");
  if (!(min_depth_m >= 0.0)) return fail("min_depth_m must be >= 0");
  return true;
}

Eigen::Vector3d TriangulateDlt(const std::vector<Eigen::Matrix3d>& R_CW,
                               const std::vector<Eigen::Vector3d>& p_CW,
                               const std::vector<Eigen::Vector2d>& xy) {
  CCSRM_CHECK(R_CW.size() == xy.size() && p_CW.size() == xy.size() && xy.size() >= 2);
  // Each view gives x (P3 . X) - (P1 . X) = 0 and y (P3 . X) - (P2 . X) = 0
  // with P = [R | t] in normalized coordinates.
  Eigen::MatrixXd A(2 * xy.size(), 4);
  for (std::size_t i = 0; i < xy.size(); ++i) {
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = R_CW[i];
    P.col(3) = p_CW[i];
    A.row(2 * i) = xy[i].x() * P.row(2) - P.row(0);
    A.row(2 * i + 1) = xy[i].y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  return X.head<3>() / X.w();
}

Eigen::Vector3d RefineTriangulation(const std::vector<const Camera*>& cameras,
                                    const std::vector<Eigen::Vector2d>& xy,
                                    const Eigen::Vector3d& p_W_initial, int iterations) {
  CCSRM_CHECK(cameras.size() == xy.size());
  Eigen::Vector3d p_W = p_W_initial;
  if (!p_W.allFinite()) return p_W;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < xy.size(); ++i) {
      const Camera& camera = *cameras[i];
      const Eigen::Vector3d p_C = camera.R_CW * p_W + camera.p_CW;
      if (!(p_C.z() > 0.0)) return p_W;  // behind a camera: leave it to the caller's check
      const double inv_z = 1.0 / p_C.z();
      const Eigen::Vector2d residual(camera.fx() * (p_C.x() * inv_z - xy[i].x()),
                                     camera.fy() * (p_C.y() * inv_z - xy[i].y()));
      // d(x/z, y/z)/d p_C, scaled to pixels, then chained through R_CW.
      Eigen::Matrix<double, 2, 3> J_C;
      J_C << camera.fx() * inv_z, 0.0, -camera.fx() * p_C.x() * inv_z * inv_z, 0.0,
          camera.fy() * inv_z, -camera.fy() * p_C.y() * inv_z * inv_z;
      const Eigen::Matrix<double, 2, 3> J = J_C * camera.R_CW;
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * residual;
    }
    const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) break;
    p_W += step;
    if (step.norm() < 1e-12) break;
  }
  return p_W;
}

std::vector<TriangulatedPoint> TriangulateFrame(
    const CameraRig& rig, const std::vector<std::vector<Eigen::Vector2d>>& uv_px,
    const TriangulationOptions& options) {
  CCSRM_CHECK(uv_px.size() == rig.cameras.size());
  FrameMatcher matcher(rig, uv_px, options);
  return matcher.Run();
}

}  // namespace ccsrm::cameras
