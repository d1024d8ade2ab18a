#pragma once
// The right-hand side of the arm's equations of motion (paper eqs. 59-68):
// the per-run data of one simulation (MuJoCo's "data") over a shared,
// immutable ArmModel. Evaluate() runs the stages of the model in order:
//   link kinematics -> cable elements -> hole friction -> connecting moments
//   -> link inertia -> constraints (Baumgarte) -> augmented solve.
//
// State y = [q (n), q_dot (n), dissipated energy (1)]; q follows eq. 59:
// every cable node (x, y, z, s) then every link (x, y, z, e0..e3).
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstdint>
#include <string>
#include <vector>

#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "kernels/connecting.h"

namespace ccsrm::sim::internal {

// Stick-slip state of one hole node: stuck (a temporary constraint s = s*),
// or slipping with a fixed direction sigma = sgn(s_dot) for the whole step.
enum class HoleMode : std::int8_t { kSlipDown = -1, kStuck = 0, kSlipUp = 1 };

struct HoleNodeRef {
  int cable = 0;
  int node = 0;  // index within the cable (1 .. nodes-2)
};

// What one evaluation learned about a hole node, for switch detection.
struct HoleReport {
  double s_dot = 0.0;              // m/s
  double required_friction = 0.0;  // stuck: friction the constraint applies on s [N]
  double friction_limit = 0.0;     // f_max (eq. 10) [N]
  double wrap_angle = 0.0;         // rad
};

// Everything written per output frame.
struct Observation {
  std::vector<Eigen::Vector2d> joint_angles;            // rad
  std::vector<Eigen::Vector2d> joint_rates;             // rad/s
  std::vector<Eigen::Matrix<double, 7, 1>> link_pose;   // x, y, z, e0..e3
  std::vector<std::vector<double>> element_tension;     // per cable, per element [N]
  std::vector<std::vector<double>> hole_slip_velocity;  // per cable, per hole [m/s]
  std::vector<std::vector<int>> hole_stuck;             // per cable, per hole
  Eigen::VectorXd input_length_change;                  // per cable [m]
  double constraint_violation = 0.0;
  double kinetic_energy = 0.0;
  double elastic_energy = 0.0;
  double dissipated_energy = 0.0;
};

class ArmDynamics {
 public:
  // `model` and `inputs` must outlive this object.
  ArmDynamics(const ArmModel& model, const CableInputs& inputs);

  int num_coordinates() const { return n_; }
  int state_size() const { return 2 * n_ + 1; }

  // Straight arm at rest, driving cables uniformly strained to T_d0.
  Eigen::VectorXd InitialState() const;

  // ydot = f(t, y) under the current hole modes. Returns false (leaving a
  // reason in failure()) when the augmented system is singular or the
  // result is not finite.
  bool Evaluate(double t, const double* y, double* ydot);
  const std::string& failure() const { return failure_; }

  // Driving-cable friction is on (mu or mu' > 0): hole nodes switch
  // between stick and slip; otherwise every node slips without friction.
  bool has_stick_slip() const { return stick_slip_; }
  const std::vector<HoleNodeRef>& holes() const { return holes_; }
  std::vector<HoleMode>& hole_modes() { return modes_; }
  std::vector<double>& stuck_position() { return stuck_s_; }
  // Filled by the last Evaluate().
  const std::vector<HoleReport>& hole_reports() const { return reports_; }

  // Norm of the active constraint violations |Phi| at (t, y).
  double ConstraintViolation(double t, const double* y);

  // Output quantities at (t, y); calls Evaluate for the tensions.
  // With `evaluate` false the caller guarantees that the last Evaluate() was
  // at (t, y) with the current hole modes, and its results are reused.
  void Observe(double t, const double* y, Observation* out, bool evaluate = true);

  std::int64_t evaluations() const { return evaluations_; }

 private:
  void BuildStructure();
  int Index(int row, int col) const;
  void FillConstraints(double t, const double* q, const double* qd, bool with_jacobian);

  const ArmModel& model_;
  const CableInputs& inputs_;
  const Config& config_;
  int n_ = 0;  // coordinates
  int m_ = 0;  // constraint rows
  bool stick_slip_ = false;
  bool smooth_connecting_friction_ = false;
  bool smooth_connecting_elasticity_ = false;
  // Power of the friction-smoothing term, (h/2) theta_dot^T C J q_dd, per
  // large-S pair and axis of the last evaluation (needs q_dd, so after the solve).
  struct SmoothingPower {
    Eigen::Matrix<double, 12, 1> weights;
    int cols[12];
    int count = 0;
  };
  std::vector<SmoothingPower> smoothing_power_;

  std::vector<HoleNodeRef> holes_;
  std::vector<int> hole_of_node_row_;  // row -> hole index, or -1
  std::vector<HoleMode> modes_;
  std::vector<double> stuck_s_;
  std::vector<HoleReport> reports_;
  std::vector<double> initial_s_;  // per cable node, s at t = 0

  // Constraint rows with a fixed column structure (<= 14 columns each).
  struct RowData {
    int count = 0;
    int cols[14];
    double vals[14];
    double phi = 0.0;  // Phi
    double b = 0.0;    // b of eq. 63
    bool active = true;
  };
  std::vector<RowData> rows_;
  std::vector<int> row_kkt_index_;   // per row: index of (n+r, col) then (col, n+r), 2*count
  std::vector<int> row_pair_index_;  // per row: count*count indices of (col_a, col_b)
  std::vector<int> row_pair_offset_;
  std::vector<int> row_diag_index_;  // index of (n+r, n+r)
  std::vector<int> element_index_;   // per element: 64 indices
  std::vector<int> link_index_;      // per link: 3 + 16 indices
  // Connecting pairs with their kernel parameters; for large S pairs the
  // links whose quaternion rates their joint rates involve (i-1, i, i+1)
  // and the KKT indices of those quaternion blocks (friction smoothing mass).
  struct PairKernel {
    ConnectingKind kind = ConnectingKind::kSmallS;
    int joint_i = 0;  // 1-based; the other joint is joint_i + 1
    SmallSParams small;
    LargeSParams large;
    std::vector<int> links;
    std::vector<int> block_index;
  };
  std::vector<PairKernel> pair_kernels_;

  // The augmented matrix is stored (both triangles) already in the
  // fill-reducing order found once by AMD, so that each factorization reads
  // it in place instead of permuting a copy (14% of the time before).
  // Index() and the vectors below are in the model's own order.
  Eigen::SparseMatrix<double> kkt_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::NaturalOrdering<int>> lu_;
  std::vector<int> kkt_order_;  // position of model unknown k in kkt_
  Eigen::VectorXd rhs_;
  Eigen::VectorXd kkt_rhs_, kkt_solution_;  // in kkt_ order
  Eigen::VectorXd solution_;                // q_dd then lambda, model order
  Eigen::VectorXd force_;
  std::string failure_;
  std::int64_t evaluations_ = 0;

  // Scratch of the last evaluation.
  std::vector<std::vector<double>> tension_;              // per cable element
  std::vector<Eigen::Matrix3d> rotation_;                 // per link A(e)
  std::vector<Eigen::Matrix<double, 3, 4>> rate_matrix_;  // per link G(e)
  std::vector<Eigen::Vector3d> omega_;                    // per link w' [rad/s]
  std::vector<Eigen::Matrix3d> relative_rotation_;        // per joint R_{L(i-1) L(i)}
  std::vector<Eigen::Vector2d> joint_moment_;             // per joint [N m]
  // Per element, what the dissipated power needs once q_dd is known.
  struct ElementRate {
    double coefficient;  // Δs EA eps_dot (beta' eps_dot + gamma eps_dot_q q_dot)
    double gamma_term;   // Δs EA gamma eps_dot, times eps_q q_dd
    Eigen::Matrix<double, 1, 8> jac;
    int cols[8];
  };
  std::vector<ElementRate> element_rates_;
  std::vector<Eigen::Vector2d> theta_, theta_dot_;
  double kinetic_ = 0.0, elastic_ = 0.0;
};

}  // namespace ccsrm::sim::internal
