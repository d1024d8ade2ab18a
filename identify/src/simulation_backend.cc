#include "ccsrm/identify/simulation_backend.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"

namespace ccsrm::identify {
namespace {

RunResult RunOne(const Experiment& e, const RunRequest& request) {
  sim::SimulationOptions options;
  options.duration_s = e.duration_s();
  options.sample_times = e.sample_time_s;
  options.solver = e.config.solver;
  sim::SimulationResult result = sim::Simulate(*e.model, request.parameters, *e.inputs, options);

  RunResult out;
  out.angles_rad = Eigen::MatrixXd::Constant(e.measured_rad.rows(), e.measured_rad.cols(),
                                             std::numeric_limits<double>::quiet_NaN());
  const std::size_t frames =
      std::min(result.trajectory.size(), static_cast<std::size_t>(e.measured_rad.rows()));
  for (std::size_t f = 0; f < frames; ++f) {
    // What motion capture records: measurement effects (mocap_offset) included.
    const std::vector<Eigen::Vector2d> recorded =
        sim::RecordedJointAngles(request.parameters, result.trajectory.frames[f]);
    for (int j = 0; j < e.joints; ++j) {
      out.angles_rad(static_cast<Eigen::Index>(f), 2 * j) =
          recorded[static_cast<std::size_t>(j)].x();
      out.angles_rad(static_cast<Eigen::Index>(f), 2 * j + 1) =
          recorded[static_cast<std::size_t>(j)].y();
    }
  }
  e.AsMeasured(&out.angles_rad);
  out.summary = std::move(result.summary);
  if (request.keep_trajectory) out.trajectory = std::move(result.trajectory);
  return out;
}

class ThreadBackend final : public SimulationBackend {
 public:
  ThreadBackend(const std::vector<Experiment>* experiments, int threads)
      : experiments_(experiments), threads_(std::max(threads, 1)) {}

  int parallelism() const override { return threads_; }

  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    for (const RunRequest& r : requests) CCSRM_CHECK(r.experiment < experiments_->size());
    std::vector<RunResult> results(requests.size());
    std::atomic<std::size_t> next{0};
    std::atomic<bool> failed{false};
    std::mutex mutex;  // guards first_error, finished and the callback
    std::exception_ptr first_error;
    std::size_t finished = 0;
    const auto work = [&] {
      for (std::size_t k = next++; k < requests.size() && !failed; k = next++) {
        try {
          results[k] = RunOne((*experiments_)[requests[k].experiment], requests[k]);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(mutex);
          if (!first_error) first_error = std::current_exception();
          failed = true;
          return;
        }
        const std::lock_guard<std::mutex> lock(mutex);
        ++finished;
        if (on_finished) on_finished(finished, requests.size(), results[k]);
      }
    };
    const std::size_t count =
        std::min<std::size_t>(static_cast<std::size_t>(threads_), requests.size());
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < count; ++t) pool.emplace_back(work);
    work();  // the calling thread is one of the workers
    for (std::thread& t : pool) t.join();
    if (first_error) std::rethrow_exception(first_error);
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
