// The kinematic planner against an independent, closed-form calculation of
// the cable path lengths through the holes of SPEC 2 for a planar bend.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

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

TEST(KinematicPlanner, BendingPerPulledLengthRecoversEverySegmentsSmallBending) {
  // Each segment bent by its own small (θx, θy) at every joint: the map
  // takes the planned pulled-in lengths back to the four bendings. It is
  // the planning linearised at the straight arm, so what is left is of
  // second order: a chord's curvature over its slope, about d θ / (8 R)
  // (2e-4 of the angle at 0.3°, d = 16 mm, R = 16 mm); 1 % of the largest
  // angle bounds it with room for the x-y coupling of the Cardan angles.
  const Config c = LoadConfig(kPaper);
  const ArmModel model(c.arm);
  const double deg = M_PI / 180.0;
  const Eigen::Vector4d bending(0.2 * deg, -0.3 * deg, 0.15 * deg, 0.25 * deg);
  JointAngles bent(model.num_joints());
  for (int j = 1; j <= model.num_joints(); ++j) {
    bent[j - 1] = bending.segment<2>(2 * model.link(j).segment);
  }
  const auto poses0 =
      ForwardKinematics(model, JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  const auto poses = ForwardKinematics(model, bent);
  Eigen::VectorXd pulled(model.num_cables());
  for (int k = 0; k < model.num_cables(); ++k) {
    pulled[k] = CablePathLength(model, k, poses0) - CablePathLength(model, k, poses);
  }
  const Eigen::MatrixXd map = SegmentBendingPerPulledLength(model);
  ASSERT_EQ(map.rows(), 4);
  ASSERT_EQ(map.cols(), model.num_cables());
  const Eigen::VectorXd recovered = map * pulled;
  for (int r = 0; r < 4; ++r) {
    std::printf("segment %d θ%c: bent %+.5f°, recovered %+.5f°\n", r / 2 + 1, r % 2 ? 'y' : 'x',
                bending[r] / deg, recovered[r] / deg);
    EXPECT_NEAR(recovered[r], bending[r], 0.01 * bending.cwiseAbs().maxCoeff()) << "row " << r;
  }
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
}

// The input the simulator prescribes (the spline's value, rate and
// acceleration) against the planned trajectory itself: the pulled-in length
// L(0) - L(t) of the planned rigid configuration, computed afresh at times
// half-way between the planner's samples, and its central differences.
TEST(KinematicPlanner, InputRatesAndAccelerationsFollowThePlannedPathLength) {
  const Config c = LoadConfig(kPaper);
  const ArmModel model(c.arm);
  const JointTrajectory plan = PaperTrajectory(model, c.protocol);
  const double sample_step = 1e-3;  // the default, which the paper cases use
  const CableInputs inputs = PlanCableInputs(model, plan, c.protocol.duration_s(), sample_step);
  const auto rest = ForwardKinematics(model, plan(0.0));
  const auto pulled_in = [&](int k, double t) {
    return CablePathLength(model, k, rest) -
           CablePathLength(model, k, ForwardKinematics(model, plan(t)));
  };
  // Inside the ramp (0-20 s) and the return (24-44 s), away from the
  // protocol's corners, where the third derivative jumps and a cubic spline
  // is locally less accurate.
  std::vector<double> times;
  for (double t0 : {0.5, 24.5}) {
    for (int i = 0; i < 95; ++i) times.push_back(t0 + 0.2 * i + 0.5 * sample_step);
  }
  // Error budget, relative to the peak of what is compared, for a pulled-in
  // length c q(t/T) with the quintic q and T = 20 s (peaks |q'| = 1.875,
  // |q''| = 5.77, |q'''| = 60, |q''''| = 360): the spline's rate and
  // acceleration errors (Hall and Meyer: dt^3/24 and 3 dt^2/8 times |f''''|)
  // are below 1e-8 at dt = 1 ms; the reference's central differences with
  // h = 10 ms miss by h^2/6 |f'''| and h^2/12 |f''''|, 1.3e-6 of the peaks.
  // We ask for 1e-5 of the peak: ten times that budget, and 15 to 50 times
  // tighter than a shift of the inputs by one sample would cause (dt q''/T
  // against q', 1.5e-4 of the peak rate; dt q'''/T against q'', 5e-4 of
  // the peak acceleration).
  const double h = 1e-2, relative = 1e-5;
  // Rounding: the samples are differences of path lengths L (up to 1.16 m,
  // cable 4-6's) that carry a few ulps of error, delta <= 8 eps L; a cubic
  // spline's second derivative takes them with weights up to 12 / dt^2
  // (6 / dt^2 times the second difference, 4 delta, through a tridiagonal
  // system whose inverse has norm <= 1/2). That floor, 2.5e-8 m/s^2, is what
  // limits the nearly straight cables 1 and 5 (peaks 3-7e-6 m/s^2); on the
  // others it is 1e-4 of the peak, still below a one-sample shift.
  double longest = 0.0;
  for (int k = 0; k < model.num_cables(); ++k)
    longest = std::max(longest, CablePathLength(model, k, rest));
  const double eps = std::numeric_limits<double>::epsilon();
  const double accel_rounding = 12.0 * 8.0 * eps * longest / (sample_step * sample_step);
  std::printf("longest cable path %.3f m\n", longest);
  for (int k = 0; k < model.num_cables(); ++k) {
    std::vector<Eigen::Vector3d> spline, reference;
    for (double t : times) {
      Eigen::Vector3d s;
      inputs.Evaluate(k, t, &s[0], &s[1], &s[2]);
      const double before = pulled_in(k, t - h), now = pulled_in(k, t), after = pulled_in(k, t + h);
      spline.push_back(s);
      reference.emplace_back(now, (after - before) / (2.0 * h),
                             (after - 2.0 * now + before) / (h * h));
    }
    Eigen::Vector3d peak = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& r : reference) peak = peak.cwiseMax(r.cwiseAbs());
    ASSERT_GT(peak[2], 0.0) << "cable " << k + 1;
    Eigen::Vector3d worst = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < times.size(); ++i)
      worst = worst.cwiseMax((spline[i] - reference[i]).cwiseAbs());
    std::printf(
        "cable %d: peak rate %.3g m/s, acceleration %.3g m/s^2; largest error %.2g m, %.2g m/s, "
        "%.2g m/s^2 (rounding floor %.2g)\n",
        k + 1, peak[1], peak[2], worst[0], worst[1], worst[2], accel_rounding);
    for (std::size_t i = 0; i < times.size(); ++i) {
      // Between samples the spline interpolates a smooth length: to a
      // picometre (its error is dt^4 |f''''| 5/384, 1e-19 m).
      EXPECT_NEAR(spline[i][0], reference[i][0], 1e-12) << "cable " << k + 1 << ", t " << times[i];
      EXPECT_NEAR(spline[i][1], reference[i][1], relative * peak[1])
          << "cable " << k + 1 << ", t " << times[i];
      EXPECT_NEAR(spline[i][2], reference[i][2], relative * peak[2] + accel_rounding)
          << "cable " << k + 1 << ", t " << times[i];
    }
  }
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
