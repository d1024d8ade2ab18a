#include "ccsrm/sim/protocol.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/gsl_errors.h"

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

CableInputs::CableInputs(Eigen::VectorXd time, Eigen::MatrixXd length_change)
    : time_(std::move(time)), length_change_(std::move(length_change)), splines_(new Splines) {
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
  const gsl_interp_type* type = n >= 3 ? gsl_interp_cspline : gsl_interp_linear;
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
  ThrowInputError(source, "",
                  "the plan tilts joint " + std::to_string(worst_joint) + " (segment " +
                      std::to_string(segment) + ") to " + Format("%.1f", worst_tilt * deg) +
                      " deg (beyond from t = " + Format("%.3g", first_time) +
                      " s), past its range of " +
                      Format("%.1f", model.joint_range_rad(worst_joint) * deg) +
                      " deg where its disks meet (2 atan(d/2R), d = " +
                      Format("%.3g", model.arm().joint_disk_gap_m * 1e3) +
                      " mm, R = " + Format("%.3g", model.joint_disk_radius_m(worst_joint) * 1e3) +
                      " mm the hole circle); ccsrm has no contact between disks");
}

}  // namespace

CableInputs PlanCableInputs(const ArmModel& model, const JointTrajectory& trajectory,
                            double duration_s, double sample_step_s, const std::string& source) {
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
  }
  return CableInputs(std::move(time), std::move(change));
}

}  // namespace ccsrm::sim
