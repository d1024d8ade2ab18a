#pragma once
// The effect library (SPEC 7): physics a real arm has and the paper's model
// lacks, each a switchable extension of the simulator with its own named
// parameters "<effect>.<parameter>". Every effect is off by default, and a
// run with every effect off is bit-identical to a run of a configuration
// without an `effects:` section.
//
//   joint_friction    Coulomb + viscous friction in every universal joint
//   table_tilt        gravity in the table plane from two small tilt angles
//   actuator_delay    the input lengths lag the command (first order + dead time)
//   backlash          a dead band in the connecting cables before they stretch
//   pretension_creep  T_p and T_d0 relax exponentially over the experiment
//   air_drag          air-bearing drag on the links, linear in velocity
//   mocap_offset      constant zero offsets of the measured joint angles
//                     (a measurement effect: what is recorded, not the dynamics)
//
// And one that is not of the library: `joint_moment`, the carrier of the
// terms the loop discovers in data (issue 28): a moment at every joint axis,
// a combination of JointMomentTerms() of the joint's own state with one
// coefficient per segment, axis and term. EffectInfo::library is false for
// it: the loop never tries it as an effect, only through its discovery step.
// Nor `segment_pretension`, a calibration of the arm: each segment's driving
// cables start at T_d0 plus their segment's "segment_pretension.segment<k>_n".
//
// An effect is switched on by a configuration's `effects:` section, by
// ArmParameters::EnableEffect, or by setting any of its parameters
// (SetParameter, `--set`, `--params`). Each effect lives in its own file
// under sim/src/effects/ behind one interface (sim/src/effects/effect.h);
// docs/effects.md says how to add one.
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::sim {

struct EffectInfo {
  std::string name;         // "joint_friction"
  std::string description;  // one line
  // True for an effect on what is measured (mocap_offset), not on the
  // dynamics: Simulate ignores it; RecordedJointAngles applies it.
  bool measurement = false;
  // The signals its residual follows (docs/model-notes.md, "Effect
  // fingerprints"), by the names of the loop's residual diagnostics:
  // "rate_sign", "rate", "angle", "heading", "time", "input_rate",
  // "constant", "hold_drift", "hysteresis", "lag". Evidence that points to
  // the effect, reported beside its score; the ranking itself is by score.
  std::vector<std::string> fingerprint;
  // False for joint_moment, the discovered terms' carrier: not a candidate
  // effect of the loop.
  bool library = true;
  // Its parameters are a function of the arm: EffectParameterNames.
};

// One term of joint_moment's library: a function of a joint axis's own
// angle θ [rad] and rate θ̇ [rad/s], of the bending rate its inputs
// command θ̇_in [rad/s], or of time t [s], whose coefficient is
// the parameter "joint_moment.segment<k>_<x|y>_<name>" (the moment on every
// joint of segment k about that axis, in N m per unit of the term).
struct JointMomentTerm {
  std::string name;     // "angle3"
  std::string formula;  // "θ³"
  std::string units;    // of its coefficient: "N m/rad^3"
  // The coefficient's realistic value (its score step in the loop): a
  // moment of 0.01 N m (joint friction's realistic Coulomb moment) at
  // θ = 0.1 rad, θ̇ = θ̇_in = 0.01 rad/s, t = 10 s; negative where the
  // physical direction is: a restoring spring (θ, θ³), a friction (θ̇,
  // sign θ̇, |θ| sign θ̇), a drag against the drive (θ̇_in), whose step then
  // damps the motion rather than drive it.
  double realistic = 0.0;
  // The simpler wins a tie in the discovery: powers count their degree.
  int complexity = 1;
};

// const (1), angle (θ), angle2 (θ²), angle3 (θ³), rate (θ̇), sign_rate
// (sign θ̇, smoothed as joint friction's: tanh(θ̇ / 1e-3 rad/s)),
// abs_angle_sign_rate (|θ| sign θ̇: friction that grows with the angle),
// input_rate (θ̇_in [rad/s]: the bending rate of the joint's segment about
// that axis that the driving cables' input rates command kinematically,
// SegmentBendingPerPulledLength in sim/kinematics.h) and time (t), in that
// order.
const std::vector<JointMomentTerm>& JointMomentTerms();

// "joint_moment.segment2_x_angle3" (segment 1-based, axis 0 = θx, 1 = θy).
std::string JointMomentParameter(int segment, int axis, const std::string& term);

// Every effect, in a fixed order (the order above).
const std::vector<EffectInfo>& Effects();

// The entry of `name`. Throws InputError "<where>: unknown effect 'x'
// (known: joint_friction, ...)".
const EffectInfo& FindEffect(const std::string& name, const std::string& where);

// The parameters `effect` has on an arm of `arm`'s size, full names as in
// AllParameters(arm) ("joint_friction.coulomb_nm"): its fixed ones, then its
// per-joint or per-cable ones, one set per joint or cable in order
// (mocap_offset: joint1_x_rad, joint1_y_rad, joint2_x_rad, ...). Throws
// InputError naming `where` for an unknown effect.
std::vector<std::string> EffectParameterNames(const std::string& effect, const ArmSize& arm,
                                              const std::string& where = "effect");

// Switches `effect` on with every parameter it has on the parameters' arm
// (ArmParameters::arm) at its realistic magnitude (ParameterInfo::realistic),
// as `ccsrm generate --effect NAME` does: mocap_offset covers every joint.
// Throws InputError naming `where` for an unknown effect.
void EnableEffectAtRealisticMagnitude(const std::string& effect, const std::string& where,
                                      ArmParameters* parameters);

// Parses "NAME" (the effect at its realistic magnitude) or
// "NAME:param=value,param=value" (the effect on, the given parameters set,
// the others at their defaults) and applies it. `where` names the option in
// errors ("--effect"). Throws InputError for an unknown effect or
// parameter (one the parameters' arm does not have included), a value that
// is not a number or out of bounds, or a malformed text. Returns the
// effect's name.
std::string ApplyEffectSpec(const std::string& text, const std::string& where,
                            ArmParameters* parameters);

// Applies a YAML mapping from effect name to a mapping of its parameters
// (`joint_friction: {coulomb_nm: 0.01}`; an empty mapping or null switches
// the effect on at its defaults), the format of a configuration's
// `effects:` section and of `ccsrm generate --effects FILE` (which may also
// hold it under a top-level `effects:` key). `file` names the file in
// errors: "<file>: line N, key 'effects.joint_friction.x': unknown
// parameter ..." (a per-joint parameter of a joint the parameters' arm
// does not have included). Checked whole before anything is applied.
void ApplyEffectsYaml(const std::string& yaml_text, const std::string& file,
                      ArmParameters* parameters);

// The joint angles motion capture records of a simulated frame: the
// physical angles (frame.joint_angles) with every measurement effect that
// is on applied (mocap_offset adds its offsets). Exactly the physical
// angles when no measurement effect is on. Identification compares
// measured angles with this. Precondition: with a measurement effect on,
// the frame has parameters.arm.joints joints.
std::vector<Eigen::Vector2d> RecordedJointAngles(const ArmParameters& parameters,
                                                 const TrajectoryFrame& frame);

// Link poses (x, y, z, e0..e3) whose joint angles are RecordedJointAngles:
// the chain rebuilt from joint 1 (where the frame has it) through the
// recorded joint angles, every joint where both its links put it. What a
// virtual mocap sees, so that processing (joint-constrained or not) gives
// the recorded angles. Exactly frame.link_pose when no measurement effect
// is on. Precondition: the frame is of `model`'s arm.
std::vector<Eigen::Matrix<double, 7, 1>> RecordedLinkPoses(const ArmModel& model,
                                                           const ArmParameters& parameters,
                                                           const TrajectoryFrame& frame);

}  // namespace ccsrm::sim
