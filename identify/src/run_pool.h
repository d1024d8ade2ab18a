#pragma once
// Many runs of one model with different parameters, on a pool of threads.
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/identify/sensitivity.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify::internal {

// Calls task(k) for every k in [0, count) on `threads` threads (the calling
// thread is one of them), then finished(k, n) under a lock, n counting the
// tasks done so far. After the first exception no new task starts; it is
// rethrown once every thread has stopped. Each task must write only its own
// slot, so results do not depend on the number of threads.
void ForEachInParallel(std::size_t count, int threads, const std::function<void(std::size_t)>& task,
                       const std::function<void(std::size_t, std::size_t)>& finished);

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

// One run of a backend's request on experiment e (every backend's runs go
// through here, so they agree to the bit whichever backend ran them).
RunResult RunExperiment(const Experiment& e, const identify::RunRequest& request);

}  // namespace ccsrm::identify::internal
