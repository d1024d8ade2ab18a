#pragma once
// The frames of a run at the requested sample times: the step loop lands a
// step exactly on next_time() and hands the frame over; the sampler keeps
// the trajectory and the largest constraint violation seen.
#include <cstddef>
#include <string>
#include <vector>

#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim::internal {

// The times at which `options` asks for frames: its sample_times, or every
// 1 / solver.output_rate_hz from 0 to duration_s (the last one at
// duration_s). Precondition: options.IsValid().
std::vector<double> SampleTimes(const SimulationOptions& options);

// What is wrong with a frame whose joint is past its range
// (ArmModel::joint_range_rad), or "" when every joint is within it. A joint
// past its range would need contact between its disks, which the model
// does not have.
std::string JointPastRange(const ArmModel& model, const TrajectoryFrame& frame);

// Where a driving cable went slack over the frames (FindSlackIntervals).
std::vector<SlackInterval> SlackIntervalsOf(const ArmModel& model, const Trajectory& trajectory);

class OutputSampler {
 public:
  explicit OutputSampler(std::vector<double> times);

  bool done() const { return next_ >= times_.size(); }
  double next_time() const { return times_[next_]; }

  // Records the frame at next_time() (and at any later sample time equal to it).
  void Record(const TrajectoryFrame& frame);

  double max_constraint_violation() const { return max_violation_; }
  Trajectory Take() { return std::move(trajectory_); }

 private:
  std::vector<double> times_;
  std::size_t next_ = 0;
  Trajectory trajectory_;
  double max_violation_ = 0.0;
};

}  // namespace ccsrm::sim::internal
