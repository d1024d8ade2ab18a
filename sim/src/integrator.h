#pragma once
// The explicit integrator of a run, behind a small interface: the step loop
// (simulator.cc) and the stick-slip event location (stick_slip.h) only try
// steps and ask whether their error is acceptable, so another embedded
// method can be put in here without touching either.
#include <memory>

#include "ccsrm/sim/config.h"

namespace ccsrm::sim::internal {

class ArmDynamics;

class Integrator {
 public:
  virtual ~Integrator() = default;

  // One trial step of dt from (t0, y0), whose derivative dydt0 is given.
  // Writes y1 and, unless dydt1 is null, the derivative at its end; the
  // dynamics' last evaluation is then at (t0 + dt, y1), so its hole reports
  // are the end's. With dydt1 null the end is not evaluated (one evaluation
  // of six fewer, which a step that will be rejected does not need).
  // False when an evaluation failed (e.g. a trial went so far that an
  // element collapsed): try a shorter step.
  virtual bool TryStep(double t0, const double* y0, const double* dydt0, double dt, double* y1,
                       double* dydt1) = 0;

  // After a successful TryStep of dt: true when its error estimate is within
  // the tolerances. *h_next is the step to try next (shorter when false).
  virtual bool ErrorAcceptable(const double* y1, double dt, double* h_next) = 0;
};

// GSL odeiv2's embedded Runge-Kutta 4(5) stepper of solver.stepper
// (Cash-Karp or Fehlberg) with GSL's standard step control and the solver's
// tolerances, scaled per state entry by ArmDynamics::ErrorScales.
std::unique_ptr<Integrator> MakeIntegrator(ArmDynamics* dynamics, const SolverConfig& solver);

}  // namespace ccsrm::sim::internal
