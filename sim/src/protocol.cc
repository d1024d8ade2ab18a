#include "ccsrm/sim/protocol.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <cmath>
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

CableInputs PlanCableInputs(const ArmModel& model, const JointTrajectory& trajectory,
                            double duration_s, double sample_step_s) {
  CCSRM_CHECK(duration_s > 0.0 && sample_step_s > 0.0);
  const int samples = static_cast<int>(std::ceil(duration_s / sample_step_s - 1e-9)) + 1;
  Eigen::VectorXd time(samples);
  Eigen::MatrixXd change(samples, model.num_cables());
  const std::vector<LinkPose> straight =
      ForwardKinematics(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  Eigen::VectorXd rest_length(model.num_cables());
  for (int c = 0; c < model.num_cables(); ++c) rest_length[c] = CablePathLength(model, c, straight);
  for (int k = 0; k < samples; ++k) {
    const double t = std::min(duration_s, k * sample_step_s);
    time[k] = t;
    const std::vector<LinkPose> poses = ForwardKinematics(model, trajectory(t));
    for (int c = 0; c < model.num_cables(); ++c) {
      change(k, c) = rest_length[c] - CablePathLength(model, c, poses);
    }
  }
  return CableInputs(std::move(time), std::move(change));
}

}  // namespace ccsrm::sim
