#pragma once
// Typed, validated configuration of an arm, its solver and its protocol.
// configs/paper.yaml is the complete default; LoadConfig() is the one way to
// get a Config, and every value is range-checked there (one source of truth).
// Units are SI unless a name says otherwise; angles are radians in C++ and
// degrees in YAML.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "ccsrm/sim/parameters.h"

namespace ccsrm::sim {

// How the driving cables' hole nodes stick and slip (docs/model-notes.md):
//  kEvents:   the paper's trial and error: a stuck node is held by a
//             constraint, switches are events located in time;
//  kSmoothed: one smooth friction law of the slip speed (stick band v_eps,
//             Stribeck transition), with model smoothing of its slope: no
//             events, so the output is smooth in every parameter;
//  kOff:      no friction in the holes, whatever mu and mu' are;
//  kPresliding: an elastoplastic law (Dupont et al. 2002): each node's
//             friction is a spring on a presliding displacement state that
//             yields at the capstan force, so a node loaded below its limit
//             holds without creep; no events, model-smoothed like kSmoothed.
enum class HoleFrictionModel { kEvents, kSmoothed, kOff, kPresliding };

// How the large-S conduits' friction acts (docs/model-notes.md):
//  kModifiedCoulomb: the paper's eq. 45, a law of the slip speed with a
//             stick band v_s: a conduit loaded below its limit creeps at up
//             to v_s ("cannot capture stick state in a strict sense");
//  kPresliding: the elastoplastic law of the holes' kPresliding on a
//             presliding displacement per conduit axis: a conduit loaded
//             below its limit holds without creep.
enum class ConduitFrictionModel { kModifiedCoulomb, kPresliding };

// The embedded Runge-Kutta 4(5) pair of GSL's odeiv2 that integrates a run
// (YAML `stepper: rkck | rkf45`).
enum class RungeKuttaStepper { kCashKarp, kFehlberg };

// Kind of cable-constrained synchronous rotating mechanism between two
// adjacent joints of a segment; kNone: no mechanism (a segment whose joints
// are held by an elastic backbone instead, BackboneGeometry).
enum class ConnectingKind { kSmallS, kLargeS, kNone };

// Small "S": a linear torsional spring-damper (eqs. 38-43).
struct SmallSGeometry {
  double cable_length_m = 0.0;   // l_sc
  double pulley_radius_m = 0.0;  // r_sc
};

// Large "S": spring with conduit friction (eqs. 44-53).
struct LargeSGeometry {
  double cable_length_m = 0.0;   // l_lc
  double pulley_radius_m = 0.0;  // r_lc
  double wrap_angle_rad = 0.0;   // Theta_lc
};

// An elastic backbone rod through the centres of a segment's disks (a
// tendon-driven continuum robot's superelastic rod): every joint of the
// segment bends against k_b E I / l per axis, l = link_length_m (the rod
// between two joints), I = pi (D^4 - d^4) / 64, and is damped by c_b
// (ArmParameters). The universal joints have no torsion, so the rod's G J
// has nothing to act on. Absent: youngs_modulus_pa = 0.
struct BackboneGeometry {
  double youngs_modulus_pa = 0.0;  // E
  double outer_diameter_m = 0.0;   // D
  double inner_diameter_m = 0.0;   // d: 0 for a solid rod
  bool present() const { return youngs_modulus_pa > 0.0; }
  double bending_stiffness_nm2() const;  // E I [N m^2]
};

struct SegmentConfig {
  std::string name;
  int links = 0;
  double link_length_m = 0.0;
  double link_mass_kg = 0.0;
  Eigen::Vector3d link_inertia_kgm2 = Eigen::Vector3d::Zero();  // diagonal, link frame
  double hole_circle_radius_m = 0.0;
  std::vector<ConnectingKind> connecting_pattern;  // links - 1 entries
  SmallSGeometry small_s;                          // needed when the pattern has a small S
  LargeSGeometry large_s;                          // needed when the pattern has a large S
  BackboneGeometry backbone;
  bool uses(ConnectingKind kind) const;
};

struct DrivingCableRoute {
  int segment = 0;              // 1-based segment the cable drives
  double hole_angle_rad = 0.0;  // from x' toward y'
};

struct DrivingCableConfig {
  double youngs_modulus_pa = 0.0;
  double cross_section_m2 = 0.0;
  double density_kgpm3 = 0.0;
  double input_offset_m = 0.0;
  std::vector<DrivingCableRoute> cables;
};

struct ConnectingCableConfig {
  double youngs_modulus_pa = 0.0;
  double cross_section_m2 = 0.0;
};

// Geometry, inertia and materials: what an ArmModel is built from. The
// friction, damping and pre-tension of the cables are not here but in
// ArmParameters, which each run takes on its own.
struct ArmConfig {
  double joint_disk_gap_m = 0.0;  // d
  Eigen::Vector3d gravity_mps2 = Eigen::Vector3d::Zero();
  std::vector<SegmentConfig> segments;
  DrivingCableConfig driving;
  ConnectingCableConfig connecting;

  int total_links() const;
  // Its joints (= links) and driving cables: what sizes the effects'
  // per-joint and per-cable parameters (ArmParameters::arm).
  ArmSize size() const;
  // Index (0-based) of the segment that holds link `link` (1-based).
  int segment_of_link(int link) const;
};

// How a run is integrated (SimulationOptions::solver). The switches that
// decide which terms the equations have are options here, never implied by
// a parameter's value, so a fit that reaches a bound of zero keeps the same
// model.
struct SolverConfig {
  // YAML `hole_friction: events | smoothed | off | presliding`.
  HoleFrictionModel hole_friction = HoleFrictionModel::kEvents;
  // YAML `conduit_friction: modified_coulomb | presliding`.
  ConduitFrictionModel conduit_friction = ConduitFrictionModel::kModifiedCoulomb;
  double baumgarte_alpha_per_s = 100.0;
  double baumgarte_beta_per_s2 = 100.0;
  double smoothing_step_s = 0.01;
  // Extends model smoothing to the large-S conduit friction (see
  // docs/model-notes.md): without it eq. 45's slope makes cases 2 and 4 stiff.
  // It acts whatever mu_c and mu'_c are (with both at zero it adds nothing).
  // Under conduit_friction: presliding it has no effect: that law is always
  // smoothed, as the holes' presliding law is.
  bool smooth_connecting_friction = true;
  // Extends model smoothing to the connecting-cable springs and dampers (see
  // docs/model-notes.md): their torsional modes (150-300 Hz against the link
  // inertia) otherwise cap explicit steps near 1.7 ms. An elastic backbone's
  // joints likewise (row 29).
  bool smooth_connecting_elasticity = true;
  // Extends model smoothing to the presliding laws' relaxation to their
  // limit (docs/model-notes.md row 28): sliding fast, it runs at |v|/xi_ss
  // (1e3/s at 10 mm/s) and caps explicit steps near 1 ms. Smoothed, it is
  // at most about 1/smoothing_step_s; slow sliding and the steady limit are
  // unchanged. No effect without a presliding law.
  bool smooth_presliding_relaxation = true;
  // Solve the equations with every driving-cable node's position written
  // as a function of its link's pose (eq. 7 substituted; 720 of the 1104
  // unknowns of the augmented system go). The same equations as the full
  // system, to the regularisation delta; false solves the full system
  // (docs/model-notes.md, row 23).
  bool embed_cable_nodes = true;
  // Cash-Karp by default: its stages extrapolate less than Fehlberg's
  // (largest coefficient 2.6 against 8), so a stage of a long step less
  // often crosses a hole node's stick band that the step itself stays clear
  // of; case 2 takes 22 % fewer evaluations (docs/model-notes.md, row 15).
  RungeKuttaStepper stepper = RungeKuttaStepper::kCashKarp;
  double stick_velocity_tolerance_mps = 1e-6;
  double stick_force_tolerance_n = 1e-3;
  double large_s_static_velocity_mps = 1e-4;
  double relative_tolerance = 1e-5;
  double absolute_tolerance = 1e-7;
  // Velocities get the absolute tolerance absolute_tolerance / this time: a
  // velocity error that small moves a position by absolute_tolerance over
  // it. Without it the tip link's quaternion rate held the steps to ~4 ms.
  double velocity_tolerance_time_s = 0.01;
  double initial_step_s = 1e-5;
  double max_step_s = 1e-2;
  double min_step_s = 1e-12;
  double switch_time_tolerance_s = 1e-6;
  double max_constraint_violation = 1e-3;
  double output_rate_hz = 100.0;
};

// The paper's protocol (SPEC 3).
struct ProtocolConfig {
  double amplitude_rad = 0.0;
  double ramp_s = 20.0;
  double hold_s = 4.0;
  double return_s = 20.0;
  double rest_s = 4.0;
  double duration_s() const { return ramp_s + hold_s + return_s + rest_s; }
};

struct Config {
  ArmConfig arm;
  ArmParameters
      parameters;  // their YAML keys sit in the cable sections (ParameterInfo::config_key)
  SolverConfig solver;
  ProtocolConfig protocol;
  std::string source_name;  // file name used in error messages
  std::string source_yaml;  // the text it was parsed from
  // Values far outside what arms of this kind have, which the model can
  // still run (a hole circle wider than the links are long, a link denser
  // than steel, a pre-tension beyond any cable's elastic range): one line
  // each, "<file>: line N, key 'k': <what>: <why>", filled by ParseConfig.
  // Commands print them; nothing is refused for them.
  std::vector<std::string> warnings;
};

// Parses and validates YAML text. `source_name` names the file in errors.
// Throws InputError "<file>: line N, key 'a.b.c': <problem>" on an unknown
// key, a missing key or section, a wrong type, a value out of range, or a
// segment its driving cables cannot bend about both axes (fewer than three
// cables, two at coincident hole angles, or all within a half-plane: see
// Validate). Values far outside the range of such arms are
// Config::warnings.
Config ParseConfig(const std::string& yaml_text, const std::string& source_name);

// The YAML word of a connecting_pattern entry ("small", "large", "none").
const std::string& ConnectingWord(ConnectingKind kind);
// The YAML word of a hole friction treatment ("events", "smoothed", ...).
const std::string& HoleFrictionWord(HoleFrictionModel model);
// The YAML word of a ConduitFrictionModel ("modified_coulomb", "presliding").
const std::string& ConduitFrictionWord(ConduitFrictionModel model);

// Reads and parses a configuration file. Throws InputError.
Config LoadConfig(const std::string& path);

// Writes the configuration back as YAML in the schema of configs/paper.yaml
// (so a run file's config_yaml reflects any overrides applied in C++).
std::string ToYaml(const Config& config);

// Checks cross-field consistency of a Config built or modified in C++, that
// every physical value of the arm lies in the range any real arm of this
// kind has, and that every segment's driving cables can bend it about both
// axes: at least three, no two at coincident hole angles (closer than 1 deg
// or than one cable diameter on the hole circle, where the holes overlap),
// not all within a closed half-plane (ParseConfig runs the same checks).
// Throws InputError naming the offending key and segment.
void Validate(const Config& config);

// Checks for one part: an arm (ArmModel's constructor: what makes the model
// well-posed, without Validate's physical ranges), solver settings
// (Simulate) or a protocol. `source_name` stands for the file in the message.
void ValidateArm(const ArmConfig& arm, const std::string& source_name);
void ValidateSolver(const SolverConfig& solver, const std::string& source_name);
void ValidateProtocol(const ProtocolConfig& protocol, const std::string& source_name);

}  // namespace ccsrm::sim
