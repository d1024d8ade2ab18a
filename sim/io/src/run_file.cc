#include "ccsrm/sim_io/run_file.h"

namespace ccsrm::sim_io {

datasets::RunFile ToRunFile(const sim::ArmModel& model, const sim::SimulationResult& result,
                            const RunFileInfo& info) {
  using datasets::Array;
  const sim::Trajectory& trajectory = result.trajectory;
  datasets::RunFile run;
  const std::size_t T = trajectory.size();
  const std::size_t J = model.num_joints(), L = model.num_links(), C = model.num_cables();
  run.time = Array({T});
  run.joint_angles = Array({T, J, 2});
  run.joint_rates = Array({T, J, 2});
  run.link_pose = Array({T, L, 7});
  run.input_tension = Array({T, C});
  run.input_length_change = Array({T, C});
  run.stuck_nodes = Array({T, C});
  run.slack_elements = Array({T, C});
  run.constraint_violation = Array({T});
  run.energy = Array({T, 3});
  run.cables.resize(C);
  for (std::size_t c = 0; c < C; ++c) {
    const std::size_t elements = model.cables()[c].num_elements();
    const std::size_t holes = model.cables()[c].num_holes();
    run.cables[c].tension = Array({T, elements});
    run.cables[c].stuck = Array({T, holes});
    run.cables[c].slip_velocity = Array({T, holes});
  }
  for (std::size_t f = 0; f < T; ++f) {
    const sim::TrajectoryFrame& o = trajectory.frames[f];
    run.time.at(f) = trajectory.time[f];
    for (std::size_t j = 0; j < J; ++j) {
      for (int a = 0; a < 2; ++a) {
        run.joint_angles.at(f, j, a) = o.joint_angles[j][a];
        run.joint_rates.at(f, j, a) = o.joint_rates[j][a];
      }
    }
    for (std::size_t i = 0; i < L; ++i)
      for (int k = 0; k < 7; ++k) run.link_pose.at(f, i, k) = o.link_pose[i][k];
    for (std::size_t c = 0; c < C; ++c) {
      run.input_tension.at(f, c) = o.element_tension[c][0];
      run.input_length_change.at(f, c) = o.input_length_change[c];
      int stuck = 0;
      for (std::size_t e = 0; e < o.element_tension[c].size(); ++e) {
        run.cables[c].tension.at(f, e) = o.element_tension[c][e];
      }
      for (std::size_t h = 0; h < o.hole_stuck[c].size(); ++h) {
        run.cables[c].stuck.at(f, h) = o.hole_stuck[c][h];
        run.cables[c].slip_velocity.at(f, h) = o.hole_slip_velocity[c][h];
        stuck += o.hole_stuck[c][h];
      }
      run.stuck_nodes.at(f, c) = stuck;
      run.slack_elements->at(f, c) = sim::CountSlackElements(o.element_tension[c]);
    }
    run.constraint_violation.at(f) = o.constraint_violation;
    run.energy.at(f, 0) = o.kinetic_energy;
    run.energy.at(f, 1) = o.elastic_energy;
    run.energy.at(f, 2) = o.dissipated_energy;
  }
  const sim::SimulationSummary& s = result.summary;
  run.case_name = info.case_name;
  run.config_yaml = info.config_yaml;
  run.protocol_yaml = info.protocol_yaml;
  run.inputs_file = info.inputs_file;
  run.wall_time_s = s.wall_time_s;
  run.steps = s.steps;
  run.rejected_steps = s.rejected_steps;
  run.rhs_evaluations = s.rhs_evaluations;
  switch (s.status) {
    case sim::SimulationStatus::kCompleted:
      run.status = datasets::RunStatus::kCompleted;
      break;
    case sim::SimulationStatus::kDiverged:
      run.status = datasets::RunStatus::kDiverged;
      break;
    case sim::SimulationStatus::kCancelled:
      run.status = datasets::RunStatus::kCancelled;
      break;
  }
  run.status_message = s.message;
  return run;
}

RunFileInfo PaperRunFileInfo(const sim::PaperRun& run) {
  RunFileInfo info;
  info.case_name = run.case_number != 0 ? std::to_string(run.case_number) : "custom";
  info.config_yaml = sim::ToYaml(run.config);
  if (run.protocol && !run.default_protocol) info.protocol_yaml = run.protocol->ToYaml();
  info.inputs_file = run.inputs_source;
  return info;
}

}  // namespace ccsrm::sim_io
