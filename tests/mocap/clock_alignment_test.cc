// Clock alignment of an actuator log with the mocap clock: edges of a
// trigger pulse, the pairing of edge sequences (offset, drift, ambiguity),
// and the offset estimated from joint angles through the kinematics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/clock_alignment.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/protocol.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::InputErrorOf;

// A 0/5 V pulse train at the times `t`, each edge a 3 ms linear ramp (a TTL
// pulse through the A/D's input filter) starting at the edge time.
constexpr double kRampS = 3e-3;
Eigen::VectorXd PulseTrain(const Eigen::VectorXd& t, const std::vector<double>& rises,
                           double width_s) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    for (double r : rises) {
      const double up = std::clamp((t[i] - r) / kRampS, 0.0, 1.0);
      const double down = std::clamp((t[i] - r - width_s) / kRampS, 0.0, 1.0);
      v[i] += 5.0 * (up - down);
    }
  }
  return v;
}

TEST(FindEdges, InterpolatedCrossingsOfARampAreExact) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(2001, 0.0, 2.0);  // 1 kHz
  const std::vector<double> rises = {0.2003, 0.9, 1.4567};
  const Eigen::VectorXd v = PulseTrain(t, rises, 0.05);
  const std::vector<double> edges = FindEdges(t, v);  // threshold: half way (2.5 V)
  ASSERT_EQ(edges.size(), 3u);
  // The ramp crosses 2.5 V half way (1.5 ms after it starts); it spans more
  // than two samples, so the two samples around the crossing lie on it and
  // linear interpolation is exact up to rounding.
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(edges[k], rises[k] + 0.5 * kRampS, 1e-9);
  EdgeOptions falling;
  falling.rising = false;
  const std::vector<double> falls = FindEdges(t, v, falling);
  ASSERT_EQ(falls.size(), 3u);
  EXPECT_NEAR(falls[1], 0.9 + 0.05 + 0.5 * kRampS, 1e-9);
  // A log's digital column: the first sample past the threshold.
  EdgeOptions at_sample;
  at_sample.interpolate = false;
  EXPECT_NEAR(FindEdges(t, v, at_sample)[0], 0.202, 1e-12);  // 0.2003 + 1.5 ms → 0.2018 → 0.202
}

TEST(FindEdges, NoiseAroundTheLevelCountsOnce) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(1001, 0.0, 1.0);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(t.size());
  for (Eigen::Index i = 500; i < t.size(); ++i) v[i] = 1.0;
  v[501] = 0.4;  // a bounce just after the edge, shorter than min_separation_s
  v[502] = 0.9;
  EdgeOptions options;
  options.threshold = 0.5;
  EXPECT_EQ(FindEdges(t, v, options).size(), 1u);
}

TEST(AlignByTrigger, RecoversOffsetAndDriftFromIrregularPulses) {
  // Mocap edges over 20 s at irregular intervals; the log started 1.37 s
  // earlier, runs 80 ppm fast and saw one pulse before the mocap started.
  const std::vector<double> mocap = {0.61, 2.13, 3.02, 5.55, 7.19, 9.90, 12.04, 15.31, 17.2, 19.7};
  const double offset = 1.37, drift = 80e-6;
  std::mt19937 rng(3);
  std::normal_distribution<double> jitter(0.0, 0.1e-3);
  std::vector<double> log = {0.4};
  for (double t : mocap) log.push_back(offset + (1.0 + drift) * t + jitter(rng));
  TriggerAlignmentOptions options;
  options.mocap_edge_sigma_s = 0.1e-3;
  options.log_edge_sigma_s = 0.1e-3;
  const ClockFit fit = AlignByTrigger(mocap, log, options, "test");
  // 10 pairs with 0.1 ms timing over 19 s: the offset to a few 0.1 ms, the
  // drift to σ ≈ 0.1 ms / (19 s × √(10/12)) ≈ 6 ppm; 4 σ bounds.
  EXPECT_NEAR(fit.offset_s, offset, 4.0 * fit.offset_sigma_s);
  EXPECT_NEAR(fit.drift, drift, 4.0 * fit.drift_sigma);
  EXPECT_LT(fit.drift_sigma, 10e-6);
  EXPECT_LT(std::abs(fit.offset_s - offset), 1e-3);
  EXPECT_EQ(fit.method, "trigger");
}

TEST(AlignByTrigger, OneEdgeEachGivesTheOffsetOnly) {
  TriggerAlignmentOptions options;
  options.mocap_edge_sigma_s = 0.3e-3;
  options.log_edge_sigma_s = 0.6e-3;
  const ClockFit fit = AlignByTrigger({2.0}, {3.5}, options, "test");
  EXPECT_DOUBLE_EQ(fit.offset_s, 1.5);
  EXPECT_EQ(fit.drift, 0.0);
  EXPECT_EQ(fit.drift_sigma, 0.0);
  EXPECT_NEAR(fit.offset_sigma_s, std::hypot(0.3e-3, 0.6e-3), 1e-12);
}

TEST(AlignByTrigger, RegularPulsesWithExtraLogEdgesAreAmbiguous) {
  // A pulse every second: shifting the pairing by one pulse fits as well.
  std::vector<double> mocap, log;
  for (int k = 0; k < 5; ++k) mocap.push_back(1.0 + k);
  for (int k = 0; k < 7; ++k) log.push_back(0.3 + k);
  TriggerAlignmentOptions options;
  options.mocap_edge_sigma_s = 0.3e-3;
  options.log_edge_sigma_s = 0.6e-3;
  const std::string error = InputErrorOf([&] { AlignByTrigger(mocap, log, options, "rec.c3d"); });
  EXPECT_NE(error.find("rec.c3d: trigger: ambiguous alignment: 3 pairings"), std::string::npos)
      << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(AlignByTrigger, EdgesThatDoNotMatchAreRefused) {
  TriggerAlignmentOptions options;
  options.mocap_edge_sigma_s = 0.3e-3;
  options.log_edge_sigma_s = 0.6e-3;
  const std::string error = InputErrorOf([&] {
    AlignByTrigger({1.0, 2.0, 5.0}, {1.0, 4.0, 4.5}, options, "rec.c3d");
  });
  EXPECT_NE(error.find("no pairing"), std::string::npos) << error;
  EXPECT_NE(InputErrorOf([&] {
              AlignByTrigger({}, {1.0}, options, "rec.c3d");
            }).find("no edge in the C3D analog channel"),
            std::string::npos);
}

// Joint angles of a smooth, non-periodic motion of every joint and the log
// of the lengths a quasi-static arm would pull in, on a clock offset by
// `offset` and sampled at 500 Hz.
struct KinematicRecording {
  std::vector<double> mocap_time;
  std::vector<double> angles;
  Eigen::VectorXd log_time;
  Eigen::MatrixXd log_length;
};

enum class Motion { kRamps, kPeriodic, kTwoSines };

KinematicRecording MakeRecording(const sim::ArmModel& model, double offset, Motion motion,
                                 double duration_s = 4.0, double drift = 0.0) {
  const int joints = model.num_joints();
  auto theta_at = [&](double t) {
    sim::JointAngles theta(joints);
    for (int j = 0; j < joints; ++j) {
      double x = 0.0;
      switch (motion) {
        case Motion::kPeriodic:
          x = 0.02 * std::sin(2.0 * M_PI * t);
          break;
        case Motion::kRamps:
          x = 0.03 * sim::QuinticBlend(std::clamp(t / 1.5, 0.0, 1.0)) -
              0.02 * sim::QuinticBlend(std::clamp((t - 2.2) / 1.0, 0.0, 1.0));
          break;
        case Motion::kTwoSines:  // incommensurate: never repeats
          x = 0.03 * std::sin(0.7 * t) + 0.02 * std::sin(1.9 * t + 1.0);
          break;
      }
      theta[j] = Eigen::Vector2d(x, 0.5 * x);
    }
    return theta;
  };
  const std::vector<sim::LinkPose> straight =
      sim::ForwardKinematics(model, sim::JointAngles(joints, Eigen::Vector2d::Zero()));
  KinematicRecording r;
  // Measured angles carry the noise of the marker fits (0.2 mrad, about
  // 0.01°, a link pose from markers 0.1 mm apart over 0.5 m).
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 2e-4);
  const int frames = static_cast<int>(std::lround(duration_s * 100.0));
  for (int f = 0; f < frames; ++f) {  // at 100 Hz
    const double t = f * 0.01;
    r.mocap_time.push_back(t);
    for (const Eigen::Vector2d& a : theta_at(t)) {
      r.angles.push_back(a.x() + noise(rng));
      r.angles.push_back(a.y() + noise(rng));
    }
  }
  // At 500 Hz from 2 s before the mocap's start (log clock) to 2 s after its
  // end: the periodic motion has equally good offsets one period either side.
  const int samples = static_cast<int>(std::lround((duration_s + 4.0) / 0.002));
  r.log_time.resize(samples);
  r.log_length.resize(samples, model.num_cables());
  for (int i = 0; i < samples; ++i) {
    const double t_log = offset - 2.0 + i * 0.002;
    r.log_time[i] = t_log;
    const std::vector<sim::LinkPose> poses =
        sim::ForwardKinematics(model, theta_at((t_log - offset) / (1.0 + drift)));
    for (int c = 0; c < model.num_cables(); ++c) {
      // Stretch (×1.02) and a zero of the log's own: the affine fit absorbs both.
      r.log_length(i, c) = 1.02 * (sim::CablePathLength(model, c, straight) -
                                   sim::CablePathLength(model, c, poses)) +
                           0.003;
    }
  }
  return r;
}

TEST(AlignByKinematics, RecoversTheOffsetWithinOneFrame) {
  const sim::ArmModel model(
      sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml").arm);
  const double offset = 1.37;
  const KinematicRecording r = MakeRecording(model, offset, Motion::kRamps);
  const ClockFit fit =
      AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, {}, "test");
  // The issue asks for one mocap frame (10 ms); the reported uncertainty
  // must cover the error (4 σ).
  EXPECT_NEAR(fit.offset_s, offset, 0.01);
  EXPECT_NEAR(fit.offset_s, offset, 4.0 * fit.offset_sigma_s);
  EXPECT_GT(fit.offset_sigma_s, 0.0);
  std::printf("kinematic offset %.6f s ± %.3g ms (true %.2f s)\n", fit.offset_s,
              fit.offset_sigma_s * 1e3, offset);
  EXPECT_EQ(fit.method, "estimate");
}

TEST(AlignByKinematics, ASearchWindowFindsTheSameOffset) {
  const sim::ArmModel model(
      sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml").arm);
  const KinematicRecording r = MakeRecording(model, 1.37, Motion::kRamps);
  const ClockFit whole =
      AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, {}, "test");
  KinematicAlignmentOptions window;
  window.search_center_s = 1.2;
  window.search_half_width_s = 0.5;
  const ClockFit windowed =
      AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, window, "test");
  // The same grid points around the minimum: the same parabola, to rounding.
  EXPECT_NEAR(windowed.offset_s, whole.offset_s, 1e-3 * whole.offset_sigma_s + 1e-9);
  window.search_center_s = 10.0;
  const std::string error = InputErrorOf([&] {
    AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, window, "rec");
  });
  EXPECT_NE(error.find("no offset within 0.5 s of 10 s"), std::string::npos) << error;
}

TEST(AlignByKinematics, PeriodicMotionIsAmbiguous) {
  const sim::ArmModel model(
      sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml").arm);
  const KinematicRecording r = MakeRecording(model, 1.37, Motion::kPeriodic);
  const std::string error = InputErrorOf([&] {
    AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, {}, "rec.c3d");
  });
  EXPECT_NE(error.find("ambiguous alignment"), std::string::npos) << error;
}

// A long recording (60 s) on a clock 300 ppm fast: 18 ms of drift over the
// recording, which the drift-free estimate would smear; with estimate_drift
// both come back.
TEST(AlignByKinematics, EstimatesTheDriftOfALongRecording) {
  const sim::ArmModel model(
      sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml").arm);
  const double offset = 0.81, drift = 300e-6;
  const KinematicRecording r = MakeRecording(model, offset, Motion::kTwoSines, 60.0, drift);
  KinematicAlignmentOptions options;
  options.estimate_drift = true;
  const ClockFit fit =
      AlignByKinematics(model, r.mocap_time, r.angles, r.log_time, r.log_length, options, "test");
  std::printf("kinematic offset %.6f s ± %.3g ms, drift %.1f ± %.2g ppm (true %.2f s, %.0f ppm)\n",
              fit.offset_s, fit.offset_sigma_s * 1e3, fit.drift * 1e6, fit.drift_sigma * 1e6,
              offset, drift * 1e6);
  // One frame (10 ms) for the offset, as the issue asks; the drift to the
  // 20 ppm the issue asks of the trigger; and both within 4 reported σ.
  EXPECT_NEAR(fit.offset_s, offset, 0.01);
  EXPECT_NEAR(fit.drift, drift, 20e-6);
  EXPECT_NEAR(fit.offset_s, offset, 4.0 * fit.offset_sigma_s);
  EXPECT_NEAR(fit.drift, drift, 4.0 * fit.drift_sigma);
}

TEST(ResampleOntoMocapTimes, RefusesALogThatDoesNotCoverTheRecording) {
  ClockFit fit;
  fit.offset_s = 0.5;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0.0, 1.0);
  const Eigen::MatrixXd l = t;
  const Eigen::MatrixXd inside = ResampleOntoMocapTimes(fit, {0.0, 0.25, 0.5}, t, l, "log.csv");
  EXPECT_NEAR(inside(1, 0), 0.75, 1e-12);
  const std::string error = InputErrorOf([&] {
    ResampleOntoMocapTimes(fit, {0.0, 0.6}, t, l, "log.csv");
  });
  EXPECT_NE(error.find("log.csv: actuator log: covers mocap time -0.5 to 0.5 s"), std::string::npos)
      << error;
}

}  // namespace
}  // namespace ccsrm::mocap
