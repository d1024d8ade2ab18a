#include "integrator.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <vector>

#include "ccsrm/common/gsl_errors.h"
#include "dynamics.h"

namespace ccsrm::sim::internal {
namespace {

int RightHandSide(double t, const double y[], double dydt[], void* params) {
  auto* dynamics = static_cast<ArmDynamics*>(params);
  // GSL_FAILURE (not GSL_EBADFUNC) lets the caller retry with a smaller
  // step: a trial step that went too far can collapse an element.
  return dynamics->Evaluate(t, y, dydt) ? GSL_SUCCESS : GSL_FAILURE;
}

// GSL's stepper and step-size control. The step loop is ours rather than
// gsl_odeiv2_evolve_apply: evolve evaluates the derivative at the start of
// every step although the stepper already computed it at the end of the
// previous one, and the hole reports of that end-of-step evaluation are what
// the stick-slip scan needs (6 evaluations per accepted step instead of 7 or
// 8, and 5 per rejected one: simulator.cc evaluates the end only once the
// error is accepted).
class GslIntegrator : public Integrator {
 public:
  GslIntegrator(ArmDynamics* dynamics, const SolverConfig& solver)
      : dim_(dynamics->state_size()),
        system_{RightHandSide, nullptr, dim_, dynamics},
        error_(dim_),
        unused_rate_(dim_, 0.0) {
    UseGslErrorCodes();
    const gsl_odeiv2_step_type* type = solver.stepper == RungeKuttaStepper::kCashKarp
                                           ? gsl_odeiv2_step_rkck
                                           : gsl_odeiv2_step_rkf45;
    step_ = gsl_odeiv2_step_alloc(type, dim_);
    const std::vector<double> scale = dynamics->ErrorScales();
    control_ = gsl_odeiv2_control_scaled_new(solver.absolute_tolerance, solver.relative_tolerance,
                                             1.0, 0.0, scale.data(), dim_);
  }
  ~GslIntegrator() override {
    gsl_odeiv2_control_free(control_);
    gsl_odeiv2_step_free(step_);
  }
  GslIntegrator(const GslIntegrator&) = delete;
  GslIntegrator& operator=(const GslIntegrator&) = delete;

  bool TryStep(double t0, const double* y0, const double* dydt0, double dt, double* y1,
               double* dydt1) override {
    std::copy(y0, y0 + dim_, y1);
    gsl_odeiv2_step_reset(step_);
    return gsl_odeiv2_step_apply(step_, t0, dt, y1, error_.data(), dydt0, dydt1, &system_) ==
           GSL_SUCCESS;
  }

  // The control weighs the derivative by a_dydt = 0, so a zero vector
  // stands in for it (an end derivative is not always evaluated).
  bool ErrorAcceptable(const double* y1, double dt, double* h_next) override {
    *h_next = dt;
    return gsl_odeiv2_control_hadjust(control_, step_, y1, error_.data(), unused_rate_.data(),
                                      h_next) != GSL_ODEIV_HADJ_DEC;
  }

 private:
  std::size_t dim_;
  gsl_odeiv2_system system_;
  std::vector<double> error_;
  std::vector<double> unused_rate_;
  gsl_odeiv2_step* step_ = nullptr;
  gsl_odeiv2_control* control_ = nullptr;
};

}  // namespace

std::unique_ptr<Integrator> MakeIntegrator(ArmDynamics* dynamics, const SolverConfig& solver) {
  return std::make_unique<GslIntegrator>(dynamics, solver);
}

}  // namespace ccsrm::sim::internal
