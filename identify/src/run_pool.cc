#include "run_pool.h"

#include "parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

namespace ccsrm::identify::internal {
namespace {

// RunAll's runs as a backend batch (FrameExperiment: experiment 0, every
// frame), converted as SampledJointAnglesDeg converts a trajectory's: the
// same expression on the same doubles, so the same outcome to the bit.
std::vector<RunOutcome> RunOnBackend(const std::vector<RunRequest>& requests,
                                     const ProgressCallback& progress, SimulationBackend* backend) {
  std::vector<identify::RunRequest> batch(requests.size());
  for (std::size_t k = 0; k < requests.size(); ++k) {
    batch[k].parameters = requests[k].parameters;
    batch[k].every_frame = true;
  }
  RunFinishedCallback finished;
  if (progress) {
    finished = [&](std::size_t done, std::size_t total, const RunResult& r) {
      progress({done, total, "", r.summary});
    };
  }
  std::vector<RunResult> results = backend->RunBatch(batch, finished);
  std::vector<RunOutcome> outcomes(requests.size());
  for (std::size_t k = 0; k < results.size(); ++k) {
    const Eigen::MatrixXd& theta = results[k].simulated;
    std::vector<double>& angles = outcomes[k].angles_deg;
    angles.reserve(static_cast<std::size_t>(theta.size()));
    for (Eigen::Index f = 0; f < theta.rows(); ++f) {
      for (Eigen::Index c = 0; c < theta.cols(); ++c) angles.push_back(theta(f, c) * 180.0 / M_PI);
    }
    outcomes[k].summary = std::move(results[k].summary);
  }
  return outcomes;
}

}  // namespace

std::vector<RunOutcome> RunAll(const sim::ArmModel& model, const sim::CableInputs& inputs,
                               const sim::SimulationOptions& simulation,
                               const std::vector<RunRequest>& requests, int threads,
                               const ProgressCallback& progress, SimulationBackend* backend) {
  if (backend != nullptr) return RunOnBackend(requests, progress, backend);
  sim::SimulationOptions options = simulation;
  options.progress = nullptr;  // it would be called from several threads at once
  std::vector<RunOutcome> outcomes(requests.size());
  ForEachInParallel(
      requests.size(), threads,
      [&](std::size_t k) {
        sim::SimulationResult result =
            sim::Simulate(model, requests[k].parameters, inputs, options);
        outcomes[k].angles_deg = SampledJointAnglesDeg(result.trajectory);
        outcomes[k].summary = std::move(result.summary);
      },
      [&](std::size_t k, std::size_t done) {
        if (progress) progress({done, requests.size(), requests[k].label, outcomes[k].summary});
      });
  return outcomes;
}

}  // namespace ccsrm::identify::internal
