#include "ccsrm/sim_io/experiment_check.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "ccsrm/sim_io/recorded_inputs.h"

namespace ccsrm::sim_io {
namespace {

constexpr const char* kAngles = "/measured/joint_angles";

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", value);
  return text;
}

bool AnyFinite(const datasets::Array& array) {
  for (double v : array.values) {
    if (std::isfinite(v)) return true;
  }
  return false;
}

// Every angle NaN (lost) or within the range of the X–Y Cardan pair of a
// universal joint (SPEC §2): θx = atan2(..) in [-π, π], θy = asin(..) in
// [-π/2, π/2]. A value outside cannot come from any pose: the data are
// corrupt or in other units (degrees).
void CheckAngleRange(const datasets::ExperimentFile& experiment, const std::string& file) {
  const datasets::Array& angles = *experiment.measured_joint_angles;
  const std::size_t joints = angles.shape[1];
  for (std::size_t i = 0; i < angles.values.size(); ++i) {
    const double v = angles.values[i];
    if (std::isnan(v)) continue;
    const std::size_t axis = i % 2;
    const std::size_t joint = (i / 2) % joints;
    const std::size_t frame = i / (2 * joints);
    const double limit = axis == 0 ? M_PI : M_PI / 2.0;
    if (std::isfinite(v) && std::abs(v) <= limit) continue;
    ThrowInputError(file, kAngles,
                    "frame index " + std::to_string(frame) +
                        " (t = " + Number(experiment.mocap_time.at(frame)) + " s), joint " +
                        std::to_string(joint + 1) + ", " + (axis == 0 ? "θx" : "θy") + " = " +
                        Number(v) + " rad: outside the universal joint's range " +
                        (axis == 0 ? "|θx| <= π" : "|θy| <= π/2") + " (lost angles are NaN)");
  }
}

// CheckInputs on a time base and its length changes, named by their paths.
void CheckInputArrays(const datasets::Array& time, const datasets::Array& length_change,
                      const std::string& file, const std::string& time_path,
                      const std::string& length_path, const sim::ArmModel* arm,
                      const std::string& arm_source) {
  if (time.rank() != 1 || time.values.empty()) {
    ThrowInputError(
        file, time_path,
        "has shape " + datasets::ShapeToString(time.shape) + ", expected at least one sample");
  }
  for (std::size_t i = 0; i < time.values.size(); ++i) {
    const double t = time.values[i];
    if (!std::isfinite(t)) {
      ThrowInputError(
          file, time_path,
          "sample " + std::to_string(i) + " is " + Number(t) + ": the time base must be finite");
    }
    if (i > 0 && !(t > time.values[i - 1])) {
      ThrowInputError(file, time_path,
                      "not strictly increasing: sample " + std::to_string(i) + " holds " +
                          Number(t) + " s after " + Number(time.values[i - 1]) + " s");
    }
  }
  const std::size_t samples = time.values.size();
  if (length_change.rank() != 2 || length_change.shape[0] != samples ||
      length_change.values.size() != samples * length_change.shape[1]) {
    ThrowInputError(file, length_path,
                    "has shape " + datasets::ShapeToString(length_change.shape) +
                        ", expected N×C with N=" + std::to_string(samples) + " (from " + time_path +
                        ")");
  }
  const std::size_t cables = length_change.shape[1];
  for (std::size_t i = 0; i < length_change.values.size(); ++i) {
    if (!std::isfinite(length_change.values[i])) {
      ThrowInputError(file, length_path,
                      "sample " + std::to_string(i / cables) + ", cable " +
                          std::to_string(i % cables + 1) + " is " +
                          Number(length_change.values[i]) + ": a length change must be finite");
    }
  }
  if (arm != nullptr && cables != 0 && cables != static_cast<std::size_t>(arm->num_cables())) {
    ThrowInputError(file, length_path,
                    "has " + std::to_string(cables) + " cable columns, the arm of " + arm_source +
                        " has " + std::to_string(arm->num_cables()) + " driving cables");
  }
  if (arm != nullptr && cables != 0) {
    sim::CheckRecordedInputsOnArm(
        InputsFromArrays(file, time_path, length_path, time, length_change), *arm);
  }
}

// The arm of a non-empty config_yaml (`known` when the caller parsed it),
// and the shapes that depend on it.
ExperimentArm CheckArm(const datasets::ExperimentFile& experiment, const std::string& file,
                       const ExperimentArm* known) {
  ExperimentArm arm;
  if (known != nullptr) {
    arm = *known;
  } else {
    arm.config = sim::ParseConfig(experiment.config_yaml, file + ": attribute 'config_yaml'");
    arm.model = std::make_shared<const sim::ArmModel>(arm.config.arm);
  }
  const sim::ArmModel& model = *arm.model;

  CheckInputs(experiment, file, &model, "its config_yaml");
  if (experiment.measured_joint_angles) {
    const datasets::Array& angles = *experiment.measured_joint_angles;
    const std::size_t joints = static_cast<std::size_t>(model.num_joints());
    if (angles.rank() != 3 || angles.shape[0] != experiment.mocap_time.rows() ||
        angles.shape[1] != joints || angles.shape[2] != 2) {
      ThrowInputError(file, kAngles,
                      "has shape " + datasets::ShapeToString(angles.shape) + ", expected F×" +
                          std::to_string(joints) +
                          "×2 with F=" + std::to_string(experiment.mocap_time.rows()) +
                          " (from /mocap/time) and the " + std::to_string(joints) +
                          " joints of its config_yaml");
    }
  }
  return arm;
}

}  // namespace

std::optional<ExperimentArm> CheckExperimentAgainstConfig(
    const datasets::ExperimentFile& experiment, const std::string& file,
    const ExperimentArm* known_arm) {
  // Cheap beside reading the file, and it makes every shape below safe to use
  // for an experiment assembled in memory.
  datasets::ValidateExperimentFile(experiment, file);
  const std::size_t frames = experiment.mocap_time.rows();
  if (frames < 2) {
    ThrowInputError(file, "/mocap/time",
                    "has " + std::to_string(frames) +
                        " frame: needs at least 2 (a frame rate for the mocap pipeline, a "
                        "motion to compare with a simulation)");
  }
  if (experiment.mocap_markers.size() > 0 && !AnyFinite(experiment.mocap_markers)) {
    ThrowInputError(file, "/mocap/markers",
                    "has no finite sample (every position NaN or infinite): no marker was "
                    "ever seen");
  }
  std::optional<ExperimentArm> arm;
  if (!experiment.config_yaml.empty()) {
    arm = CheckArm(experiment, file, known_arm);
  } else {
    CheckInputs(experiment, file, nullptr, "");
  }
  if (experiment.measured_joint_angles) {
    if (!AnyFinite(*experiment.measured_joint_angles)) {
      ThrowInputError(file, kAngles,
                      "has no finite value (every angle NaN or infinite): no joint was ever "
                      "measured");
    }
    CheckAngleRange(experiment, file);
  }
  return arm;
}

void CheckInputs(const datasets::ExperimentFile& experiment, const std::string& file,
                 const sim::ArmModel* arm, const std::string& arm_source) {
  CheckInputArrays(experiment.input_time, experiment.input_length_change, file, "/input/time",
                   "/input/length_change", arm, arm_source);
}

void CheckInputs(const datasets::RunFile& run, const std::string& file, const sim::ArmModel* arm,
                 const std::string& arm_source) {
  CheckInputArrays(run.time, run.input_length_change, file, "/time", "/input_length_change", arm,
                   arm_source);
}

void CheckRunAgainstConfig(const datasets::RunFile& run, const std::string& file) {
  if (run.config_yaml.empty()) {
    ThrowInputError(file, "config_yaml",
                    "is empty: a run file records the configuration that made it");
  }
  const sim::Config config = sim::ParseConfig(run.config_yaml, file + ": attribute 'config_yaml'");
  const sim::ArmModel model(config.arm);
  CheckInputs(run, file, &model, "its config_yaml");
}

datasets::AnyFile ReadCheckedFile(const std::string& path) {
  datasets::AnyFile file = datasets::ReadAnyFile(path);
  if (const auto* experiment = std::get_if<datasets::ExperimentFile>(&file)) {
    CheckExperimentAgainstConfig(*experiment, path);
  } else {
    CheckRunAgainstConfig(std::get<datasets::RunFile>(file), path);
  }
  return file;
}

}  // namespace ccsrm::sim_io
