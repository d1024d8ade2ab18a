#include "ccsrm/sim/protocol.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/gsl_errors.h"
#include "protocol_internal.h"

namespace ccsrm::sim {

double QuinticBlend(double tau) {
  if (tau <= 0.0) return 0.0;
  if (tau >= 1.0) return 1.0;
  return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
}

JointTrajectory PaperTrajectory(const ArmModel& model, const ProtocolConfig& p) {
  const int joints = model.num_joints();
  return [joints, p](double t) {
    double fraction = 0.0;
    if (t < p.ramp_s) {
      fraction = QuinticBlend(t / p.ramp_s);
    } else if (t < p.ramp_s + p.hold_s) {
      fraction = 1.0;
    } else {
      fraction = 1.0 - QuinticBlend((t - p.ramp_s - p.hold_s) / p.return_s);
    }
    return JointAngles(joints, Eigen::Vector2d(p.amplitude_rad * fraction, 0.0));
  };
}

struct CableInputs::Splines {
  std::vector<gsl_spline*> per_cable;
  ~Splines() {
    for (gsl_spline* s : per_cable) gsl_spline_free(s);
  }
};

CableInputs::CableInputs(Eigen::VectorXd time, Eigen::MatrixXd length_change,
                         Interpolation interpolation)
    : time_(std::move(time)),
      length_change_(std::move(length_change)),
      interpolation_(interpolation),
      splines_(new Splines) {
  const Eigen::Index n = time_.size();
  if (n < 2) ThrowInputError("cable inputs", "time", "needs at least 2 samples");
  if (length_change_.rows() != n) {
    ThrowInputError(
        "cable inputs", "length_change",
        "has " + std::to_string(length_change_.rows()) + " rows, time has " + std::to_string(n));
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(time_[i]) || (i > 0 && !(time_[i] > time_[i - 1]))) {
      ThrowInputError("cable inputs", "time[" + std::to_string(i) + "]",
                      "must be finite and strictly increasing");
    }
  }
  if (!length_change_.allFinite())
    ThrowInputError("cable inputs", "length_change", "has a non-finite value");
  UseGslErrorCodes();
  const gsl_interp_type* type = n >= 3 && interpolation == Interpolation::kCubicSpline
                                    ? gsl_interp_cspline
                                    : gsl_interp_linear;
  for (Eigen::Index c = 0; c < length_change_.cols(); ++c) {
    Eigen::VectorXd column = length_change_.col(c);
    gsl_spline* spline = gsl_spline_alloc(type, static_cast<std::size_t>(n));
    gsl_spline_init(spline, time_.data(), column.data(), static_cast<std::size_t>(n));
    splines_->per_cable.push_back(spline);
  }
}

CableInputs::~CableInputs() = default;
CableInputs::CableInputs(CableInputs&&) noexcept = default;
CableInputs& CableInputs::operator=(CableInputs&&) noexcept = default;

void CableInputs::Evaluate(int cable, double t, double* value, double* rate, double* accel) const {
  const gsl_spline* spline = splines_->per_cable[cable];
  if (t <= start_time()) {
    *value = length_change_(0, cable);
    *rate = 0.0;
    *accel = 0.0;
    return;
  }
  if (t >= end_time()) {
    *value = length_change_(length_change_.rows() - 1, cable);
    *rate = 0.0;
    *accel = 0.0;
    return;
  }
  // A null accelerator makes GSL search afresh: thread-safe for shared inputs.
  *value = gsl_spline_eval(spline, t, nullptr);
  *rate = gsl_spline_eval_deriv(spline, t, nullptr);
  *accel = gsl_spline_eval_deriv2(spline, t, nullptr);
}

namespace {

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// The planned tilt of every joint against its range (ArmModel::
// joint_range_rad), over every sample; throws naming the joint that goes
// furthest beyond, where it first leaves the range and how far it goes.
void CheckPlannedJointRange(const ArmModel& model, const Eigen::VectorXd& time,
                            const std::vector<JointAngles>& plan, const std::string& source) {
  int worst_joint = 0;
  double worst_excess = 0.0, worst_tilt = 0.0, first_time = 0.0;
  for (int j = 1; j <= model.num_joints(); ++j) {
    double peak = 0.0, first = NAN;
    for (std::size_t k = 0; k < plan.size(); ++k) {
      const double tilt = JointTiltRad(plan[k][j - 1]);
      if (tilt > model.joint_range_rad(j) && std::isnan(first)) first = time[k];
      peak = std::max(peak, tilt);
    }
    const double excess = peak - model.joint_range_rad(j);
    if (excess > worst_excess) {
      worst_joint = j;
      worst_excess = excess;
      worst_tilt = peak;
      first_time = first;
    }
  }
  if (worst_joint == 0) return;
  const double deg = 180.0 / M_PI;
  const int segment = model.link(worst_joint).segment + 1;
  ThrowInputError(
      source, "",
      "the plan tilts joint " + std::to_string(worst_joint) + " (segment " +
          std::to_string(segment) + ") to " + Format("%.1f", worst_tilt * deg) +
          " deg (beyond from t = " + Format("%.3g", first_time) + " s), past its range of " +
          Format("%.1f", model.joint_range_rad(worst_joint) * deg) +
          " deg where its disks meet (2 atan(d/2R), d = " +
          Format("%.3g", model.arm().joint_disk_gap_m * 1e3) + " mm, R = " +
          Format("%.3g", model.joint_disk_radius_m(worst_joint) * 1e3) + " mm the hole circle)" +
          internal::RangeSetBy(model.arm(), worst_joint) + "; ccsrm has no contact between disks");
}

// Stretch [m] each cable needs beyond its kinematic length for the
// frictionless arm to rest at `angles` (InputPlanning::kStaticEquilibrium):
// ΔT·L/EA, with ΔT the least-squares change of the tensions from T_d0 that
// balances the cables' moments Σ_c T_c ∂L_c/∂Θ on every segment's bending
// Θ = (θx, θy) of all its joints together. Throws InputError when a cable
// would need a tension below zero.
Eigen::VectorXd StaticEquilibriumStretch(const ArmModel& model, const JointAngles& angles,
                                         double time_s, const InputPlanning& planning,
                                         const std::string& source) {
  const int cables = model.num_cables();
  const Eigen::MatrixXd moment_arm = SegmentMomentArms(model, angles);
  // Balance: moment_armᵀ (T_d0 + ΔT) = 0, ΔT of least norm. Straight, the
  // moment arms of a segment's cables cancel and ΔT = 0.
  const Eigen::VectorXd unbalanced =
      planning.pretension_n * moment_arm.transpose() * Eigen::VectorXd::Ones(cables);
  const Eigen::VectorXd tension_change =
      -moment_arm.transpose().completeOrthogonalDecomposition().solve(unbalanced);
  const std::vector<LinkPose> poses = ForwardKinematics(model, angles);
  const DrivingCableConfig& driving = model.arm().driving;
  const double axial_stiffness_n = driving.youngs_modulus_pa * driving.cross_section_m2;
  Eigen::VectorXd stretch(cables);
  for (int c = 0; c < cables; ++c) {
    const double tension = planning.pretension_n + tension_change[c];
    if (!(tension > 0.0)) {
      ThrowInputError(source, "",
                      "planning: static_equilibrium needs cable " + std::to_string(c + 1) +
                          " to push (" + Format("%.3g", tension) +
                          " N) to hold the plan at t = " + Format("%.3f", time_s) +
                          " s: raise the pre-tension T_d0 or plan a smaller bend");
    }
    // Uniform tension along the frictionless cable: its whole free length
    // (input point to anchor) stretches.
    stretch[c] = tension_change[c] * CablePathLength(model, c, poses) / axial_stiffness_n;
  }
  return stretch;
}

}  // namespace

CableInputs PlanCableInputs(const ArmModel& model, const JointTrajectory& trajectory,
                            double duration_s, double sample_step_s, const std::string& source,
                            const InputPlanning& planning) {
  CCSRM_CHECK(duration_s > 0.0 && sample_step_s > 0.0);
  const int samples = static_cast<int>(std::ceil(duration_s / sample_step_s - 1e-9)) + 1;
  Eigen::VectorXd time(samples);
  Eigen::MatrixXd change(samples, model.num_cables());
  const std::vector<LinkPose> straight =
      ForwardKinematics(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  Eigen::VectorXd rest_length(model.num_cables());
  for (int c = 0; c < model.num_cables(); ++c) rest_length[c] = CablePathLength(model, c, straight);
  std::vector<JointAngles> plan(samples);
  for (int k = 0; k < samples; ++k) {
    time[k] = std::min(duration_s, k * sample_step_s);
    plan[k] = trajectory(time[k]);
  }
  CheckPlannedJointRange(model, time, plan, source);
  for (int k = 0; k < samples; ++k) {
    const std::vector<LinkPose> poses = ForwardKinematics(model, plan[k]);
    for (int c = 0; c < model.num_cables(); ++c) {
      change(k, c) = rest_length[c] - CablePathLength(model, c, poses);
    }
    if (planning.method == InputPlanning::Method::kStaticEquilibrium) {
      change.row(k) +=
          StaticEquilibriumStretch(model, plan[k], time[k], planning, source).transpose();
    }
  }
  return CableInputs(std::move(time), std::move(change));
}

namespace internal {
namespace {

// d/dτ of QuinticBlend: 30τ²(1 − τ)² on [0, 1], 0 outside.
double QuinticBlendRate(double tau) {
  if (tau <= 0.0 || tau >= 1.0) return 0.0;
  return 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau);
}

// Phase φ [rad] and its rate [rad/s] of an oscillation at `t` [s] into it.
void OscillationPhase(const ProtocolPiece& p, double t, double* phase, double* phase_rate) {
  const double f0 = p.start_frequency_hz, f1 = p.end_frequency_hz, T = p.duration_s;
  if (f0 == f1) {
    *phase = 2.0 * M_PI * f0 * t;
    *phase_rate = 2.0 * M_PI * f0;
  } else if (p.exponential_sweep) {
    // f(t) = f0 k^(t/T), k = f1/f0: φ = 2π f0 T (k^(t/T) − 1) / ln k.
    const double log_k = std::log(f1 / f0);
    const double growth = std::exp(log_k * t / T);
    *phase = 2.0 * M_PI * f0 * T * (growth - 1.0) / log_k;
    *phase_rate = 2.0 * M_PI * f0 * growth;
  } else {
    // f(t) = f0 + (f1 − f0) t / T.
    *phase = 2.0 * M_PI * (f0 * t + 0.5 * (f1 - f0) * t * t / T);
    *phase_rate = 2.0 * M_PI * (f0 + (f1 - f0) * t / T);
  }
}

// The fade envelope w and its rate: quintic in over fade_s, out over the
// last fade_s (their product, so that both ends are at rest however short).
void Envelope(const ProtocolPiece& p, double t, double* w, double* w_rate) {
  if (p.fade_s <= 0.0) {
    *w = 1.0;
    *w_rate = 0.0;
    return;
  }
  const double in = t / p.fade_s, out = (p.duration_s - t) / p.fade_s;
  const double w_in = QuinticBlend(in), w_out = QuinticBlend(out);
  *w = w_in * w_out;
  *w_rate = (QuinticBlendRate(in) * w_out - w_in * QuinticBlendRate(out)) / p.fade_s;
}

}  // namespace

Eigen::Vector2d PlaneBendToCardan(double plane_rad, double bend_rad) {
  const double s = std::sin(bend_rad);
  return Eigen::Vector2d(std::atan2(-std::sin(plane_rad) * s, std::cos(bend_rad)),
                         std::asin(std::clamp(std::cos(plane_rad) * s, -1.0, 1.0)));
}

JointAngles PieceAngles(const ProtocolPiece& p, double t) {
  JointAngles a = p.start;
  switch (p.kind) {
    case ProtocolPiece::Kind::kHold:
      break;
    case ProtocolPiece::Kind::kMove: {
      // Written as the paper's protocol computes it (A · q and A · (1 − q)),
      // so that configs/protocols/paper.yaml plans the same inputs to the bit.
      const double q = QuinticBlend(t / p.duration_s);
      for (std::size_t j = 0; j < a.size(); ++j) {
        for (int axis = 0; axis < 2; ++axis) {
          a[j][axis] = p.start[j][axis] * (1.0 - q) + p.target[j][axis] * q;
        }
      }
      break;
    }
    case ProtocolPiece::Kind::kOscillation: {
      double phase, phase_rate, w, w_rate;
      OscillationPhase(p, t, &phase, &phase_rate);
      Envelope(p, t, &w, &w_rate);
      const double factor = w * std::sin(phase);
      for (std::size_t j = 0; j < a.size(); ++j) a[j] += p.amplitude[j] * factor;
      break;
    }
  }
  return a;
}

JointAngles PieceRates(const ProtocolPiece& p, double t) {
  JointAngles rate(p.start.size(), Eigen::Vector2d::Zero());
  switch (p.kind) {
    case ProtocolPiece::Kind::kHold:
      break;
    case ProtocolPiece::Kind::kMove: {
      const double q_rate = QuinticBlendRate(t / p.duration_s) / p.duration_s;
      for (std::size_t j = 0; j < rate.size(); ++j) rate[j] = (p.target[j] - p.start[j]) * q_rate;
      break;
    }
    case ProtocolPiece::Kind::kOscillation: {
      double phase, phase_rate, w, w_rate;
      OscillationPhase(p, t, &phase, &phase_rate);
      Envelope(p, t, &w, &w_rate);
      const double factor = w_rate * std::sin(phase) + w * phase_rate * std::cos(phase);
      for (std::size_t j = 0; j < rate.size(); ++j) rate[j] = p.amplitude[j] * factor;
      break;
    }
  }
  return rate;
}

}  // namespace internal

namespace {

// The piece of `pieces` active at t and the time into it; nullptr after the
// last one. Durations are subtracted one by one, as the paper's protocol
// subtracts ramp_s and then hold_s.
const ProtocolPiece* ActivePiece(const std::vector<ProtocolPiece>& pieces, double t,
                                 double* local) {
  *local = t;
  for (const ProtocolPiece& p : pieces) {
    if (*local < p.duration_s) return &p;
    *local -= p.duration_s;
  }
  return nullptr;
}

}  // namespace

double Protocol::duration_s() const {
  double longest = 0.0;
  for (const auto& pieces : segments) {
    double total = 0.0;
    for (const ProtocolPiece& p : pieces) total += p.duration_s;
    longest = std::max(longest, total);
  }
  return longest;
}

JointAngles Protocol::PlannedAngles(double t) const {
  JointAngles angles;
  for (const auto& pieces : segments) {
    double local = 0.0;
    const ProtocolPiece* p = ActivePiece(pieces, t, &local);
    const JointAngles a = p != nullptr
                              ? internal::PieceAngles(*p, local)
                              : internal::PieceAngles(pieces.back(), pieces.back().duration_s);
    angles.insert(angles.end(), a.begin(), a.end());
  }
  return angles;
}

JointAngles Protocol::PlannedRates(double t) const {
  JointAngles rates;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    double local = 0.0;
    const ProtocolPiece* p = ActivePiece(segments[s], t, &local);
    const JointAngles r = p != nullptr ? internal::PieceRates(*p, local)
                                       : JointAngles(segment_joints[s], Eigen::Vector2d::Zero());
    rates.insert(rates.end(), r.begin(), r.end());
  }
  return rates;
}

JointTrajectory Protocol::Trajectory() const {
  // A copy: the trajectory may outlive the protocol it came from.
  return [protocol = *this](double t) { return protocol.PlannedAngles(t); };
}

CableInputs PlanProtocolInputs(const ArmModel& model, const Protocol& protocol,
                               const ArmParameters& parameters, double duration_s,
                               double sample_step_s) {
  InputPlanning planning;
  planning.method = protocol.planning;
  planning.pretension_n = parameters.T_d0;
  CableInputs inputs = PlanCableInputs(model, protocol.Trajectory(), duration_s, sample_step_s,
                                       protocol.source_name, planning);
  // Speeds and accelerations by central differences of the sampled lengths
  // (second order; rounding adds ~1e-10 m/s² at 1 ms, far below any limit).
  const Eigen::VectorXd& time = inputs.time();
  const Eigen::MatrixXd& length = inputs.length_change();
  for (Eigen::Index k = 1; k + 1 < time.size(); ++k) {
    const double h_back = time[k] - time[k - 1], h_fore = time[k + 1] - time[k];
    for (Eigen::Index c = 0; c < length.cols(); ++c) {
      const double back = (length(k, c) - length(k - 1, c)) / h_back;
      const double fore = (length(k + 1, c) - length(k, c)) / h_fore;
      const double speed = 0.5 * (back + fore);
      const double accel = 2.0 * (fore - back) / (h_back + h_fore);
      const bool too_fast = std::abs(speed) > protocol.limits.cable_speed_mps;
      const bool too_hard = std::abs(accel) > protocol.limits.cable_acceleration_mps2;
      if (!too_fast && !too_hard) continue;
      // Blame the piece of the cable's own segment active then.
      const int segment = model.cables()[c].segment;
      double local = 0.0;
      const ProtocolPiece* p = ActivePiece(protocol.segments[segment], time[k], &local);
      if (p == nullptr) p = &protocol.segments[segment].back();
      char what[256];
      if (too_fast) {
        std::snprintf(what, sizeof(what),
                      "cable %d would run at %.3g m/s at t = %.3f s, beyond "
                      "limits.cable_speed_mps = %.3g",
                      static_cast<int>(c) + 1, std::abs(speed), time[k],
                      protocol.limits.cable_speed_mps);
      } else {
        std::snprintf(what, sizeof(what),
                      "cable %d would accelerate at %.3g m/s² at t = %.3f s, beyond "
                      "limits.cable_acceleration_mps2 = %.3g",
                      static_cast<int>(c) + 1, std::abs(accel), time[k],
                      protocol.limits.cable_acceleration_mps2);
      }
      ThrowInputError(protocol.source_name, p->source.Where(), what);
    }
  }
  return inputs;
}

std::string DescribeProtocolFile(const Protocol& protocol) {
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.4g", v);
    return std::string(text);
  };
  std::string text = "'" + (protocol.name.empty() ? std::string("unnamed") : protocol.name) +
                     "' (" + protocol.source_name + "), " + number(protocol.duration_s()) + " s";
  for (std::size_t s = 0; s < protocol.segments.size(); ++s) {
    text += s == 0 ? ": " : "; ";
    text += "segment " + std::to_string(s + 1);
    std::string previous;
    int count = 0;
    auto flush = [&] {
      if (count == 0) return;
      text += " " + previous + (count > 1 ? " ×" + std::to_string(count) : "") + ",";
    };
    for (const ProtocolPiece& p : protocol.segments[s]) {
      const std::string word = p.kind == ProtocolPiece::Kind::kHold         ? "hold"
                               : p.kind == ProtocolPiece::Kind::kMove       ? "move"
                               : p.start_frequency_hz == p.end_frequency_hz ? "sine"
                                                                            : "chirp";
      if (word == previous) {
        ++count;
        continue;
      }
      flush();
      previous = word;
      count = 1;
    }
    flush();
    text.pop_back();  // the last ','
  }
  return text;
}

namespace internal {

std::string RangeSetBy(const ArmConfig& arm, int joint) {
  const int own = arm.segment_of_link(joint);  // 0-based
  if (own < 0) return "";
  int widest = own;
  for (const DrivingCableRoute& route : arm.driving.cables) {
    const int s = route.segment - 1;
    if (s >= own &&
        arm.segments[s].hole_circle_radius_m > arm.segments[widest].hole_circle_radius_m) {
      widest = s;
    }
  }
  if (widest == own) return "";
  char text[200];
  std::snprintf(text, sizeof(text),
                " (R = %.3g mm: the hole circle of segment %d, whose cables pass joint %d; "
                "segment %d's own is %.3g mm)",
                arm.segments[widest].hole_circle_radius_m * 1e3, widest + 1, joint, own + 1,
                arm.segments[own].hole_circle_radius_m * 1e3);
  return text;
}

}  // namespace internal

}  // namespace ccsrm::sim
