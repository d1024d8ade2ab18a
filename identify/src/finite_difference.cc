#include "finite_difference.h"

#include <cmath>

namespace ccsrm::identify::internal {

std::optional<DifferencePlan> PlanDifference(double value, double step, double lower,
                                             double upper) {
  DifferencePlan plan;
  if (value - step >= lower && value + step <= upper) {
    plan.scheme = DifferenceScheme::kCentral;
    plan.trial_values = {value - step, value + step};
    plan.base_weight = 0.0;
    plan.trial_weights = {-1.0, 1.0};
    return plan;
  }
  // One-sided, second order: f(p + k h) = f + k h f' + k^2 h^2 f''/2 + ...
  // for k = 0, 1, 2 gives 2 h f' = -3 f(p) + 4 f(p + h) - f(p + 2h).
  if (value + 2.0 * step <= upper) {
    plan.scheme = DifferenceScheme::kForward;
    plan.trial_values = {value + step, value + 2.0 * step};
    plan.base_weight = -3.0;
    plan.trial_weights = {4.0, -1.0};
    return plan;
  }
  if (value - 2.0 * step >= lower) {
    plan.scheme = DifferenceScheme::kBackward;
    plan.trial_values = {value - step, value - 2.0 * step};
    plan.base_weight = 3.0;
    plan.trial_weights = {-4.0, 1.0};
    return plan;
  }
  return std::nullopt;
}

double ParameterScale(const sim::ParameterInfo& info, double value,
                      const std::optional<sim::ArmParameters>& scale_at_zero) {
  if (value != 0.0) return std::abs(value);
  return scale_at_zero ? std::abs(sim::GetParameter(*scale_at_zero, info.name)) : 0.0;
}

nlohmann::json RunJson(const sim::SimulationSummary& s) {
  return {{"status", sim::SimulationStatusName(s.status)},
          {"message", s.message},
          {"simulated_s", s.simulated_s},
          {"wall_time_s", s.wall_time_s},
          {"steps", s.steps},
          {"rejected_steps", s.rejected_steps},
          {"rhs_evaluations", s.rhs_evaluations},
          {"stick_slip_switches", s.stick_slip_switches},
          {"max_constraint_violation", s.max_constraint_violation}};
}

double Rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / static_cast<double>(v.size()));
}

}  // namespace ccsrm::identify::internal
