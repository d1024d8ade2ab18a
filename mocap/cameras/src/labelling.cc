// Labelling triangulated points with the markers of a layout.
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

double RotationAngle(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0));
}

// A rigid fit of a body's markers to points: R_WB, p_WB, and the error of
// each fitted marker.
struct Fit {
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();
  double rms_m = 0.0;
  double worst_m = 0.0;
  int worst_marker = -1;
};

// point_of_marker[m] = index into points, or -1. Needs >= 3 markers.
Fit FitBody(const std::vector<Eigen::Vector3d>& p_BM, const std::vector<Eigen::Vector3d>& points,
            const std::vector<int>& point_of_marker) {
  std::vector<int> present;
  for (int m = 0; m < static_cast<int>(p_BM.size()); ++m) {
    if (point_of_marker[m] >= 0) present.push_back(m);
  }
  CCSRM_CHECK(present.size() >= 3);
  Eigen::Matrix3Xd src(3, present.size());
  Eigen::Matrix3Xd dst(3, present.size());
  for (std::size_t k = 0; k < present.size(); ++k) {
    src.col(k) = p_BM[present[k]];
    dst.col(k) = points[point_of_marker[present[k]]];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
  Fit fit;
  fit.R_WB = T.topLeftCorner<3, 3>();
  fit.p_WB = T.topRightCorner<3, 1>();
  double sum = 0.0;
  for (std::size_t k = 0; k < present.size(); ++k) {
    const double e = (fit.R_WB * src.col(k) + fit.p_WB - dst.col(k)).norm();
    sum += e * e;
    if (e > fit.worst_m) {
      fit.worst_m = e;
      fit.worst_marker = present[k];
    }
  }
  fit.rms_m = std::sqrt(sum / present.size());
  return fit;
}

// A set of points matching a body pattern by distances.
struct Instance {
  std::vector<int> point_of_marker;
  int count = 0;
  Fit fit;
};

// Every assignment of points to the pattern's markers (at least 3 present,
// every pair of distances within tolerance) whose rigid fit is good,
// reduced to non-overlapping instances (more markers first, then better fit).
std::vector<Instance> FindInstances(const std::vector<Eigen::Vector3d>& p_BM,
                                    const std::vector<Eigen::Vector3d>& points,
                                    const Eigen::MatrixXd& distance,
                                    const LabellingOptions& options) {
  const int k = static_cast<int>(p_BM.size());
  const int n = static_cast<int>(points.size());
  std::vector<Instance> found;
  if (k < 3 || n < 3) return found;
  std::vector<int> assignment(k, -1);
  const int max_missing = k - 3;
  // Depth-first over markers; each is a point consistent with every marker
  // already placed, or missing (while enough markers remain).
  std::function<void(int, int)> place = [&](int m, int missing) {
    if (m == k) {
      Instance instance;
      instance.point_of_marker = assignment;
      instance.count = k - missing;
      instance.fit = FitBody(p_BM, points, assignment);
      if (instance.fit.worst_m <= options.max_fit_error_m) found.push_back(std::move(instance));
      return;
    }
    if (missing < max_missing) place(m + 1, missing + 1);
    for (int i = 0; i < n; ++i) {
      bool consistent = true;
      for (int a = 0; a < m && consistent; ++a) {
        const int j = assignment[a];
        if (j < 0) continue;
        consistent = j != i && std::abs(distance(i, j) - (p_BM[a] - p_BM[m]).norm()) <=
                                   options.pattern_tolerance_m;
      }
      if (!consistent) continue;
      assignment[m] = i;
      place(m + 1, missing);
      assignment[m] = -1;
    }
  };
  place(0, 0);
  std::sort(found.begin(), found.end(), [](const Instance& a, const Instance& b) {
    if (a.count != b.count) return a.count > b.count;
    return a.fit.rms_m < b.fit.rms_m;
  });
  std::vector<bool> taken(n, false);
  std::vector<Instance> kept;
  for (Instance& instance : found) {
    bool overlaps = false;
    for (int p : instance.point_of_marker) overlaps = overlaps || (p >= 0 && taken[p]);
    if (overlaps) continue;
    for (int p : instance.point_of_marker) {
      if (p >= 0) taken[p] = true;
    }
    kept.push_back(std::move(instance));
  }
  return kept;
}

}  // namespace

bool LabellingOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(pattern_tolerance_m > 0.0)) return fail("pattern_tolerance_m must be positive");
  if (!(max_fit_error_m > 0.0)) return fail("max_fit_error_m must be positive");
  if (!(max_link_spacing_m > 0.0)) return fail("max_link_spacing_m must be positive");
  if (!(reacquire_gate_m > 0.0)) return fail("reacquire_gate_m must be positive");
  if (!(marker_gate_m > 0.0)) return fail("marker_gate_m must be positive");
  if (!(max_relative_rotation_deg > 0.0 && max_relative_rotation_deg <= 180.0)) {
    return fail("max_relative_rotation_deg must be in (0, 180]");
  }
  if (max_prediction_frames < 0) return fail("max_prediction_frames must be >= 0");
  return true;
}

// The state of one frame while it is being labelled.
struct MarkerLabeller::Frame {
  const std::vector<Eigen::Vector3d>& points;
  std::vector<bool> used;
  std::vector<int> marker_of_point;
  // Per body: point of each of its markers (-1 = not found) and its fit.
  std::vector<std::vector<int>> point_of_marker;
  std::vector<bool> has_pose;
  std::vector<Fit> fits;
};

MarkerLabeller::MarkerLabeller(mocap::MarkerLayout layout, LabellingOptions options)
    : layout_(std::move(layout)), options_(options) {
  std::size_t first = 0;
  for (std::size_t b = 0; b < layout_.bodies.size(); ++b) {
    const mocap::RigidBody& body = layout_.bodies[b];
    CCSRM_CHECK(body.p_BM.size() == body.marker_names.size());
    first_marker_.push_back(first);
    first += body.p_BM.size();
    int pattern = static_cast<int>(b);
    for (std::size_t other = 0; other < b; ++other) {
      if (layout_.bodies[other].p_BM == body.p_BM) {
        pattern = pattern_of_body_[other];
        break;
      }
    }
    pattern_of_body_.push_back(pattern);
  }
  tracks_.resize(layout_.bodies.size());
}

bool MarkerLabeller::PredictPose(std::size_t body, Eigen::Matrix3d* R_WB,
                                 Eigen::Vector3d* p_WB) const {
  if (layout_.bodies[body].link == 0) {
    // The ground carries W: its markers are where the layout says.
    *R_WB = Eigen::Matrix3d::Identity();
    *p_WB = Eigen::Vector3d::Zero();
    return true;
  }
  const BodyTrack& track = tracks_[body];
  if (!track.valid) return false;
  const int steps = track.frames_since_seen + 1;
  *R_WB = track.R_WB;
  *p_WB = track.p_WB;
  if (track.has_velocity) {
    for (int s = 0; s < steps; ++s) *R_WB = track.dR_per_frame * *R_WB;
    *p_WB += steps * track.v_per_frame;
  }
  return true;
}

std::vector<Eigen::Vector3d> MarkerLabeller::LabelFrame(const std::vector<Eigen::Vector3d>& points,
                                                        std::vector<int>* label_of_point) {
  const std::size_t bodies = layout_.bodies.size();
  const int n = static_cast<int>(points.size());
  Frame frame{points, std::vector<bool>(n, false), std::vector<int>(n, -1), {}, {}, {}};
  frame.point_of_marker.resize(bodies);
  frame.has_pose.assign(bodies, false);
  frame.fits.resize(bodies);
  for (std::size_t b = 0; b < bodies; ++b) {
    frame.point_of_marker[b].assign(layout_.bodies[b].p_BM.size(), -1);
  }
  Eigen::MatrixXd distance(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) distance(i, j) = (points[i] - points[j]).norm();
  }
  // Instances of every distinct pattern, found once.
  std::vector<std::vector<Instance>> instances(bodies);
  for (std::size_t b = 0; b < bodies; ++b) {
    if (pattern_of_body_[b] == static_cast<int>(b)) {
      instances[b] = FindInstances(layout_.bodies[b].p_BM, points, distance, options_);
    }
  }
  std::vector<std::vector<bool>> instance_taken(bodies);
  for (std::size_t b = 0; b < bodies; ++b) instance_taken[b].assign(instances[b].size(), false);
  const double max_rotation = options_.max_relative_rotation_deg * kPi / 180.0;

  // Gives body b the markers of an instance, completes it with points near
  // the fitted pattern, and drops markers that do not fit.
  auto accept = [&](std::size_t b, std::vector<int> point_of_marker) {
    const std::vector<Eigen::Vector3d>& p_BM = layout_.bodies[b].p_BM;
    Fit fit = FitBody(p_BM, points, point_of_marker);
    for (std::size_t m = 0; m < p_BM.size(); ++m) {
      if (point_of_marker[m] >= 0) continue;
      const Eigen::Vector3d predicted = fit.R_WB * p_BM[m] + fit.p_WB;
      int best = -1;
      double best_distance = options_.marker_gate_m;
      for (int i = 0; i < n; ++i) {
        if (frame.used[i]) continue;
        bool in_this_body = false;
        for (int p : point_of_marker) in_this_body = in_this_body || p == i;
        const double d = (points[i] - predicted).norm();
        if (!in_this_body && d < best_distance) {
          best_distance = d;
          best = i;
        }
      }
      if (best >= 0) point_of_marker[m] = best;
    }
    int count = 0;
    for (int p : point_of_marker) count += p >= 0 ? 1 : 0;
    for (;;) {
      fit = FitBody(p_BM, points, point_of_marker);
      if (fit.worst_m <= options_.max_fit_error_m) break;
      if (count <= 3) return false;
      point_of_marker[fit.worst_marker] = -1;
      --count;
    }
    for (std::size_t m = 0; m < p_BM.size(); ++m) {
      const int p = point_of_marker[m];
      if (p < 0) continue;
      frame.used[p] = true;
      frame.marker_of_point[p] = static_cast<int>(first_marker_[b] + m);
    }
    frame.point_of_marker[b] = point_of_marker;
    frame.has_pose[b] = true;
    frame.fits[b] = fit;
    return true;
  };
  auto instance_free = [&](const Instance& instance) {
    for (int p : instance.point_of_marker) {
      if (p >= 0 && frame.used[p]) return false;
    }
    return true;
  };

  // 1. Bodies with a prediction (the ground; links tracked in recent frames):
  //    the instance nearest the predicted pose, within the gate.
  for (std::size_t b = 0; b < bodies; ++b) {
    Eigen::Matrix3d R_pred;
    Eigen::Vector3d p_pred;
    if (!PredictPose(b, &R_pred, &p_pred)) continue;
    const std::size_t pattern = pattern_of_body_[b];
    int best = -1;
    double best_distance = options_.reacquire_gate_m;
    for (std::size_t k = 0; k < instances[pattern].size(); ++k) {
      const Instance& instance = instances[pattern][k];
      if (instance_taken[pattern][k] || !instance_free(instance)) continue;
      const double d = (instance.fit.p_WB - p_pred).norm();
      if (d < best_distance &&
          RotationAngle(R_pred.transpose() * instance.fit.R_WB) < max_rotation) {
        best_distance = d;
        best = static_cast<int>(k);
      }
    }
    if (best >= 0 && accept(b, instances[pattern][best].point_of_marker)) {
      instance_taken[pattern][best] = true;
    }
  }

  // 2. The chain: link i's plate is the nearest free instance ahead of link
  //    i-1 (of W's origin, joint 1, for link 1), within one link spacing and
  //    a small relative rotation.
  std::vector<int> body_of_link;
  for (std::size_t b = 0; b < bodies; ++b) {
    const int link = layout_.bodies[b].link;
    if (link >= static_cast<int>(body_of_link.size())) body_of_link.resize(link + 1, -1);
    body_of_link[link] = static_cast<int>(b);
  }
  for (int link = 1; link < static_cast<int>(body_of_link.size()); ++link) {
    const int b = body_of_link[link];
    if (b < 0 || frame.has_pose[b]) continue;
    Eigen::Matrix3d R_anchor = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_anchor = Eigen::Vector3d::Zero();
    if (link > 1) {
      const int previous = body_of_link[link - 1];
      if (previous < 0 || !frame.has_pose[previous]) continue;
      R_anchor = frame.fits[previous].R_WB;
      p_anchor = frame.fits[previous].p_WB;
    }
    const std::size_t pattern = pattern_of_body_[b];
    int best = -1;
    double best_distance = options_.max_link_spacing_m;
    for (std::size_t k = 0; k < instances[pattern].size(); ++k) {
      const Instance& instance = instances[pattern][k];
      if (instance_taken[pattern][k] || !instance_free(instance)) continue;
      const Eigen::Vector3d step = instance.fit.p_WB - p_anchor;
      const double d = step.norm();
      if (d < best_distance && step.dot(R_anchor.col(2)) > 0.0 &&
          RotationAngle(R_anchor.transpose() * instance.fit.R_WB) < max_rotation) {
        best_distance = d;
        best = static_cast<int>(k);
      }
    }
    if (best >= 0 &&
        accept(static_cast<std::size_t>(b), instances[pattern][best].point_of_marker)) {
      instance_taken[pattern][best] = true;
    }
  }

  // 3. Bodies still without a pose but predicted: single markers near their
  //    predicted positions (a plate with one or two markers in view).
  for (std::size_t b = 0; b < bodies; ++b) {
    if (frame.has_pose[b]) continue;
    Eigen::Matrix3d R_pred;
    Eigen::Vector3d p_pred;
    if (!PredictPose(b, &R_pred, &p_pred)) continue;
    const std::vector<Eigen::Vector3d>& p_BM = layout_.bodies[b].p_BM;
    std::vector<int> point_of_marker(p_BM.size(), -1);
    int count = 0;
    for (std::size_t m = 0; m < p_BM.size(); ++m) {
      const Eigen::Vector3d predicted = R_pred * p_BM[m] + p_pred;
      int best = -1;
      double best_distance = options_.marker_gate_m;
      for (int i = 0; i < n; ++i) {
        const double d = (points[i] - predicted).norm();
        if (!frame.used[i] && d < best_distance) {
          best_distance = d;
          best = i;
        }
      }
      // A point near two predictions is ambiguous: leave it.
      if (best >= 0 && std::find(point_of_marker.begin(), point_of_marker.end(), best) ==
                           point_of_marker.end()) {
        point_of_marker[m] = best;
        ++count;
      }
    }
    if (count >= 3) {
      accept(b, point_of_marker);
    } else if (count > 0) {
      for (std::size_t m = 0; m < p_BM.size(); ++m) {
        const int p = point_of_marker[m];
        if (p < 0) continue;
        frame.used[p] = true;
        frame.marker_of_point[p] = static_cast<int>(first_marker_[b] + m);
      }
      frame.point_of_marker[b] = point_of_marker;
    }
  }

  // Tracks: a body with a pose starts or continues its track; others coast.
  for (std::size_t b = 0; b < bodies; ++b) {
    BodyTrack& track = tracks_[b];
    if (frame.has_pose[b]) {
      const Fit& fit = frame.fits[b];
      if (track.valid && track.frames_since_seen == 0) {
        track.dR_per_frame = fit.R_WB * track.R_WB.transpose();
        track.v_per_frame = fit.p_WB - track.p_WB;
        track.has_velocity = true;
      } else {
        track.has_velocity = false;
      }
      track.valid = true;
      track.frames_since_seen = 0;
      track.R_WB = fit.R_WB;
      track.p_WB = fit.p_WB;
    } else if (track.valid) {
      ++track.frames_since_seen;
      if (track.frames_since_seen > options_.max_prediction_frames) track = BodyTrack();
    }
  }

  std::vector<Eigen::Vector3d> positions(layout_.marker_count(), Eigen::Vector3d::Constant(kNaN));
  for (int i = 0; i < n; ++i) {
    if (frame.marker_of_point[i] >= 0) positions[frame.marker_of_point[i]] = points[i];
  }
  if (label_of_point != nullptr) *label_of_point = frame.marker_of_point;
  return positions;
}

}  // namespace ccsrm::cameras
