// An elastic backbone in place of the connecting mechanisms (issue 46): a
// segment whose joints bend against k_b E I / l, as a tendon-driven
// continuum robot's rod does.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/simulator.h"
#include "sim_runs.h"

namespace ccsrm::sim {
namespace {

using test_support::EnergyBalance;
using test_support::OptionsFor;
using test_support::PullAndHold;
using test_support::PullAndHoldBalance;
using test_support::SmallArm;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kPi = 3.14159265358979323846;

// SmallArm(links) with its connecting mechanisms replaced by a steel-like
// rod of 5 mm (E I / l about 30 N m/rad per joint, the paper's small-S
// stiffness) and frictionless holes.
Config BackboneArm(int links) {
  Config c = SmallArm(links);
  SegmentConfig& s = c.arm.segments[0];
  s.connecting_pattern.assign(links - 1, ConnectingKind::kNone);
  s.backbone.youngs_modulus_pa = 5.0e10;
  s.backbone.outer_diameter_m = 5.0e-3;
  c.parameters.k_b = 1.0;
  c.parameters.c_b = 0.0;
  c.solver.hole_friction = HoleFrictionModel::kOff;
  Validate(c);
  return c;
}

std::string ErrorOf(const Config& c) {
  try {
    Validate(c);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Backbone, JointStiffnessIsTheRodsBendingStiffnessOverTheLinkLength) {
  const Config c = BackboneArm(4);
  const SegmentConfig& s = c.arm.segments[0];
  const double ei = 5.0e10 * kPi * std::pow(5.0e-3, 4) / 64.0;
  EXPECT_NEAR(s.backbone.bending_stiffness_nm2(), ei, 1e-12 * ei);
  const ArmModel model(c.arm);
  EXPECT_TRUE(model.connecting_pairs().empty());
  for (int j = 1; j <= model.num_joints(); ++j)
    EXPECT_NEAR(model.backbone_stiffness_nmprad(j), ei / s.link_length_m, 1e-12 * ei);
  // A hollow rod: I = pi (D^4 - d^4) / 64.
  BackboneGeometry tube = s.backbone;
  tube.inner_diameter_m = 4.0e-3;
  EXPECT_NEAR(tube.bending_stiffness_nm2(),
              5.0e10 * kPi * (std::pow(5.0e-3, 4) - std::pow(4.0e-3, 4)) / 64.0, 1e-12 * ei);
}

TEST(Backbone, ConfigurationNamesWhatASegmentWithoutMechanismsLacks) {
  Config c = BackboneArm(4);
  // A segment with neither mechanisms nor a rod would be a free chain.
  Config free = c;
  free.arm.segments[0].backbone = BackboneGeometry{};
  EXPECT_THAT(ErrorOf(free), HasSubstr("arm.segments[0].connecting_pattern"));
  EXPECT_THAT(ErrorOf(free), HasSubstr("'none' needs an elastic backbone"));
  Config hollow = c;
  hollow.arm.segments[0].backbone.inner_diameter_m = 6.0e-3;
  EXPECT_THAT(ErrorOf(hollow), HasSubstr("backbone.inner_diameter_m"));
  // Written out and read back: the same arm, without mechanism sections it
  // does not use, and the rod's parameters in their own section.
  c.parameters.k_b = 0.7;
  c.parameters.c_b = 0.02;
  const std::string yaml = ToYaml(c);
  EXPECT_THAT(yaml, Not(HasSubstr("small_s")));
  EXPECT_THAT(yaml, HasSubstr("connecting_pattern: [none, none, none]"));
  const Config back = ParseConfig(yaml, "written.yaml");
  EXPECT_EQ(back.arm.segments[0].connecting_pattern, c.arm.segments[0].connecting_pattern);
  EXPECT_EQ(back.arm.segments[0].backbone.outer_diameter_m, 5.0e-3);
  EXPECT_EQ(back.parameters.k_b, 0.7);
  EXPECT_EQ(back.parameters.c_b, 0.02);
  // The paper's arm has no rod: its parameters read as the neutral ones.
  const Config paper = LoadConfig(test_support::PaperConfigPath());
  EXPECT_EQ(paper.parameters.k_b, 1.0);
  EXPECT_EQ(paper.parameters.c_b, 0.0);
  EXPECT_THAT(ToYaml(paper), Not(HasSubstr("backbone")));
}

TEST(Backbone, RecordedRobotsConfigurationIsThreeRodSegmentsOfTenDisks) {
  // configs/ftdcr_v4.yaml, the tendon-driven robot of ../shared/data/tdcr
  // (its published description: 10 disks over 60, 62.5 and 64 mm, a rod of
  // E = 50 GPa and 0.5 mm radius, three tendons 4.5 mm out per segment).
  const Config c = LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/ftdcr_v4.yaml");
  EXPECT_TRUE(c.warnings.empty()) << c.warnings.front();
  const ArmModel model(c.arm);
  ASSERT_EQ(model.num_joints(), 30);
  ASSERT_EQ(model.num_cables(), 9);
  EXPECT_TRUE(model.connecting_pairs().empty());
  const double ei = 5.0e10 * kPi * std::pow(0.5e-3, 4) / 4.0;  // pi E r^4 / 4
  const double lengths[] = {0.060, 0.0625, 0.064};
  for (int j = 1; j <= 30; ++j) {
    EXPECT_NEAR(model.backbone_stiffness_nmprad(j), ei / (lengths[(j - 1) / 10] / 10.0), 1e-9 * ei)
        << "joint " << j;
  }
  for (int i = 0; i < 9; ++i) EXPECT_EQ(model.cables()[i].segment, i / 3);
  // Written back, the same arm.
  const Config back = ParseConfig(ToYaml(c), "written.yaml");
  EXPECT_EQ(ToYaml(back), ToYaml(c));
}

TEST(Backbone, RodBooksItsEnergy) {
  // No friction or damping: the rod's k theta^2 / 2 is elastic and the
  // model smoothing's work is booked as dissipated, so kinetic + elastic +
  // dissipated stays put once the input holds (as for the connecting
  // springs, ArmDynamics.EnergyBookkeepingHoldsWithModelSmoothing).
  const EnergyBalance e = PullAndHoldBalance("rod", BackboneArm(4), [](Config*) {});
  ASSERT_GT(e.kinetic_max, 1e-7);
  ASSERT_GT(e.elastic_swing, 1e-7);
  EXPECT_LT(e.drift, 0.01 * std::max(e.kinetic_max, std::abs(e.dissipated)));
}

// A link's pose in a frame: position and rotation (e0 the scalar part).
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d At(const Eigen::Vector3d& p_L) const { return position + rotation * p_L; }
};

Pose LinkPose(const TrajectoryFrame& frame, int link) {
  const Eigen::Matrix<double, 7, 1>& q = frame.link_pose[static_cast<std::size_t>(link - 1)];
  Pose pose;
  pose.position = q.head<3>();
  pose.rotation = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).normalized().toRotationMatrix();
  return pose;
}

TEST(Backbone, OneTendonBendsTheSegmentUniformlyAgainstTheRod) {
  // Frictionless holes carry one tension along each tendon and every tendon
  // ends at the segment's last disk, so every joint feels the same moment
  // and, against the same rod, bends by the same angle: a constant
  // curvature. At rest the rod's k |theta| balances, at every joint, the
  // moment about the joint of the tendons crossing its gap, taken from the
  // run's own poses and tensions (the cut through the gap: the joint's
  // reaction passes through the joint). About r dT, plus the tendons'
  // compression acting through the gap's offset, (d/2) sin(theta/2) sum T.
  // The ALE elements' tension is the Green strain's, EA (|r'|^2 - 1)/2; the
  // force a tendon exerts is that times its stretch |r'| = sqrt(1 + 2T/EA)
  // (0.6 % here, which the moment would otherwise miss).
  Config c = BackboneArm(5);
  c.parameters.c_b = 0.5;  // to settle
  const ArmModel model(c.arm);
  const CableInputs inputs = PullAndHold(model, 0, 4.0e-3, 0.5, 2.0);
  const SimulationResult result =
      Simulate(model, c.parameters, inputs, OptionsFor(c, inputs.end_time()));
  ASSERT_TRUE(result.summary.completed()) << result.summary.message;
  const TrajectoryFrame& end = result.trajectory.frames.back();
  const double k = model.backbone_stiffness_nmprad(1);
  const double r = c.arm.segments[0].hole_circle_radius_m;
  const double d = c.arm.joint_disk_gap_m;
  const double ea = c.arm.driving.youngs_modulus_pa * c.arm.driving.cross_section_m2;
  const double theta_1 = end.joint_angles[0].norm();
  ASSERT_GT(theta_1, 1.0 * kPi / 180.0) << "the pull must bend the joints";
  for (int j = 1; j <= model.num_joints(); ++j) {
    const Eigen::Vector2d& angle = end.joint_angles[static_cast<std::size_t>(j - 1)];
    EXPECT_LT(end.joint_rates[static_cast<std::size_t>(j - 1)].norm(), 1e-4) << "settled";
    // The same bend everywhere, to the integration's tolerance.
    EXPECT_NEAR(angle.norm(), theta_1, 1e-6 * theta_1) << "joint " << j;
    // The ground is the parent of joint 1, its hole d/2 below the joint.
    const Pose parent = j > 1 ? LinkPose(end, j - 1) : Pose{};
    const Pose child = LinkPose(end, j);
    const double parent_end = j > 1 ? 0.5 * model.link(j - 1).length_m : 0.0;
    const double child_end = 0.5 * model.link(j).length_m;
    const Eigen::Vector3d joint = parent.At(Eigen::Vector3d(0, 0, parent_end));
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (int i = 0; i < model.num_cables(); ++i) {
      const double a = c.arm.driving.cables[static_cast<std::size_t>(i)].hole_angle_rad;
      const Eigen::Vector3d below =
          parent.At(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), parent_end - 0.5 * d));
      const Eigen::Vector3d above =
          child.At(Eigen::Vector3d(r * std::cos(a), r * std::sin(a), -child_end + 0.5 * d));
      const double tension = end.element_tension[static_cast<std::size_t>(i)].back();
      const double force = tension * std::sqrt(1.0 + 2.0 * tension / ea);
      moment += (above - joint).cross(force * (below - above).normalized());
    }
    // What is left is the integration's and the constraints' error.
    EXPECT_NEAR(k * angle.norm(), moment.norm(), 1e-4 * moment.norm()) << "joint " << j;
  }
  std::printf("bend %.4f deg per joint, k theta %.5f N m\n", theta_1 * 180.0 / kPi, k * theta_1);
}

}  // namespace
}  // namespace ccsrm::sim
