#include "ccsrm/sim/simulator.h"

#include "ccsrm/sim/declared_values.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/common/gsl_errors.h"
#include "ccsrm/sim/kinematics.h"
#include "dynamics.h"
#include "effects/effect.h"
#include "integrator.h"
#include "output_sampler.h"
#include "quasi_static.h"
#include "run_control.h"
#include "stick_slip.h"

namespace ccsrm::sim {
namespace {

using internal::FormatTime;
using internal::StickSlipTreatment;

// One run's step loop: explicit steps with error control that land exactly
// on every sample time, the stick-slip treatment after each accepted step,
// and the checks that stop a run (divergence, cancellation).
class StepLoop {
 public:
  StepLoop(const ArmModel& model, const ArmParameters& parameters, const CableInputs& inputs,
           const SimulationOptions& options)
      : model_(model),
        options_(options),
        solver_(options.solver),
        control_(options),
        dynamics_(model, parameters, inputs, options.solver),
        integrator_(internal::MakeIntegrator(&dynamics_, solver_)),
        stick_slip_(
            internal::MakeTrialAndErrorStickSlip(model, &dynamics_, integrator_.get(), solver_)),
        sampler_(internal::SampleTimes(options)),
        y_(dynamics_.InitialState()),
        dim_(dynamics_.state_size()),
        y_try_(dim_),
        dydt_(dim_),
        dydt_try_(dim_),
        y_start_(dim_),
        dydt_start_(dim_),
        h_(solver_.initial_step_s) {}

  SimulationResult Run() {
    // Consistent initial modes: nothing may need to switch at t = 0.
    if (!stick_slip_->Settle(t_, y_.data()))
      Stop(SimulationStatus::kDiverged, stick_slip_->failure());
    while (running() && !sampler_.done()) {
      const double t_out = sampler_.next_time();
      // True while the dynamics' last evaluation is at (t, y) under the
      // current modes (the end of an accepted step): the frame reuses it.
      bool end_evaluation_current = false;
      while (running() && t_ < t_out) end_evaluation_current = Advance(t_out);
      if (!running()) break;
      Sample(!end_evaluation_current);
    }
    return Finish();
  }

 private:
  bool running() const { return status_ == SimulationStatus::kCompleted; }

  void Stop(SimulationStatus status, const std::string& cause) {
    if (!running()) return;
    status_ = status;
    message_ = cause;
  }

  void Diverge(const std::string& cause) {
    Stop(SimulationStatus::kDiverged, cause + " at t = " + FormatTime(t_));
  }

  // One accepted step towards t_out (rejected trials retried shorter), then
  // the stick-slip treatment. Returns true when the dynamics' last
  // evaluation is still at the step's end under the current modes.
  bool Advance(double t_out) {
    if (!have_dydt_) {
      if (!dynamics_.Evaluate(t_, y_.data(), dydt_.data())) {
        Diverge(dynamics_.failure());
        return false;
      }
      have_dydt_ = true;
    }
    const double h_proposed = std::min(h_, solver_.max_step_s);
    double dt = h_proposed;
    // Land on the sample time exactly; stretch rather than leave a sliver.
    const bool last = t_ + 1.01 * dt >= t_out;
    if (last) dt = t_out - t_;
    // The end derivative only once the error is accepted: a rejected
    // trial costs five evaluations instead of six.
    if (!integrator_->TryStep(t_, y_.data(), dydt_.data(), dt, y_try_.data(), nullptr)) {
      // A trial that went too far can collapse an element: retry shorter.
      RejectStep(0.5 * dt, dynamics_.failure());
      return false;
    }
    double h_next = dt;
    if (!integrator_->ErrorAcceptable(y_try_.data(), dt, &h_next)) {
      RejectStep(h_next, "");
      return false;
    }
    // The next step's first stage, and the hole reports the stick-slip
    // scan reads.
    if (!dynamics_.Evaluate(t_ + dt, y_try_.data(), dydt_try_.data())) {
      RejectStep(0.5 * dt, dynamics_.failure());
      return false;
    }
    // Accepted. A step shortened to land on t_out says nothing against the
    // longer step that was proposed.
    h_ = last ? std::max(h_proposed, h_next) : h_next;
    const double t_start = t_;
    std::swap(y_start_, y_);
    std::swap(dydt_start_, dydt_);
    std::copy(y_try_.begin(), y_try_.end(), y_.data());
    std::swap(dydt_, dydt_try_);
    t_ = last ? t_out : t_start + dt;
    ++steps_;
    CheckCancellationAndReport();
    switch (stick_slip_->AfterStep(t_start, y_start_.data(), dydt_start_.data(), &t_, y_.data())) {
      case StickSlipTreatment::Outcome::kNoSwitch:
        return true;
      case StickSlipTreatment::Outcome::kSwitched:
        have_dydt_ = false;
        return false;
      case StickSlipTreatment::Outcome::kFailed:
        Stop(SimulationStatus::kDiverged, stick_slip_->failure());
        return false;
    }
    return false;
  }

  void RejectStep(double h, const std::string& reason) {
    h_ = h;
    ++rejected_;
    if (h_ < solver_.min_step_s) {
      Diverge("step size collapsed to " + FormatTime(h_) +
              (reason.empty() ? "" : " (" + reason + ")"));
    }
  }

  void CheckCancellationAndReport() {
    // The clock is read every 64 steps: cheap against ~60 evaluations.
    const std::string stop =
        control_.Check(t_, steps_, stick_slip_->switches(), (steps_ & 63) == 0);
    if (!stop.empty()) Stop(SimulationStatus::kCancelled, stop);
  }

  // The frame at t = next sample time; a constraint violation above the
  // bound ends the run after it is recorded.
  void Sample(bool evaluate) {
    if (!y_.allFinite()) {
      Diverge("non-finite state");
      return;
    }
    dynamics_.Observe(t_, y_.data(), &frame_, evaluate);
    sampler_.Record(frame_);
    if (frame_.constraint_violation > solver_.max_constraint_violation) {
      char text[128];
      std::snprintf(text, sizeof(text), "constraint violation %.3g above bound %.3g",
                    frame_.constraint_violation, solver_.max_constraint_violation);
      Diverge(text);
      return;
    }
    // A joint past its range soon folds a cable's path through the gap
    // between its disks: the run stops there, like a divergence.
    const std::string past = internal::JointPastRange(model_, frame_);
    if (!past.empty()) Diverge(past);
  }

  SimulationResult Finish() {
    SimulationResult result = internal::FinishRun(
        model_, control_, {status_, message_, t_, steps_, rejected_, dynamics_.evaluations()},
        &sampler_);
    SimulationSummary& s = result.summary;
    s.stick_slip_switches = stick_slip_->switches();
    s.failed_releases = stick_slip_->failed_releases();
    s.largest_threshold_raise_n = stick_slip_->largest_threshold_raise_n();
    return result;
  }

  const ArmModel& model_;
  const SimulationOptions& options_;
  const SolverConfig& solver_;
  internal::RunControl control_;
  internal::ArmDynamics dynamics_;
  std::unique_ptr<internal::Integrator> integrator_;
  std::unique_ptr<StickSlipTreatment> stick_slip_;
  internal::OutputSampler sampler_;
  TrajectoryFrame frame_;

  // (t, y) and, when have_dydt_, its derivative under the current modes;
  // the trial step's end; the last accepted step's start.
  double t_ = 0.0;
  Eigen::VectorXd y_;
  const std::size_t dim_;
  std::vector<double> y_try_, dydt_, dydt_try_;
  Eigen::VectorXd y_start_;
  std::vector<double> dydt_start_;
  bool have_dydt_ = false;
  double h_;

  SimulationStatus status_ = SimulationStatus::kCompleted;
  std::string message_;
  std::int64_t steps_ = 0, rejected_ = 0;
};

}  // namespace

const char* SimulationStatusName(SimulationStatus status) {
  switch (status) {
    case SimulationStatus::kCompleted:
      return "completed";
    case SimulationStatus::kDiverged:
      return "diverged";
    case SimulationStatus::kCancelled:
      return "cancelled";
  }
  return "?";
}

bool SimulationOptions::IsValid(std::string* error) const {
  if (!(duration_s > 0.0) || !std::isfinite(duration_s)) {
    *error = "duration must be > 0 s";
    return false;
  }
  if (!(progress_interval_s > 0.0)) {
    *error = "progress interval must be > 0 s";
    return false;
  }
  if (!(wall_time_budget_s >= 0.0)) {
    *error = "wall-time budget must be >= 0 s (0: none)";
    return false;
  }
  if (!(quasi_static_increment_m > 0.0) || !std::isfinite(quasi_static_increment_m)) {
    *error = "quasi-static increment must be > 0 m";
    return false;
  }
  for (std::size_t k = 0; k < sample_times.size(); ++k) {
    const double t = sample_times[k];
    if (!(t >= 0.0 && t <= duration_s) || (k > 0 && t < sample_times[k - 1])) {
      *error = "sample_times[" + std::to_string(k) + "] = " + std::to_string(t) +
               " must be non-decreasing and within [0, duration]";
      return false;
    }
  }
  return true;
}

std::string SimulationSummary::BriefReport() const {
  char text[256];
  std::snprintf(text, sizeof(text), "%s at t = %.4g s: %.3g s wall, %.3gx real time, %lld steps",
                SimulationStatusName(status), simulated_s, wall_time_s, real_time_factor,
                static_cast<long long>(steps));
  return text;
}

std::string SimulationSummary::FullReport() const {
  std::ostringstream out;
  std::string word = SimulationStatusName(status);
  if (!completed()) {
    for (char& c : word) c = static_cast<char>(std::toupper(c));
  }
  out << "simulation " << word << "\n";
  if (!completed()) out << "  cause:                     " << message << "\n";
  char line[160];
  std::snprintf(line, sizeof(line), "  simulated time:            %.6g s\n", simulated_s);
  out << line;
  std::snprintf(line, sizeof(line), "  wall time:                 %.3f s\n", wall_time_s);
  out << line;
  std::snprintf(line, sizeof(line), "  real-time factor:          %.3f (simulated s per wall s)\n",
                real_time_factor);
  out << line;
  std::snprintf(line, sizeof(line), "  steps:                     %lld accepted, %lld rejected\n",
                static_cast<long long>(steps), static_cast<long long>(rejected_steps));
  out << line;
  std::snprintf(line, sizeof(line), "  right-hand-side evals:     %lld (%.0f per wall s)\n",
                static_cast<long long>(rhs_evaluations),
                wall_time_s > 0 ? rhs_evaluations / wall_time_s : 0.0);
  out << line;
  std::snprintf(line, sizeof(line), "  stick-slip switches:       %lld (events law)\n",
                static_cast<long long>(stick_slip_switches));
  out << line;
  if (failed_releases > 0) {
    std::snprintf(line, sizeof(line),
                  "  failed releases:           %lld (threshold raised by up to %.3g N)\n",
                  static_cast<long long>(failed_releases), largest_threshold_raise_n);
    out << line;
  }
  std::snprintf(line, sizeof(line), "  max constraint violation:  %.3g\n",
                max_constraint_violation);
  out << line;
  out << "  slack cables:              ";
  if (slack.empty()) out << "none\n";
  // Long runs can slacken a cable many times; the run file has them all.
  constexpr std::size_t kListed = 8;
  for (std::size_t i = 0; i < slack.size() && i < kListed; ++i) {
    const SlackInterval& v = slack[i];
    out << (i == 0 ? "" : "                             ");
    if (v.end_s > v.start_s) {
      std::snprintf(line, sizeof(line), "cable %d slack from %.3f s to %.3f s (%.3g s)", v.cable,
                    v.start_s, v.end_s, v.duration_s());
    } else {
      std::snprintf(line, sizeof(line), "cable %d slack at %.3f s (one frame)", v.cable, v.start_s);
    }
    out << line << ", up to " << v.most_elements << " element" << (v.most_elements == 1 ? "" : "s")
        << "\n";
  }
  if (slack.size() > kListed) {
    out << "                             and " << slack.size() - kListed
        << " more stretches (the run file's /slack_elements)\n";
  }
  return out.str();
}

int CountSlackElements(const std::vector<double>& element_tension) {
  int count = 0;
  for (double tension : element_tension) count += tension <= 0.0 ? 1 : 0;
  return count;
}

std::vector<SlackInterval> FindSlackIntervals(const std::vector<double>& time,
                                              const Eigen::MatrixXi& slack_elements) {
  CCSRM_CHECK(static_cast<Eigen::Index>(time.size()) == slack_elements.rows());
  std::vector<SlackInterval> intervals;
  for (Eigen::Index c = 0; c < slack_elements.cols(); ++c) {
    bool open = false;
    for (Eigen::Index f = 0; f < slack_elements.rows(); ++f) {
      const int count = slack_elements(f, c);
      if (count <= 0) {
        open = false;
        continue;
      }
      if (!open) {
        intervals.push_back({static_cast<int>(c) + 1, time[f], time[f], 0});
        open = true;
      }
      intervals.back().end_s = time[f];
      intervals.back().most_elements = std::max(intervals.back().most_elements, count);
    }
  }
  return intervals;
}

SimulationResult Simulate(const ArmModel& model, const ArmParameters& parameters,
                          const CableInputs& inputs, const SimulationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("simulation options", "", error);
  ValidateSolver(options.solver, "simulation options");
  if (!parameters.IsValid(&error)) ThrowInputError("simulation parameters", "", error);
  if (inputs.num_cables() != model.num_cables()) {
    ThrowInputError("cable inputs", "",
                    "has " + std::to_string(inputs.num_cables()) + " cables, the model has " +
                        std::to_string(model.num_cables()));
  }
  UseGslErrorCodes();
  // Declared-value corrections (declared_values.h): the arm built with the
  // corrected values; with none, the model as given.
  if (AnyDeclaredCorrection(parameters)) {
    const ArmModel corrected(CorrectedArm(model.arm(), parameters));
    ArmParameters rest = parameters;
    rest.declared_deltas.clear();
    return Simulate(corrected, rest, inputs, options);
  }
  // Actuator effects (delay, creep) drive the arm with what the actuators
  // realise from the commanded inputs; with none on, the inputs as given.
  const std::unique_ptr<CableInputs> realised =
      internal::RealisedInputs(model, parameters, inputs, options.duration_s);
  const CableInputs& driven = realised ? *realised : inputs;
  if (options.quasi_static)
    return internal::SimulateSettledPoses(model, parameters, driven, options);
  return StepLoop(model, parameters, driven, options).Run();
}

}  // namespace ccsrm::sim
