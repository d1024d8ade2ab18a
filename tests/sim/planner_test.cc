// The kinematic planner against an independent, closed-form calculation of
// the cable path lengths through the holes of SPEC 2 for a planar bend.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim {
namespace {

const std::string kPaper = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";

// Length of a cable at hole offset y (from the bending axis) across one joint
// bent by theta about x: from (y, -d/2) in the parent's joint frame to
// Rx(theta) (y, d/2) in the child's. The x offset of the hole cancels.
double ChordAcrossJoint(double y, double d, double theta) {
  const double dy = y * std::cos(theta) - 0.5 * d * std::sin(theta) - y;
  const double dz = y * std::sin(theta) + 0.5 * d * std::cos(theta) + 0.5 * d;
  return std::hypot(dy, dz);
}

// Pulled-in length of a cable of `segment` (1-based) at hole angle phi when
// every joint bends by theta: the within-link runs do not change, so only
// the chords across the traversed joints do.
double PulledIn(const Config& c, int segment, double phi, double theta) {
  const double d = c.arm.joint_disk_gap_m;
  const double y = c.arm.segments[segment - 1].hole_circle_radius_m * std::sin(phi);
  int joints = 0;
  for (int s = 0; s < segment; ++s) joints += c.arm.segments[s].links;
  return joints * (ChordAcrossJoint(y, d, 0.0) - ChordAcrossJoint(y, d, theta));
}

TEST(KinematicPlanner, InputLengthsMatchClosedFormPathLengthsAtSixDegrees) {
  const Config c = LoadConfig(kPaper);
  const ArmModel model(c.arm);
  const double theta = 6.0 * M_PI / 180.0;
  const JointAngles bent(model.num_joints(), Eigen::Vector2d(theta, 0.0));
  const JointAngles straight(model.num_joints(), Eigen::Vector2d::Zero());
  const auto poses0 = ForwardKinematics(model, straight);
  const auto poses = ForwardKinematics(model, bent);
  for (int k = 0; k < model.num_cables(); ++k) {
    const auto& route = c.arm.driving.cables[k];
    const double planned = CablePathLength(model, k, poses0) - CablePathLength(model, k, poses);
    const double closed_form = PulledIn(c, route.segment, route.hole_angle_rad, theta);
    std::printf("cable %d: pulled in %+.4f mm (closed form %+.4f mm)\n", k + 1, planned * 1e3,
                closed_form * 1e3);
    EXPECT_NEAR(planned, closed_form, 1e-12) << "cable " << k + 1;
  }
  // The antagonistic pairs of SPEC 2: 2/3 in segment 1, 4/6 in segment 2.
  const auto pulled = [&](int k) {
    return CablePathLength(model, k, poses0) - CablePathLength(model, k, poses);
  };
  EXPECT_LT(pulled(1), 0.0);
  EXPECT_GT(pulled(2), 0.0);
  EXPECT_LT(pulled(3), 0.0);
  EXPECT_GT(pulled(5), 0.0);
}

TEST(KinematicPlanner, PaperProtocolFollowsTheQuinticAndHolds) {
  Config c = LoadConfig(kPaper);
  const ArmModel model(c.arm);
  const JointTrajectory plan = PaperTrajectory(model, c.protocol);
  const double a = c.protocol.amplitude_rad;
  EXPECT_DOUBLE_EQ(plan(0.0)[0][0], 0.0);
  EXPECT_NEAR(plan(10.0)[5][0], 0.5 * a, 1e-15);
  EXPECT_DOUBLE_EQ(plan(20.0)[11][0], a);
  EXPECT_DOUBLE_EQ(plan(22.0)[0][0], a);
  EXPECT_NEAR(plan(34.0)[3][0], 0.5 * a, 1e-15);
  EXPECT_DOUBLE_EQ(plan(44.0)[0][0], 0.0);
  EXPECT_DOUBLE_EQ(plan(47.0)[0][1], 0.0);

  const CableInputs inputs = PlanCableInputs(model, plan, c.protocol.duration_s());
  double value, rate, accel;
  // Held inputs during 20-24 s: no rate, no acceleration.
  inputs.Evaluate(2, 22.0, &value, &rate, &accel);
  EXPECT_NEAR(rate, 0.0, 1e-9);
  EXPECT_NEAR(accel, 0.0, 1e-7);
  // Spline rate against a central difference of the sampled plan.
  double v1, v2, r, acc;
  inputs.Evaluate(2, 9.9995, &v1, &r, &acc);
  inputs.Evaluate(2, 10.0005, &v2, &r, &acc);
  inputs.Evaluate(2, 10.0, &value, &rate, &accel);
  EXPECT_NEAR(rate, (v2 - v1) / 1e-3, 1e-9);
  EXPECT_GT(rate, 0.0);
}

TEST(KinematicPlanner, MirroredAmplitudeMirrorsTheInputs) {
  Config plus = LoadConfig(kPaper);
  Config minus = plus;
  minus.protocol.amplitude_rad = -plus.protocol.amplitude_rad;
  const ArmModel model_plus(plus.arm), model_minus(minus.arm);
  const CableInputs a =
      PlanCableInputs(model_plus, PaperTrajectory(model_plus, plus.protocol), 48.0, 0.01);
  const CableInputs b =
      PlanCableInputs(model_minus, PaperTrajectory(model_minus, minus.protocol), 48.0, 0.01);
  // Cables 2 <-> 3 (120 / 240 deg) and 4 <-> 6 (60 / 300 deg) swap roles.
  const int swap[6] = {0, 2, 1, 5, 4, 3};
  for (int k = 0; k < 6; ++k) {
    for (Eigen::Index i = 0; i < a.length_change().rows(); i += 97) {
      EXPECT_NEAR(a.length_change()(i, k), b.length_change()(i, swap[k]), 1e-15);
    }
  }
}

}  // namespace
}  // namespace ccsrm::sim
