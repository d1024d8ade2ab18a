#pragma once
// A generated experiment (`ccsrm generate`, ccsrm.generate): the arm
// simulated with a truth, recorded by virtual motion capture (noise,
// occlusions, resolution), and written as a ccsrm-dataset/1 experiment that
// states only the nominal configuration, with the ground truth beside it in
// two files no fitting code reads: <name>.truth.yaml (ccsrm-truth/1: the
// true parameters and effects, the recording's noise and occlusions) and
// <name>.truth.h5 (the physical run, ccsrm-run/1).
#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/mocap/virtual_experiment.h"
#include "ccsrm/sim/paper_run.h"

namespace ccsrm::mocap {

struct GenerateOptions {
  // The truth's run (sim::PreparePaperRun): configuration, paper case,
  // motion (a protocol, or recorded inputs already read) and named
  // parameters. The experiment keeps the configuration as given, with the
  // case (part of the arm as built) and without its effects; the named
  // parameters are the truth identification must find.
  sim::PaperRunOptions run;
  // Effects switched on in the truth only: a YAML file (sim::
  // ApplyEffectsYaml), then specs "NAME" or "NAME:param=value,..." (sim::
  // ApplyEffectSpec) in order. Default: none.
  std::string effects_path;
  std::vector<std::string> effects;
  // Marker noise, resolution, occlusions and seed (defaults: 0.2 mm, full
  // precision, occlusions on, seed 1).
  VirtualRecordingOptions recording;
  // The experiment file; must end in .h5 (the truth files are named after
  // it). Checked against the output policy (common/output_policy.h) with
  // the truth files, before the run.
  std::string out;
  // How the simulation reports and stops (sim::SimulationOptions' fields of
  // the same names): `progress` from the simulating thread every
  // progress_interval_s of wall time, a stop once *cancel is true (a
  // cancelled run writes nothing). Default: neither.
  std::function<void(const sim::SimulationProgress&)> progress;
  double progress_interval_s = 1.0;
  const std::atomic<bool>* cancel = nullptr;
  // Called once the run is prepared, before it is simulated (the command
  // prints the configuration's warnings there). May be empty.
  std::function<void(const sim::PaperRun&)> on_prepared;
};

struct GeneratedExperiment {
  sim::PaperRun run;       // as prepared (sim::DescribeRun)
  sim::Config truth = {};  // the run's configuration with the truth's effects on
  // The simulation: a run that did not complete writes nothing.
  sim::SimulationSummary simulation = {};
  double wall_time_s = 0.0;  // of the simulation
  std::string experiment_path = {}, truth_yaml_path = {}, truth_h5_path = {};
  std::size_t frames = 0, markers = 0;
  VirtualRecordingSummary recording = {};  // what the occlusion model hid
};

// Generates and writes the experiment. Throws InputError for bad options or
// files (one line naming the option or file), before any simulation; a run
// that does not complete is reported in `simulation` with nothing written.
GeneratedExperiment GenerateExperiment(const GenerateOptions& options);

// "<dir>/exp.h5" -> "<dir>/exp": the stem the truth files share. Throws
// InputError naming `out` when it does not end in .h5.
std::string GeneratedOutputStem(const std::string& out);

}  // namespace ccsrm::mocap
