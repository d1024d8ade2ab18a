#include "ccsrm/identify/runs.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::identify {

int DefaultThreads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

std::string ThreadCountProblem(int threads) {
  if (threads >= 1 && threads <= kMaxThreads) return "";
  return "threads: must be in 1.." + std::to_string(kMaxThreads);
}

std::vector<std::string> AllParameterNames() {
  std::vector<std::string> names;
  for (const sim::ParameterInfo& p : sim::Parameters()) names.push_back(p.name);
  return names;
}

Experiment FrameExperiment(const std::string& name, const sim::ArmModel& model,
                           const sim::CableInputs& inputs,
                           const sim::SimulationOptions& simulation) {
  std::string error;
  if (!simulation.IsValid(&error)) ThrowInputError("SimulationOptions", "", error);
  if (simulation.cancel != nullptr || simulation.wall_time_budget_s != 0.0) {
    ThrowInputError("SimulationOptions", "",
                    "cancel and wall_time_budget_s do not reach a backend's runs");
  }
  Experiment e;
  e.name = name;
  e.path = name;
  e.config.solver = simulation.solver;
  // Not owned (no deleter): the caller keeps model and inputs alive.
  e.model = std::shared_ptr<const sim::ArmModel>(std::shared_ptr<void>(), &model);
  e.inputs = std::shared_ptr<const sim::CableInputs>(std::shared_ptr<void>(), &inputs);
  e.sample_time_s = simulation.sample_times;
  e.simulated_s = simulation.duration_s;
  e.joints = model.num_joints();
  e.measured.resize(0, 2 * e.joints);
  return e;
}

std::vector<double> SampledJointAnglesDeg(const sim::Trajectory& trajectory) {
  std::vector<double> angles;
  for (const sim::TrajectoryFrame& frame : trajectory.frames) {
    for (const Eigen::Vector2d& theta : frame.joint_angles) {
      angles.push_back(theta.x() * 180.0 / M_PI);
      angles.push_back(theta.y() * 180.0 / M_PI);
    }
  }
  return angles;
}

}  // namespace ccsrm::identify
