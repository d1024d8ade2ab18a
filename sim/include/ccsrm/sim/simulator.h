#pragma once
// Forward dynamics of the arm: Simulate(model, parameters, inputs, options).
//
// The run API that identification calls thousands of times. One ArmModel
// (geometry, topology, sparsity) is shared read-only; each call owns its
// data and takes its own ArmParameters, so runs may go in parallel threads,
// and the same call always gives bit-identical results. Inside: an explicit
// embedded Runge-Kutta 4(5) with step control, the stick-slip switches of
// the driving-cable hole nodes located in time, and frames sampled at the
// requested times (sim/src/: integrator, stick_slip, output_sampler).
#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim {

// Progress of a long run, reported about once per `progress_interval_s`.
struct SimulationProgress {
  double simulated_s = 0.0;
  double duration_s = 0.0;
  double wall_time_s = 0.0;
  double real_time_factor = 0.0;  // simulated seconds per wall second
  std::int64_t steps = 0;
  std::int64_t stick_slip_switches = 0;
};

struct SimulationOptions {
  // Simulated time [s]; the run starts at t = 0.
  double duration_s = 48.0;
  // Times [s] at which frames are sampled, non-decreasing, in [0,
  // duration_s] (e.g. an experiment's mocap frame times). Empty: every
  // 1 / solver.output_rate_hz from 0 to duration_s.
  std::vector<double> sample_times;
  // Integration and structure switches; the defaults are those of
  // configs/paper.yaml's `solver:` section (Config::solver).
  SolverConfig solver;
  // Cancellation: the run stops with status kCancelled at the next step
  // once *cancel is true (may be null), or once it has used
  // wall_time_budget_s of wall time (0: no budget).
  const std::atomic<bool>* cancel = nullptr;
  double wall_time_budget_s = 0.0;
  // Called from the simulating thread; may be empty.
  std::function<void(const SimulationProgress&)> progress;
  double progress_interval_s = 1.0;  // wall seconds between progress calls

  // Quasi-static replay, for recordings of settled poses: instead of
  // integrating the dynamics, the frame at each sample time is the arm's
  // static equilibrium at rest under the inputs then, reached from the
  // previous frame's through equilibria at most quasi_static_increment_m of
  // any input apart, with every presliding displacement carried over its
  // contact's slip, so friction's hysteresis is kept (docs/model-notes.md,
  // "Quasi-static replay"). It needs friction laws that hold at rest:
  // solver.hole_friction presliding or off, and conduit friction presliding
  // or none (mu_c = mu_c_s = 0); the frames' rates and dissipated energy
  // are zero.
  bool quasi_static = false;
  double quasi_static_increment_m = 5e-4;

  // Checks every field except `solver` (Simulate checks that with
  // ValidateSolver).
  bool IsValid(std::string* error) const;
};

// Everything sampled at one instant.
struct TrajectoryFrame {
  std::vector<Eigen::Vector2d> joint_angles;            // per joint (θx, θy) [rad]
  std::vector<Eigen::Vector2d> joint_rates;             // per joint [rad/s]
  std::vector<Eigen::Matrix<double, 7, 1>> link_pose;   // per link x, y, z [m], e0..e3
  std::vector<std::vector<double>> element_tension;     // per cable, per element [N]
  std::vector<std::vector<double>> hole_slip_velocity;  // per cable, per hole [m/s]
  std::vector<std::vector<int>> hole_stuck;             // per cable, per hole (1 stuck)
  Eigen::VectorXd input_length_change;                  // per cable, pulled in [m]
  double constraint_violation = 0.0;                    // |Phi|
  double kinetic_energy = 0.0;                          // [J]
  double elastic_energy = 0.0;                          // [J]
  double dissipated_energy = 0.0;                       // since t = 0 [J]
};

// The frames of a run at the sample times it reached (all of them when it
// completed; those up to its end when it diverged or was cancelled).
struct Trajectory {
  std::vector<double> time;  // [s]
  std::vector<TrajectoryFrame> frames;
  std::size_t size() const { return time.size(); }
};

enum class SimulationStatus { kCompleted, kDiverged, kCancelled };

// "completed", "diverged" or "cancelled".
const char* SimulationStatusName(SimulationStatus status);

// A stretch of time in which a driving cable was slack: at least one of its
// elements carried no tension (a cable cannot push; docs/model-notes.md row
// 26). Times are those of the frames, so a stretch is known to the frame
// spacing.
struct SlackInterval {
  int cable = 0;          // 1-based
  double start_s = 0.0;   // first frame of the stretch with a slack element
  double end_s = 0.0;     // last such frame
  int most_elements = 0;  // most of its elements slack at once
  double duration_s() const { return end_s - start_s; }
};

// The elements of one cable in one frame that carry no tension (<= 0 N, so
// that a record from a model that let cables push counts them too).
int CountSlackElements(const std::vector<double>& element_tension);

// The stretches of consecutive frames in which slack_elements(f, c) > 0, per
// cable in order of cable then time. `time` holds the frame times (one per
// row of slack_elements, frames by cables).
std::vector<SlackInterval> FindSlackIntervals(const std::vector<double>& time,
                                              const Eigen::MatrixXi& slack_elements);

struct SimulationSummary {
  SimulationStatus status = SimulationStatus::kCompleted;
  bool completed() const { return status == SimulationStatus::kCompleted; }
  std::string message;       // "completed", or the cause with its time
  double simulated_s = 0.0;  // time reached
  double wall_time_s = 0.0;
  double real_time_factor = 0.0;  // simulated / wall
  std::int64_t steps = 0;         // accepted steps
  std::int64_t rejected_steps = 0;
  std::int64_t rhs_evaluations = 0;
  std::int64_t stick_slip_switches = 0;  // solver.hole_friction: events only
  // Events: releases undone at once, each raising that node's release
  // threshold above f_max (docs/model-notes.md row 16), and the largest raise.
  std::int64_t failed_releases = 0;
  double largest_threshold_raise_n = 0.0;
  double max_constraint_violation = 0.0;  // largest |Phi| over the sampled frames
  // Where a driving cable went slack (FindSlackIntervals over the frames).
  std::vector<SlackInterval> slack;

  // One line; and the one-screen summary of SPEC 3.
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct SimulationResult {
  Trajectory trajectory;
  SimulationSummary summary;
};

// Simulates the arm driven by `inputs` from the straight, pre-tensioned
// state at rest, with every effect that is on in `parameters`
// (ccsrm/sim/effects.h): actuator effects change the inputs the arm sees
// (the frames' input_length_change are those), dynamic effects act in the
// equations; measurement effects do not act here (RecordedJointAngles).
// A divergence (non-finite state, constraint violation above
// solver.max_constraint_violation, a step below solver.min_step_s) or a
// cancellation ends the run early with its status in the summary; it is not
// thrown. Throws InputError only for invalid parameters or options, or
// inputs that do not drive every cable of the model.
SimulationResult Simulate(const ArmModel& model, const ArmParameters& parameters,
                          const CableInputs& inputs, const SimulationOptions& options);

// Why the arm cannot be replayed quasi-statically under `solver`, or "" when
// it can: its friction laws must hold at rest (SimulationOptions::quasi_static).
// Simulate refuses such a replay with this text (InputError).
std::string WhyNotQuasiStatic(const ArmModel& model, const ArmParameters& parameters,
                              const SolverConfig& solver);

}  // namespace ccsrm::sim
