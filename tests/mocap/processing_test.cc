// Processing of known marker trajectories: rigid fit, gap filling, world
// frame from the ground cluster, joint angles, quality figures.
#include "ccsrm/mocap/processing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRate = 100.0;

const sim::ArmModel& PaperModel() {
  static const sim::ArmModel model(sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml").arm);
  return model;
}

// Joint angles of frame f of a smooth test motion: every joint different,
// both axes, up to about 8 degrees.
sim::JointAngles Motion(const sim::ArmModel& model, std::size_t f) {
  const double t = static_cast<double>(f) / kRate;
  sim::JointAngles angles(model.num_joints());
  for (int j = 0; j < model.num_joints(); ++j) {
    angles[j] = Eigen::Vector2d(0.14 * std::sin(0.4 * t + 0.3 * j), 0.05 * std::cos(0.3 * t + j));
  }
  return angles;
}

// Markers of the layout for `frames` frames of Motion, in a file frame F
// with p_F = X_FW · p_W.
MarkerTable Record(const MarkerLayout& layout, std::size_t frames,
                   const Eigen::Isometry3d& X_FW = Eigen::Isometry3d::Identity()) {
  MarkerTable table;
  table.Reset(frames, layout.MarkerNames(), false);
  table.rate_hz = kRate;
  for (std::size_t f = 0; f < frames; ++f) {
    const auto poses = sim::ForwardKinematics(PaperModel(), Motion(PaperModel(), f));
    const auto p_WM = PlaceMarkers(layout, poses);
    for (std::size_t k = 0; k < p_WM.size(); ++k) table.set_position(f, k, X_FW * p_WM[k]);
  }
  return table;
}

void Hide(MarkerTable* table, std::size_t marker, std::size_t first, std::size_t length) {
  for (std::size_t f = first; f < first + length; ++f) {
    table->set_position(f, marker, Eigen::Vector3d::Constant(kNaN));
  }
}

ProcessingOptions Unfiltered() {
  ProcessingOptions options;
  options.cutoff_hz = 0.0;
  return options;
}

TEST(FitRigidTransform, RecoversAKnownPoseAndItsNoiseLevel) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.2e-3);
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const RigidBody& plate = layout.bodies[1];
  const Eigen::Isometry3d X_WB = Eigen::Translation3d(0.01, -0.2, 0.4) *
                                 Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, -1).normalized());
  // Exact without noise.
  std::vector<Eigen::Vector3d> p_W;
  for (const auto& p : plate.p_BM) p_W.push_back(X_WB * p);
  EXPECT_LT((FitRigidTransform(plate.p_BM, p_W).matrix() - X_WB.matrix()).norm(), 1e-12);
  // With 0.2 mm noise the rotation error averages what the plate's size
  // implies: about σ / sqrt(Σ r²) ≈ 0.2 mm / 5 cm ≈ 0.25 deg, never 5 times that.
  double sum_sq = 0.0;
  const int trials = 400;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<Eigen::Vector3d> noisy;
    for (const auto& p : plate.p_BM)
      noisy.push_back(X_WB * p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    const Eigen::Isometry3d fit = FitRigidTransform(plate.p_BM, noisy);
    const double angle =
        Eigen::Quaterniond(fit.rotation()).angularDistance(Eigen::Quaterniond(X_WB.rotation()));
    sum_sq += angle * angle;
    EXPECT_LT(angle, 1.5 * M_PI / 180.0);
  }
  const double rms_deg = std::sqrt(sum_sq / trials) * 180.0 / M_PI;
  EXPECT_GT(rms_deg, 0.1);
  EXPECT_LT(rms_deg, 0.6);
}

TEST(ProcessMarkers, JointAnglesOfKnownPosesAreExactWithoutNoise) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const std::size_t frames = 50;
  const MarkerTable table = Record(layout, frames);
  const ProcessingResult result = ProcessMarkers(table, {}, layout, Unfiltered(), "test");
  ASSERT_EQ(result.joint_angles.shape, (std::vector<std::size_t>{frames, 12, 2}));
  for (std::size_t f = 0; f < frames; ++f) {
    const sim::JointAngles truth = Motion(PaperModel(), f);
    const auto poses = sim::ForwardKinematics(PaperModel(), truth);
    for (std::size_t j = 0; j < 12; ++j) {
      EXPECT_NEAR(result.joint_angles.at(f, j, 0), truth[j].x(), 1e-10);
      EXPECT_NEAR(result.joint_angles.at(f, j, 1), truth[j].y(), 1e-10);
      EXPECT_NEAR(result.joint_twist.at(f, j), 0.0, 1e-10);
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_NEAR(result.link_pose.at(f, j, axis), poses[j].p_WB[axis], 1e-12);
      }
    }
  }
  EXPECT_TRUE(result.summary.world_from_ground);
  for (const BodyQuality& b : result.summary.bodies) {
    EXPECT_EQ(b.frames_lost, 0u);
    EXPECT_LT(b.fit_rms_m, 1e-12);
  }
  // The filter passes this slow motion (0.06 Hz) almost untouched: below
  // 0.001 deg away from the ends of a 4 s trial; at the ends the filter's
  // pivot (a line through 0.5 s) misses the curvature of a turning point by
  // x''·(0.5 s)²/12 ≈ 0.03 deg.
  const MarkerTable longer = Record(layout, 400);
  const ProcessingResult filtered = ProcessMarkers(longer, {}, layout, ProcessingOptions(), "test");
  for (std::size_t f = 0; f < 400; ++f) {
    const double tolerance = f >= 100 && f < 300 ? 1.7e-5 : 6e-4;
    EXPECT_NEAR(filtered.joint_angles.at(f, 5, 0), Motion(PaperModel(), f)[5].x(), tolerance) << f;
  }
}

// RMS over frames and joints of (measured - Motion) in degrees, per axis.
Eigen::Vector2d AngleRmsDeg(const ProcessingResult& result) {
  Eigen::Vector2d sum_sq = Eigen::Vector2d::Zero();
  std::size_t n = 0;
  for (std::size_t f = 0; f < result.time.size(); ++f) {
    const sim::JointAngles truth = Motion(PaperModel(), f);
    for (std::size_t j = 0; j < 12; ++j) {
      for (int axis = 0; axis < 2; ++axis) {
        const double e = (result.joint_angles.at(f, j, axis) - truth[j][axis]) * 180.0 / M_PI;
        sum_sq[axis] += e * e;
      }
      ++n;
    }
  }
  return (sum_sq / static_cast<double>(n)).cwiseSqrt();
}

TEST(ProcessMarkers, JointConstrainedFitIsExactAndHalvesTheNoise) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const JointChain chain = JointChain::FromModel(PaperModel());
  const MarkerTable table = Record(layout, 200);
  const ProcessingResult exact = ProcessMarkers(table, {}, layout, Unfiltered(), "test", &chain);
  EXPECT_TRUE(exact.summary.joint_constrained);
  EXPECT_LT(AngleRmsDeg(exact).maxCoeff(), 1e-8);
  // 0.2 mm noise, no filter: per-frame joint-angle noise of each fit.
  MarkerTable noisy = table;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.2e-3);
  for (double& v : noisy.positions_m) v += noise(rng);
  const Eigen::Vector2d independent =
      AngleRmsDeg(ProcessMarkers(noisy, {}, layout, Unfiltered(), "test"));
  const Eigen::Vector2d constrained =
      AngleRmsDeg(ProcessMarkers(noisy, {}, layout, Unfiltered(), "test", &chain));
  std::printf("per-frame joint-angle noise (x, y) deg: independent %.3f %.3f, chain %.3f %.3f\n",
              independent.x(), independent.y(), constrained.x(), constrained.y());
  EXPECT_GT(independent.y(), 0.25);  // the plates alone resolve θy poorly
  EXPECT_LT(constrained.y(), 0.6 * independent.y());
  EXPECT_LT(constrained.x(), 0.9 * independent.x());
  // A chain shorter than the layout is refused.
  JointChain short_chain = chain;
  short_chain.p_BJ_proximal.resize(5);
  EXPECT_NE(testing::InputErrorOf([&] {
              ProcessMarkers(table, {}, layout, Unfiltered(), "f.c3d", &short_chain);
            }).find("joint chain"),
            std::string::npos);
}

TEST(ProcessMarkers, GroundClusterDefinesTheWorldFrame) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  // A lab frame far from W and turned: z up instead of along the arm.
  const Eigen::Isometry3d X_FW = Eigen::Translation3d(1.2, -0.4, 0.9) *
                                 Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  const MarkerTable table = Record(layout, 20, X_FW);
  const ProcessingResult result = ProcessMarkers(table, {}, layout, Unfiltered(), "test");
  EXPECT_TRUE(result.summary.world_from_ground);
  EXPECT_LT(result.summary.ground_fit_rms_m, 1e-12);
  const auto poses = sim::ForwardKinematics(PaperModel(), Motion(PaperModel(), 7));
  for (std::size_t l = 0; l < 12; ++l) {
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(result.link_pose.at(7, l, axis), poses[l].p_WB[axis], 1e-12);
    }
    EXPECT_NEAR(result.joint_angles.at(7, l, 0), Motion(PaperModel(), 7)[l].x(), 1e-10);
  }
  // Without the ground body, the file frame is W: joint 1 then sees the
  // lab's rotation, the other joints (relative rotations) do not.
  MarkerLayout no_ground = layout;
  no_ground.bodies.erase(no_ground.bodies.begin());
  const ProcessingResult in_file_frame = ProcessMarkers(table, {}, no_ground, Unfiltered(), "test");
  EXPECT_FALSE(in_file_frame.summary.world_from_ground);
  EXPECT_GT(std::abs(in_file_frame.joint_angles.at(7, 0, 0) - Motion(PaperModel(), 7)[0].x()), 0.5);
  EXPECT_NEAR(in_file_frame.joint_angles.at(7, 4, 0), Motion(PaperModel(), 7)[4].x(), 1e-10);
}

TEST(ProcessMarkers, ShortGapIsFilledBySplineLongGapByRigidFit) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  MarkerTable table = Record(layout, 200);
  const MarkerTable truth = table;
  const std::size_t short_marker = 4 + 1;         // L01_B
  const std::size_t long_marker = 4 + 4 * 6 + 2;  // L07_C
  Hide(&table, short_marker, 60, 8);
  Hide(&table, long_marker, 50, 80);
  const ProcessingResult result = ProcessMarkers(table, {}, layout, Unfiltered(), "test");
  const MarkerQuality& s = result.summary.markers[short_marker];
  EXPECT_EQ(s.name, "L01_B");
  EXPECT_EQ(s.gaps_before_fill, 1u);
  EXPECT_EQ(s.longest_gap_before_fill, 8u);
  EXPECT_EQ(s.spline_filled_frames, 8u);
  EXPECT_EQ(s.rigid_filled_frames, 0u);
  EXPECT_EQ(s.longest_gap_after_fill, 0u);
  const MarkerQuality& l = result.summary.markers[long_marker];
  EXPECT_EQ(l.spline_filled_frames, 0u);
  EXPECT_EQ(l.rigid_filled_frames, 80u);
  EXPECT_EQ(l.longest_gap_after_fill, 0u);
  // Both fills put the markers where they were (the motion is slow and exact).
  for (std::size_t f = 60; f < 68; ++f) {
    const Eigen::Vector3d p(result.markers.at(f, short_marker, 0),
                            result.markers.at(f, short_marker, 1),
                            result.markers.at(f, short_marker, 2));
    EXPECT_LT((p - truth.position(f, short_marker)).norm(), 1e-6);
  }
  for (std::size_t f = 50; f < 130; ++f) {
    const Eigen::Vector3d p(result.markers.at(f, long_marker, 0),
                            result.markers.at(f, long_marker, 1),
                            result.markers.at(f, long_marker, 2));
    EXPECT_LT((p - truth.position(f, long_marker)).norm(), 1e-9);
  }
  for (const BodyQuality& b : result.summary.bodies) EXPECT_EQ(b.frames_lost, 0u) << b.name;
  // The raw markers in the result keep the gaps.
  EXPECT_TRUE(std::isnan(result.raw_markers.at(65, short_marker, 0)));
}

TEST(ProcessMarkers, WholeLinkLossStaysNaNAndIsReported) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  MarkerTable table = Record(layout, 120);
  // Link 3 (markers 12..15 after the 4 ground markers) vanishes for 5 frames,
  // shorter than the spline limit: still never bridged.
  for (std::size_t m = 0; m < 4; ++m) Hide(&table, 4 + 8 + m, 40, 5);
  // Link 9 keeps only two markers for 30 frames: no pose either.
  Hide(&table, 4 + 32 + 0, 70, 30);
  Hide(&table, 4 + 32 + 1, 70, 30);
  const ProcessingResult result = ProcessMarkers(table, {}, layout, ProcessingOptions(), "test");
  const BodyQuality& link3 = result.summary.bodies[3];
  ASSERT_EQ(link3.name, "link3");
  EXPECT_EQ(link3.frames_lost, 5u);
  EXPECT_EQ(link3.whole_loss_frames, 5u);
  EXPECT_EQ(link3.whole_loss_runs, 1u);
  const BodyQuality& link9 = result.summary.bodies[9];
  EXPECT_EQ(link9.frames_lost, 30u);
  EXPECT_EQ(link9.whole_loss_frames, 0u);
  for (std::size_t f = 0; f < 120; ++f) {
    const bool lost3 = f >= 40 && f < 45;
    EXPECT_EQ(std::isnan(result.link_pose.at(f, 2, 0)), lost3) << f;
    // Joints 3 and 4 need link 3.
    EXPECT_EQ(std::isnan(result.joint_angles.at(f, 2, 0)), lost3) << f;
    EXPECT_EQ(std::isnan(result.joint_angles.at(f, 3, 1)), lost3) << f;
    EXPECT_FALSE(std::isnan(result.joint_angles.at(f, 5, 0))) << f;
    const bool lost9 = f >= 70 && f < 100;
    EXPECT_EQ(std::isnan(result.joint_angles.at(f, 8, 0)), lost9) << f;
  }
  EXPECT_EQ(result.summary.joints[2].frames_lost, 5u);
  EXPECT_EQ(result.summary.joints[9].frames_lost, 30u);
  EXPECT_NE(result.summary.FullReport().find("link3"), std::string::npos);
}

TEST(ProcessMarkers, MatchesViconSubjectPrefixesAndReportsMissingMarkers) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  MarkerTable table = Record(layout, 10);
  for (std::string& label : table.labels) label = "arm:" + label;
  table.labels[5] = "arm:something_else";  // L01_B is missing
  const ProcessingResult result = ProcessMarkers(table, {}, layout, Unfiltered(), "test");
  EXPECT_FALSE(result.summary.markers[5].in_file);
  EXPECT_EQ(result.summary.markers[5].visibility, 0.0);
  EXPECT_EQ(result.summary.input_labels_unused, 1u);
  EXPECT_NEAR(result.joint_angles.at(3, 0, 0), Motion(PaperModel(), 3)[0].x(), 1e-10);
  ASSERT_FALSE(result.summary.warnings.empty());
  EXPECT_NE(result.summary.warnings[0].find("L01_B"), std::string::npos);
}

TEST(ProcessMarkers, WarningsOfTheMarkerFileReachTheSummary) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  MarkerTable table = Record(layout, 10);
  table.warnings = {"holds only 10 complete frame(s)"};
  const ProcessingSummary summary =
      ProcessMarkers(table, {}, layout, Unfiltered(), "cut.c3d").summary;
  EXPECT_EQ(summary.warnings, std::vector<std::string>{"cut.c3d: holds only 10 complete frame(s)"});
  EXPECT_NE(summary.BriefReport().find("; 1 warning(s)"), std::string::npos);
  EXPECT_NE(summary.FullReport().find("warning: cut.c3d: holds only 10"), std::string::npos);
}

TEST(ProcessMarkers, RejectsBadOptionsTimeBasesAndTablesWithoutLayoutMarkers) {
  using testing::InputErrorOf;
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const MarkerTable table = Record(layout, 10);
  ProcessingOptions options;
  options.filter_order = 0;
  EXPECT_NE(InputErrorOf([&] {
              ProcessMarkers(table, {}, layout, options, "f.c3d");
            }).find("f.c3d: processing options: filter_order"),
            std::string::npos);
  options = ProcessingOptions();
  options.cutoff_hz = 60.0;
  EXPECT_NE(InputErrorOf([&] {
              ProcessMarkers(table, {}, layout, options, "f.c3d");
            }).find("half the frame rate"),
            std::string::npos);
  std::vector<double> uneven = {0, 0.01, 0.02, 0.03, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};
  EXPECT_NE(InputErrorOf([&] {
              ProcessMarkers(table, uneven, layout, Unfiltered(), "f.c3d");
            }).find("uniformly"),
            std::string::npos);
  MarkerTable strangers = table;
  for (std::string& label : strangers.labels) label = "X" + label;
  EXPECT_NE(InputErrorOf([&] {
              ProcessMarkers(strangers, {}, layout, Unfiltered(), "f.c3d");
            }).find("no marker of the rigid bodies"),
            std::string::npos);
}

// Issue 33: markers that were never seen (all NaN, or all infinite in an
// HDF5 file) and a single frame are refused at this door, naming the file and
// the field, instead of giving an experiment with no finite angle.
TEST(ProcessMarkers, RefusesMarkersNeverSeenAndASingleFrame) {
  using testing::InputErrorOf;
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  MarkerTable unseen = Record(layout, 10);
  for (double& v : unseen.positions_m) v = kNaN;
  EXPECT_EQ(InputErrorOf([&] { ProcessMarkers(unseen, {}, layout, Unfiltered(), "f.c3d"); }),
            "f.c3d: marker data: has no finite sample (every position NaN or infinite): no "
            "marker was ever seen, so there is no pose to fit");
  unseen.format = "ccsrm-dataset";
  EXPECT_EQ(InputErrorOf([&] {
              ProcessMarkers(unseen, {}, layout, Unfiltered(), "e.h5");
            }).rfind("e.h5: /mocap/markers: has no finite sample", 0),
            0u);

  MarkerTable one = Record(layout, 1);
  one.rate_hz = 0.0;  // what a one-frame HDF5 file gives: no rate to derive
  one.format = "ccsrm-dataset";
  EXPECT_EQ(InputErrorOf([&] { ProcessMarkers(one, {0.5}, layout, Unfiltered(), "e.h5"); }),
            "e.h5: /mocap/time: has 1 frame(s): processing needs at least 2 (a frame rate for "
            "the time base and the low-pass filter)");
}

}  // namespace
}  // namespace ccsrm::mocap
