#pragma once
// Quasi-static replay (SimulationOptions::quasi_static): the arm's static
// equilibria at rest, one per sample time, each reached from the one before
// through equilibria at most options.quasi_static_increment_m of any input
// apart, every presliding displacement carried over its contact's slip
// (ArmDynamics::SettledResidual). It is the limit of slow motion, in which
// the presliding laws are rate independent and keep friction's hysteresis:
// the model for a recording of settled poses, whose transients between
// poses nobody measured (docs/model-notes.md, "Quasi-static replay").
//
// Each equilibrium is a Newton solve of SettledResidual over x = [q,
// lambda]. Its Jacobian is sparse with the arm's topology (elements, hole
// nodes, joints, connecting pairs, constraint rows): forward differences of
// groups of columns that share no row (a greedy distance-2 colouring of the
// pattern) give it in a few dozen residuals, and a sparse LU solves it; a
// Jacobian is kept while the iterations contract fast (chord steps) and
// every step must pass Deuflhard's natural monotonicity test.
#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/sim/simulator.h"
#include "dynamics.h"

namespace ccsrm::sim::internal {

class SettledPoseSolver {
 public:
  // `dynamics` must outlive the solver.
  SettledPoseSolver(const ArmModel& model, ArmDynamics* dynamics);

  int size() const { return size_; }
  int num_colours() const { return static_cast<int>(colours_.size()); }

  // The equilibrium at t with the friction carried from `from`, from the
  // guess *x; on success *x is the equilibrium and
  // dynamics->settled_friction() its friction state. Each contact's
  // presliding law has a kink where its slip turns from along its
  // displacement to against it (loading to unloading), which Newton's
  // method cannot cross: an active set fixes every contact's branch
  // (ArmDynamics::SettledBranches; at first from the guess's slips, the
  // elastic side where it has none), solves, and flips the contacts whose
  // slip contradicts their branch, until none does. The force is monotone
  // in each slip, so one consistent set exists. Where that fails (a cable
  // going slack or taut), it is solved again by continuation in the
  // elements' residual stiffness (ArmDynamics::kSettledElementStiffness,
  // from 1e-2 down). Returns false (with failure()) when a Newton solve
  // stops contracting or the set does not settle.
  bool Solve(double t, const SettledFriction& from, Eigen::VectorXd* x);
  const std::string& failure() const { return failure_; }

  // The forward-difference Jacobian of the residual at x, factorised for
  // the next Solve (which keeps it while it serves).
  bool ComputeJacobian(double t, const SettledFriction& from, const Eigen::VectorXd& x);
  const Eigen::SparseMatrix<double>& jacobian() const { return jacobian_; }

  std::int64_t jacobians() const { return jacobians_; }
  std::int64_t iterations() const { return iterations_; }

 private:
  bool Residual(double t, const SettledFriction& from, const Eigen::VectorXd& x,
                Eigen::VectorXd* r);
  // Solve without the continuation.
  bool SolveWithBranches(double t, const SettledFriction& from, Eigen::VectorXd* x);
  // Newton on the residual with the branches as they are.
  bool Newton(double t, const SettledFriction& from, Eigen::VectorXd* x);
  // Each contact's branch from its slip at the last residual: `initial`,
  // along where it slips along its displacement, else against; otherwise
  // flips those whose slip contradicts their branch. Returns the flips.
  int ChooseBranches(const SettledFriction& from, bool initial);
  // The Newton correction -J^-1 r; false if not finite.
  bool Correction(const Eigen::VectorXd& r, Eigen::VectorXd* dx);
  // The largest fraction of dx that leaves every element at least half its
  // material length (at most 1): a slack cable's material, weakly held,
  // would otherwise be stepped through itself.
  double MaterialStepLimit(const Eigen::VectorXd& x, const Eigen::VectorXd& dx) const;
  // Weighted RMS of a correction's coordinates (the multipliers follow
  // them): 1 is the convergence tolerance.
  double Norm(const Eigen::VectorXd& dx, const Eigen::VectorXd& x) const;

  ArmDynamics* dynamics_;
  const SparseLayout& layout_;
  int n_ = 0;                             // coordinates
  int size_ = 0;                          // coordinates and multipliers
  Eigen::SparseMatrix<double> jacobian_;  // column-major, pattern fixed
  // The coordinates' columns by colour: forward differences of the force
  // rows. The constraint rows and the multipliers' columns are exact:
  // their entries' positions in jacobian_ per constraint row r, over its
  // columns from row_start_[r] (Phi_q, then -Phi_q^T), and its diagonal.
  std::vector<std::vector<int>> colours_;
  std::vector<int> row_start_, gradient_entry_, reaction_entry_, diagonal_entry_;
  // Per cable element, the material coordinates' columns of its two nodes
  // (a step may shorten an element's material by at most half).
  std::vector<std::pair<int, int>> element_material_;
  // The cables' coordinates are the first columns (kCableDifferenceStepM).
  int cable_columns_ = 0;
  // The Jacobian is unsymmetric and indefinite (a saddle point in the
  // multipliers). Eigen's supernodal LU with COLAMD: on the robot's arm
  // (3 400 unknowns) 3.5x faster than SuiteSparse's KLU through Eigen.
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_;
  bool factorised_ = false;
  std::string failure_;
  std::int64_t jacobians_ = 0, iterations_ = 0;
  Eigen::VectorXd r_, r_try_, x_try_, perturbed_;
};

// Simulate() under options.quasi_static (after its checks and the
// realisation of the inputs).
SimulationResult SimulateSettledPoses(const ArmModel& model, const ArmParameters& parameters,
                                      const CableInputs& inputs, const SimulationOptions& options);

}  // namespace ccsrm::sim::internal
