#pragma once
// Experiments made in the tests: the paper's arm on a compressed protocol
// (case 4, connecting-cable friction only: a run takes about a second),
// recorded as white noise of a known size on the true angles.
#include <gtest/gtest.h>
#include <Eigen/Core>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/mocap/signal.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify::testing_support {

inline constexpr double kDeg = 180.0 / M_PI;

// The nominal configuration of the experiments: the paper's arm (or the
// bundled configuration `config`, e.g. "three-segment.yaml"), case 4's
// friction (none on the driving cables), a compressed protocol of which the
// experiments record the 2 s ramp and the 1 s hold.
inline sim::Config Nominal(const std::string& config = "paper.yaml") {
  sim::Config c = sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/" + config);
  c.protocol.ramp_s = 2.0;
  c.protocol.hold_s = 1.0;
  c.protocol.return_s = 2.0;
  c.protocol.rest_s = 0.5;
  c.parameters.mu = c.parameters.mu_s = 0.0;
  return c;
}

// An experiment recorded from the arm with `truth`: inputs at 100 Hz, the
// true angles at 100 Hz plus white noise of noise_deg, and a twist record of
// the same noise (from which the loader estimates it). With low_pass_hz > 0
// the true angles pass through the mocap pipeline's low-pass (order 2,
// recorded in the file's quality figures, so identification filters its
// simulated angles alike) before the noise is added. With pose_step_s > 0
// the rows are settled poses that far apart (motion: settled_poses), the
// truth replayed quasi-statically, as identification replays them.
inline datasets::ExperimentFile Record(const sim::ArmParameters& truth, double noise_deg,
                                       unsigned seed, const sim::Config& config = Nominal(),
                                       double low_pass_hz = 0.0, double pose_step_s = 0.0) {
  const sim::ArmModel model(config.arm);
  const double duration = config.protocol.ramp_s + config.protocol.hold_s;
  const sim::CableInputs planned =
      sim::PlanCableInputs(model, sim::PaperTrajectory(model, config.protocol), duration);
  const bool settled = pose_step_s > 0.0;
  const double step = settled ? pose_step_s : 0.01;
  const std::size_t frames = static_cast<std::size_t>(std::lround(duration / step)) + 1;
  const int cables = model.num_cables();
  datasets::ExperimentFile file;
  file.name = "synthetic";
  file.source = datasets::ExperimentSource::kGenerated;
  if (settled) file.motion = datasets::RecordedMotion::kSettledPoses;
  file.config_yaml = sim::ToYaml(config);
  file.input_time = datasets::Array({frames});
  file.input_length_change = datasets::Array({frames, static_cast<std::size_t>(cables)});
  Eigen::VectorXd time(static_cast<Eigen::Index>(frames));
  Eigen::MatrixXd length(static_cast<Eigen::Index>(frames), cables);
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = static_cast<double>(f) * step;
    file.input_time.at(f) = t;
    time[static_cast<Eigen::Index>(f)] = t;
    for (int c = 0; c < cables; ++c) {
      double value = 0.0, rate = 0.0, accel = 0.0;
      planned.Evaluate(c, t, &value, &rate, &accel);
      file.input_length_change.at(f, static_cast<std::size_t>(c)) = value;
      length(static_cast<Eigen::Index>(f), c) = value;
    }
  }
  // The truth runs from the recorded inputs, as identification will.
  const sim::CableInputs inputs(time, length);
  sim::SimulationOptions options;
  options.duration_s = duration;
  options.sample_times.assign(time.data(), time.data() + time.size());
  options.solver = config.solver;
  options.quasi_static = settled;
  const sim::SimulationResult run = sim::Simulate(model, truth, inputs, options);
  EXPECT_TRUE(run.summary.completed()) << run.summary.message;
  EXPECT_EQ(run.trajectory.size(), frames);

  const std::size_t joints = static_cast<std::size_t>(model.num_joints());
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_deg / kDeg);
  file.mocap_time = file.input_time;
  file.mocap_markers = datasets::Array({frames, 0, 3});
  file.measured_joint_angles = datasets::Array({frames, joints, 2});
  file.measured_joint_twist = datasets::Array({frames, joints});
  // What motion capture records: measurement effects (mocap_offset) included.
  std::vector<double>& angles = file.measured_joint_angles->values;
  for (std::size_t f = 0; f < frames; ++f) {
    const std::vector<Eigen::Vector2d> recorded =
        sim::RecordedJointAngles(truth, run.trajectory.frames[f]);
    for (std::size_t j = 0; j < joints; ++j) {
      for (int a = 0; a < 2; ++a)
        angles[(f * joints + j) * 2 + static_cast<std::size_t>(a)] = recorded[j][a];
    }
  }
  if (low_pass_hz > 0.0) {
    constexpr int kOrder = 2;
    constexpr int kMinRun = 4;
    const auto sections = mocap::DesignButterworthLowPass(kOrder, low_pass_hz, 100.0);
    for (std::size_t c = 0; c < 2 * joints; ++c) {
      mocap::ZeroLagLowPass(sections, low_pass_hz, 100.0, angles.data() + c, frames, 2 * joints,
                            kMinRun);
    }
    const auto figure = [&file](const char* name, double value, const char* units) {
      file.mocap_quality[name] = datasets::Array({1});
      file.mocap_quality[name].values[0] = value;
      file.mocap_quality_units[name] = units;
    };
    figure("filter_cutoff_hz", low_pass_hz, "Hz");
    figure("filter_order", kOrder, "1");
    figure("filter_min_run_frames", kMinRun, "frames");
  }
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t j = 0; j < joints; ++j) {
      for (int a = 0; a < 2; ++a)
        angles[(f * joints + j) * 2 + static_cast<std::size_t>(a)] += noise(rng);
      file.measured_joint_twist->at(f, j) = noise(rng);
    }
  }
  return file;
}

inline sim::ArmParameters Truth() {
  sim::ArmParameters p = Nominal().parameters;
  p.T_p = 65.0;  // nominal 50
  return p;
}

// The second arm of configs/ (three segments of four links, nine cables) on
// the same compressed protocol, and experiments of it recorded with the
// mocap floor's 0.03 deg of noise, one per seed ("arm3_<seed>").
inline constexpr double kSecondArmNoiseDeg = 0.03;
inline sim::Config SecondArm() { return Nominal("three-segment.yaml"); }
inline std::vector<Experiment> Recordings(const sim::ArmParameters& truth,
                                          const std::vector<unsigned>& seeds,
                                          const sim::Config& config) {
  std::vector<Experiment> out;
  for (unsigned seed : seeds) {
    const std::string name = "arm3_" + std::to_string(seed);
    out.push_back(
        MakeExperiment(Record(truth, kSecondArmNoiseDeg, seed, config), name + ".h5", {}));
    out.back().name = name;
  }
  return out;
}

}  // namespace ccsrm::identify::testing_support
