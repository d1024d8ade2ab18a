#include "run_experiment.h"

#include <algorithm>
#include <limits>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"

namespace ccsrm::identify::internal {

RunResult RunExperiment(const Experiment& e, const identify::RunRequest& request) {
  sim::SimulationOptions options;
  options.duration_s = e.duration_s();
  options.sample_times = e.sample_time_s;
  options.solver = e.config.solver;
  options.quasi_static = e.settled_poses;
  sim::SimulationResult result = sim::Simulate(*e.model, request.parameters, *e.inputs, options);

  RunResult out;
  if (request.every_frame) {
    CCSRM_CHECK(request.measurement_variants.empty());
    const std::size_t frames = result.trajectory.size();
    const int joints = e.model->num_joints();
    out.simulated.resize(static_cast<Eigen::Index>(frames), 2 * joints);
    for (std::size_t f = 0; f < frames; ++f) {
      const std::vector<Eigen::Vector2d>& theta = result.trajectory.frames[f].joint_angles;
      for (int j = 0; j < joints; ++j) {
        out.simulated(static_cast<Eigen::Index>(f), 2 * j) = theta[static_cast<std::size_t>(j)].x();
        out.simulated(static_cast<Eigen::Index>(f), 2 * j + 1) =
            theta[static_cast<std::size_t>(j)].y();
      }
    }
    out.summary = std::move(result.summary);
    if (request.keep_trajectory) out.trajectory = std::move(result.trajectory);
    return out;
  }
  const auto record = [&](const sim::ArmParameters& parameters) {
    Eigen::MatrixXd angles = Eigen::MatrixXd::Constant(e.measured.rows(), e.measured.cols(),
                                                       std::numeric_limits<double>::quiet_NaN());
    const std::size_t frames =
        std::min(result.trajectory.size(), static_cast<std::size_t>(e.measured.rows()));
    for (std::size_t f = 0; f < frames; ++f) {
      // What motion capture records: measurement effects (mocap_offset) included.
      const std::vector<Eigen::Vector2d> recorded =
          sim::RecordedJointAngles(parameters, result.trajectory.frames[f]);
      for (int j = 0; j < e.joints; ++j) {
        angles(static_cast<Eigen::Index>(f), 2 * j) = recorded[static_cast<std::size_t>(j)].x();
        angles(static_cast<Eigen::Index>(f), 2 * j + 1) = recorded[static_cast<std::size_t>(j)].y();
      }
    }
    if (!e.tracked_points.empty()) RecordTrackedPoints(e, result.trajectory, &angles);
    e.AsMeasured(&angles);
    return angles;
  };
  out.simulated = record(request.parameters);
  for (const sim::ArmParameters& variant : request.measurement_variants) {
    out.variant_simulated.push_back(record(variant));
  }
  out.summary = std::move(result.summary);
  if (request.keep_trajectory) out.trajectory = std::move(result.trajectory);
  return out;
}

}  // namespace ccsrm::identify::internal
