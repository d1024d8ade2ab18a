#pragma once
// Many runs of one model with different parameters, on a pool of threads.
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/identify/runs.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify::internal {

struct RunRequest {
  sim::ArmParameters parameters;
  std::string label;  // for progress
};

struct RunOutcome {
  sim::SimulationSummary summary;
  std::vector<double> angles_deg;  // SampledJointAnglesDeg of the trajectory
};

// One Simulate per request, `threads` at a time (threads >= 1), or on
// `backend` (not null: one batch of every_frame runs of its experiment 0,
// FrameExperiment of model, inputs and simulation; progress without labels).
// Outcome k belongs to requests[k] whatever the number of threads or ranks:
// each task writes only its own slot. Only the sampled angles of each
// trajectory are kept. simulation.progress is not called. An exception of a
// run (InputError for invalid input) is rethrown here once every thread has
// stopped.
std::vector<RunOutcome> RunAll(const sim::ArmModel& model, const sim::CableInputs& inputs,
                               const sim::SimulationOptions& simulation,
                               const std::vector<RunRequest>& requests, int threads,
                               const ProgressCallback& progress, SimulationBackend* backend);

}  // namespace ccsrm::identify::internal
