#include "ccsrm/sim/simulator.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "ccsrm/common/error.h"
#include "dynamics.h"

namespace ccsrm::sim {
namespace {

using internal::ArmDynamics;
using internal::HoleMode;
using internal::HoleReport;
using internal::Observation;
using Clock = std::chrono::steady_clock;

int RightHandSide(double t, const double y[], double dydt[], void* params) {
  auto* dynamics = static_cast<ArmDynamics*>(params);
  // GSL_FAILURE (not GSL_EBADFUNC) lets evolve retry with a smaller step: a
  // trial step that went too far can collapse an element.
  return dynamics->Evaluate(t, y, dydt) ? GSL_SUCCESS : GSL_FAILURE;
}

// Owns the GSL stepper and step-size control of one run. The step loop is
// ours rather than gsl_odeiv2_evolve_apply: evolve evaluates the derivative at
// the start of every step although RKF45 already computed it at the end of
// the previous one, and the hole reports of that end-of-step evaluation are
// what the stick-slip scan needs (6 evaluations per step instead of 8).
struct GslStepper {
  gsl_odeiv2_step* step = nullptr;
  gsl_odeiv2_control* control = nullptr;
  // State layout: n coordinates, n velocities, dissipated energy.
  GslStepper(std::size_t dim, const SolverConfig& solver) {
    step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rkf45, dim);
    std::vector<double> scale(dim, 1.0);
    const std::size_t n = (dim - 1) / 2;
    for (std::size_t k = n; k < 2 * n; ++k) scale[k] = 1.0 / solver.velocity_tolerance_time_s;
    control = gsl_odeiv2_control_scaled_new(solver.absolute_tolerance, solver.relative_tolerance,
                                            1.0, 0.0, scale.data(), dim);
  }
  ~GslStepper() {
    gsl_odeiv2_control_free(control);
    gsl_odeiv2_step_free(step);
  }
  GslStepper(const GslStepper&) = delete;
  GslStepper& operator=(const GslStepper&) = delete;
};

// Stick-slip switching of the hole nodes at (t, y) (paper section 2.3,
// trial and error). A stuck node slips once the friction its constraint needs
// exceeds f_max (eq. 10) by the force tolerance; a slipping node sticks once
// its slip reverses past v_eps. Both are located in time. Where even f_max is
// below the force tolerance (a cable running nearly straight through the
// hole) the dynamics leave friction out, so such a node never sticks and its
// slip direction just follows the slip speed, without an event.
//
// A release that fails at once (the node sticks again within
// kFailedReleaseWindow of being released, before it has moved) means that
// neither slip direction is consistent with a load so close to f_max: trial
// and error then keeps the node stuck, and it is not released again until the
// friction it needs exceeds f_max by the force tolerance more than it did at
// that failed release. Without this, such a node switches back and forth at
// one instant forever.
class SwitchDetector {
 public:
  SwitchDetector(const ArmModel& model, ArmDynamics* dynamics, const SolverConfig& solver)
      : model_(model),
        dynamics_(dynamics),
        solver_(solver),
        scratch_(dynamics->state_size()),
        release_time_(dynamics->hole_modes().size(), -1.0),
        release_excess_(dynamics->hole_modes().size(), 0.0),
        pinned_excess_(dynamics->hole_modes().size(), 0.0) {}

  struct Switches {
    std::vector<int> located;  // must be located in time, then switched
    std::vector<int> flips;    // negligible friction: flip the slip direction, no event
    bool any() const { return !located.empty() || !flips.empty(); }
  };

  // Returns false if the evaluation at (t, y) failed. A slip reversal is
  // detected past v_eps (hysteresis against noise) but, with `locating`,
  // located at the zero crossing of the slip speed, so that the node sticks
  // with no speed left for the stick constraint to take out at once.
  // `only`, when given, restricts the scan to those nodes (the ones whose
  // switch is being located).
  // With `evaluate` false the reports of the dynamics' last evaluation are
  // used; the caller guarantees it was at (t, y) with the current modes.
  bool Scan(double t, const double* y, Switches* out, bool locating = false,
            const std::vector<int>* only = nullptr, bool evaluate = true) {
    out->located.clear();
    out->flips.clear();
    if (!dynamics_->has_stick_slip()) return true;
    if (evaluate && !dynamics_->Evaluate(t, y, scratch_.data())) return false;
    const auto& modes = dynamics_->hole_modes();
    const auto& reports = dynamics_->hole_reports();
    const double f_tol = solver_.stick_force_tolerance_n;
    const int count =
        only != nullptr ? static_cast<int>(only->size()) : static_cast<int>(modes.size());
    for (int k = 0; k < count; ++k) {
      const int h = only != nullptr ? (*only)[k] : k;
      const HoleReport& r = reports[h];
      if (modes[h] == HoleMode::kStuck) {
        if (std::abs(r.required_friction) > ReleaseThreshold(h)) out->located.push_back(h);
      } else {
        const double sigma = modes[h] == HoleMode::kSlipUp ? 1.0 : -1.0;
        const double threshold = locating ? 0.0 : solver_.stick_velocity_tolerance_mps;
        if (sigma * r.s_dot < -threshold) {
          (r.friction_limit >= f_tol ? out->located : out->flips).push_back(h);
        }
      }
    }
    return true;
  }

  // The switching function of hole h at the dynamics' last evaluation,
  // positive once the node must switch and crossing zero where it does: for a
  // stuck node the excess of required friction over f_max (+ tolerance) [N],
  // for a slipping node its slip speed against its friction direction [m/s].
  double SwitchFunction(int h) const {
    const HoleReport& r = dynamics_->hole_reports()[h];
    const HoleMode mode = dynamics_->hole_modes()[h];
    if (mode == HoleMode::kStuck) return std::abs(r.required_friction) - ReleaseThreshold(h);
    return mode == HoleMode::kSlipUp ? -r.s_dot : r.s_dot;
  }

  // Applies the switches found by the last Scan at (t, y); returns how many
  // stick-slip switches (not direction flips) it made.
  std::int64_t Apply(double t, const double* y, const Switches& switches) {
    auto& modes = dynamics_->hole_modes();
    for (int h : switches.flips) {
      modes[h] = modes[h] == HoleMode::kSlipUp ? HoleMode::kSlipDown : HoleMode::kSlipUp;
    }
    // Reports of the Scan, before the trials below overwrite them.
    const std::vector<HoleReport> reports = dynamics_->hole_reports();
    for (int h : switches.located) {
      Trace(h, modes[h], reports[h]);
      if (modes[h] == HoleMode::kStuck) {
        modes[h] = SlipDirection(t, y, h, reports[h]);
        release_time_[h] = t;
        release_excess_[h] = std::abs(reports[h].required_friction) - reports[h].friction_limit;
        pinned_excess_[h] = 0.0;
      } else {
        const auto& hole = dynamics_->holes()[h];
        modes[h] = HoleMode::kStuck;
        dynamics_->stuck_position()[h] = y[model_.node_offset(hole.cable, hole.node) + 3];
        if (release_time_[h] >= 0.0 &&
            t - release_time_[h] <= kFailedReleaseWindow * solver_.switch_time_tolerance_s) {
          pinned_excess_[h] = release_excess_[h] + solver_.stick_force_tolerance_n;
        }
      }
    }
    return static_cast<std::int64_t>(switches.located.size());  // flips are not stick-slip switches
  }

 private:
  // A failed release is one undone within this many switch time tolerances.
  static constexpr double kFailedReleaseWindow = 2.0;

  // The required friction [N] above which stuck hole h slips.
  double ReleaseThreshold(int h) const {
    const HoleReport& r = dynamics_->hole_reports()[h];
    return r.friction_limit + std::max(solver_.stick_force_tolerance_n, pinned_excess_[h]);
  }

  // The direction a released node slips (trial and error, section 2.3). A
  // node still moving slips the way it moves. A node at rest is tried both
  // ways, starting against the friction its constraint was applying, and
  // takes the direction in which its acceleration agrees with the slip: with
  // the coupled (smoothed) mass matrix the sign of the reaction alone does
  // not say which way the node will move.
  HoleMode SlipDirection(double t, const double* y, int h, const HoleReport& report) {
    if (std::abs(report.s_dot) > solver_.stick_velocity_tolerance_mps) {
      return report.s_dot > 0.0 ? HoleMode::kSlipUp : HoleMode::kSlipDown;
    }
    const auto& hole = dynamics_->holes()[h];
    const int s_index =
        dynamics_->num_coordinates() + model_.node_offset(hole.cable, hole.node) + 3;
    const HoleMode first = report.required_friction > 0.0 ? HoleMode::kSlipDown : HoleMode::kSlipUp;
    const HoleMode second = first == HoleMode::kSlipUp ? HoleMode::kSlipDown : HoleMode::kSlipUp;
    for (HoleMode trial : {first, second}) {
      dynamics_->hole_modes()[h] = trial;
      if (!dynamics_->Evaluate(t, y, scratch_.data())) break;
      const double sigma = trial == HoleMode::kSlipUp ? 1.0 : -1.0;
      if (sigma * scratch_[s_index] > 0.0) return trial;
    }
    return first;
  }

  void Trace(int h, HoleMode mode, const HoleReport& r) const {
    if (trace_ == nullptr) return;
    const auto& hole = dynamics_->holes()[h];
    std::fprintf(
        trace_, "switch cable %d node %d: %s, s_dot %.3e m/s, friction %.4g / limit %.4g N\n",
        hole.cable + 1, hole.node, mode == HoleMode::kStuck ? "stick->slip" : "slip->stick",
        r.s_dot, r.required_friction, r.friction_limit);
  }

  const ArmModel& model_;
  ArmDynamics* dynamics_;
  const SolverConfig& solver_;
  std::vector<double> scratch_;
  // Per hole: when it was last released (-1: never), by how much the friction
  // it needed then exceeded f_max [N], and the raised excess a release needs
  // after a failed one (0: the force tolerance applies).
  std::vector<double> release_time_;
  std::vector<double> release_excess_;
  std::vector<double> pinned_excess_;
  // CCSRM_TRACE_SWITCHES=1 prints every stick-slip switch on stderr.
  std::FILE* trace_ = std::getenv("CCSRM_TRACE_SWITCHES") != nullptr ? stderr : nullptr;
};

void AppendFrame(const Observation& o, double t, std::vector<double>* time,
                 std::vector<Observation>* frames) {
  time->push_back(t);
  frames->push_back(o);
}

datasets::RunFile BuildRunFile(const ArmModel& model, const std::vector<double>& time,
                               const std::vector<Observation>& frames) {
  using datasets::Array;
  datasets::RunFile run;
  const std::size_t T = time.size();
  const std::size_t J = model.num_joints(), L = model.num_links(), C = model.num_cables();
  run.time = Array({T});
  run.joint_angles = Array({T, J, 2});
  run.joint_rates = Array({T, J, 2});
  run.link_pose = Array({T, L, 7});
  run.input_tension = Array({T, C});
  run.input_length_change = Array({T, C});
  run.stuck_nodes = Array({T, C});
  run.constraint_violation = Array({T});
  run.energy = Array({T, 3});
  run.cables.resize(C);
  for (std::size_t c = 0; c < C; ++c) {
    const std::size_t elements = model.cables()[c].num_elements();
    const std::size_t holes = model.cables()[c].num_holes();
    run.cables[c].tension = Array({T, elements});
    run.cables[c].stuck = Array({T, holes});
    run.cables[c].slip_velocity = Array({T, holes});
  }
  for (std::size_t f = 0; f < T; ++f) {
    const Observation& o = frames[f];
    run.time.at(f) = time[f];
    for (std::size_t j = 0; j < J; ++j) {
      for (int a = 0; a < 2; ++a) {
        run.joint_angles.at(f, j, a) = o.joint_angles[j][a];
        run.joint_rates.at(f, j, a) = o.joint_rates[j][a];
      }
    }
    for (std::size_t i = 0; i < L; ++i)
      for (int k = 0; k < 7; ++k) run.link_pose.at(f, i, k) = o.link_pose[i][k];
    for (std::size_t c = 0; c < C; ++c) {
      run.input_tension.at(f, c) = o.element_tension[c][0];
      run.input_length_change.at(f, c) = o.input_length_change[c];
      int stuck = 0;
      for (std::size_t e = 0; e < o.element_tension[c].size(); ++e) {
        run.cables[c].tension.at(f, e) = o.element_tension[c][e];
      }
      for (std::size_t h = 0; h < o.hole_stuck[c].size(); ++h) {
        run.cables[c].stuck.at(f, h) = o.hole_stuck[c][h];
        run.cables[c].slip_velocity.at(f, h) = o.hole_slip_velocity[c][h];
        stuck += o.hole_stuck[c][h];
      }
      run.stuck_nodes.at(f, c) = stuck;
    }
    run.constraint_violation.at(f) = o.constraint_violation;
    run.energy.at(f, 0) = o.kinetic_energy;
    run.energy.at(f, 1) = o.elastic_energy;
    run.energy.at(f, 2) = o.dissipated_energy;
  }
  return run;
}

std::string FormatTime(double t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g s", t);
  return text;
}

}  // namespace

bool SimulationOptions::IsValid(std::string* error) const {
  if (!(duration_s > 0.0) || !std::isfinite(duration_s)) {
    *error = "duration must be > 0 s";
    return false;
  }
  if (!(progress_interval_s > 0.0)) {
    *error = "progress interval must be > 0 s";
    return false;
  }
  return true;
}

std::string SimulationSummary::BriefReport() const {
  char text[256];
  std::snprintf(text, sizeof(text), "%s at t = %.4g s: %.3g s wall, %.3gx real time, %lld steps",
                completed ? "completed" : "diverged", simulated_s, wall_time_s, real_time_factor,
                static_cast<long long>(steps));
  return text;
}

std::string SimulationSummary::FullReport() const {
  std::ostringstream out;
  out << "simulation " << (completed ? "completed" : "DIVERGED") << "\n";
  if (!completed) out << "  cause:                     " << message << "\n";
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
  std::snprintf(line, sizeof(line), "  stick-slip switches:       %lld\n",
                static_cast<long long>(stick_slip_switches));
  out << line;
  std::snprintf(line, sizeof(line), "  max constraint violation:  %.3g\n",
                max_constraint_violation);
  out << line;
  return out.str();
}

SimulationResult Simulate(const ArmModel& model, const CableInputs& inputs,
                          const SimulationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("simulation options", "", error);
  if (inputs.num_cables() != model.num_cables()) {
    ThrowInputError("cable inputs", "",
                    "has " + std::to_string(inputs.num_cables()) + " cables, the model has " +
                        std::to_string(model.num_cables()));
  }
  gsl_set_error_handler_off();
  const SolverConfig& solver = model.config().solver;
  const auto wall_start = Clock::now();
  auto wall_seconds = [&] {
    return std::chrono::duration<double>(Clock::now() - wall_start).count();
  };

  ArmDynamics dynamics(model, inputs);
  const std::size_t dim = dynamics.state_size();
  Eigen::VectorXd y = dynamics.InitialState();
  // dydt_in: derivative at (t, y) under the current modes (valid when
  // have_dydt_in); dydt_out: at the end of the step being tried.
  std::vector<double> y_try(dim), y_err(dim), dydt_in(dim), dydt_out(dim);
  std::vector<double> y_prev(dim), dydt_prev(dim);
  bool have_dydt_in = false;
  gsl_odeiv2_system system{RightHandSide, nullptr, dim, &dynamics};
  GslStepper gsl(dim, solver);
  SwitchDetector switches(model, &dynamics, solver);

  SimulationSummary summary;
  std::vector<double> time;
  std::vector<Observation> frames;
  Observation observation;
  double t = 0.0;
  double h = solver.initial_step_s;
  const double dt_out = 1.0 / solver.output_rate_hz;
  const long frames_total = static_cast<long>(std::floor(options.duration_s / dt_out + 1e-9)) + 1;
  double next_progress = options.progress_interval_s;
  SwitchDetector::Switches found;

  auto diverge = [&](const std::string& cause) {
    summary.completed = false;
    summary.message = cause + " at t = " + FormatTime(t);
  };
  // One RKF45 step of size dt from (t0, y0) with derivative dydt0 into y1 and
  // dydt1 (the last evaluation, so the hole reports are those of the end).
  auto try_step = [&](double t0, const double* y0, const double* dydt0, double dt, double* y1,
                      double* dydt1) {
    std::copy(y0, y0 + dim, y1);
    gsl_odeiv2_step_reset(gsl.step);
    return gsl_odeiv2_step_apply(gsl.step, t0, dt, y1, y_err.data(), dydt0, dydt1, &system);
  };
  // Switches nodes at (t, y) until no node needs to (a node that has just
  // stuck may at once need more friction than it can hold, and so on).
  auto settle_modes = [&]() {
    for (int pass = 0; pass < 8 && switches.Scan(t, y.data(), &found) && found.any(); ++pass) {
      summary.stick_slip_switches += switches.Apply(t, y.data(), found);
    }
    have_dydt_in = false;
  };

  // Consistent initial modes: nothing may need to switch at t = 0.
  settle_modes();
  dynamics.Observe(t, y.data(), &observation);
  AppendFrame(observation, t, &time, &frames);
  summary.max_constraint_violation = observation.constraint_violation;
  summary.completed = true;
  std::int64_t rejected = 0;
  // Switch events in a row that left time where it was: a guard against
  // stick-slip chatter that the trial-and-error rules do not resolve.
  int stalled_switch_events = 0;
  double last_switch_event_t = -1.0;
  constexpr int kMaxStalledSwitchEvents = 1000;

  for (long frame = 1; frame < frames_total && summary.completed; ++frame) {
    const double t_out = std::min(options.duration_s, frame * dt_out);
    // True while the dynamics' last evaluation is at (t, y) under the
    // current modes (the end of an accepted step): the frame reuses it.
    bool last_evaluation_current = false;
    while (t < t_out && summary.completed) {
      last_evaluation_current = false;
      if (!have_dydt_in) {
        if (!dynamics.Evaluate(t, y.data(), dydt_in.data())) {
          diverge(dynamics.failure());
          break;
        }
        have_dydt_in = true;
      }
      const double h_proposed = std::min(h, solver.max_step_s);
      double dt = h_proposed;
      // Land on the output time exactly; stretch rather than leave a sliver.
      const bool last = t + 1.01 * dt >= t_out;
      if (last) dt = t_out - t;
      if (try_step(t, y.data(), dydt_in.data(), dt, y_try.data(), dydt_out.data()) != GSL_SUCCESS) {
        // A trial that went too far can collapse an element: retry shorter.
        h = 0.5 * dt;
        ++rejected;
        if (h < solver.min_step_s) {
          diverge("step size collapsed to " + FormatTime(h) +
                  (dynamics.failure().empty() ? "" : " (" + dynamics.failure() + ")"));
        }
        continue;
      }
      double h_next = dt;
      if (gsl_odeiv2_control_hadjust(gsl.control, gsl.step, y_try.data(), y_err.data(),
                                     dydt_out.data(), &h_next) == GSL_ODEIV_HADJ_DEC) {
        h = h_next;
        ++rejected;
        if (h < solver.min_step_s) diverge("step size collapsed to " + FormatTime(h));
        continue;
      }
      // Accepted. A step shortened to land on t_out says nothing against the
      // longer step that was proposed.
      h = last ? std::max(h_proposed, h_next) : h_next;
      const double t0 = t;
      std::copy(y.data(), y.data() + dim, y_prev.begin());
      std::swap(dydt_prev, dydt_in);
      std::copy(y_try.begin(), y_try.end(), y.data());
      std::swap(dydt_in, dydt_out);
      t = last ? t_out : t0 + dt;
      ++summary.steps;
      if (options.progress && (summary.steps & 255) == 0 && wall_seconds() >= next_progress) {
        next_progress = wall_seconds() + options.progress_interval_s;
        SimulationProgress p{t,
                             options.duration_s,
                             wall_seconds(),
                             t / std::max(1e-9, wall_seconds()),
                             summary.steps,
                             summary.stick_slip_switches};
        options.progress(p);
      }
      // The last evaluation of the step was at (t, y): scan its reports.
      switches.Scan(t, y.data(), &found, false, nullptr, /*evaluate=*/false);
      if (found.located.empty()) {
        if (!found.flips.empty()) {
          switches.Apply(t, y.data(), found);  // direction flips only: not stick-slip switches
          have_dydt_in = false;
        } else {
          last_evaluation_current = true;
        }
        continue;
      }
      // A switch happened inside [t0, t]: locate it within
      // switch_time_tolerance_s by the Illinois method on the candidates'
      // switching functions, normalised and combined by their maximum (the
      // first node to switch decides). Trials restart single steps from the
      // last point known to need no switch.
      const std::vector<int> candidates = found.located;
      if (t0 - last_switch_event_t > solver.switch_time_tolerance_s) stalled_switch_events = 0;
      if (++stalled_switch_events > kMaxStalledSwitchEvents) {
        const auto& hole = dynamics.holes()[candidates.front()];
        diverge("stick-slip chatter of cable " + std::to_string(hole.cable + 1) + " hole node " +
                std::to_string(hole.node) + " (" + std::to_string(kMaxStalledSwitchEvents) +
                " switch events without time advancing)");
        break;
      }
      last_switch_event_t = t0;
      std::vector<double> scale(candidates.size());
      auto combined = [&](bool set_scale) {
        double g = -std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          const double value = switches.SwitchFunction(candidates[k]);
          if (set_scale) scale[k] = std::max(std::abs(value), 1e-300);
          g = std::max(g, value / scale[k]);
        }
        return g;
      };
      double gb = combined(true);
      double ta = t0, tb = t;
      std::vector<double> ya(y_prev), yb(y.data(), y.data() + dim), dydt_a(dydt_prev);
      std::vector<double> y_mid(dim), dydt_mid(dim);
      // g at t0 from the dynamics at (t0, y0); one evaluation per switch.
      if (!dynamics.Evaluate(ta, ya.data(), dydt_mid.data())) {
        diverge(dynamics.failure());
        break;
      }
      double ga = combined(false);
      if (ga >= 0.0) {
        tb = ta;  // already crossed (within the detection hysteresis) at t0
        yb = ya;
      }
      int side = 0;  // which end the last two trials kept (Illinois)
      while (tb - ta > solver.switch_time_tolerance_s) {
        double tm = ta + (tb - ta) * ga / (ga - gb);
        const double margin = 0.25 * solver.switch_time_tolerance_s;
        if (!(tm > ta + margin && tm < tb - margin)) tm = 0.5 * (ta + tb);
        if (try_step(ta, ya.data(), dydt_a.data(), tm - ta, y_mid.data(), dydt_mid.data()) !=
            GSL_SUCCESS) {
          break;
        }
        const double gm = combined(false);
        if (gm >= 0.0) {
          tb = tm;
          yb = y_mid;
          gb = gm;
          if (side == +1) ga *= 0.5;
          side = +1;
        } else {
          ta = tm;
          ya = y_mid;
          std::swap(dydt_a, dydt_mid);
          ga = gm;
          if (side == -1) gb *= 0.5;
          side = -1;
        }
      }
      t = tb;
      std::copy(yb.begin(), yb.end(), y.data());
      if (switches.Scan(t, y.data(), &found, /*locating=*/true, &candidates)) {
        summary.stick_slip_switches += switches.Apply(t, y.data(), found);
      }
      settle_modes();
    }
    if (!summary.completed) break;
    if (!y.allFinite()) {
      diverge("non-finite state");
      break;
    }
    dynamics.Observe(t, y.data(), &observation, !last_evaluation_current);
    summary.max_constraint_violation =
        std::max(summary.max_constraint_violation, observation.constraint_violation);
    if (observation.constraint_violation > solver.max_constraint_violation) {
      char text[128];
      std::snprintf(text, sizeof(text), "constraint violation %.3g above bound %.3g",
                    observation.constraint_violation, solver.max_constraint_violation);
      diverge(text);
      AppendFrame(observation, t, &time, &frames);
      break;
    }
    AppendFrame(observation, t, &time, &frames);
  }
  if (summary.completed) summary.message = "completed";

  summary.simulated_s = t;
  summary.wall_time_s = wall_seconds();
  summary.real_time_factor = summary.wall_time_s > 0 ? t / summary.wall_time_s : 0.0;
  summary.rejected_steps = rejected;
  summary.rhs_evaluations = dynamics.evaluations();

  SimulationResult result;
  result.run = BuildRunFile(model, time, frames);
  result.run.case_name = options.case_name;
  result.run.config_yaml = ToYaml(model.config());
  result.run.wall_time_s = summary.wall_time_s;
  result.run.steps = summary.steps;
  result.run.rejected_steps = summary.rejected_steps;
  result.run.rhs_evaluations = summary.rhs_evaluations;
  result.run.status =
      summary.completed ? datasets::RunStatus::kCompleted : datasets::RunStatus::kDiverged;
  result.run.status_message = summary.message;
  result.summary = summary;
  return result;
}

}  // namespace ccsrm::sim
