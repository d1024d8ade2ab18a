#pragma once
// How the hole nodes of the driving cables switch between stick and slip
// during a run, behind a small interface: the step loop (simulator.cc) calls
// Settle once and AfterStep after every accepted step, so another treatment
// (e.g. event-capturing time stepping) can be put in without touching it.
#include <cstdint>
#include <memory>
#include <string>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::sim::internal {

class ArmDynamics;
class Integrator;

class StickSlipTreatment {
 public:
  virtual ~StickSlipTreatment() = default;

  // Makes the modes consistent at (t, y): switches nodes until none needs
  // to. False when an evaluation failed (reason in failure()).
  virtual bool Settle(double t, const double* y) = 0;

  enum class Outcome {
    kNoSwitch,  // the modes stand; the dynamics' last evaluation (the step's end) is current
    kSwitched,  // modes changed at *t (moved back to the located switch): evaluate again
    kFailed,    // the run cannot go on: failure() says why
  };
  // After an accepted step from (t0, y0), whose derivative was dydt0, to
  // (*t, y), where the dynamics evaluated last. May move *t and y back to
  // the time of the first switch inside the step.
  virtual Outcome AfterStep(double t0, const double* y0, const double* dydt0, double* t,
                            double* y) = 0;

  virtual std::int64_t switches() const = 0;  // stick-slip switches so far
  // Releases undone at once, after which a node's release threshold was
  // raised (the failed-release rule, docs/model-notes.md row 16), and the
  // largest such raise above f_max [N]. 0 where there is no such rule.
  virtual std::int64_t failed_releases() const = 0;
  virtual double largest_threshold_raise_n() const = 0;
  virtual const std::string& failure() const = 0;
};

// The paper's trial and error (section 2.3), with switches located in time
// by the Illinois method to solver.switch_time_tolerance_s. Does nothing
// when solver.stick_slip is off.
std::unique_ptr<StickSlipTreatment> MakeTrialAndErrorStickSlip(const ArmModel& model,
                                                               ArmDynamics* dynamics,
                                                               Integrator* integrator,
                                                               const SolverConfig& solver);

}  // namespace ccsrm::sim::internal
