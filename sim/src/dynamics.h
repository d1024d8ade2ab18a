#pragma once
// The right-hand side of the arm's equations of motion (paper eqs. 59-68):
// the per-run data of one simulation (MuJoCo's "data") over a shared,
// immutable ArmModel, with the run's own ArmParameters and solver settings.
// Evaluate() is the physics in order, one named stage per call (see
// dynamics.cc); the index bookkeeping of the sparse system lives in
// sparse_system.h.
//
// State y = [q (n), q_dot (n), dissipated energy (1), frictional memory];
// q follows eq. 59: every cable node (x, y, z, s) then every link (x, y, z,
// e0..e3); the memory z in [0, 1] of every hole node, then of every large-S
// pair's x and y conduit (kernels/hole_friction.h, kernels/connecting.h);
// under hole_friction: presliding, then every hole node's presliding
// displacement xi [m].
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "effects/effect.h"
#include "kernels/ale_element.h"
#include "kernels/connecting.h"
#include "kernels/hole_friction.h"
#include "kernels/rigid_body.h"
#include "sparse_system.h"

namespace ccsrm::sim::internal {

// Stick-slip state of one hole node: stuck (a temporary constraint s = s*),
// or slipping with a fixed direction sigma = sgn(s_dot) for the whole step.
enum class HoleMode : std::int8_t { kSlipDown = -1, kStuck = 0, kSlipUp = 1 };

// What one evaluation learned about a hole node, for switch detection.
struct HoleReport {
  double s_dot = 0.0;              // m/s
  double required_friction = 0.0;  // stuck: friction the constraint applies on s [N]
  double friction_limit = 0.0;     // f_max (eq. 10) [N]
  double wrap_angle = 0.0;         // rad
  // Presliding: the part of s_dot that slides, s_dot - xi_dot [m/s].
  double sliding_speed = 0.0;
};

// The frictional state that a settled pose leaves for the next (the
// quasi-static replay, quasi_static.h): per hole node its material
// coordinate s [m] and presliding displacement xi [m]; per connecting pair
// and axis (index 2 p + axis; small-S pairs unused) its conduit's slip
// coordinate -r (theta_i + theta_j) / 2 [m] and presliding displacement eta [m].
struct SettledFriction {
  std::vector<double> hole_s, hole_xi;
  std::vector<double> conduit_slip, conduit_eta;
};

class ArmDynamics {
 public:
  // `model` and `inputs` must outlive this object. Preconditions (checked):
  // parameters valid, inputs for every cable of the model.
  ArmDynamics(const ArmModel& model, const ArmParameters& parameters, const CableInputs& inputs,
              const SolverConfig& solver);
  ~ArmDynamics();

  int num_coordinates() const { return n_; }
  int state_size() const { return 2 * n_ + 1 + num_memory_; }
  // The frictional memory states follow the coordinates, velocities and
  // dissipated energy.
  int memory_offset() const { return 2 * n_ + 1; }
  const SolverConfig& solver() const { return solver_; }

  // Per state entry, the factor of solver.absolute_tolerance in the step
  // control's error bound (GSL's scale_abs).
  std::vector<double> ErrorScales() const;

  // What state entry k is, for diagnostics (CCSRM_TRACE_STEPS): "link
  // coordinate", "node coordinate", "link velocity", "node velocity", "hole
  // slip speed", "energy", "hole memory", "conduit memory", "hole presliding"
  // or "conduit presliding".
  const char* StateEntryKind(int k) const;

  // Straight arm at rest, driving cables uniformly strained to T_d0.
  Eigen::VectorXd InitialState() const;

  // ydot = f(t, y) under the current hole modes. Returns false (leaving a
  // reason in failure()) when the augmented system is singular or the
  // result is not finite.
  bool Evaluate(double t, const double* y, double* ydot);
  const std::string& failure() const { return failure_; }

  // Hole nodes switch between stick and slip by events (kEvents); otherwise
  // every node's friction is a function of its state (kSmoothed, kOff,
  // kPresliding).
  bool has_stick_slip() const { return solver_.hole_friction == HoleFrictionModel::kEvents; }
  const std::vector<HoleNodeRef>& holes() const { return layout_.holes(); }
  std::vector<HoleMode>& hole_modes() { return modes_; }
  std::vector<double>& stuck_position() { return stuck_s_; }
  // Filled by the last Evaluate().
  const std::vector<HoleReport>& hole_reports() const { return reports_; }

  // Norm of the active constraint violations |Phi| at (t, y).
  double ConstraintViolation(double t, const double* y);

  // Output quantities at (t, y); calls Evaluate for the tensions.
  // With `evaluate` false the caller guarantees that the last Evaluate() was
  // at (t, y) with the current hole modes, and its results are reused.
  void Observe(double t, const double* y, TrajectoryFrame* out, bool evaluate = true);

  std::int64_t evaluations() const { return evaluations_; }

  // Quasi-static replay (quasi_static.h). The unknowns x = [q (n), lambda
  // (num_constraints())] of the static equilibrium at rest at time t, and
  // its residual [F(q) - Phi_q^T lambda; Phi(q, t)] with every velocity zero,
  // every frictional memory at rest (z = 1) and every presliding
  // displacement carried from `from` over its contact's slip since then
  // (ElastoplasticDisplacementAfterSlip); a constraint row that is off has
  // the residual lambda. Returns false as Evaluate does.
  int num_constraints() const { return m_; }
  bool SettledResidual(double t, const double* x, const SettledFriction& from, double* residual);
  // Row r of Phi_q over SparseLayout::rows()[r].cols at the last
  // SettledResidual (or Evaluate), and whether the row is on.
  const double* constraint_gradient(int r) const { return rows_[r].vals; }
  bool constraint_active(int r) const { return rows_[r].active; }
  // The branch of each contact's presliding law that SettledResidual
  // evaluates (ElastoplasticDisplacementOnBranch): per hole node, and per
  // connecting pair and axis (2 p + axis), +1 slipping along its last
  // settled displacement, -1 against it, 0 the law itself (the default).
  struct SettledBranches {
    std::vector<signed char> hole, conduit;
  };
  SettledBranches& settled_branches() { return branches_; }
  // At rest a slack element (row 27) has no stiffness, and a slack cable's
  // material coordinates none: its equilibrium would not be unique. In the
  // settled residual every element also carries this fraction of EA on its
  // strain: a slack cable's material then spreads evenly (pushing with at
  // most 1e-5 EA at a strain of -0.1), a taut one's tension moves by that
  // fraction of itself. The solver raises it for a continuation where the
  // toe's stiffness, rising from nothing, defeats Newton's method.
  static constexpr double kSettledElementStiffness = 1e-4;
  void set_settled_element_stiffness(double fraction) { settled_element_stiffness_ = fraction; }
  // The friction state at the x of the last SettledResidual.
  const SettledFriction& settled_friction() const { return settled_now_; }
  // That of InitialState(): no presliding displacement anywhere.
  SettledFriction InitialSettledFriction() const;
  // The state at rest at coordinates q with the friction state `friction`
  // (for Observe).
  Eigen::VectorXd RestState(const double* q, const SettledFriction& friction) const;

 private:
  // The stages of Evaluate, in order.
  void ComputeLinkKinematics(const double* q, const double* qd);
  bool AddCableElements(const double* q, const double* qd);
  void AddHoleFriction(const double* q, const double* qd, const double* memory);
  void AddPreslidingFriction(int h, int s_col, double t_before, double v, const double* memory,
                             double xi);
  // Settled residual: hole h's and conduit (pair p, axis)'s presliding
  // displacement after their slips since settled_from_, recorded in
  // settled_now_.
  double SettledHoleDisplacement(int h, double s, double wrap_angle);
  double SettledConduitDisplacement(int p, int axis, double theta_i, double theta_j);
  void ComputeJointAngles();
  void AddConnectingMoments(double t, const double* memory);
  void AddBackboneMoments();
  void AddEffectLoads(double t, const double* qd);
  void ApplyJointMoments(const double* q);
  void AddLinkInertia(const double* q, const double* qd);
  void AddConstraints(double t, const double* q, const double* qd);
  bool SolveAugmentedSystem();
  bool FinishDerivative(const double* qd, double* ydot);

  // h for the presliding laws' relaxation (ElastoplasticSlide), 0 without
  // solver.smooth_presliding_relaxation.
  double PreslidingRelaxationResolution() const {
    return solver_.smooth_presliding_relaxation ? solver_.smoothing_step_s : 0.0;
  }

  // The holes' presliding law of this run, its relaxation smoothed over
  // `relaxation_resolution_s` (0: not).
  PreslidingLaw HolePreslidingLaw(double relaxation_resolution_s) const {
    return {
        {parameters_.mu, parameters_.mu_s, parameters_.v_s, solver_.stick_velocity_tolerance_mps},
        parameters_.xi_f,
        relaxation_resolution_s};
  }

  // Row `axis` of d(theta_dot of joint k)/d(e_dot of link), 1-based k and
  // link (zero unless link is k or k - 1).
  Eigen::Matrix<double, 1, 4> JointRateRow(int k, int link, int axis) const;
  // Joint-space moment on joint `joint`'s `axis` from an effect, with the
  // model smoothing of its damping (EffectLoads::AddJointMoment).
  void AddEffectJointMoment(int joint, int axis, double moment, double damping);
  // Model smoothing's `mass` [kg m^2] on joint `joint`'s angle `axis`.
  void AddJointSmoothingMass(int joint, int axis, double mass);

  // Phi, its Baumgarte right-hand side b and (with_jacobian) Phi_q of every
  // row (eqs. 35-37, 61-63); needs the link rotations.
  void FillConstraints(double t, const double* q, const double* qd, bool with_jacobian);

  const ArmModel& model_;
  const SparseLayout& layout_;
  const CableInputs& inputs_;
  const ArmParameters parameters_;
  const SolverConfig solver_;
  int n_ = 0;           // coordinates
  int m_ = 0;           // constraint rows
  int num_memory_ = 0;  // frictional memory states
  // Presliding: index of the first hole's xi among them (-1: none).
  int presliding_ = -1;

  // Element and connecting-pair kernel parameters of this run.
  AleElementParams ale_;
  struct PairKernel {
    ConnectingKind kind = ConnectingKind::kSmallS;
    int joint_i = 0;  // 1-based; the other joint is joint_i + 1
    int memory = -1;  // large S: index of its x conduit's memory (y: memory + 1)
    // Large S under conduit presliding: index of its x conduit's presliding
    // displacement among the memory states (y: presliding + 1); else -1.
    int presliding = -1;
    SmallSParams small;
    LargeSParams large;
  };
  std::vector<PairKernel> pair_kernels_;

  // The effects that are on (ccsrm/sim/effects.h), and those of them that
  // act in the right-hand side, by hook; all empty when every effect is off.
  class EffectLoadsView;
  std::vector<std::unique_ptr<Effect>> effects_;
  std::vector<const Effect*> pretension_effects_, deflection_effects_, load_effects_;
  std::unique_ptr<EffectLoadsView> effect_loads_;

  // Set during SettledResidual only.
  const SettledFriction* settled_from_ = nullptr;
  SettledFriction settled_now_;
  SettledBranches branches_;
  double settled_element_stiffness_ = kSettledElementStiffness;
  std::vector<double> zero_rates_;   // n zeros: q_dot at rest
  std::vector<double> rest_memory_;  // the memory states at rest

  std::vector<HoleMode> modes_;
  std::vector<double> stuck_s_;
  std::vector<HoleReport> reports_;
  std::vector<double> initial_s_;    // per cable node, s at t = 0
  std::vector<double> memory_rate_;  // dz/dt of every memory state [1/s]

  // Per constraint row: its values at the current state.
  struct RowValues {
    double vals[ConstraintRowLayout::kMaxColumns];
    double phi = 0.0;  // Phi
    double b = 0.0;    // b of eq. 63
    bool active = true;
  };
  std::vector<RowValues> rows_;
  // Per cable node, its acceleration as an affine function of its link's
  // (solver.embed_cable_nodes), filled with the rows.
  std::vector<NodeEmbedding> embedding_;
  AugmentedSystem system_;
  Eigen::VectorXd force_;
  std::string failure_;
  std::int64_t evaluations_ = 0;

  // Scratch of the last evaluation.
  double dissipation_ = 0.0;  // W, power taken out by friction, damping and smoothing
  double kinetic_ = 0.0, elastic_ = 0.0;
  std::vector<std::vector<double>> tension_;              // per cable element
  std::vector<Eigen::Matrix3d> rotation_;                 // per link A(e)
  std::vector<Eigen::Matrix<double, 3, 4>> rate_matrix_;  // per link G(e)
  std::vector<Eigen::Vector3d> omega_;                    // per link w' [rad/s]
  std::vector<BodyPointKinematics> point_kinematics_;     // per link
  std::vector<Eigen::Matrix3d> relative_rotation_;        // per joint R_{L(i-1) L(i)}
  std::vector<Eigen::Vector2d> joint_moment_;             // per joint [N m]
  std::vector<Eigen::Vector2d> theta_, theta_dot_;        // per joint [rad], [rad/s]
  // Per element, what the dissipated power needs once q_dd is known.
  struct ElementRate {
    double coefficient;  // Δs EA eps_dot (beta' eps_dot + gamma eps_dot_q q_dot - pushing eps)
    double gamma_term;   // Δs EA gamma eps_dot, times eps_q q_dd
    Eigen::Matrix<double, 1, 8> jac;
    int cols[8];
  };
  std::vector<ElementRate> element_rates_;
  // Power of the connecting-cable smoothing terms, (h/2) theta_dot^T C J q_dd,
  // per pair and axis (needs q_dd, so after the solve).
  struct SmoothingPower {
    Eigen::Matrix<double, 12, 1> weights;
    int cols[12];
    int count = 0;
  };
  std::vector<SmoothingPower> smoothing_power_;
  // The same for the smoothed hole friction: (s column, added mass * s_dot).
  std::vector<std::pair<int, double>> hole_smoothing_power_;
};

}  // namespace ccsrm::sim::internal
