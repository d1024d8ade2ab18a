#pragma once
// Protocols: planned joint trajectories and the driving-cable inputs they
// need. Inputs come from pure kinematic planning (SPEC 3): the change of each
// cable's geometric path length through every hole is pulled in at the input.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::sim {

// Planned joint angles as a function of time [s].
using JointTrajectory = std::function<JointAngles(double t)>;

// 10τ³ − 15τ⁴ + 6τ⁵ on [0, 1]: zero velocity and acceleration at both ends.
double QuinticBlend(double tau);

// The paper's protocol: every joint's θx goes 0 → A along a quintic over
// ramp_s, holds for hold_s, returns over return_s and rests for rest_s; θy = 0.
JointTrajectory PaperTrajectory(const ArmModel& model, const ProtocolConfig& protocol);

// Prescribed pulled-in length of every driving cable [m] (positive = pulled
// in) as a function of time, interpolated by a C2 cubic spline through
// samples; before the first and after the last sample the end value holds.
class CableInputs {
 public:
  // time: N >= 2 strictly increasing samples [s]; length_change: N × C [m].
  // Throws InputError on a bad shape, non-increasing time or a non-finite value.
  CableInputs(Eigen::VectorXd time, Eigen::MatrixXd length_change);
  ~CableInputs();
  CableInputs(CableInputs&&) noexcept;
  CableInputs& operator=(CableInputs&&) noexcept;

  int num_cables() const { return static_cast<int>(length_change_.cols()); }
  double start_time() const { return time_[0]; }
  double end_time() const { return time_[time_.size() - 1]; }
  const Eigen::VectorXd& time() const { return time_; }
  const Eigen::MatrixXd& length_change() const { return length_change_; }

  // Value [m], rate [m/s] and acceleration [m/s²] of cable `cable` at t.
  // Thread-safe.
  void Evaluate(int cable, double t, double* value, double* rate, double* accel) const;

 private:
  struct Splines;
  Eigen::VectorXd time_;
  Eigen::MatrixXd length_change_;
  std::unique_ptr<Splines> splines_;
};

// Plans the inputs for a joint trajectory by pure kinematics: samples the
// trajectory every `sample_step_s` over [0, duration_s] and records
// L(0) − L(t) for every cable. Throws InputError, labelled `source` (the
// option or file the motion came from), when a planned joint tilts beyond
// its range (ArmModel::joint_range_rad): past it the paths through the gap
// fold and the plan means nothing.
CableInputs PlanCableInputs(const ArmModel& model, const JointTrajectory& trajectory,
                            double duration_s, double sample_step_s = 1e-3,
                            const std::string& source = "planned motion");

}  // namespace ccsrm::sim
