#pragma once
// What every batch of runs in identify/ shares: the progress of a run, the
// number of threads, the parameters by name, and a run of the derivative
// check as a backend's experiment. Below the instruments (sensitivity.h),
// the fits (identification.h) and the design (design.h), which all use it.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

// Reported after every finished run, from the thread that ran it, one call
// at a time (calls are serialised by a lock).
struct RunProgress {
  std::size_t finished = 0;  // runs finished so far, this one included
  std::size_t total = 0;
  std::string label;  // which run, e.g. "mu = 0.2121 (step 0.01)"
  sim::SimulationSummary summary;
};
using ProgressCallback = std::function<void(const RunProgress&)>;

// The sampled angles of a trajectory [deg]: every frame, every joint, θx
// then θy; index (frame * joints + joint) * 2 + axis.
std::vector<double> SampledJointAnglesDeg(const sim::Trajectory& trajectory);

// std::thread::hardware_concurrency(), or 1 when it is unknown.
int DefaultThreads();

// The most runs a batch takes at a time: beyond a machine's cores they only
// queue, and a slip of the keyboard (100000) would otherwise be refused only
// by the memory of that many simulations.
inline constexpr int kMaxThreads = 1024;
// "" when `threads` is in 1..kMaxThreads, else "threads: must be in
// 1..1024" (the callers add what was found where they know it).
std::string ThreadCountProblem(int threads);

// The names of every entry of sim::Parameters(), in table order.
std::vector<std::string> AllParameterNames();

// The run (model, inputs, simulation) of a DerivativeCheck or a
// ParameterSweep as a backend's experiment, so that its runs can go to the
// ranks of an MPI job: simulated for simulation.duration_s, sampled at
// simulation.sample_times (empty: the solver's output grid) with
// simulation.solver, its runs requested every_frame. A backend's run of it
// calls Simulate with the same options as the thread pool, so it gives the
// same angles to the bit. `name` stands for the run in messages and in the
// check that every rank built the same. The experiment refers to model and
// inputs without owning them: they must outlive it. Throws InputError for
// options a backend cannot carry over (cancel, a wall time budget).
Experiment FrameExperiment(const std::string& name, const sim::ArmModel& model,
                           const sim::CableInputs& inputs,
                           const sim::SimulationOptions& simulation);

}  // namespace ccsrm::identify
