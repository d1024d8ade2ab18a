#pragma once
// The trial points and weights of a second-order finite difference that
// stays inside a parameter's bounds.
#include <array>
#include <nlohmann/json.hpp>
#include <optional>

#include "ccsrm/identify/difference.h"
#include "ccsrm/identify/runs.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::identify::internal {

struct DifferencePlan {
  DifferenceScheme scheme = DifferenceScheme::kCentral;
  std::array<double, 2> trial_values{};  // the two trial points
  // h f'(p) = (w_base f(p) + w[0] f(trial 0) + w[1] f(trial 1)) / 2, to
  // second order in h.
  double base_weight = 0.0;
  std::array<double, 2> trial_weights{};
};

// The plan for a step h > 0 at p inside [lower, upper]: central when p - h
// and p + h are inside, else forward when p + 2h is, else backward when
// p - 2h is; nothing when the interval is narrower than 2h on both sides.
std::optional<DifferencePlan> PlanDifference(double value, double step, double lower, double upper);

// The scale s of a parameter of value p: |p|, or when p is 0 the magnitude of
// its entry in scale_at_zero (0 when that is unset).
double ParameterScale(const sim::ParameterInfo& info, double value,
                      const std::optional<sim::ArmParameters>& scale_at_zero);

// A run's summary as JSON (status, message and counters).
nlohmann::json RunJson(const sim::SimulationSummary& summary);

// Root mean square of v (0 when empty).
double Rms(const std::vector<double>& v);

}  // namespace ccsrm::identify::internal
