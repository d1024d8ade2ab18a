#include "ccsrm/identify/simulation_backend.h"

#include <algorithm>
#include <limits>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "parallel.h"
#include "run_experiment.h"

namespace ccsrm::identify {

namespace {

class ThreadBackend final : public SimulationBackend {
 public:
  ThreadBackend(const std::vector<Experiment>* experiments, int threads)
      : experiments_(experiments), threads_(std::max(threads, 1)) {}

  int parallelism() const override { return threads_; }

  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    for (const RunRequest& r : requests) CCSRM_CHECK(r.experiment < experiments_->size());
    std::vector<RunResult> results(requests.size());
    internal::ForEachInParallel(
        requests.size(), threads_,
        [&](std::size_t k) {
          results[k] =
              internal::RunExperiment((*experiments_)[requests[k].experiment], requests[k]);
        },
        [&](std::size_t k, std::size_t done) {
          if (on_finished) on_finished(done, requests.size(), results[k]);
        });
    return results;
  }

 private:
  const std::vector<Experiment>* experiments_;
  int threads_;
};

}  // namespace

std::unique_ptr<SimulationBackend> MakeThreadBackend(const std::vector<Experiment>* experiments,
                                                     int threads) {
  return std::make_unique<ThreadBackend>(experiments, threads);
}

}  // namespace ccsrm::identify
