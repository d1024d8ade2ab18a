#include "output_sampler.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ccsrm/sim/kinematics.h"

namespace ccsrm::sim::internal {

std::vector<double> SampleTimes(const SimulationOptions& options) {
  if (!options.sample_times.empty()) return options.sample_times;
  const double dt = 1.0 / options.solver.output_rate_hz;
  const long count = static_cast<long>(std::floor(options.duration_s / dt + 1e-9)) + 1;
  std::vector<double> times(count);
  for (long k = 0; k < count; ++k) times[k] = std::min(options.duration_s, k * dt);
  return times;
}

std::string JointPastRange(const ArmModel& model, const TrajectoryFrame& frame) {
  for (int j = 1; j <= model.num_joints(); ++j) {
    const double tilt = JointTiltRad(frame.joint_angles[j - 1]);
    if (tilt <= model.joint_range_rad(j)) continue;
    char text[224];
    std::snprintf(text, sizeof(text),
                  "joint %d tilted to %.2f deg, past its range of %.2f deg where its disks "
                  "meet (ccsrm has no contact between disks)",
                  j, tilt * 180.0 / M_PI, model.joint_range_rad(j) * 180.0 / M_PI);
    return text;
  }
  return "";
}

std::vector<SlackInterval> SlackIntervalsOf(const ArmModel& model, const Trajectory& trajectory) {
  Eigen::MatrixXi slack(static_cast<Eigen::Index>(trajectory.size()), model.num_cables());
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    for (int c = 0; c < model.num_cables(); ++c)
      slack(f, c) = CountSlackElements(trajectory.frames[f].element_tension[c]);
  }
  return FindSlackIntervals(trajectory.time, slack);
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
