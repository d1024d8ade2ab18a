#include "output_sampler.h"

#include <algorithm>
#include <cmath>

namespace ccsrm::sim::internal {

std::vector<double> SampleTimes(const SimulationOptions& options) {
  if (!options.sample_times.empty()) return options.sample_times;
  const double dt = 1.0 / options.solver.output_rate_hz;
  const long count = static_cast<long>(std::floor(options.duration_s / dt + 1e-9)) + 1;
  std::vector<double> times(count);
  for (long k = 0; k < count; ++k) times[k] = std::min(options.duration_s, k * dt);
  return times;
}

OutputSampler::OutputSampler(std::vector<double> times) : times_(std::move(times)) {
  trajectory_.time.reserve(times_.size());
  trajectory_.frames.reserve(times_.size());
}

void OutputSampler::Record(const TrajectoryFrame& frame) {
  const double t = times_[next_];
  while (next_ < times_.size() && times_[next_] == t) {
    trajectory_.time.push_back(t);
    trajectory_.frames.push_back(frame);
    ++next_;
  }
  max_violation_ = std::max(max_violation_, frame.constraint_violation);
}

}  // namespace ccsrm::sim::internal
