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

}  // namespace ccsrm::sim::internal
