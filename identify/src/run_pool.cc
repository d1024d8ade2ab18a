#include "run_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

namespace ccsrm::identify::internal {

std::vector<RunOutcome> RunAll(const sim::ArmModel& model, const sim::CableInputs& inputs,
                               const sim::SimulationOptions& simulation,
                               const std::vector<RunRequest>& requests, int threads,
                               const ProgressCallback& progress) {
  sim::SimulationOptions options = simulation;
  options.progress = nullptr;  // it would be called from several threads at once

  std::vector<RunOutcome> outcomes(requests.size());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;  // guards first_error, finished and the progress callback
  std::exception_ptr first_error;
  std::size_t finished = 0;

  const auto work = [&] {
    for (std::size_t k = next++; k < requests.size() && !failed; k = next++) {
      try {
        sim::SimulationResult result =
            sim::Simulate(model, requests[k].parameters, inputs, options);
        outcomes[k].angles_deg = SampledJointAnglesDeg(result.trajectory);
        outcomes[k].summary = std::move(result.summary);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
        return;
      }
      const std::lock_guard<std::mutex> lock(mutex);
      ++finished;
      if (progress) progress({finished, requests.size(), requests[k].label, outcomes[k].summary});
    }
  };

  const std::size_t count =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)), requests.size());
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < count; ++t) pool.emplace_back(work);
  work();  // the calling thread is one of the workers
  for (std::thread& t : pool) t.join();
  if (first_error) std::rethrow_exception(first_error);
  return outcomes;
}

}  // namespace ccsrm::identify::internal
