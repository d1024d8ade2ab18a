#include "integrator.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
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
        unused_rate_(dim_, 0.0),
        dynamics_(dynamics),
        absolute_tolerance_(solver.absolute_tolerance),
        relative_tolerance_(solver.relative_tolerance),
        trace_(std::getenv("CCSRM_TRACE_STEPS") != nullptr) {
    UseGslErrorCodes();
    const gsl_odeiv2_step_type* type = solver.stepper == RungeKuttaStepper::kCashKarp
                                           ? gsl_odeiv2_step_rkck
                                           : gsl_odeiv2_step_rkf45;
    step_ = gsl_odeiv2_step_alloc(type, dim_);
    scale_ = dynamics->ErrorScales();
    control_ = gsl_odeiv2_control_scaled_new(solver.absolute_tolerance, solver.relative_tolerance,
                                             1.0, 0.0, scale_.data(), dim_);
  }
  ~GslIntegrator() override {
    for (const auto& [kind, count] : limiting_) {
      std::fprintf(stderr, "steps limited by %-20s %8lld accepted %8lld rejected\n", kind.c_str(),
                   count.first, count.second);
    }
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
    const bool acceptable =
        gsl_odeiv2_control_hadjust(control_, step_, y1, error_.data(), unused_rate_.data(),
                                   h_next) != GSL_ODEIV_HADJ_DEC;
    if (trace_) CountLimitingEntry(y1, acceptable);
    return acceptable;
  }

 private:
  // Which kind of state entry had the largest error against its bound (the
  // control's own measure), counted over accepted and rejected steps and
  // printed at the end: what sets the steps.
  void CountLimitingEntry(const double* y1, bool accepted) {
    int worst = 0;
    double worst_ratio = -1.0;
    for (std::size_t i = 0; i < dim_; ++i) {
      const double bound = absolute_tolerance_ * scale_[i] + relative_tolerance_ * std::abs(y1[i]);
      const double ratio = std::abs(error_[i]) / bound;
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = static_cast<int>(i);
      }
    }
    auto& count = limiting_[dynamics_->StateEntryKind(worst)];
    ++(accepted ? count.first : count.second);
  }

  std::size_t dim_;
  gsl_odeiv2_system system_;
  std::vector<double> error_;
  std::vector<double> unused_rate_;
  gsl_odeiv2_step* step_ = nullptr;
  gsl_odeiv2_control* control_ = nullptr;
  std::vector<double> scale_;
  ArmDynamics* dynamics_;
  double absolute_tolerance_;
  double relative_tolerance_;
  // CCSRM_TRACE_STEPS=1 prints, at the end of a run, how many steps each
  // kind of state entry limited.
  bool trace_;
  std::map<std::string, std::pair<long long, long long>> limiting_;
};

}  // namespace

std::unique_ptr<Integrator> MakeIntegrator(ArmDynamics* dynamics, const SolverConfig& solver) {
  return std::make_unique<GslIntegrator>(dynamics, solver);
}

}  // namespace ccsrm::sim::internal
