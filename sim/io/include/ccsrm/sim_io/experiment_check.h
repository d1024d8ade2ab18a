#pragma once
// The one check of an experiment against what the rest of the pipeline needs
// (the arm of its own config_yaml, the physical range of a universal joint),
// applied at every door an experiment comes through: `ccsrm dataset
// inspect`, `ccsrm mocap process` before it writes, and identification when
// it loads one. It lives with the file converters because it needs both the
// experiment schema (datasets) and the arm (sim).
#include <memory>
#include <optional>
#include <string>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::sim_io {

// The arm an experiment's config_yaml describes, parsed once.
struct ExperimentArm {
  sim::Config config;
  std::shared_ptr<const sim::ArmModel> model;
};

// Checks that `experiment` is a consistent ccsrm-dataset/1 record
// (datasets::ValidateExperimentFile) and that it holds what simulation, mocap
// processing and identification will need:
//  - /mocap/time has at least 2 frames (a frame rate, a motion);
//  - /mocap/markers, when it holds any value, holds a finite one;
//  - its inputs pass CheckInputs (below), against the arm of its
//    config_yaml when that is not empty;
//  - config_yaml, when not empty, parses (sim::ParseConfig), and then
//    /measured/joint_angles (when present) is F × J × 2 with J the arm's
//    joints;
//  - /measured/joint_angles (when present) holds at least one finite value,
//    and every value is NaN (lost) or within the mathematical range of the
//    X–Y Cardan pair of a universal joint: |θx| <= π, |θy| <= π/2 rad.
// `file` names the experiment in messages. Returns the arm, or nullopt when
// config_yaml is empty (nothing to check the shapes against; a caller that
// needs the arm says so). Throws InputError "<file>: <path>: <problem>" on
// the first problem. `known_arm`: the arm of config_yaml when the caller
// has already parsed it (identification parses a configuration once per
// experiment, or once per job for a --config), used instead of parsing it
// again; null: parsed here.
std::optional<ExperimentArm> CheckExperimentAgainstConfig(
    const datasets::ExperimentFile& experiment, const std::string& file,
    const ExperimentArm* known_arm = nullptr);

// The check of a run file (ccsrm-run/1) against its own config_yaml, which
// every run file has (simulate writes it): it parses, and the run's inputs
// pass CheckInputs against that arm. Throws InputError as above.
void CheckRunAgainstConfig(const datasets::RunFile& run, const std::string& file);

// The one door of a ccsrm HDF5 file read whole by a command (`dataset
// inspect`, `report`, `simulate --inputs`, `mocap process --inputs`):
// datasets::ReadAnyFile, then CheckExperimentAgainstConfig or
// CheckRunAgainstConfig, so that every command refuses the same files with
// the same line.
datasets::AnyFile ReadCheckedFile(const std::string& path);

// The one check of recorded cable inputs, at every door they come through
// (CheckExperimentAgainstConfig for an experiment's own; `ccsrm mocap
// process --inputs FILE` where it reads another file's): the time base
// (/input/time, or a run's /time) has at least one sample, every time finite
// and strictly increasing; the length changes (/input/length_change, or a
// run's /input_length_change) are one row per time with every value finite;
// and, with `arm` given, they have either no cable column (no actuator
// record) or one per driving cable of that arm, within its physical bounds
// (sim::CheckRecordedInputsOnArm: no pull beyond a cable's route, no speed
// beyond any actuator's). `file` names the file and
// `arm_source` where the arm came from ("arm.yaml", "e.h5 (its
// config_yaml)") in messages. Throws InputError "<file>: <path>: <problem>"
// on the first problem.
void CheckInputs(const datasets::ExperimentFile& experiment, const std::string& file,
                 const sim::ArmModel* arm, const std::string& arm_source);
void CheckInputs(const datasets::RunFile& run, const std::string& file, const sim::ArmModel* arm,
                 const std::string& arm_source);

}  // namespace ccsrm::sim_io
