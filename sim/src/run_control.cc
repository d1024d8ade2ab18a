#include "run_control.h"

#include <algorithm>
#include <cstdio>

namespace ccsrm::sim::internal {

std::string FormatTime(double t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g s", t);
  return text;
}

RunControl::RunControl(const SimulationOptions& options) : options_(options) {}

double RunControl::WallSeconds() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

std::string RunControl::Check(double t, std::int64_t steps, std::int64_t switches,
                              bool read_clock) {
  if (options_.cancel != nullptr && options_.cancel->load(std::memory_order_relaxed)) {
    return "cancelled at t = " + FormatTime(t);
  }
  if (!read_clock) return "";
  const double wall = WallSeconds();
  if (options_.wall_time_budget_s > 0.0 && wall > options_.wall_time_budget_s) {
    char text[128];
    std::snprintf(text, sizeof(text), "wall-time budget of %.3g s used up at t = %s",
                  options_.wall_time_budget_s, FormatTime(t).c_str());
    return text;
  }
  if (options_.progress && wall >= next_progress_) {
    next_progress_ = wall + options_.progress_interval_s;
    options_.progress({t, options_.duration_s, wall, t / std::max(1e-9, wall), steps, switches});
  }
  return "";
}

SimulationResult FinishRun(const ArmModel& model, const RunControl& control, const RunTally& tally,
                           OutputSampler* sampler) {
  SimulationResult result;
  SimulationSummary& s = result.summary;
  s.status = tally.status;
  s.message = tally.status == SimulationStatus::kCompleted ? "completed" : tally.message;
  s.simulated_s = tally.simulated_s;
  s.wall_time_s = control.WallSeconds();
  s.real_time_factor = s.wall_time_s > 0 ? tally.simulated_s / s.wall_time_s : 0.0;
  s.steps = tally.steps;
  s.rejected_steps = tally.rejected_steps;
  s.rhs_evaluations = tally.evaluations;
  s.max_constraint_violation = sampler->max_constraint_violation();
  result.trajectory = sampler->Take();
  s.slack = SlackIntervalsOf(model, result.trajectory);
  return result;
}

}  // namespace ccsrm::sim::internal
