#include "ccsrm/mocap/marker_layout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"

namespace ccsrm::mocap {
namespace {

const sim::ArmModel& PaperModel() {
  static const sim::ArmModel model(sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml").arm);
  return model;
}

TEST(DefaultMarkerLayout, PaperArmHasFourMarkersPerLinkAndAFourMarkerBase) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  ASSERT_EQ(layout.bodies.size(), 13u);
  EXPECT_EQ(layout.bodies[0].name, "base");
  EXPECT_EQ(layout.bodies[12].name, "link12");
  EXPECT_EQ(layout.marker_count(), 52u);
  const std::vector<std::string> names = layout.MarkerNames();
  EXPECT_EQ(names.front(), "B0_A");
  EXPECT_EQ(names[4], "L01_A");
  EXPECT_EQ(names.back(), "L12_D");
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
}

TEST(DefaultMarkerLayout, PlateDistancesAreAllDifferentSoMarkersCanBeTold) {
  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const RigidBody& link = layout.bodies[1];
  std::vector<double> d;
  for (size_t a = 0; a < link.p_BM.size(); ++a)
    for (size_t b = a + 1; b < link.p_BM.size(); ++b)
      d.push_back((link.p_BM[a] - link.p_BM[b]).norm());
  std::sort(d.begin(), d.end());
  for (size_t k = 1; k < d.size(); ++k) EXPECT_GT(d[k] - d[k - 1], 2e-3) << "distances too alike";
  EXPECT_GT(d.front(), 0.015);  // markers of 10-14 mm need this much room
}

TEST(PlaceMarkers, StraightArmPutsPlatesAboveTheirLinkCentres) {
  const sim::ArmModel& model = PaperModel();
  const MarkerLayout layout = DefaultMarkerLayout(model);
  const sim::JointAngles straight(model.num_joints(), Eigen::Vector2d::Zero());
  const std::vector<sim::LinkPose> poses = sim::ForwardKinematics(model, straight);
  const std::vector<Eigen::Vector3d> p_WM = PlaceMarkers(layout, poses);
  ASSERT_EQ(p_WM.size(), layout.marker_count());
  EXPECT_EQ(p_WM[0], layout.bodies[0].p_BM[0]);  // ground markers are in W
  for (size_t b = 1; b < layout.bodies.size(); ++b) {
    const sim::LinkPose& pose = poses[layout.bodies[b].link - 1];
    const double half = 0.5 * model.links()[layout.bodies[b].link - 1].length_m;
    for (size_t m = 0; m < 4; ++m) {
      const Eigen::Vector3d p = p_WM[4 * b + m];
      EXPECT_NEAR((p - pose.p_WB - layout.bodies[b].p_BM[m]).norm(), 0.0, 1e-12);
      EXPECT_LT(std::abs(p.z() - pose.p_WB.z()), half - 0.01);  // on its own link
    }
  }
}

TEST(PlaceMarkers, BentArmMovesMarkersRigidlyWithTheirLink) {
  const sim::ArmModel& model = PaperModel();
  const MarkerLayout layout = DefaultMarkerLayout(model);
  sim::JointAngles bent(model.num_joints(), Eigen::Vector2d(0.1, -0.05));
  const std::vector<sim::LinkPose> poses = sim::ForwardKinematics(model, bent);
  const std::vector<Eigen::Vector3d> p_WM = PlaceMarkers(layout, poses);
  for (size_t b = 1; b < layout.bodies.size(); ++b) {
    for (size_t m = 0; m + 1 < 4; ++m) {
      const double d_world = (p_WM[4 * b + m] - p_WM[4 * b + m + 1]).norm();
      const double d_body = (layout.bodies[b].p_BM[m] - layout.bodies[b].p_BM[m + 1]).norm();
      EXPECT_NEAR(d_world, d_body, 1e-12);
    }
  }
}

}  // namespace
}  // namespace ccsrm::mocap
