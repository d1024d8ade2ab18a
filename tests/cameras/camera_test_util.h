#pragma once
// Shared set-up of the camera tests: the paper arm, planned motions whose
// markers are known exactly, and scratch directories.
#include <gtest/gtest.h>
#include <unistd.h>
#include <Eigen/Core>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::cameras::testing {

inline const sim::ArmModel& PaperModel() {
  static const sim::ArmModel model(sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml").arm);
  return model;
}

inline const mocap::MarkerLayout& PaperLayout() {
  static const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(PaperModel());
  return layout;
}

inline double DegToRad(double degrees) { return degrees * M_PI / 180.0; }

// Planned joint angles like the paper's case 2 at +amplitude: every joint
// follows the quintic ramp over 0-20 s and holds, the amplitude falls from
// root to tip within each segment except the last joint, and a small theta_y
// appears.
inline sim::JointAngles CaseTwoLikeAngles(double t, double amplitude_deg) {
  const int joints = PaperModel().num_joints();
  const double blend = sim::QuinticBlend(std::clamp(t / 20.0, 0.0, 1.0));
  sim::JointAngles angles(joints);
  for (int j = 0; j < joints; ++j) {
    const int in_segment = j % 6;
    const double scale = in_segment == 5 ? 0.9 : 1.25 - 0.1 * in_segment;
    angles[j] = Eigen::Vector2d(DegToRad(amplitude_deg * scale * blend),
                                DegToRad(0.15 * std::sin(0.7 * j) * blend));
  }
  return angles;
}

// Markers of the paper arm's default layout at the given times.
inline MarkerMotion PlannedMotion(const std::vector<double>& times, double amplitude_deg,
                                  std::vector<sim::JointAngles>* angles_out = nullptr) {
  MarkerMotion motion;
  motion.marker_names = PaperLayout().MarkerNames();
  for (double t : times) {
    const sim::JointAngles angles = CaseTwoLikeAngles(t, amplitude_deg);
    motion.time_s.push_back(t);
    motion.p_WM.push_back(
        mocap::PlaceMarkers(PaperLayout(), sim::ForwardKinematics(PaperModel(), angles)));
    if (angles_out != nullptr) angles_out->push_back(angles);
  }
  motion.rate_hz = times.size() > 1 ? (times.size() - 1) / (times.back() - times.front()) : 100.0;
  return motion;
}

inline std::vector<double> EvenTimes(double first, double last, int count) {
  std::vector<double> times;
  for (int k = 0; k < count; ++k)
    times.push_back(first + (last - first) * k / std::max(count - 1, 1));
  return times;
}

// A fresh directory under the build tree, removed with its contents; the
// process id keeps tests that run in parallel apart.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(std::filesystem::path(CCSRM_BINARY_DIR) / "test-scratch" /
              (name + "-" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& file) const { return (path_ / file).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace ccsrm::cameras::testing
