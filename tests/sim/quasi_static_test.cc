// The quasi-static replay (SimulationOptions::quasi_static; sim/src/
// quasi_static.h): its sparse Jacobian against the dense one, friction's
// hysteresis, the refusal of laws that hold nothing at rest, and the replay
// against the dynamic arm on the paper's slow protocol (issue 46).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "../support/sim_runs.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/simulator.h"
#include "dynamics.h"
#include "quasi_static.h"

namespace ccsrm::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

void UsePreslidingFriction(SolverConfig* solver) {
  solver->hole_friction = HoleFrictionModel::kPresliding;
  solver->conduit_friction = ConduitFrictionModel::kPresliding;
}

// A small arm's settled residual and its solver, at rest: x the straight
// arm's coordinates (InitialState) and zero multipliers.
struct SettledArm {
  explicit SettledArm(std::optional<double> mu_s = std::nullopt)
      : config(PreslidingSmallArm(mu_s)),
        model(config.arm),
        inputs(test_support::PullAndHold(model, 0, 2e-3, 1.0, 2.0)),
        dynamics(model, config.parameters, inputs, config.solver),
        solver(model, &dynamics),
        n(dynamics.num_coordinates()),
        size(solver.size()),
        x(Eigen::VectorXd::Zero(size)) {
    x.head(n) = dynamics.InitialState().head(n);
  }
  static Config PreslidingSmallArm(std::optional<double> mu_s) {
    Config c = test_support::SmallArm(5);
    UsePreslidingFriction(&c.solver);
    if (mu_s) c.parameters.mu_s = *mu_s;
    return c;
  }

  Config config;
  ArmModel model;
  CableInputs inputs;
  internal::ArmDynamics dynamics;
  internal::SettledPoseSolver solver;
  int n, size;
  Eigen::VectorXd x;
};

TEST(SettledPoseSolver, ColouredJacobianIsTheDenseFiniteDifferenceOne) {
  SettledArm arm(0.25);  // static above kinetic
  const ArmModel& model = arm.model;
  internal::ArmDynamics& dynamics = arm.dynamics;
  internal::SettledPoseSolver& solver = arm.solver;
  // A pose off the straight one (every wrap angle away from zero) and off
  // its constraints, multipliers of a few newtons, friction carried from
  // the straight arm: nothing the Jacobian's pattern leaves out may move
  // the residual. The nodes move by 0.2 um, a strain of 4e-5 over an
  // element, below the pre-strain, so that no element goes slack.
  const int n = arm.n, size = arm.size;
  Eigen::VectorXd& x = arm.x;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < n; ++k) x[k] += 2e-7 * unit(random);
  for (int k = n; k < size; ++k) x[k] = 3.0 * unit(random);
  const internal::SettledFriction from = dynamics.InitialSettledFriction();
  const double t = 0.5;
  ASSERT_TRUE(solver.ComputeJacobian(t, from, x)) << solver.failure();
  const Eigen::MatrixXd sparse = Eigen::MatrixXd(solver.jacobian());

  Eigen::VectorXd base(size), perturbed(size);
  ASSERT_TRUE(dynamics.SettledResidual(t, x.data(), from, base.data()));
  double largest = 0.0, worst_difference = 0.0;
  for (int c = 0; c < size; ++c) {
    Eigen::VectorXd xc = x;
    // The solver's steps: a picometre on the cables' coordinates, sqrt(eps)
    // of the size elsewhere.
    const double step =
        c < model.link_offset(1) ? 1e-13 : 1.5e-8 * std::max(std::abs(x[c]), c < n ? 1e-2 : 1.0);
    xc[c] += step;
    ASSERT_TRUE(dynamics.SettledResidual(t, xc.data(), from, perturbed.data()));
    const Eigen::VectorXd column = (perturbed - base) / (xc[c] - x[c]);
    largest = std::max(largest, column.cwiseAbs().maxCoeff());
    worst_difference = std::max(worst_difference, (column - sparse.col(c)).cwiseAbs().maxCoeff());
  }
  // Both are the same forward differences, column by column or grouped:
  // equal to rounding, wherever the pattern has the entry or not.
  EXPECT_LE(worst_difference, 1e-9 * largest);
  // The point of the pattern: far fewer residuals than columns.
  EXPECT_LT(solver.num_colours(), size / 5);
  std::printf("%d unknowns in %d colours\n", size, solver.num_colours());
}

TEST(SettledPoseSolver, ForwardDifferencesResolveTheToeOfACableAtTheVergeOfSlack) {
  // A cable just taut (every element at zero strain), where its elements'
  // stiffness is the settled residual's weak one (1e-4 EA) and rises into
  // the slack toe (1e-4 of strain) at a curvature of 4 EA / toe. A
  // difference step of sqrt(eps) of a coordinate (1.5e-9 m on
  // millimetre elements, a strain of 1e-6) would see a stiffness of 2e-2
  // EA, two hundred times the true one, and Newton's corrections on a
  // cable going slack would point nowhere (the robot's log, issue 46). The
  // Jacobian's material columns must match the residual's central
  // differences to a tenth of the weak stiffness.
  SettledArm arm;
  const ArmModel& model = arm.model;
  internal::ArmDynamics& dynamics = arm.dynamics;
  const int n = arm.n, size = arm.size;
  Eigen::VectorXd& x = arm.x;
  const int cable = 0, nodes = static_cast<int>(model.cables()[cable].nodes.size());
  double shortest = 1.0;
  for (int k = 1; k < nodes; ++k) {
    const int a = model.node_offset(cable, k - 1), b = model.node_offset(cable, k);
    x[b + 3] = x[a + 3] + (x.segment<3>(b) - x.segment<3>(a)).norm();
    shortest = std::min(shortest, x[b + 3] - x[a + 3]);
  }
  const internal::SettledFriction from = dynamics.InitialSettledFriction();
  ASSERT_TRUE(arm.solver.ComputeJacobian(0.0, from, x)) << arm.solver.failure();
  const Eigen::MatrixXd jacobian = Eigen::MatrixXd(arm.solver.jacobian());
  const DrivingCableConfig& driving = arm.config.arm.driving;
  const double ea = driving.youngs_modulus_pa * driving.cross_section_m2;
  const double weak = internal::ArmDynamics::kSettledElementStiffness * ea / shortest;
  Eigen::VectorXd plus(size), minus(size);
  double worst = 0.0;
  for (int k = 0; k < nodes; ++k) {
    const int c = model.node_offset(cable, k) + 3;
    // A strain of 1e-10 each way: the toe's force there is 1e-6 of the
    // weak one's slope over the step.
    constexpr double kStep = 1e-13;
    Eigen::VectorXd xc = x;
    xc[c] = x[c] + kStep;
    ASSERT_TRUE(dynamics.SettledResidual(0.0, xc.data(), from, plus.data()));
    xc[c] = x[c] - kStep;
    ASSERT_TRUE(dynamics.SettledResidual(0.0, xc.data(), from, minus.data()));
    const Eigen::VectorXd column = (plus - minus) / (2.0 * kStep);
    worst = std::max(worst, (column - jacobian.col(c)).head(n).cwiseAbs().maxCoeff());
  }
  std::printf("worst material entry off by %.3g N/m; weak stiffness %.3g N/m\n", worst, weak);
  EXPECT_LE(worst, 0.1 * weak);
}

TEST(SettledPoseSolver, EquilibriumOfSlackCablesIsRegular) {
  // Every element 1 % longer in material than its chord: all cables slack.
  // Slack elements have no stiffness of their own, and without the settled
  // residual's weak stiffness every material coordinate of a hole node
  // would be a column of zeros (a singular Jacobian: no unique
  // equilibrium).
  SettledArm arm;
  const ArmModel& model = arm.model;
  Eigen::VectorXd& x = arm.x;
  for (int c = 0; c < model.num_cables(); ++c) {
    for (std::size_t k = 0; k < model.cables()[c].nodes.size(); ++k)
      x[model.node_offset(c, static_cast<int>(k)) + 3] *= 1.01;
  }
  EXPECT_TRUE(arm.solver.ComputeJacobian(0.0, arm.dynamics.InitialSettledFriction(), x))
      << arm.solver.failure();
}

SimulationResult Replay(const ArmModel& model, const ArmParameters& parameters,
                        const CableInputs& inputs, SolverConfig solver,
                        const std::vector<double>& times) {
  SimulationOptions options;
  options.solver = solver;
  options.duration_s = times.back();
  options.sample_times = times;
  options.quasi_static = true;
  return Simulate(model, parameters, inputs, options);
}

TEST(QuasiStaticReplay, FrictionKeepsTheBendThatTheFrictionlessArmGivesBack) {
  // A cable pulled in and let back to zero: the frictionless arm returns
  // straight (its equilibrium is a function of the inputs), the arm with
  // presliding friction in its holes and conduits keeps part of the bend
  // (hysteresis), and both agree at the top of the pull within what
  // friction can hold.
  Config config = test_support::SmallArm(5);
  UsePreslidingFriction(&config.solver);
  const ArmModel model(config.arm);
  const int n = 201;
  Eigen::VectorXd time(n);
  Eigen::MatrixXd change = Eigen::MatrixXd::Zero(n, model.num_cables());
  for (int i = 0; i < n; ++i) {
    time[i] = 0.01 * i;
    change(i, 0) = 5e-3 * std::sin(M_PI * time[i] / 2.0);  // out and back over 2 s
  }
  const CableInputs inputs(time, change);
  const std::vector<double> frames = {0.0, 1.0, 2.0};
  const SimulationResult with = Replay(model, config.parameters, inputs, config.solver, frames);
  ASSERT_TRUE(with.summary.completed()) << with.summary.message;
  ArmParameters frictionless = config.parameters;
  frictionless.mu = frictionless.mu_s = frictionless.mu_c = frictionless.mu_c_s = 0.0;
  const SimulationResult without = Replay(model, frictionless, inputs, config.solver, frames);
  ASSERT_TRUE(without.summary.completed()) << without.summary.message;
  const double last_joint = [&] {
    double bend = 0.0;
    for (const Eigen::Vector2d& angles : without.trajectory.frames[1].joint_angles)
      bend = std::max(bend, angles.cwiseAbs().maxCoeff());
    return bend;
  }();
  ASSERT_GT(last_joint, 1.0 * kDeg) << "the pull must bend the arm";
  double back_without = 0.0, back_with = 0.0;
  for (std::size_t j = 0; j < without.trajectory.frames[2].joint_angles.size(); ++j) {
    back_without =
        std::max(back_without, without.trajectory.frames[2].joint_angles[j].cwiseAbs().maxCoeff());
    back_with =
        std::max(back_with, with.trajectory.frames[2].joint_angles[j].cwiseAbs().maxCoeff());
  }
  // Frictionless: straight again to the solver's tolerance (1e-8 rad).
  EXPECT_LT(back_without, 1e-6);
  // With friction: a bend it holds, a visible part of the pull's.
  EXPECT_GT(back_with, 1e-3 * last_joint);
  std::printf("largest bend %.4f deg; after the return %.3g deg with friction, %.3g without\n",
              last_joint / kDeg, back_with / kDeg, back_without / kDeg);
}

TEST(QuasiStaticReplay, SettlesWithACableSlack) {
  // Cables paid out by more than their stretch lie slack: at rest their
  // material coordinates have no stiffness of their own, and the replay
  // must still find the one equilibrium (the settled residual's weak
  // stiffness spreads the slack material evenly), with the cables
  // reported slack and the arm held straight by its connecting cables.
  Config config = test_support::SmallArm(5);
  UsePreslidingFriction(&config.solver);
  const ArmModel model(config.arm);
  Eigen::VectorXd time(3);
  time << 0.0, 1.0, 2.0;
  Eigen::MatrixXd change = Eigen::MatrixXd::Zero(3, model.num_cables());
  change.bottomRows(2).setConstant(-3e-3);  // paid out 3 mm, about 7x the stretch
  const SimulationResult run =
      Replay(model, config.parameters, CableInputs(time, change), config.solver, {0.0, 1.0, 2.0});
  ASSERT_TRUE(run.summary.completed()) << run.summary.message;
  ASSERT_EQ(run.summary.slack.size(), static_cast<std::size_t>(model.num_cables()));
  for (const Eigen::Vector2d& angles : run.trajectory.frames.back().joint_angles)
    EXPECT_LT(angles.cwiseAbs().maxCoeff(), 1e-6);
}

TEST(QuasiStaticReplay, ARecordThatStartsPulledSettlesWhereThePullFromStraightDoes) {
  // A log's slice starts with the cables pulled; the replay reaches its
  // first pose from the straight arm along a straight line in the inputs,
  // as a record that starts at zero and pulls the same in its first second.
  Config config = test_support::SmallArm(5);
  UsePreslidingFriction(&config.solver);
  const ArmModel model(config.arm);
  Eigen::RowVectorXd pull = Eigen::RowVectorXd::Zero(model.num_cables());
  pull[0] = 1.5e-3;
  pull[1] = -0.5e-3;
  Eigen::VectorXd time(2);
  time << 0.0, 1.0;
  Eigen::MatrixXd pulled(2, model.num_cables()), from_zero(2, model.num_cables());
  pulled << pull, pull;
  from_zero << Eigen::RowVectorXd::Zero(model.num_cables()), pull;
  const SimulationResult started =
      Replay(model, config.parameters, CableInputs(time, pulled), config.solver, {0.0, 1.0});
  const SimulationResult ramped =
      Replay(model, config.parameters, CableInputs(time, from_zero), config.solver, {0.0, 1.0});
  ASSERT_TRUE(started.summary.completed()) << started.summary.message;
  ASSERT_TRUE(ramped.summary.completed()) << ramped.summary.message;
  const std::vector<Eigen::Vector2d>& a = started.trajectory.frames[0].joint_angles;
  const std::vector<Eigen::Vector2d>& b = ramped.trajectory.frames[1].joint_angles;
  double bend = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) {
    bend = std::max(bend, b[j].cwiseAbs().maxCoeff());
    // Both end on one monotone loading: the same pose to the solver's
    // tolerance (1e-9 rad absolute, 1e-8 relative, on every coordinate).
    EXPECT_NEAR(a[j].x(), b[j].x(), 1e-7) << j;
    EXPECT_NEAR(a[j].y(), b[j].y(), 1e-7) << j;
  }
  EXPECT_GT(bend, 1e-3);  // the pull bends the arm
}

TEST(QuasiStaticReplay, LawsThatHoldNothingAtRestAreRefused) {
  Config config = test_support::SmallArm(5);
  const ArmModel model(config.arm);
  const CableInputs inputs = test_support::PullAndHold(model, 0, 1e-3, 1.0, 2.0);
  SolverConfig solver = config.solver;
  solver.hole_friction = HoleFrictionModel::kEvents;
  try {
    Replay(model, config.parameters, inputs, solver, {0.0, 1.0});
    ADD_FAILURE() << "events friction was replayed quasi-statically";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hole_friction: presliding or off"), std::string::npos)
        << e.what();
  }
  solver.hole_friction = HoleFrictionModel::kPresliding;
  solver.conduit_friction = ConduitFrictionModel::kModifiedCoulomb;
  EXPECT_THROW(Replay(model, config.parameters, inputs, solver, {0.0, 1.0}), InputError);
}

// Paper case 2 (friction in every cable) under the presliding laws, frames
// every second: the quasi-static replay against the dynamic arm. On the
// paper's slow protocol (6 deg over 20 s ramps) the arm's transients are
// far below what is compared: the two must give the same joint angles
// within 0.03 deg (issue 46: the noise floor of a joint angle from motion
// capture, 0.2 mm of marker noise).
void CompareWithDynamicArm(double duration_s) {
  PaperRunOptions o;
  o.case_number = 2;
  o.duration_s = duration_s;
  PaperRun run = PreparePaperRun(o);
  UsePreslidingFriction(&run.simulation.solver);
  std::vector<double> frames;
  for (double t = 0.0; t <= duration_s + 1e-9; t += 1.0) frames.push_back(t);
  SimulationOptions dynamic = run.simulation;
  dynamic.sample_times = frames;
  const SimulationResult reference =
      Simulate(run.model, run.config.parameters, run.inputs, dynamic);
  ASSERT_TRUE(reference.summary.completed()) << reference.summary.message;
  SimulationOptions settled = dynamic;
  settled.quasi_static = true;
  const SimulationResult replay = Simulate(run.model, run.config.parameters, run.inputs, settled);
  ASSERT_TRUE(replay.summary.completed()) << replay.summary.message;
  ASSERT_EQ(replay.trajectory.size(), reference.trajectory.size());
  double worst = 0.0, worst_t = 0.0, largest = 0.0;
  int worst_joint = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto& a = replay.trajectory.frames[f].joint_angles;
    const auto& b = reference.trajectory.frames[f].joint_angles;
    for (std::size_t j = 0; j < a.size(); ++j) {
      largest = std::max(largest, b[j].cwiseAbs().maxCoeff());
      const double d = (a[j] - b[j]).cwiseAbs().maxCoeff();
      if (d > worst) {
        worst = d;
        worst_t = frames[f];
        worst_joint = static_cast<int>(j) + 1;
      }
    }
  }
  std::printf(
      "largest joint angle %.3f deg; replay against the dynamic arm: worst %.4f deg (joint %d, "
      "t = %.0f s)\n  dynamic: %s (%lld evaluations)\n  replay:  %s (%lld residuals)\n",
      largest / kDeg, worst / kDeg, worst_joint, worst_t, reference.summary.BriefReport().c_str(),
      static_cast<long long>(reference.summary.rhs_evaluations),
      replay.summary.BriefReport().c_str(), static_cast<long long>(replay.summary.rhs_evaluations));
  EXPECT_LE(worst, 0.03 * kDeg);
}

TEST(QuasiStaticReplay, FollowsTheDynamicArmOverThePapersProtocol) {
  // The whole protocol: ramps out and back, holds, and the return through
  // the straight arm (44 s), where every wrap angle passes zero.
  CompareWithDynamicArm(48.0);
}

}  // namespace
}  // namespace ccsrm::sim
