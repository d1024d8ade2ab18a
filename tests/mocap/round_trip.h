#pragma once
// What the round-trip tests share: one simulated and virtually recorded
// trial, and the comparison of measured with simulated joint angles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/mocap/virtual_experiment.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "ccsrm/sim_io/run_file.h"

namespace ccsrm::mocap::testing {

// The target: per joint and axis, RMS over the trial.
inline constexpr double kTargetRmsDeg = 0.05;
inline constexpr double kRadToDeg = 180.0 / M_PI;

struct ProtocolConfig {
  double ramp_s, hold_s, return_s, rest_s;
};

struct RoundTripTrial {
  bool completed = false;
  std::string message;
  datasets::RunFile truth;              // the simulation with noise-free markers
  datasets::ExperimentFile experiment;  // what motion capture recorded
  VirtualRecordingSummary recording;
  std::string directory;        // scratch directory of this trial
  std::string experiment_path;  // the experiment, written there
};

// Simulates the paper's arm (case `case_number`, +6 deg, the given protocol
// timing), records it with the default layout and recording options (0.2 mm,
// occlusions on) and writes the experiment to a scratch directory.
inline RoundTripTrial MakeRoundTripTrial(int case_number, const ProtocolConfig& protocol,
                                         std::uint64_t seed, const std::string& name) {
  sim::Config nominal = sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml");
  nominal.protocol.ramp_s = protocol.ramp_s;
  nominal.protocol.hold_s = protocol.hold_s;
  nominal.protocol.return_s = protocol.return_s;
  nominal.protocol.rest_s = protocol.rest_s;
  sim::Config truth = nominal;
  sim::ApplyPaperCase(case_number, &truth.parameters);
  const sim::ArmModel model(truth.arm);
  const double duration = truth.protocol.duration_s();
  const sim::CableInputs inputs =
      sim::PlanCableInputs(model, sim::PaperTrajectory(model, truth.protocol), duration);
  sim::SimulationOptions options;
  options.duration_s = duration;
  options.solver = truth.solver;
  const sim::SimulationResult simulated = sim::Simulate(model, truth.parameters, inputs, options);

  RoundTripTrial trial;
  trial.completed = simulated.summary.completed();
  trial.message = simulated.summary.message;
  VirtualExperimentOptions recording;
  recording.name = name;
  recording.nominal_config_yaml = sim::ToYaml(nominal);
  recording.recording.seed = seed;
  VirtualExperiment generated = MakeVirtualExperiment(
      sim_io::ToRunFile(model, simulated,
                        {std::to_string(case_number), sim::ToYaml(truth), "", ""}),
      DefaultMarkerLayout(model), recording);
  trial.truth = std::move(generated.truth);
  trial.experiment = std::move(generated.experiment);
  trial.recording = generated.recording;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("ccsrm_round_trip_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  trial.directory = dir.string();
  trial.experiment_path = (dir / "exp.h5").string();
  datasets::WriteExperimentFile(trial.experiment_path, trial.experiment);
  return trial;
}

// The experiment processed with the default options, its own rigid bodies
// and the joint chain of its nominal configuration.
inline ProcessingResult ProcessTrial(const RoundTripTrial& trial) {
  const sim::ArmModel model(sim::ParseConfig(trial.experiment.config_yaml, "nominal").arm);
  const JointChain chain = JointChain::FromModel(model);
  return ProcessMarkers(MarkerTableFromExperiment(trial.experiment),
                        trial.experiment.mocap_time.values,
                        LayoutFromExperiment(trial.experiment.rigid_bodies, "exp"),
                        ProcessingOptions(), "exp", &chain);
}

struct AngleErrors {
  std::size_t joints = 0;
  std::vector<double> rms_deg;  // J × 2, [joint * 2 + axis]
  double worst_rms_deg = 0.0;
  std::size_t worst_joint = 0;  // 1-based
  std::size_t worst_axis = 0;   // 0 = θx, 1 = θy
  double max_abs_deg = 0.0;
  std::size_t compared = 0;      // finite (frame, joint) pairs
  std::size_t not_measured = 0;  // NaN (frame, joint) pairs

  std::string Report() const {
    std::string text;
    char buffer[160];
    std::snprintf(buffer, sizeof(buffer),
                  "worst RMS %.4f deg (joint %zu, theta_%c), max |error| %.4f deg, %zu of %zu "
                  "joint-frames measured\n  RMS deg per joint (x/y):",
                  worst_rms_deg, worst_joint, worst_axis == 0 ? 'x' : 'y', max_abs_deg, compared,
                  compared + not_measured);
    text += buffer;
    for (std::size_t j = 0; j < joints; ++j) {
      std::snprintf(buffer, sizeof(buffer), " %zu:%.4f/%.4f", j + 1, rms_deg[2 * j],
                    rms_deg[2 * j + 1]);
      text += buffer;
    }
    return text;
  }
};

// Per joint and axis RMS of measured − simulated over the frames where the
// measurement is finite. Both F × J × 2 with the same F.
inline AngleErrors CompareJointAngles(const datasets::Array& measured,
                                      const datasets::Array& simulated) {
  AngleErrors e;
  EXPECT_EQ(measured.shape, simulated.shape);
  if (measured.shape != simulated.shape) return e;
  const std::size_t F = measured.shape[0];
  e.joints = measured.shape[1];
  e.rms_deg.assign(2 * e.joints, 0.0);
  for (std::size_t j = 0; j < e.joints; ++j) {
    for (std::size_t axis = 0; axis < 2; ++axis) {
      double sum_sq = 0.0;
      std::size_t n = 0;
      for (std::size_t f = 0; f < F; ++f) {
        const double error = (measured.at(f, j, axis) - simulated.at(f, j, axis)) * kRadToDeg;
        if (!std::isfinite(error)) {
          if (axis == 0) ++e.not_measured;
          continue;
        }
        sum_sq += error * error;
        ++n;
        e.max_abs_deg = std::max(e.max_abs_deg, std::abs(error));
      }
      if (axis == 0) e.compared += n;
      const double rms = n > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) : INFINITY;
      e.rms_deg[2 * j + axis] = rms;
      if (rms > e.worst_rms_deg || (j == 0 && axis == 0)) {
        e.worst_rms_deg = rms;
        e.worst_joint = j + 1;
        e.worst_axis = axis;
      }
    }
  }
  return e;
}

// The target, and NaN exactly where the summary says a joint was lost.
inline void ExpectWithinTarget(const AngleErrors& errors, const ProcessingResult& result) {
  EXPECT_LT(errors.worst_rms_deg, kTargetRmsDeg) << errors.Report();
  std::size_t lost = 0;
  for (const JointQuality& j : result.summary.joints) lost += j.frames_lost;
  EXPECT_EQ(errors.not_measured, lost);
  // Whole-link losses are rare: nearly every joint-frame is measured.
  EXPECT_GT(static_cast<double>(errors.compared),
            0.97 * static_cast<double>(errors.compared + errors.not_measured));
}

}  // namespace ccsrm::mocap::testing
