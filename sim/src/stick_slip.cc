#include "stick_slip.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "dynamics.h"
#include "integrator.h"

namespace ccsrm::sim::internal {
namespace {

std::string FormatTime(double t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g s", t);
  return text;
}

// Stick-slip switching of the hole nodes (paper section 2.3, trial and
// error). A stuck node slips once the friction its constraint needs
// exceeds f_max (eq. 10) by the force tolerance; a slipping node sticks once
// its slip reverses past v_eps. Both are located in time. Where even f_max
// is below the force tolerance (a cable running nearly straight through the
// hole) the dynamics leave friction out, so such a node never sticks: a
// stuck one is released and a slipping one's direction just follows its
// slip speed, without an event.
//
// A release that fails at once (the node sticks again within
// kFailedReleaseWindow of being released, before it has moved) means that
// neither slip direction is consistent with a load so close to f_max: trial
// and error then keeps the node stuck, and it is not released again until
// the friction it needs exceeds f_max by the force tolerance more than it
// did at that failed release. Without this, such a node switches back and
// forth at one instant forever.
class TrialAndError : public StickSlipTreatment {
 public:
  TrialAndError(const ArmModel& model, ArmDynamics* dynamics, Integrator* integrator,
                const SolverConfig& solver)
      : model_(model),
        dynamics_(dynamics),
        integrator_(integrator),
        solver_(solver),
        dim_(dynamics->state_size()),
        scratch_(dim_),
        release_time_(dynamics->hole_modes().size(), -1.0),
        release_excess_(dynamics->hole_modes().size(), 0.0),
        pinned_excess_(dynamics->hole_modes().size(), 0.0) {}

  bool Settle(double t, const double* y) override {
    Switches found;
    // A node that has just stuck may at once need more friction than it can
    // hold, and so on: a few passes.
    for (int pass = 0; pass < 8; ++pass) {
      if (!Scan(t, y, &found)) return false;
      if (!found.any()) break;
      switches_ += Apply(t, y, found);
    }
    return true;
  }

  Outcome AfterStep(double t0, const double* y0, const double* dydt0, double* t,
                    double* y) override {
    Switches found;
    // The last evaluation of the step was at (t, y): scan its reports.
    Scan(*t, y, &found, false, nullptr, /*evaluate=*/false);
    if (found.located.empty()) {
      if (found.immediate.empty()) return Outcome::kNoSwitch;
      Apply(*t, y, found);  // no event to locate: not counted as stick-slip switches
      return Outcome::kSwitched;
    }
    // A switch happened inside [t0, t]: locate it.
    const std::vector<int> candidates = found.located;
    if (t0 - last_event_t_ > solver_.switch_time_tolerance_s) stalled_events_ = 0;
    if (++stalled_events_ > kMaxStalledEvents) {
      const auto& hole = dynamics_->holes()[candidates.front()];
      failure_ = "stick-slip chatter of cable " + std::to_string(hole.cable + 1) + " hole node " +
                 std::to_string(hole.node) + " (" + std::to_string(kMaxStalledEvents) +
                 " switch events without time advancing) at t = " + FormatTime(t0);
      return Outcome::kFailed;
    }
    last_event_t_ = t0;
    if (!Locate(candidates, t0, y0, dydt0, t, y)) return Outcome::kFailed;
    if (Scan(*t, y, &found, /*locating=*/true, &candidates)) switches_ += Apply(*t, y, found);
    if (!Settle(*t, y)) return Outcome::kFailed;
    return Outcome::kSwitched;
  }

  std::int64_t switches() const override { return switches_; }
  std::int64_t failed_releases() const override { return failed_releases_; }
  double largest_threshold_raise_n() const override { return largest_raise_n_; }
  const std::string& failure() const override { return failure_; }

 private:
  // A failed release is one undone within this many switch time tolerances.
  static constexpr double kFailedReleaseWindow = 2.0;
  // Switch events in a row that leave time where it was: a guard against
  // stick-slip chatter that the trial-and-error rules do not resolve.
  static constexpr int kMaxStalledEvents = 1000;

  struct Switches {
    std::vector<int> located;    // must be located in time, then switched
    std::vector<int> immediate;  // negligible friction: switch now, no event
    bool any() const { return !located.empty() || !immediate.empty(); }
  };

  // Returns false if the evaluation at (t, y) failed. A slip reversal is
  // detected past v_eps (hysteresis against noise) but, with `locating`,
  // located at the zero crossing of the slip speed, so that the node sticks
  // with no speed left for the stick constraint to take out at once.
  // `only`, when given, restricts the scan to those nodes (the ones whose
  // switch is being located). With `evaluate` false the reports of the
  // dynamics' last evaluation are used; the caller guarantees it was at
  // (t, y) with the current modes.
  bool Scan(double t, const double* y, Switches* out, bool locating = false,
            const std::vector<int>* only = nullptr, bool evaluate = true) {
    out->located.clear();
    out->immediate.clear();
    if (!dynamics_->has_stick_slip()) return true;
    if (evaluate && !dynamics_->Evaluate(t, y, scratch_.data())) {
      failure_ = dynamics_->failure() + " at t = " + FormatTime(t);
      return false;
    }
    const auto& modes = dynamics_->hole_modes();
    const auto& reports = dynamics_->hole_reports();
    const double f_tol = solver_.stick_force_tolerance_n;
    const int count =
        only != nullptr ? static_cast<int>(only->size()) : static_cast<int>(modes.size());
    for (int k = 0; k < count; ++k) {
      const int h = only != nullptr ? (*only)[k] : k;
      const HoleReport& r = reports[h];
      const bool negligible = r.friction_limit < f_tol;
      if (modes[h] == HoleMode::kStuck) {
        if (negligible) {
          out->immediate.push_back(h);
        } else if (std::abs(r.required_friction) > ReleaseThreshold(h)) {
          out->located.push_back(h);
        }
      } else {
        const double sigma = modes[h] == HoleMode::kSlipUp ? 1.0 : -1.0;
        const double threshold = locating ? 0.0 : solver_.stick_velocity_tolerance_mps;
        if (sigma * r.s_dot < -threshold) (negligible ? out->immediate : out->located).push_back(h);
      }
    }
    return true;
  }

  // The switching function of hole h at the dynamics' last evaluation,
  // positive once the node must switch and crossing zero where it does: for
  // a stuck node the excess of required friction over f_max (+ tolerance)
  // [N], for a slipping node its slip speed against its friction direction
  // [m/s].
  double SwitchFunction(int h) const {
    const HoleReport& r = dynamics_->hole_reports()[h];
    const HoleMode mode = dynamics_->hole_modes()[h];
    if (mode == HoleMode::kStuck) return std::abs(r.required_friction) - ReleaseThreshold(h);
    return mode == HoleMode::kSlipUp ? -r.s_dot : r.s_dot;
  }

  // Applies the switches found by the last Scan at (t, y); returns how many
  // stick-slip switches (not immediate ones) it made.
  std::int64_t Apply(double t, const double* y, const Switches& switches) {
    auto& modes = dynamics_->hole_modes();
    // Reports of the Scan, before the trials below overwrite them.
    const std::vector<HoleReport> reports = dynamics_->hole_reports();
    for (int h : switches.immediate) {
      if (modes[h] == HoleMode::kStuck) {
        const HoleReport& r = reports[h];
        const bool moving = std::abs(r.s_dot) > solver_.stick_velocity_tolerance_mps;
        const bool up = moving ? r.s_dot > 0.0 : r.required_friction < 0.0;
        modes[h] = up ? HoleMode::kSlipUp : HoleMode::kSlipDown;
      } else {
        modes[h] = modes[h] == HoleMode::kSlipUp ? HoleMode::kSlipDown : HoleMode::kSlipUp;
      }
    }
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
          ++failed_releases_;
          largest_raise_n_ = std::max(largest_raise_n_, pinned_excess_[h]);
        }
      }
    }
    return static_cast<std::int64_t>(switches.located.size());
  }

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

  // Locates the first switch of `candidates` inside [t0, *t] within
  // switch_time_tolerance_s by the Illinois method on their switching
  // functions, normalised and combined by their maximum (the first node to
  // switch decides). Trials restart single steps from the last point known
  // to need no switch. Leaves (*t, y) at the switch.
  bool Locate(const std::vector<int>& candidates, double t0, const double* y0, const double* dydt0,
              double* t, double* y) {
    std::vector<double> scale(candidates.size());
    auto combined = [&](bool set_scale) {
      double g = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < candidates.size(); ++k) {
        const double value = SwitchFunction(candidates[k]);
        if (set_scale) scale[k] = std::max(std::abs(value), 1e-300);
        g = std::max(g, value / scale[k]);
      }
      return g;
    };
    double gb = combined(true);
    double ta = t0, tb = *t;
    std::vector<double> ya(y0, y0 + dim_), yb(y, y + dim_), dydt_a(dydt0, dydt0 + dim_);
    std::vector<double> y_mid(dim_), dydt_mid(dim_);
    // g at t0 from the dynamics at (t0, y0); one evaluation per switch.
    if (!dynamics_->Evaluate(ta, ya.data(), dydt_mid.data())) {
      failure_ = dynamics_->failure() + " at t = " + FormatTime(ta);
      return false;
    }
    double ga = combined(false);
    if (ga >= 0.0) {
      tb = ta;  // already crossed (within the detection hysteresis) at t0
      yb = ya;
    }
    int side = 0;  // which end the last two trials kept (Illinois)
    while (tb - ta > solver_.switch_time_tolerance_s) {
      double tm = ta + (tb - ta) * ga / (ga - gb);
      const double margin = 0.25 * solver_.switch_time_tolerance_s;
      if (!(tm > ta + margin && tm < tb - margin)) tm = 0.5 * (ta + tb);
      if (!integrator_->TryStep(ta, ya.data(), dydt_a.data(), tm - ta, y_mid.data(),
                                dydt_mid.data())) {
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
    *t = tb;
    std::copy(yb.begin(), yb.end(), y);
    return true;
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
  Integrator* integrator_;
  const SolverConfig& solver_;
  const std::size_t dim_;
  std::vector<double> scratch_;
  std::int64_t switches_ = 0;
  std::int64_t failed_releases_ = 0;
  double largest_raise_n_ = 0.0;
  std::string failure_;
  int stalled_events_ = 0;
  double last_event_t_ = -1.0;
  // Per hole: when it was last released (-1: never), by how much the friction
  // it needed then exceeded f_max [N], and the raised excess a release needs
  // after a failed one (0: the force tolerance applies).
  std::vector<double> release_time_;
  std::vector<double> release_excess_;
  std::vector<double> pinned_excess_;
  // CCSRM_TRACE_SWITCHES=1 prints every stick-slip switch on stderr.
  std::FILE* trace_ = std::getenv("CCSRM_TRACE_SWITCHES") != nullptr ? stderr : nullptr;
};

}  // namespace

std::unique_ptr<StickSlipTreatment> MakeTrialAndErrorStickSlip(const ArmModel& model,
                                                               ArmDynamics* dynamics,
                                                               Integrator* integrator,
                                                               const SolverConfig& solver) {
  return std::make_unique<TrialAndError>(model, dynamics, integrator, solver);
}

}  // namespace ccsrm::sim::internal
