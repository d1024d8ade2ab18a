#include "ccsrm/mocap/processing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/mocap/signal.h"
#include "ccsrm/sim/kinematics.h"
#include "chain_fit.h"

namespace ccsrm::mocap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

// Marker positions of F frames × K markers, row-major [(f·K + k)·3 + axis].
class MarkerFrames {
 public:
  MarkerFrames(std::size_t frames, std::size_t markers)
      : frames_(frames), markers_(markers), values_(frames * markers * 3, kNaN) {}
  std::size_t stride() const { return markers_ * 3; }
  double* column(std::size_t k, int axis) { return values_.data() + k * 3 + axis; }
  bool finite(std::size_t f, std::size_t k) const {
    return std::isfinite(values_[(f * markers_ + k) * 3]);
  }
  Eigen::Vector3d get(std::size_t f, std::size_t k) const {
    const double* p = &values_[(f * markers_ + k) * 3];
    return Eigen::Vector3d(p[0], p[1], p[2]);
  }
  void set(std::size_t f, std::size_t k, const Eigen::Vector3d& p) {
    double* q = &values_[(f * markers_ + k) * 3];
    q[0] = p.x();
    q[1] = p.y();
    q[2] = p.z();
  }
  std::vector<double>& values() { return values_; }
  std::size_t frames() const { return frames_; }

 private:
  std::size_t frames_;
  std::size_t markers_;
  std::vector<double> values_;
};

// First marker index of each body in layout order.
std::vector<std::size_t> BodyOffsets(const MarkerLayout& layout) {
  std::vector<std::size_t> offsets;
  std::size_t k = 0;
  for (const RigidBody& body : layout.bodies) {
    offsets.push_back(k);
    k += body.marker_names.size();
  }
  return offsets;
}

// Where the markers and their times sit in `table`'s file, for messages: the
// HDF5 paths of our own files, the format's own words otherwise.
std::string MarkerField(const MarkerTable& table) {
  if (table.format == "ccsrm-dataset") return "/mocap/markers";
  if (table.format == "ccsrm-run") return "/markers";
  return "marker data";
}
std::string TimeField(const MarkerTable& table) {
  if (table.format == "ccsrm-dataset") return "/mocap/time";
  if (table.format == "ccsrm-run") return "/time";
  return "frames";
}

std::vector<double> TimeBase(const MarkerTable& table, const std::vector<double>& time,
                             const std::string& source, double* rate_hz) {
  const std::size_t frames = table.frames();
  if (time.empty()) {
    if (!(table.rate_hz > 0.0) || !std::isfinite(table.rate_hz)) {
      ThrowInputError(source, "frame rate", "must be > 0 Hz to build a time base");
    }
    *rate_hz = table.rate_hz;
    std::vector<double> t(frames);
    for (std::size_t f = 0; f < frames; ++f) t[f] = static_cast<double>(f) / table.rate_hz;
    return t;
  }
  if (time.size() != frames) {
    ThrowInputError(
        source, "time",
        std::to_string(time.size()) + " times for " + std::to_string(frames) + " frames");
  }
  for (std::size_t f = 0; f < frames; ++f) {
    if (!std::isfinite(time[f]) || (f > 0 && !(time[f] > time[f - 1]))) {
      ThrowInputError(source, "time[" + std::to_string(f) + "]",
                      "times must be finite and strictly increasing");
    }
  }
  if (frames < 2) {
    *rate_hz = table.rate_hz;
    return time;
  }
  const double dt = (time.back() - time.front()) / static_cast<double>(frames - 1);
  for (std::size_t f = 1; f < frames; ++f) {
    if (std::abs(time[f] - time[f - 1] - dt) > 0.01 * dt) {
      ThrowInputError(source, "time[" + std::to_string(f) + "]",
                      "frames are not uniformly spaced (the low-pass filter needs a fixed rate)");
    }
  }
  *rate_hz = 1.0 / dt;
  return time;
}

std::size_t LongestGap(const std::vector<Gap>& gaps) {
  std::size_t longest = 0;
  for (const Gap& g : gaps) longest = std::max(longest, g.length);
  return longest;
}

void StoreQuaternion(const Eigen::Matrix3d& R_WB, double* out) {
  Eigen::Quaterniond q(R_WB);
  q.normalize();
  // e0 >= 0: one of the two quaternions of a rotation, as the simulator's
  // near-identity link rotations have.
  const double sign = q.w() < 0.0 ? -1.0 : 1.0;
  out[0] = sign * q.w();
  out[1] = sign * q.x();
  out[2] = sign * q.y();
  out[3] = sign * q.z();
}

std::string Mm(double metres) {
  char buffer[32];
  if (std::isnan(metres)) return "-";
  std::snprintf(buffer, sizeof(buffer), "%.3f", metres * 1e3);
  return buffer;
}

datasets::Array Vector(const std::vector<double>& values) {
  datasets::Array a({values.size()});
  a.values = values;
  return a;
}

}  // namespace

bool ProcessingOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (max_spline_gap_frames < 0) return fail("max_spline_gap_frames must be >= 0");
  if (spline_context_frames < 1) return fail("spline_context_frames must be >= 1");
  if (!(cutoff_hz >= 0.0) || !std::isfinite(cutoff_hz)) return fail("cutoff_hz must be >= 0");
  if (filter_order < 1 || filter_order > 8) return fail("filter_order must be in 1..8");
  if (min_filter_run_frames < 2) return fail("min_filter_run_frames must be >= 2");
  return true;
}

std::vector<std::optional<std::size_t>> MatchMarkerLabels(const std::vector<std::string>& names,
                                                          const MarkerTable& table,
                                                          std::vector<std::string>* warnings) {
  std::map<std::string, std::size_t> exact;
  std::map<std::string, std::vector<std::size_t>> by_suffix;
  for (std::size_t c = 0; c < table.labels.size(); ++c) {
    const std::string& label = table.labels[c];
    exact.emplace(label, c);  // a repeated label: the first column wins
    const std::size_t colon = label.rfind(':');
    if (colon != std::string::npos) by_suffix[label.substr(colon + 1)].push_back(c);
  }
  std::vector<std::optional<std::size_t>> columns;
  for (const std::string& name : names) {
    if (const auto it = exact.find(name); it != exact.end()) {
      columns.emplace_back(it->second);
      continue;
    }
    const auto it = by_suffix.find(name);
    if (it != by_suffix.end() && it->second.size() == 1) {
      columns.emplace_back(it->second.front());
      continue;
    }
    columns.emplace_back(std::nullopt);
    if (warnings != nullptr) {
      warnings->push_back(it != by_suffix.end()
                              ? "marker '" + name + "' matches several labels ('subject:" + name +
                                    "'): not used"
                              : "marker '" + name + "' is not in the input: never seen");
    }
  }
  return columns;
}

Eigen::Isometry3d FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                                    const std::vector<Eigen::Vector3d>& to) {
  CCSRM_CHECK(from.size() == to.size() && from.size() >= 3);
  Eigen::Matrix3Xd src(3, from.size());
  Eigen::Matrix3Xd dst(3, to.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = from[i];
    dst.col(static_cast<Eigen::Index>(i)) = to[i];
  }
  Eigen::Isometry3d X;
  X.matrix() = Eigen::umeyama(src, dst, /*with_scaling=*/false);
  return X;
}

JointChain JointChain::FromModel(const sim::ArmModel& model) {
  JointChain chain;
  for (int link = 1; link <= model.num_links(); ++link) {
    chain.p_BJ_proximal.push_back(model.p_child_joint(link));
    // The last link has no joint beyond it: its distal point is only a
    // lever for nothing, kept for a uniform table.
    chain.p_BJ_distal.push_back(link < model.num_links()
                                    ? model.p_parent_joint(link + 1)
                                    : Eigen::Vector3d(0, 0, 0.5 * model.link(link).length_m));
  }
  return chain;
}

namespace internal {

void FitChain(std::vector<ChainLink>* links) {
  std::vector<ChainLink>& c = *links;
  const std::size_t n = c.size();
  const Eigen::Index unknowns = static_cast<Eigen::Index>(3 + 3 * n);
  // Joint 1 of the segment, and the rotations, from the per-link fits.
  Eigen::Vector3d t = *c[0].X_WB * c[0].p_BJ_proximal;
  std::vector<Eigen::Matrix3d> R(n);
  for (std::size_t i = 0; i < n; ++i) R[i] = c[i].X_WB->rotation();
  auto skew = [](const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
  };
  Eigen::MatrixXd JtJ(unknowns, unknowns);
  Eigen::VectorXd Jtr(unknowns);
  Eigen::MatrixXd A(3, unknowns);         // the Jacobian columns every marker of a link shares
  std::vector<Eigen::Vector3d> joint(n);  // p_WJ of every link's proximal joint
  // Gauss–Newton on t and a rotation increment per link (R ← R·exp([δ]×));
  // the per-link fits start it within the noise, so it converges in 2–3 steps.
  // A marker m on link i predicts p_WJi + R_i·v_m (v_m = p_BM - p_BJ): its
  // Jacobian row block is [A_i | H_m] with A_i = [I, -R_0[d_0]×, ...,
  // -R_(i-1)[d_(i-1)]×] (d = distal - proximal joint) shared by the link's
  // markers, and H_m = -R_i[v_m]×, so the normal equations take per-link sums.
  for (int iteration = 0; iteration < 10; ++iteration) {
    JtJ.setZero();
    Jtr.setZero();
    joint[0] = t;
    for (std::size_t i = 1; i < n; ++i) {
      joint[i] = joint[i - 1] + R[i - 1] * (c[i - 1].p_BJ_distal - c[i - 1].p_BJ_proximal);
    }
    A.leftCols<3>().setIdentity();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Index shared = static_cast<Eigen::Index>(3 + 3 * i);
      if (i > 0) {
        A.block<3, 3>(0, shared - 3) =
            -R[i - 1] * skew(c[i - 1].p_BJ_distal - c[i - 1].p_BJ_proximal);
      }
      Eigen::Vector3d sum_r = Eigen::Vector3d::Zero(), sum_Hr = Eigen::Vector3d::Zero();
      Eigen::Matrix3d sum_H = Eigen::Matrix3d::Zero(), sum_HH = Eigen::Matrix3d::Zero();
      for (std::size_t m = 0; m < c[i].p_BM.size(); ++m) {
        const Eigen::Vector3d v = c[i].p_BM[m] - c[i].p_BJ_proximal;
        const Eigen::Vector3d r = joint[i] + R[i] * v - c[i].p_WM[m];
        const Eigen::Matrix3d H = -R[i] * skew(v);
        sum_r += r;
        sum_H += H;
        sum_HH.noalias() += H.transpose() * H;
        sum_Hr.noalias() += H.transpose() * r;
      }
      const double count = static_cast<double>(c[i].p_BM.size());
      const auto Ai = A.leftCols(shared);
      JtJ.topLeftCorner(shared, shared).noalias() += count * Ai.transpose() * Ai;
      const Eigen::MatrixXd cross = Ai.transpose() * sum_H;
      JtJ.block(0, shared, shared, 3) += cross;
      JtJ.block(shared, 0, 3, shared) += cross.transpose();
      JtJ.block<3, 3>(shared, shared) += sum_HH;
      Jtr.head(shared).noalias() += Ai.transpose() * sum_r;
      Jtr.segment<3>(shared) += sum_Hr;
    }
    const Eigen::VectorXd step = -JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) return;  // keep the per-link fits
    t += step.head<3>();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d delta = step.segment<3>(static_cast<Eigen::Index>(3 + 3 * i));
      const double angle = delta.norm();
      if (angle > 0.0) R[i] = R[i] * Eigen::AngleAxisd(angle, delta / angle).toRotationMatrix();
    }
    if (step.lpNorm<Eigen::Infinity>() < 1e-10) break;  // rad and m: far below the noise
  }
  Eigen::Vector3d p_WJ = t;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = R[i];
    X.translation() = p_WJ - R[i] * c[i].p_BJ_proximal;
    *c[i].X_WB = X;
    p_WJ += R[i] * (c[i].p_BJ_distal - c[i].p_BJ_proximal);
  }
}

}  // namespace internal

namespace {

// The pipeline's markers and what every stage needs of the layout.
struct PipelineMarkers {
  PipelineMarkers(std::size_t frames, std::size_t markers)
      : F(frames), K(markers), raw(frames, markers), work(frames, markers) {}
  std::size_t F, K;                  // frames, layout markers
  std::size_t B = 0, L = 0;          // bodies, links
  std::vector<std::size_t> offset;   // first marker of each body
  std::vector<std::size_t> body_of;  // body of each marker
  // whole_loss[b][f]: no marker of body b seen in frame f.
  std::vector<std::vector<bool>> whole_loss;
  MarkerFrames raw;   // as recorded (in W once the ground is fitted)
  MarkerFrames work;  // gaps filled
};

// Options, layout and table fit for processing. Returns the number of links.
std::size_t CheckProcessingInputs(const MarkerTable& table, const MarkerLayout& layout,
                                  const ProcessingOptions& options, const std::string& source) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError(source, "processing options", error);
  ValidateMarkerLayout(layout, source);
  const std::size_t F = table.frames();
  if (F < 2) {
    // Before the table's own check, which would only find no frame rate.
    ThrowInputError(source, TimeField(table),
                    "has " + std::to_string(F) +
                        " frame(s): processing needs at least 2 (a frame rate for the time "
                        "base and the low-pass filter)");
  }
  if (!table.IsConsistent(&error)) ThrowInputError(source, "", error);
  if (std::none_of(table.positions_m.begin(), table.positions_m.end(),
                   [](double v) { return std::isfinite(v); })) {
    ThrowInputError(source, MarkerField(table),
                    "has no finite sample (every position NaN or infinite): no marker was ever "
                    "seen, so there is no pose to fit");
  }
  // Every format, at this one door (an experiment's own file is checked
  // when read, by datasets::ValidateExperimentFile).
  const std::string beyond = datasets::MarkerBeyondCaptureVolume(table.positions_m, table.labels);
  if (!beyond.empty()) ThrowInputError(source, MarkerField(table), beyond);
  int num_links = 0;
  for (const RigidBody& body : layout.bodies) num_links = std::max(num_links, body.link);
  return static_cast<std::size_t>(num_links);
}

// Raw markers in layout order, whole-body losses, and each marker's
// visibility and gaps before filling.
void ReadRawMarkers(const MarkerTable& table, const MarkerLayout& layout,
                    const std::vector<std::optional<std::size_t>>& column,
                    const std::vector<std::string>& names, PipelineMarkers* m,
                    ProcessingSummary* summary) {
  const std::size_t F = m->F, K = m->K, B = m->B;
  for (std::size_t k = 0; k < K; ++k) {
    if (!column[k]) continue;
    for (std::size_t f = 0; f < F; ++f) {
      if (table.is_valid(f, *column[k])) m->raw.set(f, k, table.position(f, *column[k]));
    }
  }
  m->whole_loss.assign(B, std::vector<bool>(F, true));
  for (std::size_t b = 0; b < B; ++b) {
    for (std::size_t f = 0; f < F; ++f) {
      for (std::size_t i = 0; i < layout.bodies[b].marker_names.size(); ++i) {
        if (m->raw.finite(f, m->offset[b] + i)) {
          m->whole_loss[b][f] = false;
          break;
        }
      }
    }
  }
  summary->markers.resize(K);
  m->body_of.assign(K, 0);
  for (std::size_t b = 0; b < B; ++b) {
    for (std::size_t i = 0; i < layout.bodies[b].marker_names.size(); ++i) {
      const std::size_t k = m->offset[b] + i;
      m->body_of[k] = b;
      MarkerQuality& q = summary->markers[k];
      q.name = names[k];
      q.body = layout.bodies[b].name;
      q.in_file = column[k].has_value();
      std::size_t seen = 0;
      for (std::size_t f = 0; f < F; ++f) seen += m->raw.finite(f, k);
      q.visibility = static_cast<double>(seen) / static_cast<double>(F);
      const std::vector<Gap> gaps = FindGaps(m->raw.column(k, 0), F, m->raw.stride());
      q.gaps_before_fill = gaps.size();
      q.longest_gap_before_fill = LongestGap(gaps);
    }
  }
}

// Gaps filled by splines (never across a whole-body loss), then from the
// body's other markers (rigid fill), and each marker's gaps after.
void FillGaps(const MarkerLayout& layout, const ProcessingOptions& options, PipelineMarkers* m,
              ProcessingSummary* summary) {
  const std::size_t F = m->F, K = m->K, B = m->B;
  MarkerFrames& work = m->work;
  work = m->raw;
  for (std::size_t k = 0; k < K; ++k) {
    const std::vector<bool>& lost = m->whole_loss[m->body_of[k]];
    for (const Gap& gap : FindGaps(work.column(k, 0), F, work.stride())) {
      if (gap.length > static_cast<std::size_t>(options.max_spline_gap_frames)) continue;
      // Never across a whole-body loss: nothing of the body was seen there.
      if (std::any_of(lost.begin() + static_cast<std::ptrdiff_t>(gap.first),
                      lost.begin() + static_cast<std::ptrdiff_t>(gap.first + gap.length),
                      [](bool l) { return l; })) {
        continue;
      }
      bool filled = true;
      for (int axis = 0; axis < 3; ++axis) {
        filled = FillGapBySpline(work.column(k, axis), F, gap,
                                 static_cast<std::size_t>(options.spline_context_frames),
                                 work.stride()) &&
                 filled;
      }
      if (filled) summary->markers[k].spline_filled_frames += gap.length;
    }
  }
  if (options.rigid_fill) {
    std::vector<Eigen::Vector3d> from, to;
    for (std::size_t b = 0; b < B; ++b) {
      const RigidBody& body = layout.bodies[b];
      const std::size_t n = body.marker_names.size();
      const std::size_t first = m->offset[b];
      for (std::size_t f = 0; f < F; ++f) {
        from.clear();
        to.clear();
        for (std::size_t i = 0; i < n; ++i) {
          if (work.finite(f, first + i)) {
            from.push_back(body.p_BM[i]);
            to.push_back(work.get(f, first + i));
          }
        }
        if (from.size() < 3 || from.size() == n) continue;
        const Eigen::Isometry3d X = FitRigidTransform(from, to);
        for (std::size_t i = 0; i < n; ++i) {
          if (!work.finite(f, first + i)) {
            work.set(f, first + i, X * body.p_BM[i]);
            ++summary->markers[first + i].rigid_filled_frames;
          }
        }
      }
    }
  }
  for (std::size_t k = 0; k < K; ++k) {
    const std::vector<Gap> gaps = FindGaps(work.column(k, 0), F, work.stride());
    summary->markers[k].gaps_after_fill = gaps.size();
    summary->markers[k].longest_gap_after_fill = LongestGap(gaps);
  }
}

// World frame from the ground cluster: the ground does not move, so one
// transform from the markers' mean positions over the whole trial averages
// their noise away. Every marker is moved into W.
void AlignToGround(const MarkerLayout& layout, PipelineMarkers* m, ProcessingSummary* summary) {
  const std::size_t F = m->F, K = m->K;
  Eigen::Isometry3d X_WF = Eigen::Isometry3d::Identity();
  for (std::size_t b = 0; b < m->B; ++b) {
    const RigidBody& body = layout.bodies[b];
    if (body.link != 0) continue;
    std::vector<Eigen::Vector3d> mean_F, p_W;
    for (std::size_t i = 0; i < body.marker_names.size(); ++i) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      std::size_t count = 0;
      for (std::size_t f = 0; f < F; ++f) {
        if (m->work.finite(f, m->offset[b] + i)) {
          sum += m->work.get(f, m->offset[b] + i);
          ++count;
        }
      }
      if (count > 0) {
        mean_F.push_back(sum / static_cast<double>(count));
        p_W.push_back(body.p_BM[i]);
      }
    }
    if (mean_F.size() >= 3) {
      X_WF = FitRigidTransform(mean_F, p_W);
      summary->world_from_ground = true;
      double sum_sq = 0.0;
      for (std::size_t i = 0; i < mean_F.size(); ++i)
        sum_sq += (X_WF * mean_F[i] - p_W[i]).squaredNorm();
      summary->ground_fit_rms_m = std::sqrt(sum_sq / static_cast<double>(mean_F.size()));
    } else {
      summary->warnings.push_back("ground markers seen fewer than 3: the file frame is taken as W");
    }
  }
  for (MarkerFrames* frames : {&m->raw, &m->work}) {
    for (std::size_t f = 0; f < F; ++f) {
      for (std::size_t k = 0; k < K; ++k) {
        if (frames->finite(f, k)) frames->set(f, k, X_WF * frames->get(f, k));
      }
    }
  }
}

// X_WB[b][f]: every body's pose in every frame where it has at least 3
// markers, refined by the joint-constrained fit over runs of consecutive
// posed links when `chain` is given and asked for.
using BodyPoses = std::vector<std::vector<std::optional<Eigen::Isometry3d>>>;
BodyPoses FitBodies(const MarkerLayout& layout, const ProcessingOptions& options,
                    const JointChain* chain, const std::string& source, const PipelineMarkers& m,
                    ProcessingSummary* summary) {
  const std::size_t F = m.F, B = m.B, L = m.L;
  if (chain != nullptr && options.joint_constrained_fit &&
      (chain->p_BJ_proximal.size() < L || chain->p_BJ_distal.size() < L)) {
    ThrowInputError(source, "joint chain",
                    "has " + std::to_string(chain->p_BJ_proximal.size()) +
                        " links, the rigid bodies need " + std::to_string(L));
  }
  BodyPoses X_WB(B, std::vector<std::optional<Eigen::Isometry3d>>(F));
  std::vector<std::ptrdiff_t> body_of_link(L + 1, -1);
  std::vector<Eigen::Vector3d> from, to;
  for (std::size_t b = 0; b < B; ++b) {
    const RigidBody& body = layout.bodies[b];
    body_of_link[static_cast<std::size_t>(body.link)] = static_cast<std::ptrdiff_t>(b);
    for (std::size_t f = 0; f < F; ++f) {
      from.clear();
      to.clear();
      for (std::size_t i = 0; i < body.marker_names.size(); ++i) {
        if (m.work.finite(f, m.offset[b] + i)) {
          from.push_back(body.p_BM[i]);
          to.push_back(m.work.get(f, m.offset[b] + i));
        }
      }
      if (from.size() >= 3) X_WB[b][f] = FitRigidTransform(from, to);
    }
  }
  if (chain == nullptr || !options.joint_constrained_fit) return X_WB;
  summary->joint_constrained = true;
  std::vector<internal::ChainLink> segment;
  for (std::size_t f = 0; f < F; ++f) {
    // Runs of consecutive links that all have a pose in this frame.
    std::size_t link = 1;
    while (link <= L) {
      segment.clear();
      while (link <= L && body_of_link[link] >= 0 &&
             X_WB[static_cast<std::size_t>(body_of_link[link])][f]) {
        const std::size_t b = static_cast<std::size_t>(body_of_link[link]);
        internal::ChainLink c;
        c.p_BJ_proximal = chain->p_BJ_proximal[link - 1];
        c.p_BJ_distal = chain->p_BJ_distal[link - 1];
        c.X_WB = &*X_WB[b][f];
        for (std::size_t i = 0; i < layout.bodies[b].marker_names.size(); ++i) {
          if (m.work.finite(f, m.offset[b] + i)) {
            c.p_BM.push_back(layout.bodies[b].p_BM[i]);
            c.p_WM.push_back(m.work.get(f, m.offset[b] + i));
          }
        }
        segment.push_back(std::move(c));
        ++link;
      }
      if (segment.size() >= 2) internal::FitChain(&segment);
      if (segment.empty()) ++link;
    }
  }
  return X_WB;
}

// The link poses and marker residuals of the fitted bodies, each body's and
// marker's fit quality; returns R_WB of every link in every frame (identity
// for the ground, link 0), set where fitted.
using LinkRotations = std::vector<std::vector<std::optional<Eigen::Matrix3d>>>;
LinkRotations StoreLinkPoses(const MarkerLayout& layout, const BodyPoses& X_WB,
                             const PipelineMarkers& m, ProcessingResult* result) {
  const std::size_t F = m.F, K = m.K, L = m.L;
  ProcessingSummary& summary = result->summary;
  result->link_pose = datasets::Array({F, L, 7}, kNaN);
  result->marker_residual = datasets::Array({F, K}, kNaN);
  LinkRotations R_WB(L + 1, std::vector<std::optional<Eigen::Matrix3d>>(F));
  for (std::size_t f = 0; f < F; ++f) R_WB[0][f] = Eigen::Matrix3d::Identity();
  summary.bodies.resize(m.B);
  std::vector<double> marker_sum_sq(K, 0.0);
  std::vector<std::size_t> marker_count(K, 0);
  for (std::size_t b = 0; b < m.B; ++b) {
    const RigidBody& body = layout.bodies[b];
    BodyQuality& q = summary.bodies[b];
    q.name = body.name;
    q.link = body.link;
    double sum_sq = 0.0;
    std::size_t count = 0;
    for (std::size_t f = 0; f < F; ++f) {
      if (m.whole_loss[b][f]) {
        ++q.whole_loss_frames;
        if (f == 0 || !m.whole_loss[b][f - 1]) ++q.whole_loss_runs;
      }
      if (!X_WB[b][f]) {
        ++q.frames_lost;
        continue;
      }
      const Eigen::Isometry3d& X = *X_WB[b][f];
      for (std::size_t i = 0; i < body.marker_names.size(); ++i) {
        const std::size_t k = m.offset[b] + i;
        if (!m.work.finite(f, k)) continue;
        const double residual = (X * body.p_BM[i] - m.work.get(f, k)).norm();
        result->marker_residual.at(f, k) = residual;
        if (m.raw.finite(f, k)) {  // only seen samples: filled ones fit by construction
          sum_sq += residual * residual;
          ++count;
          marker_sum_sq[k] += residual * residual;
          ++marker_count[k];
        }
      }
      if (body.link == 0) continue;  // the ground's frame is W by construction
      const std::size_t l = static_cast<std::size_t>(body.link - 1);
      R_WB[l + 1][f] = X.rotation();
      const Eigen::Vector3d p_WB = X.translation();
      for (int axis = 0; axis < 3; ++axis) result->link_pose.at(f, l, axis) = p_WB[axis];
      StoreQuaternion(X.rotation(), &result->link_pose.values[(f * L + l) * 7 + 3]);
    }
    q.fit_rms_m = count > 0 ? std::sqrt(sum_sq / static_cast<double>(count)) : kNaN;
  }
  for (std::size_t k = 0; k < K; ++k) {
    summary.markers[k].fit_rms_m =
        marker_count[k] > 0 ? std::sqrt(marker_sum_sq[k] / static_cast<double>(marker_count[k]))
                            : kNaN;
  }
  return R_WB;
}

// Every joint's X–Y Cardan angles and twist from its two links' rotations.
void StoreJointAngles(const LinkRotations& R_WB, std::size_t F, std::size_t L,
                      ProcessingResult* result) {
  ProcessingSummary& summary = result->summary;
  result->joint_angles = datasets::Array({F, L, 2}, kNaN);
  result->joint_twist = datasets::Array({F, L}, kNaN);
  summary.joints.resize(L);
  for (std::size_t j = 0; j < L; ++j) {
    summary.joints[j].joint = static_cast<int>(j + 1);
    for (std::size_t f = 0; f < F; ++f) {
      const auto& parent = R_WB[j][f];
      const auto& child = R_WB[j + 1][f];
      if (!parent || !child) {
        ++summary.joints[j].frames_lost;
        continue;
      }
      const Eigen::Vector3d angles = sim::CardanXyzAngles(parent->transpose() * *child);
      result->joint_angles.at(f, j, 0) = angles[0];
      result->joint_angles.at(f, j, 1) = angles[1];
      result->joint_twist.at(f, j) = angles[2];
    }
  }
}

// Zero-lag low-pass of the fitted motion. After the fit, not before:
// smoothing the markers of a swinging link pulls them inside their arcs,
// which a rigid (and joint-constrained) fit can only absorb by turning the
// link. The joint angles stay small, so filtering them is filtering the
// markers' information linearly.
void LowPassFittedMotion(const ProcessingOptions& options, double rate_hz, std::size_t F,
                         std::size_t L, ProcessingResult* result) {
  const std::vector<BiquadSection> sections =
      DesignButterworthLowPass(options.filter_order, options.cutoff_hz, rate_hz);
  const auto min_run = static_cast<std::size_t>(options.min_filter_run_frames);
  auto filter_columns = [&](datasets::Array* array) {
    const std::size_t columns = array->size() / F;
    for (std::size_t c = 0; c < columns; ++c) {
      ZeroLagLowPass(sections, options.cutoff_hz, rate_hz, array->values.data() + c, F, columns,
                     min_run);
    }
  };
  filter_columns(&result->joint_angles);
  filter_columns(&result->joint_twist);
  // Poses: positions, and quaternion components (one hemisphere along time,
  // renormalised after), which is exact to first order for smooth motion.
  datasets::Array& pose = result->link_pose;
  for (std::size_t l = 0; l < L; ++l) {
    for (std::size_t f = 1; f < F; ++f) {
      double* q = &pose.values[(f * L + l) * 7 + 3];
      const double* previous = q - L * 7;
      if (!std::isfinite(q[0]) || !std::isfinite(previous[0])) continue;
      if (q[0] * previous[0] + q[1] * previous[1] + q[2] * previous[2] + q[3] * previous[3] < 0) {
        for (int i = 0; i < 4; ++i) q[i] = -q[i];
      }
    }
  }
  filter_columns(&pose);
  for (std::size_t f = 0; f < F; ++f) {
    for (std::size_t l = 0; l < L; ++l) {
      double* q = &pose.values[(f * L + l) * 7 + 3];
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      for (int i = 0; i < 4; ++i) q[i] /= norm;
    }
  }
}

}  // namespace

ProcessingResult ProcessMarkers(const MarkerTable& table, const std::vector<double>& time,
                                const MarkerLayout& layout, const ProcessingOptions& options,
                                const std::string& source, const JointChain* chain) {
  const std::size_t num_links = CheckProcessingInputs(table, layout, options, source);
  const std::size_t F = table.frames();
  ProcessingResult result;
  ProcessingSummary& summary = result.summary;
  // What the reader noticed (a recording cut short, a missing unit) stays in
  // sight of whoever reads only the summary.
  for (const std::string& w : table.warnings) summary.warnings.push_back(source + ": " + w);
  double rate_hz = 0.0;
  result.time = TimeBase(table, time, source, &rate_hz);
  summary.frames = F;
  summary.rate_hz = rate_hz;
  summary.filter_cutoff_hz = options.cutoff_hz;
  summary.filter_order = options.filter_order;
  summary.min_filter_run_frames = options.min_filter_run_frames;
  if (options.cutoff_hz > 0.0 && !(options.cutoff_hz < 0.5 * rate_hz)) {
    ThrowInputError(source, "cutoff",
                    "low-pass cutoff " + std::to_string(options.cutoff_hz) +
                        " Hz must be below half the frame rate (" + std::to_string(rate_hz) +
                        " Hz)");
  }

  const std::vector<std::string> names = layout.MarkerNames();
  result.marker_names = names;
  const std::vector<std::optional<std::size_t>> column =
      MatchMarkerLabels(names, table, &summary.warnings);
  if (std::none_of(column.begin(), column.end(), [](const auto& c) { return c.has_value(); })) {
    ThrowInputError(source, "labels", "no marker of the rigid bodies is in the file");
  }
  std::vector<bool> used(table.markers(), false);
  for (const auto& c : column) {
    if (c) used[*c] = true;
  }
  summary.input_labels_unused =
      static_cast<std::size_t>(std::count(used.begin(), used.end(), false));
  if (num_links == 0) {
    ThrowInputError(source, "bodies", "the rigid bodies hold no link (only the ground)");
  }
  PipelineMarkers m(F, names.size());
  m.offset = BodyOffsets(layout);
  m.B = layout.bodies.size();
  m.L = num_links;

  ReadRawMarkers(table, layout, column, names, &m, &summary);
  FillGaps(layout, options, &m, &summary);
  AlignToGround(layout, &m, &summary);
  const BodyPoses X_WB = FitBodies(layout, options, chain, source, m, &summary);
  const LinkRotations R_WB = StoreLinkPoses(layout, X_WB, m, &result);
  // The rigid bodies must describe the markers recorded. Markers on a rigid
  // body fit it within the noise (a fraction of a mm), and a layout placed
  // by hand is off by millimetres (which a static trial refines); a body
  // fitted worse than 10 mm RMS is another arm, another marker set or
  // another unit, and its angles would be of nothing.
  const BodyQuality* worst = nullptr;
  std::size_t beyond = 0;
  for (const BodyQuality& q : summary.bodies) {
    if (!(q.fit_rms_m > 0.01)) continue;
    ++beyond;
    if (worst == nullptr || q.fit_rms_m > worst->fit_rms_m) worst = &q;
  }
  if (worst != nullptr) {
    ThrowInputError(source, MarkerField(table),
                    "the markers of " + worst->name + " fit its rigid body to " +
                        Mm(worst->fit_rms_m) + " mm RMS (" + std::to_string(beyond) +
                        " bodies beyond 10 mm; within that on the arm they were placed on): the "
                        "recording is not of this arm's marker set (another --config or "
                        "--rigid-bodies)");
  }
  StoreJointAngles(R_WB, F, m.L, &result);
  if (options.cutoff_hz > 0.0) LowPassFittedMotion(options, rate_hz, F, m.L, &result);
  for (std::size_t j = 0; j < m.L; ++j) {
    double max_twist = kNaN;
    for (std::size_t f = 0; f < F; ++f) {
      const double twist = std::abs(result.joint_twist.at(f, j));
      if (std::isfinite(twist))
        max_twist = std::isnan(max_twist) ? twist : std::max(max_twist, twist);
    }
    summary.joints[j].max_abs_twist_rad = max_twist;
  }
  result.markers = datasets::Array({F, m.K, 3});
  result.markers.values = std::move(m.work.values());
  result.raw_markers = datasets::Array({F, m.K, 3});
  result.raw_markers.values = std::move(m.raw.values());
  return result;
}

std::string ProcessingSummary::BriefReport() const {
  std::size_t spline = 0, rigid = 0, lost = 0;
  double worst_rms = 0.0, worst_twist = 0.0;
  std::string lost_body;
  for (const MarkerQuality& m : markers) {
    spline += m.spline_filled_frames;
    rigid += m.rigid_filled_frames;
  }
  for (const BodyQuality& b : bodies) {
    if (b.link == 0) continue;
    if (b.frames_lost > lost) {
      lost = b.frames_lost;
      lost_body = b.name;
    }
    if (std::isfinite(b.fit_rms_m)) worst_rms = std::max(worst_rms, b.fit_rms_m);
  }
  for (const JointQuality& j : joints) {
    if (std::isfinite(j.max_abs_twist_rad))
      worst_twist = std::max(worst_twist, j.max_abs_twist_rad);
  }
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer),
                "%zu frames at %.6g Hz, %zu markers: filled %zu marker-frames by spline and %zu "
                "by rigid fit; most frames lost on one link %zu%s%s%s; worst link fit RMS %s mm; "
                "max |twist| %.3f deg",
                frames, rate_hz, markers.size(), spline, rigid, lost, lost_body.empty() ? "" : " (",
                lost_body.c_str(), lost_body.empty() ? "" : ")", Mm(worst_rms).c_str(),
                worst_twist * kRadToDeg);
  if (warnings.empty()) return buffer;
  return std::string(buffer) + "; " + std::to_string(warnings.size()) + " warning(s)";
}

std::string ProcessingSummary::FullReport() const {
  std::ostringstream out;
  char line[256];
  out << "mocap processing: " << BriefReport() << "\n";
  out << "  link fits: "
      << (joint_constrained ? "joint-constrained chain (joint centres shared)"
                            : "each link on its own (no arm configuration given)")
      << "\n";
  out << "  world frame: "
      << (world_from_ground ? "from the ground cluster (fit RMS " + Mm(ground_fit_rms_m) + " mm)"
                            : std::string("the file's frame"))
      << "\n";
  if (input_labels_unused > 0) {
    out << "  input labels not in the rigid bodies: " << input_labels_unused << "\n";
  }
  out << "\n  body      fit RMS mm   frames lost   whole-body losses (frames)\n";
  for (const BodyQuality& b : bodies) {
    std::snprintf(line, sizeof(line), "  %-8s  %10s   %11zu   %zu (%zu)\n", b.name.c_str(),
                  Mm(b.fit_rms_m).c_str(), b.frames_lost, b.whole_loss_runs, b.whole_loss_frames);
    out << line;
  }
  out << "\n  marker        seen %   gaps before (longest)   after (longest)   spline   rigid   "
         "fit RMS mm\n";
  for (const MarkerQuality& m : markers) {
    std::snprintf(line, sizeof(line),
                  "  %-12s  %6.1f   %11zu (%7zu)   %5zu (%7zu)   %6zu   %5zu   %10s\n",
                  m.name.c_str(), 100.0 * m.visibility, m.gaps_before_fill,
                  m.longest_gap_before_fill, m.gaps_after_fill, m.longest_gap_after_fill,
                  m.spline_filled_frames, m.rigid_filled_frames, Mm(m.fit_rms_m).c_str());
    out << line;
  }
  out << "\n  joint   frames lost   max |twist| deg\n";
  for (const JointQuality& j : joints) {
    std::snprintf(line, sizeof(line), "  %5d   %11zu   %15.4f\n", j.joint, j.frames_lost,
                  j.max_abs_twist_rad * kRadToDeg);
    out << line;
  }
  for (const std::string& w : warnings) out << "  warning: " << w << "\n";
  return out.str();
}

void StoreInExperiment(const ProcessingResult& result, datasets::ExperimentFile* experiment) {
  CCSRM_CHECK(experiment->mocap_time.rows() == result.time.size());
  experiment->measured_joint_angles = result.joint_angles;
  experiment->measured_link_pose = result.link_pose;
  experiment->measured_joint_twist = result.joint_twist;
  const ProcessingSummary& s = result.summary;
  auto& quality = experiment->mocap_quality;
  auto& units = experiment->mocap_quality_units;
  auto put = [&](const std::string& name, datasets::Array array, const std::string& unit) {
    quality[name] = std::move(array);
    units[name] = unit;
  };
  // Per-marker figures follow /mocap/marker_names; markers the layout does
  // not have get NaN.
  const std::size_t M = experiment->marker_names.size();
  std::map<std::string, std::size_t> layout_index;
  for (std::size_t k = 0; k < s.markers.size(); ++k) layout_index[s.markers[k].name] = k;
  auto per_marker = [&](auto field) {
    std::vector<double> v(M, kNaN);
    for (std::size_t i = 0; i < M; ++i) {
      const auto it = layout_index.find(experiment->marker_names[i]);
      if (it != layout_index.end()) v[i] = field(s.markers[it->second]);
    }
    return Vector(v);
  };
  put("marker_visibility", per_marker([](const MarkerQuality& m) { return m.visibility; }), "1");
  put("marker_gaps_before_fill",
      per_marker([](const MarkerQuality& m) { return double(m.gaps_before_fill); }), "1");
  put("marker_longest_gap_before_fill",
      per_marker([](const MarkerQuality& m) { return double(m.longest_gap_before_fill); }),
      "frames");
  put("marker_gaps_after_fill",
      per_marker([](const MarkerQuality& m) { return double(m.gaps_after_fill); }), "1");
  put("marker_longest_gap_after_fill",
      per_marker([](const MarkerQuality& m) { return double(m.longest_gap_after_fill); }),
      "frames");
  put("marker_spline_filled_frames",
      per_marker([](const MarkerQuality& m) { return double(m.spline_filled_frames); }), "frames");
  put("marker_rigid_filled_frames",
      per_marker([](const MarkerQuality& m) { return double(m.rigid_filled_frames); }), "frames");
  put("marker_fit_rms", per_marker([](const MarkerQuality& m) { return m.fit_rms_m; }), "m");
  {
    const std::size_t F = result.time.size();
    datasets::Array residual({F, M}, kNaN);
    for (std::size_t i = 0; i < M; ++i) {
      const auto it = layout_index.find(experiment->marker_names[i]);
      if (it == layout_index.end()) continue;
      for (std::size_t f = 0; f < F; ++f)
        residual.at(f, i) = result.marker_residual.at(f, it->second);
    }
    put("marker_fit_residual", std::move(residual), "m");
  }
  // Per-body figures follow /mocap/rigid_bodies as read back: base first,
  // then by link number (the layout's order).
  std::vector<double> body_rms, body_lost, body_whole;
  for (const BodyQuality& b : s.bodies) {
    body_rms.push_back(b.fit_rms_m);
    body_lost.push_back(static_cast<double>(b.frames_lost));
    body_whole.push_back(static_cast<double>(b.whole_loss_frames));
  }
  put("body_fit_rms", Vector(body_rms), "m");
  put("body_frames_lost", Vector(body_lost), "frames");
  put("body_whole_loss_frames", Vector(body_whole), "frames");
  std::vector<double> joint_lost, joint_twist;
  for (const JointQuality& j : s.joints) {
    joint_lost.push_back(static_cast<double>(j.frames_lost));
    joint_twist.push_back(j.max_abs_twist_rad);
  }
  put("joint_frames_lost", Vector(joint_lost), "frames");
  put("joint_max_abs_twist", Vector(joint_twist), "rad");
  put("ground_fit_rms", Vector({s.world_from_ground ? s.ground_fit_rms_m : kNaN}), "m");
  // The low-pass of the measured motion (identification filters simulated
  // angles the same way before comparing them).
  put("filter_cutoff_hz", Vector({s.filter_cutoff_hz}), "Hz");
  put("filter_order", Vector({double(s.filter_order)}), "1");
  put("filter_min_run_frames", Vector({double(s.min_filter_run_frames)}), "frames");
}

}  // namespace ccsrm::mocap
