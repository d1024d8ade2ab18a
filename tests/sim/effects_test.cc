// The effect library (ccsrm/sim/effects.h): each effect's physics on short
// runs of the paper's arm, off is neutral, the energy bookkeeping with each
// dissipative effect on, the name-based parameter API and configuration
// doors on effect parameters, and bad effect input.
#include "ccsrm/sim/effects.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "effects/effect.h"
#include "sim_runs.h"

namespace ccsrm::sim {
namespace {

using test_support::BalanceAfter;
using test_support::EnergyBalance;
using test_support::OptionsFor;
using test_support::PaperConfigPath;
using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180.0;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The paper's arm in one of its cases over a compressed protocol: 6° in
// 1.5 s, held 0.5 s (planned for 2 s).
struct PaperShort {
  Config config;
  ArmModel model;
  CableInputs inputs;
  explicit PaperShort(int case_number)
      : config(Compressed(case_number)),
        model(config.arm),
        inputs(PlanCableInputs(model, PaperTrajectory(model, config.protocol), 2.0)) {}
  static Config Compressed(int case_number) {
    Config c = LoadConfig(PaperConfigPath());
    ApplyPaperCase(case_number, &c.parameters);
    c.protocol.ramp_s = 1.5;
    c.protocol.hold_s = 0.5;
    return c;
  }
  SimulationResult Run(const ArmParameters& p, double duration_s) const {
    SimulationResult r = Simulate(model, p, inputs, OptionsFor(config, duration_s));
    EXPECT_TRUE(r.summary.completed()) << r.summary.message;
    return r;
  }
};

const PaperShort& Case(int number) {
  static const PaperShort* cases[5] = {};
  if (cases[number] == nullptr) cases[number] = new PaperShort(number);
  return *cases[number];
}

// Inputs that hold every cable where it is.
CableInputs Held(const ArmModel& model, double end_s) {
  Eigen::VectorXd time(2);
  time << 0.0, end_s;
  return CableInputs(time, Eigen::MatrixXd::Zero(2, model.num_cables()));
}

void ExpectBitIdentical(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.time, b.time);
  for (std::size_t f = 0; f < a.size(); ++f) {
    const TrajectoryFrame &x = a.frames[f], &y = b.frames[f];
    ASSERT_EQ(x.joint_angles, y.joint_angles) << "frame " << f;
    ASSERT_EQ(x.joint_rates, y.joint_rates) << "frame " << f;
    ASSERT_EQ(x.link_pose, y.link_pose) << "frame " << f;
    ASSERT_EQ(x.element_tension, y.element_tension) << "frame " << f;
    ASSERT_EQ(x.dissipated_energy, y.dissipated_energy) << "frame " << f;
  }
}

double MaxAngleDifference(const TrajectoryFrame& a, const TrajectoryFrame& b) {
  double worst = 0.0;
  for (std::size_t j = 0; j < a.joint_angles.size(); ++j)
    worst = std::max(worst, (a.joint_angles[j] - b.joint_angles[j]).cwiseAbs().maxCoeff());
  return worst;
}

// ---------------------------------------------------------------- registry

TEST(Effects, SevenLibraryEffectsAndTheTermsCarrierEachWithNamedBoundedParameters) {
  std::vector<std::string> names;
  for (const EffectInfo& e : Effects()) {
    if (e.library) names.push_back(e.name);
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{"joint_friction", "table_tilt", "actuator_delay", "backlash",
                                      "pretension_creep", "air_drag", "mocap_offset"}));
  // The discovered terms' carrier and the per-segment pre-tension are
  // registered but not of the library.
  EXPECT_FALSE(FindEffect("joint_moment", "test").library);
  EXPECT_FALSE(FindEffect("segment_pretension", "test").library);
  const ArmSize paper_arm{12, 6, 2};
  // One coefficient per segment, axis and term.
  EXPECT_EQ(EffectParameterNames("joint_moment", paper_arm).size(),
            2u * 2u * JointMomentTerms().size());
  EXPECT_EQ(JointMomentParameter(2, 0, "angle3"), "joint_moment.segment2_x_angle3");
  EXPECT_THROW(FindParameter("joint_moment.segment3_x_angle", "test", paper_arm), InputError);
  for (const EffectInfo& e : Effects()) {
    const std::vector<std::string> parameters = EffectParameterNames(e.name, paper_arm);
    ASSERT_FALSE(parameters.empty()) << e.name;
    for (const std::string& name : parameters) {
      const ParameterInfo& p = FindParameter(name, "test", paper_arm);
      EXPECT_EQ(p.name, e.name + "." + p.short_name);
      EXPECT_EQ(p.effect, e.name);
      EXPECT_EQ(p.field, nullptr);
      EXPECT_FALSE(p.units.empty()) << name;
      EXPECT_LT(p.lower, p.upper) << name;
      EXPECT_TRUE(p.realistic >= p.lower && p.realistic <= p.upper) << name;
      EXPECT_TRUE(p.absent_value >= p.lower && p.absent_value <= p.upper) << name;
    }
  }
  EXPECT_TRUE(FindEffect("mocap_offset", "test").measurement);
  // AllParameters: the model's table first, then every effect parameter.
  const std::vector<ParameterInfo> all = AllParameters(paper_arm);
  ASSERT_GT(all.size(), Parameters().size());
  for (std::size_t k = 0; k < Parameters().size(); ++k)
    EXPECT_EQ(all[k].name, Parameters()[k].name);
  EXPECT_EQ(all[Parameters().size()].name, "joint_friction.coulomb_nm");
}

// --------------------------------------------------- the name-based API

TEST(EffectParameters, SetParameterSwitchesTheEffectOnAndGetReadsDefaults) {
  ArmParameters p = LoadConfig(PaperConfigPath()).parameters;
  EXPECT_FALSE(p.AnyEffectOn());
  EXPECT_FALSE(p.EffectOn("joint_friction"));
  // Off: reads its default (neutral) value.
  EXPECT_EQ(GetParameter(p, "joint_friction.coulomb_nm"), 0.0);
  EXPECT_EQ(GetParameter(p, "pretension_creep.time_constant_s"), 30.0);
  SetParameter("joint_friction.coulomb_nm", 0.02, "test", &p);
  EXPECT_TRUE(p.EffectOn("joint_friction"));
  EXPECT_EQ(p.EnabledEffects(), std::vector<std::string>{"joint_friction"});
  EXPECT_EQ(GetParameter(p, "joint_friction.coulomb_nm"), 0.02);
  EXPECT_EQ(GetParameter(p, "joint_friction.viscous_nmsprad"), 0.0);
  std::string error;
  EXPECT_TRUE(p.IsValid(&error)) << error;
  // Out of bounds: refused, nothing changes, the table's message.
  EXPECT_THAT(ErrorOf([&] { SetParameter("table_tilt.lateral_rad", 0.5, "--set", &p); }),
              HasSubstr("--set: parameter 'table_tilt.lateral_rad' = 0.5 is outside [-0.05, "
                        "0.05] rad"));
  EXPECT_FALSE(p.EffectOn("table_tilt"));
  // IsValid sees a value written around SetParameter.
  ArmParameters bad = p;
  bad.effect_values["joint_friction.coulomb_nm"] = 7.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("joint_friction.coulomb_nm"));
  p.DisableEffect("joint_friction");
  EXPECT_FALSE(p.AnyEffectOn());
  EXPECT_EQ(GetParameter(p, "joint_friction.coulomb_nm"), 0.0);
}

TEST(EffectParameters, AssignmentsAndParameterFilesTakeEffectNames) {
  const auto [name, value] = ParseParameterAssignment("air_drag.linear_nspm=0.003", "--set");
  EXPECT_EQ(name, "air_drag.linear_nspm");
  EXPECT_EQ(value, 0.003);
  ArmParameters p = LoadConfig(PaperConfigPath()).parameters;
  // Flat names, and a truth file's nested `effects:` section.
  ApplyParameterYaml("mu: 0.1\nbacklash.dead_band_rad: 0.001\n", "p.yaml", &p);
  EXPECT_TRUE(p.EffectOn("backlash"));
  EXPECT_EQ(GetParameter(p, "backlash.dead_band_rad"), 0.001);
  ApplyParameterYaml(
      "parameters:\n  T_d0: 90\neffects:\n  table_tilt:\n    lateral_rad: 0.002\n"
      "  air_drag: {}\n",
      "truth.yaml", &p);
  EXPECT_EQ(p.T_d0, 90.0);
  EXPECT_EQ(GetParameter(p, "table_tilt.lateral_rad"), 0.002);
  EXPECT_TRUE(p.EffectOn("air_drag"));
  EXPECT_EQ(p.EnabledEffects(), (std::vector<std::string>{"table_tilt", "backlash", "air_drag"}));
}

TEST(EffectParameters, BadEffectInputGetsOneLineNamingWhere) {
  ArmParameters p = LoadConfig(PaperConfigPath()).parameters;
  const std::string unknown_parameter =
      ErrorOf([&] { ParseParameterAssignment("joint_friction.colomb_nm=1", "--set"); });
  EXPECT_THAT(unknown_parameter, HasSubstr("--set: unknown parameter 'joint_friction.colomb_nm'"));
  EXPECT_THAT(unknown_parameter, HasSubstr("joint_friction.coulomb_nm"));  // what it has
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("joint_fiction", "--effect", &p); }),
              HasSubstr("--effect: unknown effect 'joint_fiction' (known: joint_friction,"));
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("backlash:dead_band=0.1", "--effect", &p); }),
              HasSubstr("unknown parameter 'dead_band' of backlash (known: dead_band_rad)"));
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("backlash:dead_band_rad", "--effect", &p); }),
              HasSubstr("expected param=value"));
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("backlash:dead_band_rad=x", "--effect", &p); }),
              HasSubstr("is not a number"));
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("backlash:dead_band_rad=1e-400", "--effect", &p); }),
              HasSubstr("value '1e-400' of dead_band_rad underflows"));
  EXPECT_EQ(ErrorOf([&] {
              ApplyEffectsYaml("backlash: {dead_band_rad: 0.01, dead_band_rad: 0.02}\n", "fx.yaml",
                               &p);
            }),
            "fx.yaml: line 1, key 'backlash.dead_band_rad': duplicate key (first at line 1)");
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("backlash:dead_band_rad=1", "--effect", &p); }),
              HasSubstr("parameter 'backlash.dead_band_rad' = 1 is outside [0, 0.05] rad"));
  EXPECT_FALSE(p.AnyEffectOn());  // nothing applied by a failed spec
  EXPECT_THAT(ErrorOf([&] { ApplyEffectsYaml("tilt: {}\n", "fx.yaml", &p); }),
              HasSubstr("fx.yaml: line 1, key 'tilt': unknown effect (known: joint_friction"));
  EXPECT_THAT(
      ErrorOf([&] { ApplyEffectsYaml("effects:\n  air_drag:\n    linear: 1\n", "fx.yaml", &p); }),
      HasSubstr("fx.yaml: line 3, key 'effects.air_drag.linear': unknown parameter of air_drag"));
  EXPECT_THAT(
      ErrorOf([&] { ApplyEffectsYaml("air_drag: {linear_nspm: 3}\n", "fx.yaml", &p); }),
      HasSubstr("fx.yaml: line 1, key 'air_drag.linear_nspm': parameter 'air_drag.linear_nspm' = "
                "3 is outside [0, 1] N s/m"));
  for (const std::string& e :
       {ErrorOf([&] { ApplyEffectsYaml("air_drag: 3\n", "fx.yaml", &p); }),
        ErrorOf([&] { ParseParameterAssignment("tilt.angle=1", "--set"); })}) {
    EXPECT_FALSE(e.empty());
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_FALSE(p.AnyEffectOn());
}

TEST(EffectParameters, RealisticSpecAndValuedSpec) {
  ArmParameters p = LoadConfig(PaperConfigPath()).parameters;
  EXPECT_EQ(ApplyEffectSpec("actuator_delay", "--effect", &p), "actuator_delay");
  EXPECT_EQ(GetParameter(p, "actuator_delay.time_constant_s"),
            FindParameter("actuator_delay.time_constant_s", "t").realistic);
  ApplyEffectSpec("joint_friction:coulomb_nm=0.03,viscous_nmsprad=0.001", "--effect", &p);
  EXPECT_EQ(GetParameter(p, "joint_friction.coulomb_nm"), 0.03);
  EXPECT_EQ(GetParameter(p, "joint_friction.viscous_nmsprad"), 0.001);
  EXPECT_EQ(GetParameter(p, "joint_friction.smoothing_rate_radps"), 1e-3);  // its default
}

// ------------------------------------------------------- configuration

TEST(EffectConfig, EffectsSectionSwitchesOnAndWritesBack) {
  const std::string text = ReadTextFile(PaperConfigPath());
  const Config c = ParseConfig(
      text +
          "effects:\n  table_tilt: {lateral_rad: 0.001}\n  mocap_offset:\n    joint3_x_rad: "
          "0.002\n",
      "cfg.yaml");
  EXPECT_EQ(c.parameters.EnabledEffects(),
            (std::vector<std::string>{"table_tilt", "mocap_offset"}));
  EXPECT_EQ(GetParameter(c.parameters, "mocap_offset.joint3_x_rad"), 0.002);
  const Config again = ParseConfig(ToYaml(c), "again.yaml");
  EXPECT_EQ(again.parameters.effect_values.at("table_tilt.lateral_rad"), 0.001);
  EXPECT_EQ(again.parameters.EnabledEffects(), c.parameters.EnabledEffects());
  // A configuration without effects writes no section.
  EXPECT_EQ(ToYaml(ParseConfig(text, "p.yaml")).find("effects"), std::string::npos);
}

TEST(EffectConfig, BadEffectsSectionNamesFileLineAndKey) {
  const std::string text = ReadTextFile(PaperConfigPath());
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  const std::string at = "line " + std::to_string(lines + 2);
  EXPECT_THAT(ErrorOf([&] { ParseConfig(text + "effects:\n  joint_frict: {}\n", "c.yaml"); }),
              HasSubstr("c.yaml: " + at + ", key 'effects.joint_frict': unknown effect"));
  EXPECT_THAT(ErrorOf([&] { ParseConfig(text + "effects:\n  backlash: {band: 0.1}\n", "c.yaml"); }),
              HasSubstr("c.yaml: " + at + ", key 'effects.backlash.band': unknown parameter"));
  EXPECT_THAT(
      ErrorOf([&] { ParseConfig(text + "effects:\n  backlash: {dead_band_rad: -1}\n", "c.yaml"); }),
      HasSubstr("c.yaml: " + at +
                ", key 'effects.backlash.dead_band_rad': parameter "
                "'backlash.dead_band_rad' = -1 is outside [0, 0.05] rad"));
}

// --------------------------------------------------------- off is neutral

TEST(EffectsOff, RunsAreBitIdenticalToAConfigurationWithoutEffects) {
  // Case 2 (every term of the model acts), the first 0.6 s of the ramp.
  const PaperShort& run = Case(2);
  const std::string text = ReadTextFile(PaperConfigPath());
  Config with_section = ParseConfig(text + "effects: {}\n", "with.yaml");
  ApplyPaperCase(2, &with_section.parameters);
  EXPECT_FALSE(with_section.parameters.AnyEffectOn());
  ArmParameters switched_off = run.config.parameters;
  for (const EffectInfo& e : Effects())
    EnableEffectAtRealisticMagnitude(e.name, "t", &switched_off);
  for (const EffectInfo& e : Effects()) switched_off.DisableEffect(e.name);
  const SimulationResult reference = run.Run(run.config.parameters, 0.6);
  ExpectBitIdentical(reference.trajectory, run.Run(with_section.parameters, 0.6).trajectory);
  ExpectBitIdentical(reference.trajectory, run.Run(switched_off, 0.6).trajectory);
}

// ----------------------------------------------------------- the physics

// The settled deflection: every joint's angle about `axis` (0 θx, 1 θy)
// averaged over the frames from t = 2.5 s on (the last 0.5 s of the 3 s
// runs below, after the damped arm has settled).
Eigen::VectorXd SettledAngles(const Trajectory& trajectory, int axis) {
  const std::size_t n = trajectory.frames.empty() ? 0 : trajectory.frames[0].joint_angles.size();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  int count = 0;
  for (std::size_t f = 0; f < trajectory.size(); ++f) {
    if (trajectory.time[f] < 2.5) continue;
    for (std::size_t j = 0; j < n; ++j) mean[j] += trajectory.frames[f].joint_angles[j][axis];
    ++count;
  }
  EXPECT_GT(count, 0);
  return count > 0 ? Eigen::VectorXd(mean / count) : mean;
}

// Quasi-static planar estimate of the frictionless arm's θx under in-plane
// loads `tau` (generalised forces on θx of joints 1..N): the stiffness of
// the driving cables (axial, EA/L ∇L ∇Lᵀ, and geometric, T_d0 ∇²L: each
// cable a spring held at both ends, lengths by pure kinematics) and of the
// connecting couples (eq. 41's k = 2 E_c A_c r²/l on θ_j − θ_i; the large S
// without friction is the same law).
Eigen::VectorXd QuasiStaticDeflection(const ArmModel& model, const ArmParameters& p,
                                      const Eigen::VectorXd& tau) {
  const int n = model.num_joints();
  auto length = [&](int cable, const Eigen::VectorXd& theta_x) {
    JointAngles angles(n, Eigen::Vector2d::Zero());
    for (int j = 0; j < n; ++j) angles[j][0] = theta_x[j];
    return CablePathLength(model, cable, ForwardKinematics(model, angles));
  };
  const double ea = model.arm().driving.youngs_modulus_pa * model.arm().driving.cross_section_m2;
  const double h = 1e-4;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  for (int c = 0; c < model.num_cables(); ++c) {
    const double l0 = length(c, zero);
    Eigen::VectorXd grad(n);
    for (int a = 0; a < n; ++a) {
      Eigen::VectorXd e = zero;
      e[a] = h;
      grad[a] = (length(c, e) - length(c, -e)) / (2 * h);
      for (int b = 0; b < n; ++b) {
        Eigen::VectorXd f = zero;
        f[b] = h;
        const double second =
            (length(c, e + f) - length(c, e - f) - length(c, f - e) + length(c, -e - f)) /
            (4 * h * h);
        k(a, b) += p.T_d0 * second;
      }
    }
    k += ea / l0 * grad * grad.transpose();
  }
  const double eca =
      model.arm().connecting.youngs_modulus_pa * model.arm().connecting.cross_section_m2;
  for (const ConnectingPairModel& pair : model.connecting_pairs()) {
    const double kc = 2.0 * eca * pair.pulley_radius_m * pair.pulley_radius_m / pair.cable_length_m;
    const int i = pair.joint_i - 1, j = pair.joint_i;
    k(i, i) += kc;
    k(j, j) += kc;
    k(i, j) -= kc;
    k(j, i) -= kc;
  }
  return k.ldlt().solve(tau);
}

TEST(TableTilt, TiltedTableBendsArmAtRest) {
  // Case 1 (frictionless: the quasi-static estimate has no friction to
  // model), inputs held, the table tilted by 0.02 rad about the arm's axis.
  // Damping raised (beta 0.02 s) so that the arm's slow S-shaped mode
  // settles within 2.5 s; the static deflection does not depend on damping.
  PaperShort arm(1);
  ArmParameters p = arm.config.parameters;
  p.beta = 0.02;
  const double tilt = 0.02;
  SetParameter("table_tilt.lateral_rad", tilt, "test", &p);
  const CableInputs held = Held(arm.model, 3.0);
  const SimulationResult r = Simulate(arm.model, p, held, OptionsFor(arm.config, 3.0));
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const int n = arm.model.num_joints();
  const Eigen::VectorXd sim_x = SettledAngles(r.trajectory, 0);
  const Eigen::VectorXd sim_y = SettledAngles(r.trajectory, 1);
  // Generalised gravity forces on θx: sum over links of m g_y ∂y_i/∂θx_j.
  const double g_y = 9.80665 * std::sin(tilt);
  Eigen::VectorXd tau(n);
  const std::vector<LinkPose> straight =
      ForwardKinematics(arm.model, JointAngles(n, Eigen::Vector2d::Zero()));
  for (int j = 0; j < n; ++j) {
    JointAngles bent(n, Eigen::Vector2d::Zero());
    bent[j][0] = 1e-6;
    const std::vector<LinkPose> moved = ForwardKinematics(arm.model, bent);
    tau[j] = 0.0;
    for (int i = 0; i < n; ++i) {
      tau[j] +=
          arm.model.link(i + 1).mass_kg * g_y * (moved[i].p_WB[1] - straight[i].p_WB[1]) / 1e-6;
    }
  }
  const Eigen::VectorXd estimate = QuasiStaticDeflection(arm.model, p, tau);
  for (int j = 0; j < n; ++j) {
    std::printf("joint %2d: θx %+.5f° (estimate %+.5f°), θy %+.2e°\n", j + 1, sim_x[j] / kDeg,
                estimate[j] / kDeg, sim_y[j] / kDeg);
  }
  // Gravity along +y bends the arm towards -y: negative θx (Rx turns z to -y).
  EXPECT_LT(sim_x.sum(), 0.0);
  // The estimate is a simpler model (each cable one spring over its
  // kinematic path length, tension uniform along it) of the same physics,
  // linearised; what is left of the settling oscillation adds to the
  // difference. 10 % of the deflection's size, joint by joint.
  EXPECT_LT((sim_x - estimate).norm(), 0.1 * estimate.norm());
  // In-plane gravity leaves the out-of-plane angle alone (θy stays at the
  // frictionless arm's cable-stretch level, far below θx).
  EXPECT_LT(sim_y.cwiseAbs().maxCoeff(), 0.05 * sim_x.cwiseAbs().maxCoeff());
}

TEST(ActuatorDelay, DelayShiftsResponseByDelay) {
  // A dead time d shifts the whole response by d: the arm is at rest under
  // constant inputs before the motion starts, and its equations do not
  // depend on time, so θ_delayed(t) = θ(t − d) up to integration error
  // (tolerance 1e-5 relative). Bound: 1 % of how far the delayed run is
  // from the undelayed one at the same time.
  const PaperShort& run = Case(1);
  ArmParameters p = run.config.parameters;
  const double dead = 0.1;  // ten 10 ms frames
  SetParameter("actuator_delay.dead_time_s", dead, "test", &p);
  const SimulationResult nominal = run.Run(run.config.parameters, 1.2);
  const SimulationResult delayed = run.Run(p, 1.2);
  const std::size_t shift = 10;
  ASSERT_NEAR(nominal.trajectory.time[shift], dead, 1e-12);
  double shifted = 0.0, unshifted = 0.0;
  for (std::size_t f = shift; f < delayed.trajectory.size(); ++f) {
    shifted = std::max(shifted, MaxAngleDifference(delayed.trajectory.frames[f],
                                                   nominal.trajectory.frames[f - shift]));
    unshifted = std::max(
        unshifted, MaxAngleDifference(delayed.trajectory.frames[f], nominal.trajectory.frames[f]));
  }
  std::printf("delayed vs nominal: %.3e° at the same time, %.3e° shifted by %.2f s\n",
              unshifted / kDeg, shifted / kDeg, dead);
  EXPECT_GT(unshifted, 0.1 * kDeg);  // the delay matters on this ramp
  EXPECT_LT(shifted, 0.01 * unshifted);
}

TEST(ActuatorDelay, FirstOrderLagDelaysASlowRampByItsTimeConstant) {
  // A first-order lag τ of a command that changes slowly against τ is, to
  // first order in τ, the command delayed by τ: y(t) = u(t − τ) + O(τ² u'').
  // On this ramp the remainder is τ u''/(2 u') ≈ 4 % of the shift's effect
  // at τ = 20 ms, so mid-ramp the response shifted by τ matches within 10 %
  // of the unshifted difference.
  const PaperShort& run = Case(1);
  ArmParameters p = run.config.parameters;
  const double tau = 0.02;  // two frames
  SetParameter("actuator_delay.time_constant_s", tau, "test", &p);
  const SimulationResult nominal = run.Run(run.config.parameters, 1.2);
  const SimulationResult lagged = run.Run(p, 1.2);
  double shifted = 0.0, unshifted = 0.0;
  for (std::size_t f = 40; f <= 110; ++f) {  // 0.4-1.1 s, mid-ramp
    shifted = std::max(
        shifted, MaxAngleDifference(lagged.trajectory.frames[f], nominal.trajectory.frames[f - 2]));
    unshifted = std::max(
        unshifted, MaxAngleDifference(lagged.trajectory.frames[f], nominal.trajectory.frames[f]));
  }
  std::printf("lagged vs nominal: %.3e° at the same time, %.3e° shifted by τ\n", unshifted / kDeg,
              shifted / kDeg);
  EXPECT_LT(shifted, 0.1 * unshifted);
}

// Trapezoid integral over a run's frames of `rate(frame)`, from 0 to t_end.
double Integral(const Trajectory& run, double t_end,
                const std::function<double(std::size_t)>& rate) {
  double sum = 0.0;
  for (std::size_t f = 1; f < run.size() && run.time[f] <= t_end + 1e-12; ++f) {
    sum += 0.5 * (rate(f) + rate(f - 1)) * (run.time[f] - run.time[f - 1]);
  }
  return sum;
}

TEST(JointFriction, JointFrictionDissipatesItsWorkAndCalmsTheHold) {
  // Case 1 (the model itself dissipates little), Coulomb 0.02 N m and
  // viscous 0.002 N m s/rad in every joint over the compressed ramp.
  const PaperShort& run = Case(1);
  ArmParameters p = run.config.parameters;
  SetParameter("joint_friction.coulomb_nm", 0.02, "test", &p);
  SetParameter("joint_friction.viscous_nmsprad", 0.002, "test", &p);
  const SimulationResult nominal = run.Run(run.config.parameters, 2.0);
  const SimulationResult rubbing = run.Run(p, 2.0);
  const Trajectory& t = rubbing.trajectory;
  // The friction law's power, integrated from the sampled joint rates.
  const double omega = GetParameter(p, "joint_friction.smoothing_rate_radps");
  const double work = Integral(t, 1.5, [&](std::size_t f) {
    double power = 0.0;
    for (const Eigen::Vector2d& w : t.frames[f].joint_rates)
      for (int a = 0; a < 2; ++a)
        power += 0.02 * std::tanh(w[a] / omega) * w[a] + 0.002 * w[a] * w[a];
    return power;
  });
  const std::size_t ramp_end = 150;
  ASSERT_NEAR(t.time[ramp_end], 1.5, 1e-12);
  const double extra =
      t.frames[ramp_end].dissipated_energy - nominal.trajectory.frames[ramp_end].dissipated_energy;
  // Coulomb's work is M_c Σ|Δθ| = 0.02 N m × 12 joints × 6° = 0.025 J.
  std::printf("extra dissipation over the ramp %.4e J, friction work from the rates %.4e J\n",
              extra, work);
  EXPECT_GT(work, 0.9 * 0.02 * 12 * 6 * kDeg);
  // The booked dissipation is the friction's work: the rest of the arm's
  // dissipation changes only with the slightly different motion (5 %).
  EXPECT_NEAR(extra, work, 0.05 * work);
  // Once the inputs hold (1.5-2 s), the frictionless arm rings on its
  // connecting cables while Coulomb friction stops the joints: the largest
  // joint rate in the last 0.3 s is far smaller with friction.
  auto hold_rate = [](const Trajectory& frames) {
    double worst = 0.0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
      if (frames.time[f] < 1.7) continue;
      for (const Eigen::Vector2d& w : frames.frames[f].joint_rates)
        worst = std::max(worst, w.cwiseAbs().maxCoeff());
    }
    return worst;
  };
  std::printf("largest joint rate in the hold: %.3e rad/s frictionless, %.3e with friction\n",
              hold_rate(nominal.trajectory), hold_rate(t));
  EXPECT_LT(hold_rate(t), hold_rate(nominal.trajectory));
}

TEST(Backlash, DeadBandHasNoStiffnessInsideAndFullStiffnessBeyond) {
  ArmParameters p;
  SetParameter("backlash.dead_band_rad", 0.002, "test", &p);
  const std::unique_ptr<internal::Effect> backlash = internal::BacklashEffect().make(p);
  ASSERT_TRUE(backlash->deflects_couples());
  const internal::CoupleDeflection at_zero = backlash->Deflect(0.0);
  EXPECT_EQ(at_zero.value, 0.0);
  EXPECT_EQ(at_zero.slope, 0.0);
  // Beyond the band (10 b) the spring is stretched by what exceeds the play.
  EXPECT_NEAR(backlash->Deflect(0.02).value, 0.018, 1e-10);
  EXPECT_NEAR(backlash->Deflect(-0.02).value, -0.018, 1e-10);
  EXPECT_NEAR(backlash->Deflect(0.02).slope, 1.0, 1e-7);
  // The energy's derivative is the deflection (energy bookkeeping).
  for (double d : {-0.01, -0.002, -3e-4, 5e-4, 0.002, 0.007}) {
    const double h = 1e-7;
    EXPECT_NEAR((backlash->Deflect(d + h).energy - backlash->Deflect(d - h).energy) / (2 * h),
                backlash->Deflect(d).value, 1e-9);
    EXPECT_NEAR((backlash->Deflect(d + h).value - backlash->Deflect(d - h).value) / (2 * h),
                backlash->Deflect(d).slope, 1e-6);
  }
}

TEST(Backlash, BacklashLetsLoadedCouplesOpenByUpToTheBand) {
  // Case 3: the holes' friction bends the root joints of a segment more than
  // the tip joints, so every couple is loaded. With play b the couples give
  // way by up to b more before they resist: the relative rotation of a
  // loaded couple grows, by no more than b (the band's half-width).
  const PaperShort& run = Case(3);
  ArmParameters p = run.config.parameters;
  const double band = 0.004;
  SetParameter("backlash.dead_band_rad", band, "test", &p);
  const SimulationResult nominal = run.Run(run.config.parameters, 1.5);
  const SimulationResult loose = run.Run(p, 1.5);
  const TrajectoryFrame& a = nominal.trajectory.frames.back();
  const TrajectoryFrame& b = loose.trajectory.frames.back();
  double growth = 0.0;
  for (const ConnectingPairModel& pair : run.model.connecting_pairs()) {
    const int i = pair.joint_i - 1, j = pair.joint_i;
    const double d_nominal = a.joint_angles[j][0] - a.joint_angles[i][0];
    const double d_loose = b.joint_angles[j][0] - b.joint_angles[i][0];
    std::printf("couple %2d-%2d: θj − θi %+.4f° nominal, %+.4f° with backlash\n", i + 1, j + 1,
                d_nominal / kDeg, d_loose / kDeg);
    growth += std::abs(d_loose) - std::abs(d_nominal);
    // No couple opens by more than its play (5 %: the spring beyond the
    // band carries a slightly different load).
    EXPECT_LT(std::abs(d_loose) - std::abs(d_nominal), band * 1.05) << "couple " << i + 1;
  }
  // On average the couples open, by less than the band: a couple can also
  // close a little when its neighbours give way.
  const double mean = growth / run.model.connecting_pairs().size();
  std::printf("mean opening %.4f° against a band of %.4f°\n", mean / kDeg, band / kDeg);
  EXPECT_GT(mean, 0.0);
  EXPECT_LT(mean, band);
}

// Case 1, inputs held 3 s, the driving cables' pre-tension relaxing by 20 %
// with τ = 1 s (and segment 2's cables `segment2_change_n` above T_d0).
// Frictionless holes let the tension equalise along each cable within
// milliseconds, so each cable's input tension follows its own pre-tension
// T (1 − 0.2 (1 − e^(−t/τ))); 1 % of it covers the lumped length (path
// length by kinematics) and the cable's dynamic lag.
void ExpectEachCableLosesItsShare(double segment2_change_n) {
  PaperShort arm(1);
  ArmParameters p = arm.config.parameters;
  if (segment2_change_n != 0.0)
    SetParameter("segment_pretension.segment2_n", segment2_change_n, "test", &p);
  SetParameter("pretension_creep.driving_fraction", 0.2, "test", &p);
  SetParameter("pretension_creep.connecting_fraction", 0.2, "test", &p);
  SetParameter("pretension_creep.time_constant_s", 1.0, "test", &p);
  const SimulationResult r =
      Simulate(arm.model, p, Held(arm.model, 3.0), OptionsFor(arm.config, 3.0));
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  for (std::size_t f : {std::size_t{100}, std::size_t{200}, std::size_t{300}}) {
    const double t = r.trajectory.time[f];
    for (int c = 0; c < arm.model.num_cables(); ++c) {
      const double own = p.T_d0 + (arm.model.cables()[c].segment == 1 ? segment2_change_n : 0.0);
      const double expected = own * (1.0 - 0.2 * (1.0 - std::exp(-t)));
      const double tension = r.trajectory.frames[f].element_tension[c][0];
      EXPECT_NEAR(tension, expected, 0.01 * own) << "cable " << c + 1 << " at " << t << " s";
    }
  }
}

TEST(PretensionCreep, CreepLowersTensionOverTime) {
  ExpectEachCableLosesItsShare(0.0);
  // The connecting cables' T_p relaxes the same way.
  ArmParameters p = PaperShort(1).config.parameters;
  SetParameter("pretension_creep.connecting_fraction", 0.2, "test", &p);
  SetParameter("pretension_creep.time_constant_s", 1.0, "test", &p);
  const std::unique_ptr<internal::Effect> creep = internal::PretensionCreepEffect().make(p);
  EXPECT_EQ(creep->PretensionFactor(0.0), 1.0);
  EXPECT_NEAR(creep->PretensionFactor(1.0), 1.0 - 0.2 * (1.0 - std::exp(-1.0)), 1e-15);
}

TEST(PretensionCreep, EachSegmentsCablesLoseTheirOwnPretension) {
  // Segment 2's cables 20 N above T_d0 lose a fifth of their own (a creep
  // computed from T_d0 alone would leave them 4 N too taut at t → ∞).
  ExpectEachCableLosesItsShare(20.0);
}

TEST(SegmentPretension, EachSegmentsCablesStartAtTheirOwnPretension) {
  // Case 1, inputs held, segment 2's cables 20 N above T_d0: a pre-strain
  // of the straight arm, so with frictionless holes every element of a
  // cable holds its segment's pre-tension from the start, and the arm
  // stays straight (a segment's cables pull alike). 1 % of T_d0 as for
  // the creep: the lumped length and the cable's dynamic lag.
  PaperShort arm(1);
  ArmParameters p = arm.config.parameters;
  SetParameter("segment_pretension.segment2_n", 20.0, "test", &p);
  const SimulationResult r =
      Simulate(arm.model, p, Held(arm.model, 0.5), OptionsFor(arm.config, 0.5));
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  for (std::size_t f : {std::size_t{0}, r.trajectory.size() - 1}) {
    for (int c = 0; c < arm.model.num_cables(); ++c) {
      const double expected = p.T_d0 + (arm.model.cables()[c].segment == 1 ? 20.0 : 0.0);
      for (double tension : r.trajectory.frames[f].element_tension[c])
        EXPECT_NEAR(tension, expected, 0.01 * p.T_d0) << "cable " << c + 1 << ", frame " << f;
    }
    for (const Eigen::Vector2d& angle : r.trajectory.frames[f].joint_angles)
      EXPECT_LT(angle.cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(AirDrag, AirDragDissipatesEnergy) {
  // Case 1 over the ramp with drag 0.5 N s/m on every link: the extra
  // dissipated energy is the drag's work c ∫Σ|v|² dt, with the links'
  // velocities differenced from their sampled positions (the motion is
  // smooth at 10 ms frames: 5 % covers the differencing and the slightly
  // changed motion's own damping).
  const PaperShort& run = Case(1);
  ArmParameters p = run.config.parameters;
  const double c = 0.5;
  SetParameter("air_drag.linear_nspm", c, "test", &p);
  const SimulationResult nominal = run.Run(run.config.parameters, 1.5);
  const SimulationResult dragged = run.Run(p, 1.5);
  const Trajectory& t = dragged.trajectory;
  auto speed2 = [&](std::size_t f) {
    const std::size_t a = f == 0 ? 0 : f - 1, b = std::min(f + 1, t.size() - 1);
    double sum = 0.0;
    for (std::size_t l = 0; l < t.frames[f].link_pose.size(); ++l) {
      const Eigen::Vector3d v =
          (t.frames[b].link_pose[l].head<3>() - t.frames[a].link_pose[l].head<3>()) /
          (t.time[b] - t.time[a]);
      sum += v.squaredNorm();
    }
    return sum;
  };
  const double work = c * Integral(t, 1.5, speed2);
  const double extra =
      t.frames.back().dissipated_energy - nominal.trajectory.frames.back().dissipated_energy;
  std::printf("drag: extra dissipation %.4e J, c ∫Σ|v|² %.4e J\n", extra, work);
  EXPECT_GT(extra, 0.0);
  EXPECT_NEAR(extra, work, 0.05 * work);
}

TEST(MocapOffset, MocapOffsetShiftsOnlyMeasuredAngles) {
  const PaperShort& run = Case(1);
  ArmParameters p = run.config.parameters;
  EnableEffectAtRealisticMagnitude("mocap_offset", "test", &p);
  SetParameter("mocap_offset.joint3_x_rad", 0.01, "test", &p);
  // The dynamics are untouched: the same run to the last bit.
  const SimulationResult physical = run.Run(run.config.parameters, 0.5);
  const SimulationResult with_offsets = run.Run(p, 0.5);
  ExpectBitIdentical(physical.trajectory, with_offsets.trajectory);
  const TrajectoryFrame& frame = with_offsets.trajectory.frames.back();
  // Without a measurement effect the recorded angles are the physical ones.
  EXPECT_EQ(RecordedJointAngles(run.config.parameters, frame), frame.joint_angles);
  EXPECT_EQ(RecordedLinkPoses(run.model, run.config.parameters, frame), frame.link_pose);
  const std::vector<Eigen::Vector2d> recorded = RecordedJointAngles(p, frame);
  ASSERT_EQ(recorded.size(), frame.joint_angles.size());
  for (std::size_t j = 0; j < recorded.size(); ++j) {
    for (int a = 0; a < 2; ++a) {
      const std::string name =
          "mocap_offset.joint" + std::to_string(j + 1) + (a == 0 ? "_x_rad" : "_y_rad");
      EXPECT_EQ(recorded[j][a], frame.joint_angles[j][a] + GetParameter(p, name)) << name;
    }
  }
  EXPECT_EQ(recorded[2][0], frame.joint_angles[2][0] + 0.01);
  // The poses a virtual mocap sees give exactly those angles, and a chain
  // whose joints hold together (what a joint-constrained fit assumes), from
  // joint 1 where it is.
  const auto poses = RecordedLinkPoses(run.model, p, frame);
  Eigen::Matrix3d parent = Eigen::Matrix3d::Identity();
  Eigen::Vector3d parent_distal = Eigen::Vector3d::Zero();  // joint 1 at W's origin
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(poses[i][3], poses[i][4], poses[i][5], poses[i][6]).toRotationMatrix();
    const Eigen::Vector2d angles = UniversalJointAngles(parent.transpose() * R);
    EXPECT_NEAR(angles[0], recorded[i][0], 1e-12) << "joint " << i + 1;
    EXPECT_NEAR(angles[1], recorded[i][1], 1e-12) << "joint " << i + 1;
    const int link = static_cast<int>(i) + 1;
    const Eigen::Vector3d proximal = poses[i].head<3>() + R * run.model.p_child_joint(link);
    EXPECT_LT((proximal - parent_distal).norm(), 1e-8) << "joint " << link;
    if (link < run.model.num_links())
      parent_distal = poses[i].head<3>() + R * run.model.p_parent_joint(link + 1);
    parent = R;
  }
}

// The second arm (configs/three-segment.yaml, 12 joints and 9 cables) with
// its first `segments` segments given `links` links each: 3 and 3 make 9
// joints, 1 and 8 make 16.
Config ThreeSegmentArm(int segments, int links) {
  std::string text = ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  std::string pattern;
  for (int k = 0; k + 1 < links; ++k)
    pattern += std::string(k ? ", " : "") + (k % 2 ? "large" : "small");
  std::size_t at = 0;
  for (int s = 0; s < segments; ++s) {
    at = text.find("links: 4", at);
    text.replace(at, 8, "links: " + std::to_string(links));
    const std::size_t open = text.find("connecting_pattern: [", at);
    const std::size_t close = text.find(']', open);
    text.replace(open, close + 1 - open, "connecting_pattern: [" + pattern + "]");
  }
  return ParseConfig(text,
                     "arm" + std::to_string(segments) + "x" + std::to_string(links) + ".yaml");
}

// Issue 32: mocap_offset had joints 1-12 whatever the arm. Its parameters
// are now the arm's own, at every door that takes a name.
TEST(MocapOffset, ParametersAreOnePairPerJointOfTheArm) {
  const Config nine = ThreeSegmentArm(3, 3);
  const Config sixteen = ThreeSegmentArm(1, 8);
  ASSERT_EQ(nine.arm.total_links(), 9);
  ASSERT_EQ(sixteen.arm.total_links(), 16);
  EXPECT_EQ(nine.parameters.arm, (ArmSize{9, 9}));
  EXPECT_EQ(EffectParameterNames("mocap_offset", nine.parameters.arm).size(), 18u);
  EXPECT_EQ(EffectParameterNames("mocap_offset", sixteen.parameters.arm).back(),
            "mocap_offset.joint16_y_rad");
  // The paper's arm keeps its 24 names, in their order, and their values.
  const std::vector<std::string> paper =
      EffectParameterNames("mocap_offset", LoadConfig(PaperConfigPath()).parameters.arm);
  ASSERT_EQ(paper.size(), 24u);
  EXPECT_EQ(paper[0], "mocap_offset.joint1_x_rad");
  EXPECT_EQ(paper[1], "mocap_offset.joint1_y_rad");
  EXPECT_EQ(paper[23], "mocap_offset.joint12_y_rad");
  EXPECT_EQ(FindParameter("mocap_offset.joint1_x_rad", "test", ArmSize{12, 6}).realistic,
            std::round(std::sin(2.7) * 2e-3 * 1e5) / 1e5);

  // On 16 joints: joint16 exists; --effect mocap_offset covers every joint.
  ArmParameters p = sixteen.parameters;
  SetParameter("mocap_offset.joint16_x_rad", 0.01, "--set", &p);
  EXPECT_EQ(GetParameter(p, "mocap_offset.joint16_x_rad"), 0.01);
  ArmParameters realistic = sixteen.parameters;
  ApplyEffectSpec("mocap_offset", "--effect", &realistic);
  TrajectoryFrame frame;
  frame.joint_angles.assign(16, Eigen::Vector2d::Zero());
  const std::vector<Eigen::Vector2d> recorded = RecordedJointAngles(realistic, frame);
  ASSERT_EQ(recorded.size(), 16u);
  for (int j = 1; j <= 16; ++j) {
    for (int a = 0; a < 2; ++a) {
      const std::string name =
          "mocap_offset.joint" + std::to_string(j) + (a == 0 ? "_x_rad" : "_y_rad");
      const double value = FindParameter(name, "test", realistic.arm).realistic;
      EXPECT_NE(value, 0.0) << name;  // the fixed pattern has no zero up to here
      EXPECT_EQ(recorded[j - 1][a], value) << name;
    }
  }

  // On 9 joints: joint12 is refused at every door, one line naming it.
  ArmParameters q = nine.parameters;
  const std::string beyond =
      "this arm has 9 joints: known: mocap_offset.joint<k>_x_rad, "
      "mocap_offset.joint<k>_y_rad (k = 1..9, one per joint)";
  EXPECT_EQ(ErrorOf([&] { SetParameter("mocap_offset.joint12_x_rad", 0.01, "--set", &q); }),
            "--set: unknown parameter 'mocap_offset.joint12_x_rad' (" + beyond + ")");
  EXPECT_THAT(ErrorOf([&] { ApplyEffectSpec("mocap_offset:joint12_x_rad=0.01", "--effect", &q); }),
              HasSubstr("--effect: 'mocap_offset:joint12_x_rad=0.01': unknown parameter "
                        "'joint12_x_rad' of mocap_offset (this arm has 9 joints: known: "
                        "joint<k>_x_rad, joint<k>_y_rad (k = 1..9, one per joint))"));
  EXPECT_THAT(
      ErrorOf([&] { ApplyParameterYaml("mocap_offset.joint12_y_rad: 0.001\n", "p.yaml", &q); }),
      HasSubstr("p.yaml: line 1, key 'mocap_offset.joint12_y_rad': unknown parameter "
                "(this arm has 9 joints"));
  EXPECT_THAT(
      ErrorOf([&] { ApplyEffectsYaml("mocap_offset: {joint10_x_rad: 0.001}\n", "e.yaml", &q); }),
      HasSubstr("e.yaml: line 1, key 'mocap_offset.joint10_x_rad': unknown parameter of "
                "mocap_offset (this arm has 9 joints"));
  EXPECT_FALSE(q.EffectOn("mocap_offset"));  // nothing applied
  // A configuration's own effects section, by file, line and key.
  std::string text = nine.source_yaml + "effects:\n  mocap_offset: {joint12_x_rad: 0.001}\n";
  EXPECT_THAT(
      ErrorOf([&] { ParseConfig(text, "nine.yaml"); }),
      HasSubstr("nine.yaml: line " + std::to_string(std::count(text.begin(), text.end(), '\n')) +
                ", key 'effects.mocap_offset.joint12_x_rad': unknown parameter of "
                "mocap_offset (this arm has 9 joints"));
  // Its joint 9 is there, and the configuration writes back what it was given.
  SetParameter("mocap_offset.joint9_y_rad", -0.002, "--set", &q);
  Config written = nine;
  written.parameters = q;
  EXPECT_EQ(
      GetParameter(ParseConfig(ToYaml(written), "w.yaml").parameters, "mocap_offset.joint9_y_rad"),
      -0.002);
}

// ----------------------------------------------------- energy bookkeeping

// As ArmDynamics.EnergyBookkeepingHoldsWithModelSmoothing, with one
// dissipative (or spring-changing) effect on at a magnitude where it takes
// out a good part of the motion's energy: whatever it takes out is booked,
// so kinetic + elastic + dissipated stays put after the pull (1 % of the
// energy in play, the tolerance of that test).
void ExpectEnergyCloses(const std::string& name, double value) {
  Config c = test_support::SmallArm(4);
  test_support::SwitchOffDissipation(&c.parameters);
  SetParameter(name, value, "test", &c.parameters);
  c.solver.relative_tolerance = 1e-8;
  c.solver.absolute_tolerance = 1e-11;
  c.solver.output_rate_hz = 1000.0;
  const ArmModel model(c.arm);
  const CableInputs inputs = test_support::PullAndHold(model, 2, 0.5e-3, 0.02, 0.2);
  const SimulationResult result = Simulate(model, c.parameters, inputs, OptionsFor(c, 0.2));
  ASSERT_TRUE(result.summary.completed()) << result.summary.message;
  const EnergyBalance e = BalanceAfter(result.trajectory, 0.03);
  std::printf("%s = %g: kinetic up to %.3e J, dissipated %.3e J, drift %.3e J\n", name.c_str(),
              value, e.kinetic_max, e.dissipated, e.drift);
  ASSERT_GT(e.kinetic_max, 1e-7);
  EXPECT_LT(e.drift, 0.01 * std::max(e.kinetic_max, std::abs(e.dissipated)));
}

TEST(EffectEnergy, BookkeepingClosesWithJointFriction) {
  ExpectEnergyCloses("joint_friction.coulomb_nm", 0.002);
}
TEST(EffectEnergy, BookkeepingClosesWithAirDrag) {
  ExpectEnergyCloses("air_drag.linear_nspm", 0.5);
}
TEST(EffectEnergy, BookkeepingClosesWithBacklash) {
  ExpectEnergyCloses("backlash.dead_band_rad", 0.002);
}
// A discovered term that damps (θ̇) and one that stores energy as a spring
// (θ): -M θ̇ is booked either way, so the balance closes for both.
TEST(EffectEnergy, BookkeepingClosesWithADampingJointMomentTerm) {
  ExpectEnergyCloses("joint_moment.segment1_x_rate", -0.05);
}
TEST(EffectEnergy, BookkeepingClosesWithASpringJointMomentTerm) {
  ExpectEnergyCloses("joint_moment.segment1_x_angle", -0.5);
}

// ------------------------------------------------------------ joint_moment

TEST(JointMoment, ConstantMomentBendsTheArmAsTheQuasiStaticModelPredicts) {
  // A constant moment on every joint about x is a generalised force on θx
  // of the same size: the settled deflection is the quasi-static model's
  // (as for the tilted table above). Segment 2's moment is of the other
  // sign and half the size, which checks that each joint takes its own
  // segment's coefficient. Case 1, beta 0.02 s: settled within 2.5 s.
  PaperShort arm(1);
  ArmParameters p = arm.config.parameters;
  p.beta = 0.02;
  const double m1 = 0.01, m2 = -0.005;  // N m: joint friction's realistic size
  SetParameter(JointMomentParameter(1, 0, "const"), m1, "test", &p);
  SetParameter(JointMomentParameter(2, 0, "const"), m2, "test", &p);
  const SimulationResult r =
      Simulate(arm.model, p, Held(arm.model, 3.0), OptionsFor(arm.config, 3.0));
  ASSERT_TRUE(r.summary.completed()) << r.summary.message;
  const int n = arm.model.num_joints();
  const Eigen::VectorXd sim_x = SettledAngles(r.trajectory, 0);
  Eigen::VectorXd tau(n);
  for (int j = 0; j < n; ++j) tau[j] = arm.model.link(j + 1).segment == 0 ? m1 : m2;
  const Eigen::VectorXd estimate = QuasiStaticDeflection(arm.model, p, tau);
  for (int j = 0; j < n; ++j) {
    std::printf("joint %2d: θx %+.5f° (estimate %+.5f°)\n", j + 1, sim_x[j] / kDeg,
                estimate[j] / kDeg);
  }
  // The tilted table's bound and reason: a simpler linearised model of the
  // same physics, plus what is left of the settling oscillation.
  EXPECT_LT((sim_x - estimate).norm(), 0.1 * estimate.norm());
}

TEST(JointMoment, InputRateTermActsWhileTheInputsMoveAsTheMomentOfTheRateTheyCommand) {
  // θ̇_in is the bending rate the inputs command (sim/kinematics.h,
  // SegmentBendingPerPulledLength). Held inputs command none: the term
  // moves nothing, to the bit.
  PaperShort arm(1);
  ArmParameters p = arm.config.parameters;
  p.beta = 0.02;
  ArmParameters with_term = p;
  const double c = -1.0;  // N m s/rad: the term's realistic coefficient
  SetParameter(JointMomentParameter(1, 0, "input_rate"), c, "test", &with_term);
  const CableInputs held = Held(arm.model, 0.5);
  ExpectBitIdentical(Simulate(arm.model, with_term, held, OptionsFor(arm.config, 0.5)).trajectory,
                     Simulate(arm.model, p, held, OptionsFor(arm.config, 0.5)).trajectory);

  // Segment 1 planned to bend at a constant rate ω about x, segment 2
  // straight: θ̇_in is ω on segment 1's joints and 0 on segment 2's, so
  // the term is a constant moment c ω on segment 1 alone, and the arm
  // settles on the plan's deflection plus that moment's: the difference
  // from the run without the term is the quasi-static estimate's. Case 1
  // (frictionless) and the damping of the constant-moment test above,
  // whose bound and reason this takes.
  const double omega = 0.01;  // rad/s: 1.7° over the 3 s
  const JointTrajectory ramp = [&](double t) {
    JointAngles a(arm.model.num_joints(), Eigen::Vector2d::Zero());
    for (int j = 1; j <= arm.model.num_joints(); ++j) {
      if (arm.model.link(j).segment == 0) a[j - 1][0] = omega * t;
    }
    return a;
  };
  const CableInputs inputs = PlanCableInputs(arm.model, ramp, 3.0);
  const SimulationResult a = Simulate(arm.model, with_term, inputs, OptionsFor(arm.config, 3.0));
  const SimulationResult b = Simulate(arm.model, p, inputs, OptionsFor(arm.config, 3.0));
  ASSERT_TRUE(a.summary.completed()) << a.summary.message;
  ASSERT_TRUE(b.summary.completed()) << b.summary.message;
  const int n = arm.model.num_joints();
  const Eigen::VectorXd difference =
      SettledAngles(a.trajectory, 0) - SettledAngles(b.trajectory, 0);
  Eigen::VectorXd tau(n);
  for (int j = 0; j < n; ++j) tau[j] = arm.model.link(j + 1).segment == 0 ? c * omega : 0.0;
  const Eigen::VectorXd estimate = QuasiStaticDeflection(arm.model, p, tau);
  for (int j = 0; j < n; ++j) {
    std::printf("joint %2d: θx moved %+.5f° by the term (estimate %+.5f°)\n", j + 1,
                difference[j] / kDeg, estimate[j] / kDeg);
  }
  EXPECT_LT((difference - estimate).norm(), 0.1 * estimate.norm());
}

}  // namespace
}  // namespace ccsrm::sim
