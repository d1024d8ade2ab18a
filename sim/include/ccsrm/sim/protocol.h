#pragma once
// Protocols: planned joint trajectories and the driving-cable inputs they
// need. Inputs come from pure kinematic planning (SPEC 3): the change of each
// cable's geometric path length through every hole is pulled in at the input.
#include <Eigen/Core>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::sim {

// Planned joint angles as a function of time [s].
using JointTrajectory = std::function<JointAngles(double t)>;

// 10τ³ − 15τ⁴ + 6τ⁵ on [0, 1]: zero velocity and acceleration at both ends.
double QuinticBlend(double tau);

// The paper's protocol: every joint's θx goes 0 → A along a quintic over
// ramp_s, holds for hold_s, returns over return_s and rests for rest_s; θy = 0.
// The same motion as configs/protocols/paper.yaml with its parameters set
// from `protocol` (PaperProtocolParameters), to the bit.
JointTrajectory PaperTrajectory(const ArmModel& model, const ProtocolConfig& protocol);

// Prescribed pulled-in length of every driving cable [m] (positive = pulled
// in) as a function of time, interpolated by a C2 cubic spline through
// samples; before the first and after the last sample the end value holds.
class CableInputs {
 public:
  // Between the samples: a C2 cubic spline (a continuous motion: its rate
  // and acceleration enter the constraints, eq. 63), or straight lines (an
  // actuator moving from one set point to the next between settled poses:
  // a spline would swing past them).
  enum class Interpolation { kCubicSpline, kLinear };

  // time: N >= 2 strictly increasing samples [s]; length_change: N × C [m].
  // Throws InputError on a bad shape, non-increasing time or a non-finite value.
  CableInputs(Eigen::VectorXd time, Eigen::MatrixXd length_change,
              Interpolation interpolation = Interpolation::kCubicSpline);
  ~CableInputs();
  CableInputs(CableInputs&&) noexcept;
  CableInputs& operator=(CableInputs&&) noexcept;

  int num_cables() const { return static_cast<int>(length_change_.cols()); }
  double start_time() const { return time_[0]; }
  double end_time() const { return time_[time_.size() - 1]; }
  const Eigen::VectorXd& time() const { return time_; }
  const Eigen::MatrixXd& length_change() const { return length_change_; }
  Interpolation interpolation() const { return interpolation_; }

  // Value [m], rate [m/s] and acceleration [m/s²] of cable `cable` at t.
  // Thread-safe.
  void Evaluate(int cable, double t, double* value, double* rate, double* accel) const;

 private:
  struct Splines;
  Eigen::VectorXd time_;
  Eigen::MatrixXd length_change_;
  Interpolation interpolation_;
  std::unique_ptr<Splines> splines_;
};

// How planned joint angles become input lengths (docs/protocols.md,
// "Planning").
struct InputPlanning {
  enum class Method {
    // SPEC 3, the paper's: the change of each cable's geometric path length,
    // L(0) − L(t). Every cable keeps its pre-tension, which does not hold a
    // bent arm in place: the frictionless arm bends past the plan by a
    // fraction that grows with T_d0 / EA (0.15° at −6° on segment 2 of the
    // paper's arm).
    kKinematic,
    // The kinematic lengths plus each cable's stretch under the tensions
    // that hold the frictionless arm at the planned state: the smallest
    // change ΔT from T_d0 (least squares) that balances the cables' moments
    // on every segment's bending (all its joints together), pulled in as
    // ΔT·L/EA. Assumes what the frictionless arm does when it follows a plan
    // slowly: constant curvature per segment, uniform tension along each
    // cable.
    kStaticEquilibrium,
  };
  Method method = Method::kKinematic;
  // The driving cables' pre-tension T_d0 [N] (the run's ArmParameters::T_d0);
  // kStaticEquilibrium only.
  double pretension_n = 0.0;
};

// Plans the inputs for a joint trajectory: samples the trajectory every
// `sample_step_s` over [0, duration_s] and records each cable's pulled-in
// length by `planning` (by default pure kinematics, L(0) − L(t)). Throws
// InputError, labelled `source` (the option or file the motion came from),
// when a planned joint tilts beyond its range (ArmModel::joint_range_rad):
// past it the paths through the gap fold and the plan means nothing; and,
// planning for static equilibrium, when a cable would have to push to hold
// a planned state.
CableInputs PlanCableInputs(const ArmModel& model, const JointTrajectory& trajectory,
                            double duration_s, double sample_step_s = 1e-3,
                            const std::string& source = "planned motion",
                            const InputPlanning& planning = {});

// ---------------------------------------------------------------------------
// Protocol files (ccsrm-protocol/1, docs/protocols.md): per segment a
// sequence of pieces (hold, move, step, sine, chirp, repeat blocks),
// bound to one arm.

// Where a piece came from, for messages: "line 12, key 'segments.1[2].sine'".
struct ProtocolSource {
  int line = 0;     // 1-based line in the file; 0 when built in code
  std::string key;  // key path in the file
  std::string Where() const;
};

// One piece of a segment's motion, already expanded (a step is a move and a
// hold; a repeat block its pieces over again) and resolved to numbers. Every
// piece starts from the state (angles and rates) where the previous one
// ended; the first starts from the straight arm at rest.
struct ProtocolPiece {
  enum class Kind { kHold, kMove, kOscillation };
  Kind kind = Kind::kHold;
  double duration_s = 0.0;
  // kMove: the state reached, one (θx, θy) per joint of the segment [rad],
  // along 10τ³ − 15τ⁴ + 6τ⁵ (quintic = minimum jerk).
  JointAngles target;
  // kOscillation (sine, chirp): start + amplitude · w(t) · sin φ(t), with
  // amplitude per joint [rad], instantaneous frequency going from
  // start_frequency_hz to end_frequency_hz (equal for a sine; linearly or
  // exponentially in time for a chirp), and w a quintic fade in and out over
  // fade_s at each end (w = 1 throughout when fade_s = 0).
  JointAngles amplitude;
  double start_frequency_hz = 0.0;
  double end_frequency_hz = 0.0;
  bool exponential_sweep = false;
  double fade_s = 0.0;
  // The state it starts from, (θx, θy) per joint [rad]: where the previous
  // piece ended (set by ParseProtocol).
  JointAngles start;
  ProtocolSource source;
};

// What the protocol's inputs may ask of the actuators and the joints.
struct ProtocolLimits {
  double cable_speed_mps = 0.1;          // largest |rate| of any pulled-in length [m/s]
  double cable_acceleration_mps2 = 1.0;  // largest |second derivative| [m/s²]
  // Largest bend of a joint (the angle between its links' axes) [rad]; NaN:
  // the joint's range, where its disks meet (ArmModel::joint_range_rad:
  // 41.7° and 53.1° on the paper's arm). A value narrows the range, never
  // widens it.
  double joint_bend_rad = NAN;
};

// Options of ParseProtocol / LoadProtocol.
struct ProtocolOptions {
  // Values replacing the file's `parameters:` of the same names, in SI
  // (rad for a name ending in _deg, s for _s, Hz for _hz). A name the file
  // does not declare is refused, blamed on `parameters_source`.
  std::map<std::string, double> parameters;
  std::string parameters_source = "parameters";  // e.g. "--amplitude"
};

// A protocol bound to an arm: one sequence of pieces per segment.
struct Protocol {
  std::string name;
  std::string description;
  std::string source_name;  // the file, in messages
  std::string source_yaml;  // the text it was parsed from
  // The parameters' values as used (SI: rad, s or Hz), by name.
  std::map<std::string, double> parameters;
  ProtocolLimits limits;
  // The file's `planning:` (kinematic unless it says static_equilibrium).
  InputPlanning::Method planning = InputPlanning::Method::kKinematic;
  std::vector<std::vector<ProtocolPiece>> segments;  // [segment][piece]
  std::vector<int> segment_joints;                   // joints of each segment

  // The longest segment's total duration [s]; every segment holds its last
  // state after its own pieces end.
  double duration_s() const;
  // Planned (θx, θy) of every joint of the arm at time t [s] (before 0: the
  // straight arm; after the end: the last state).
  JointAngles PlannedAngles(double t) const;
  // Their rates [rad/s].
  JointAngles PlannedRates(double t) const;
  JointTrajectory Trajectory() const;
  // The protocol as YAML again, its parameters at the values used, so that a
  // run file records what drove it (the `protocol_yaml` attribute).
  std::string ToYaml() const;
};

// Parses a ccsrm-protocol/1 document for `arm` and checks it: schema, known
// keys and forms, durations positive (a hold may be 0), frequencies
// positive, a fade no longer than half its piece, a segment for every one
// of the arm (or `all`), planned bends within limits.joint_bend_rad, and
// pieces that join without a jump in rate (position joins by construction),
// also into the hold after a segment's last piece. Throws InputError
// "<file>: line N, key 'k': <problem>". Cable speeds need the planned
// lengths: PlanProtocolInputs checks them.
Protocol ParseProtocol(const std::string& yaml_text, const std::string& source_name,
                       const ArmConfig& arm, const ProtocolOptions& options = {});
Protocol LoadProtocol(const std::string& path, const ArmConfig& arm,
                      const ProtocolOptions& options = {});

// The parameters that make configs/protocols/paper.yaml the protocol of a
// configuration's `protocol:` section (amplitude_deg, ramp_s, hold_s,
// return_s, rest_s, in SI).
std::map<std::string, double> PaperProtocolParameters(const ProtocolConfig& protocol);

// The protocol's inputs over [0, duration_s] (PlanCableInputs, by the
// protocol's planning, for an arm with `parameters`), checked against
// limits.cable_speed_mps and cable_acceleration_mps2 (central differences
// of the sampled lengths). Throws InputError naming the piece active where
// a limit is exceeded, the cable, the time and the limit.
CableInputs PlanProtocolInputs(const ArmModel& model, const Protocol& protocol,
                               const ArmParameters& parameters, double duration_s,
                               double sample_step_s = 1e-3);

// "'two-axis' (file.yaml), 12 s: segment 1 move, hold, sine; segment 2 ...".
std::string DescribeProtocolFile(const Protocol& protocol);

}  // namespace ccsrm::sim
