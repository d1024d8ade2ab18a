#pragma once
// What may stop a run between its steps, and its progress reports: shared
// by the step loop (simulator.cc) and the quasi-static replay
// (quasi_static.cc).
#include <chrono>
#include <cstdint>
#include <string>

#include "ccsrm/sim/simulator.h"
#include "output_sampler.h"

namespace ccsrm::sim::internal {

// "1.25 s": a time in messages.
std::string FormatTime(double t);

class RunControl {
 public:
  // `options` must outlive this object; the wall clock starts here.
  explicit RunControl(const SimulationOptions& options);

  double WallSeconds() const;

  // After a step that reached t: "" to go on, or why the run stops
  // (options.cancel set, or the wall-time budget used up), with the
  // progress report made when one is due. Without `read_clock` only the
  // cancellation is looked at (a loop of cheap steps reads the clock on
  // some of them).
  std::string Check(double t, std::int64_t steps, std::int64_t switches, bool read_clock = true);

 private:
  using Clock = std::chrono::steady_clock;
  const SimulationOptions& options_;
  const Clock::time_point start_ = Clock::now();
  double next_progress_ = 0.0;
};

// How a run ended and what it did.
struct RunTally {
  SimulationStatus status = SimulationStatus::kCompleted;
  std::string message;  // the cause, when it did not complete
  double simulated_s = 0.0;
  std::int64_t steps = 0, rejected_steps = 0, evaluations = 0;
};

// A run's result: its frames (taken from `sampler`) and the summary of
// `tally` with the wall time, the largest constraint violation and where a
// cable went slack.
SimulationResult FinishRun(const ArmModel& model, const RunControl& control, const RunTally& tally,
                           OutputSampler* sampler);

}  // namespace ccsrm::sim::internal
