#pragma once
// Forward dynamics of the arm over a protocol: explicit embedded Runge-Kutta
// 4(5) (GSL odeiv2 rkf45) with step control, stick-slip switches of the
// driving-cable hole nodes located in time by bisection, and the outputs of
// SPEC 4 recorded at a fixed rate. Thread-compatible: runs on one ArmModel
// may go in parallel threads, each with its own Simulate call.
#include <cstdint>
#include <functional>
#include <string>

#include "ccsrm/datasets/run_file.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim {

// Progress of a long run, reported about once per `progress_interval_s`.
struct SimulationProgress {
  double simulated_s = 0.0;
  double duration_s = 0.0;
  double wall_time_s = 0.0;
  double real_time_factor = 0.0;  // simulated seconds per wall second
  std::int64_t steps = 0;
  std::int64_t stick_slip_switches = 0;
};

struct SimulationOptions {
  // Simulated time [s]; the run starts at t = 0.
  double duration_s = 48.0;
  // Written to the run file's `case` attribute: "1".."4" or "custom".
  std::string case_name = "custom";
  // Called from the simulating thread; may be empty.
  std::function<void(const SimulationProgress&)> progress;
  double progress_interval_s = 1.0;  // wall seconds between progress calls

  bool IsValid(std::string* error) const;
};

struct SimulationSummary {
  bool completed = false;    // false: diverged (see message)
  std::string message;       // "completed", or the cause with its time
  double simulated_s = 0.0;  // time reached
  double wall_time_s = 0.0;
  double real_time_factor = 0.0;  // simulated / wall
  std::int64_t steps = 0;         // accepted steps
  std::int64_t rejected_steps = 0;
  std::int64_t rhs_evaluations = 0;
  std::int64_t stick_slip_switches = 0;
  double max_constraint_violation = 0.0;  // largest |Phi| over the output frames

  // One line; and the one-screen summary of SPEC 3.
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct SimulationResult {
  datasets::RunFile run;  // every output frame written so far (also on divergence)
  SimulationSummary summary;
};

// Simulates the arm driven by `inputs` from the straight, pre-tensioned
// state at rest. A divergence (non-finite state, constraint violation above
// solver.max_constraint_violation, a step below solver.min_step_s) ends the
// run early with summary.completed = false; it is not thrown.
// Throws InputError only for invalid options.
SimulationResult Simulate(const ArmModel& model, const CableInputs& inputs,
                          const SimulationOptions& options);

}  // namespace ccsrm::sim
