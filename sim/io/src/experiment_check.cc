#include "ccsrm/sim_io/experiment_check.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/error.h"

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

// The arm of a non-empty config_yaml, and the shapes that depend on it.
ExperimentArm ParseArm(const datasets::ExperimentFile& experiment, const std::string& file) {
  ExperimentArm arm;
  arm.config = sim::ParseConfig(experiment.config_yaml, file + ": attribute 'config_yaml'");
  arm.model = std::make_shared<const sim::ArmModel>(arm.config.arm);
  const sim::ArmModel& model = *arm.model;

  // ValidateExperimentFile made /input/length_change N × C.
  const std::size_t cables = experiment.input_length_change.shape[1];
  if (cables != 0 && cables != static_cast<std::size_t>(model.num_cables())) {
    ThrowInputError(file, "/input/length_change",
                    "has " + std::to_string(cables) +
                        " cable columns, the arm of its config_yaml has " +
                        std::to_string(model.num_cables()) + " driving cables");
  }
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
    const datasets::ExperimentFile& experiment, const std::string& file) {
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
  if (!experiment.config_yaml.empty()) arm = ParseArm(experiment, file);
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

}  // namespace ccsrm::sim_io
