#include "quasi_static.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include "ccsrm/common/error.h"
#include "output_sampler.h"
#include "run_control.h"

namespace ccsrm::sim::internal {
namespace {

// Convergence: a correction's weighted RMS below 1 with these weights,
// about 2e-9 m on the arm's coordinates (~0.1 m) and 1e-8 on the
// quaternions: far below what any frame is compared with (0.03 deg of a
// joint is 5e-4 rad).
constexpr double kAbsoluteTolerance = 1e-9;
constexpr double kRelativeTolerance = 1e-8;
constexpr int kMaxIterations = 40;
// A Jacobian is kept while the corrections shrink at least this fast.
constexpr double kKeepJacobianContraction = 0.7;
// A correction within this many tolerances that no step improves on is
// taken as converged (about 2e-8 m).
constexpr double kStallTolerance = 10.0;
// Forward-difference steps: sqrt(machine epsilon) of the coordinate's
// size, at least of 1 cm; on the cables' coordinates a tenth of a
// picometre. An element's stiffness rises from the weak 1e-4 EA at zero
// strain at a curvature of 4 EA over the toe (1e-4 of strain), so a step's
// strain must stay far below 1e-8 for the difference to see the stiffness
// at the point: sqrt(eps) of a coordinate (1e-9 m over millimetre
// elements, a strain of 1e-6) measured 200 times the weak stiffness there,
// and Newton's corrections on a cable going slack pointed nowhere. The
// step's rounding (positions of 0.3 m to 6e-17 m) costs a relative 1e-3
// on a taut element's entries.
constexpr double kDifferenceStep = 1.5e-8;
constexpr double kCableDifferenceStepM = 1e-13;
// The active set of the contacts' branches: at most this many passes, and
// a slip against a contact's branch by less than this [m] (the solves'
// accuracy) is none.
constexpr int kMaxActiveSetPasses = 20;
constexpr double kBranchTolerance = 1e-9;
// An increment that fails is halved at most this often.
constexpr int kMaxHalvings = 8;

// The residual's sparsity from the arm's topology: which unknowns each
// residual row may depend on (sim/src/dynamics.cc's stages at rest).
class PatternBuilder {
 public:
  explicit PatternBuilder(int size) : rows_of_column_(size) {
    for (int k = 0; k < size; ++k) rows_of_column_[k].insert(k);
  }
  void Depends(const std::vector<int>& rows, const std::vector<int>& cols) {
    for (int c : cols)
      for (int r : rows) rows_of_column_[c].insert(r);
  }
  void Clique(const std::vector<int>& cols) { Depends(cols, cols); }
  Eigen::SparseMatrix<double> Matrix() const {
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t c = 0; c < rows_of_column_.size(); ++c)
      for (int r : rows_of_column_[c]) entries.emplace_back(r, static_cast<int>(c), 0.0);
    const int size = static_cast<int>(rows_of_column_.size());
    Eigen::SparseMatrix<double> m(size, size);
    m.setFromTriplets(entries.begin(), entries.end());
    m.makeCompressed();
    return m;
  }

 private:
  std::vector<std::set<int>> rows_of_column_;
};

std::vector<int> NodeColumns(const ArmModel& model, int cable, int node) {
  const int o = model.node_offset(cable, node);
  return {o, o + 1, o + 2, o + 3};
}

std::vector<int> QuaternionColumns(const ArmModel& model, const std::vector<int>& links) {
  std::vector<int> cols;
  for (int link : links)
    for (int k = 3; k < 7; ++k) cols.push_back(model.link_offset(link) + k);
  return cols;
}

// The force rows' dependence on the coordinates, F(q) - Phi_q^T lambda
// (the multipliers' columns and the constraint rows are known exactly:
// -Phi_q^T and Phi_q).
Eigen::SparseMatrix<double> ForcePattern(const ArmModel& model) {
  const int n = model.num_coordinates();
  PatternBuilder pattern(n);
  const SparseLayout& layout = model.sparse_layout();
  // Elements: forces on both nodes from both nodes.
  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e) {
      std::vector<int> cols = NodeColumns(model, c, e);
      const std::vector<int> next = NodeColumns(model, c, e + 1);
      cols.insert(cols.end(), next.begin(), next.end());
      pattern.Clique(cols);
    }
  }
  // Hole friction on s from the wrap angle (both neighbours), the tension
  // before and s itself.
  for (const HoleNodeRef& hole : layout.holes()) {
    std::vector<int> cols;
    for (int k = hole.node - 1; k <= hole.node + 1; ++k) {
      const std::vector<int> node = NodeColumns(model, hole.cable, k);
      cols.insert(cols.end(), node.begin(), node.end());
    }
    pattern.Depends({model.node_offset(hole.cable, hole.node) + 3}, cols);
  }
  // Joint moments (backbone, effects) on the joint's two links'
  // quaternions, from its angles; and Phi_q^T lambda of its rows, whose
  // gradients vary with those quaternions only.
  for (int j = 1; j <= model.num_joints(); ++j) {
    pattern.Clique(QuaternionColumns(model, j > 1 ? std::vector<int>{j - 1, j} : std::vector{j}));
  }
  // Connecting pairs: the moments on both joints from both joints' angles.
  for (std::size_t p = 0; p < model.connecting_pairs().size(); ++p)
    pattern.Clique(QuaternionColumns(model, layout.pair_links(static_cast<int>(p))));
  // The other rows' gradients vary with their link's quaternion alone (a
  // node's rows with A(e) p, the norm row with 2e); the rest is constant.
  for (int i = 1; i <= model.num_links(); ++i) pattern.Clique(QuaternionColumns(model, {i}));
  return pattern.Matrix();
}

// The whole residual's: the force rows', and the constraint rows' and
// multipliers' blocks Phi_q and -Phi_q^T, and a diagonal.
Eigen::SparseMatrix<double> ResidualPattern(const ArmModel& model, int constraints) {
  const int n = model.num_coordinates();
  std::vector<Eigen::Triplet<double>> entries;
  const Eigen::SparseMatrix<double> force = ForcePattern(model);
  for (int c = 0; c < n; ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(force, c); it; ++it)
      entries.emplace_back(it.row(), c, 0.0);
  }
  for (int r = 0; r < constraints; ++r) {
    const ConstraintRowLayout& row = model.sparse_layout().rows()[r];
    for (int a = 0; a < row.count; ++a) {
      entries.emplace_back(n + r, row.cols[a], 0.0);
      entries.emplace_back(row.cols[a], n + r, 0.0);
    }
    entries.emplace_back(n + r, n + r, 0.0);
  }
  Eigen::SparseMatrix<double> m(n + constraints, n + constraints);
  m.setFromTriplets(entries.begin(), entries.end());  // sums duplicates: all 0
  m.makeCompressed();
  return m;
}

// Greedy distance-2 colouring of the columns: a column takes the first
// colour that no column sharing one of its rows has.
std::vector<std::vector<int>> ColourColumns(const Eigen::SparseMatrix<double>& pattern) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> by_row = pattern;
  const int size = static_cast<int>(pattern.cols());
  std::vector<int> colour(size, -1);
  std::vector<int> seen;  // per colour, the last column that met it
  std::vector<std::vector<int>> colours;
  for (int c = 0; c < size; ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator row(pattern, c); row; ++row) {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator other(by_row, row.row());
           other; ++other) {
        const int k = colour[other.col()];
        if (k >= 0) seen[k] = c;
      }
    }
    int k = 0;
    while (k < static_cast<int>(colours.size()) && seen[k] == c) ++k;
    if (k == static_cast<int>(colours.size())) {
      colours.emplace_back();
      seen.push_back(-1);
    }
    colour[c] = k;
    colours[k].push_back(c);
  }
  return colours;
}

}  // namespace

namespace {

// Where entry (row, col) of a compressed column-major matrix is stored.
int EntryIndex(const Eigen::SparseMatrix<double>& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(begin, end, row);
  CCSRM_CHECK(at != end && *at == row);
  return static_cast<int>(at - m.innerIndexPtr());
}

}  // namespace

SettledPoseSolver::SettledPoseSolver(const ArmModel& model, ArmDynamics* dynamics)
    : dynamics_(dynamics),
      layout_(model.sparse_layout()),
      n_(dynamics->num_coordinates()),
      size_(dynamics->num_coordinates() + dynamics->num_constraints()),
      jacobian_(ResidualPattern(model, dynamics->num_constraints())),
      colours_(ColourColumns(ForcePattern(model))),
      r_(size_),
      r_try_(size_),
      x_try_(size_),
      perturbed_(size_) {
  for (int r = 0; r < dynamics->num_constraints(); ++r) {
    const ConstraintRowLayout& row = layout_.rows()[r];
    row_start_.push_back(static_cast<int>(gradient_entry_.size()));
    for (int a = 0; a < row.count; ++a) {
      gradient_entry_.push_back(EntryIndex(jacobian_, n_ + r, row.cols[a]));
      reaction_entry_.push_back(EntryIndex(jacobian_, row.cols[a], n_ + r));
    }
    diagonal_entry_.push_back(EntryIndex(jacobian_, n_ + r, n_ + r));
  }
  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e)
      element_material_.emplace_back(model.node_offset(c, e) + 3, model.node_offset(c, e + 1) + 3);
  }
  lu_.analyzePattern(jacobian_);
  cable_columns_ = model.num_links() > 0 ? model.link_offset(1) : n_;
}

bool SettledPoseSolver::Residual(double t, const SettledFriction& from, const Eigen::VectorXd& x,
                                 Eigen::VectorXd* r) {
  if (dynamics_->SettledResidual(t, x.data(), from, r->data())) return true;
  failure_ = dynamics_->failure();
  return false;
}

bool SettledPoseSolver::ComputeJacobian(double t, const SettledFriction& from,
                                        const Eigen::VectorXd& x) {
  Eigen::VectorXd base(size_);
  if (!Residual(t, from, x, &base)) return false;
  ++jacobians_;
  const int* outer = jacobian_.outerIndexPtr();
  const int* inner = jacobian_.innerIndexPtr();
  double* values = jacobian_.valuePtr();
  // Exact: Phi_q in the constraint rows, -Phi_q^T in the multipliers'
  // columns; a row that is off has the residual lambda.
  for (int r = 0; r < dynamics_->num_constraints(); ++r) {
    const bool active = dynamics_->constraint_active(r);
    const double* gradient = dynamics_->constraint_gradient(r);
    for (int a = 0; a < layout_.rows()[r].count; ++a) {
      values[gradient_entry_[row_start_[r] + a]] = active ? gradient[a] : 0.0;
      values[reaction_entry_[row_start_[r] + a]] = active ? -gradient[a] : 0.0;
    }
    values[diagonal_entry_[r]] = active ? 0.0 : 1.0;
  }
  // Forward differences of the force rows, a colour of coordinates at a time.
  std::vector<double> step(n_);
  for (const std::vector<int>& colour : colours_) {
    perturbed_ = x;
    for (int c : colour) {
      perturbed_[c] += c < cable_columns_ ? kCableDifferenceStepM
                                          : kDifferenceStep * std::max(std::abs(x[c]), 1e-2);
      step[c] = perturbed_[c] - x[c];  // the step as represented
    }
    if (!Residual(t, from, perturbed_, &r_try_)) return false;
    for (int c : colour) {
      for (int k = outer[c]; k < outer[c + 1] && inner[k] < n_; ++k)
        values[k] = (r_try_[inner[k]] - base[inner[k]]) / step[c];
    }
  }
  lu_.factorize(jacobian_);
  factorised_ = lu_.info() == Eigen::Success;
  if (!factorised_) failure_ = "the equilibrium's Jacobian is singular";
  return factorised_;
}

bool SettledPoseSolver::Correction(const Eigen::VectorXd& r, Eigen::VectorXd* dx) {
  *dx = -lu_.solve(r);
  if (dx->allFinite()) return true;
  failure_ = "non-finite Newton correction";
  return false;
}

double SettledPoseSolver::MaterialStepLimit(const Eigen::VectorXd& x,
                                            const Eigen::VectorXd& dx) const {
  double limit = 1.0;
  for (const auto& [before, after] : element_material_) {
    const double shrink = dx[before] - dx[after];  // > 0 shortens the element
    if (shrink > 0.0) limit = std::min(limit, 0.5 * (x[after] - x[before]) / shrink);
  }
  return limit;
}

double SettledPoseSolver::Norm(const Eigen::VectorXd& dx, const Eigen::VectorXd& x) const {
  double sum = 0.0;
  for (int k = 0; k < n_; ++k) {
    const double w = dx[k] / (kAbsoluteTolerance + kRelativeTolerance * std::abs(x[k]));
    sum += w * w;
  }
  return std::sqrt(sum / n_);
}

bool SettledPoseSolver::Solve(double t, const SettledFriction& from, Eigen::VectorXd* x) {
  const Eigen::VectorXd guess = *x;
  if (SolveWithBranches(t, from, x)) return true;
  // A cable going slack or taut: the toe's stiffness rises from nothing,
  // and Newton's corrections from a slack side fly off. Continuation in
  // the elements' residual stiffness: solved where the slack side is
  // stiffer, then brought back to the model's in two steps.
  *x = guess;
  bool solved = true;
  for (double fraction : {1e-2, 1e-3, ArmDynamics::kSettledElementStiffness}) {
    dynamics_->set_settled_element_stiffness(fraction);
    factorised_ = false;
    solved = solved && SolveWithBranches(t, from, x);
  }
  dynamics_->set_settled_element_stiffness(ArmDynamics::kSettledElementStiffness);
  if (!solved) *x = guess;
  return solved;
}

bool SettledPoseSolver::SolveWithBranches(double t, const SettledFriction& from,
                                          Eigen::VectorXd* x) {
  failure_.clear();
  if (!Residual(t, from, *x, &r_)) return false;
  ChooseBranches(from, true);
  for (int pass = 0; pass < kMaxActiveSetPasses; ++pass) {
    if (!Newton(t, from, x)) return false;
    if (ChooseBranches(from, false) == 0) return true;
  }
  failure_ = "the contacts' loading and unloading did not settle in " +
             std::to_string(kMaxActiveSetPasses) + " passes";
  return false;
}

int SettledPoseSolver::ChooseBranches(const SettledFriction& from, bool initial) {
  const SettledFriction& now = dynamics_->settled_friction();
  ArmDynamics::SettledBranches& branches = dynamics_->settled_branches();
  int flips = 0;
  auto choose = [&](double slip, double displacement, signed char* branch) {
    const double along = displacement < 0.0 ? -slip : slip;
    signed char wanted = *branch;
    if (initial) {
      wanted = along > 0.0 ? 1 : -1;
    } else if (*branch > 0 && along < -kBranchTolerance) {
      wanted = -1;
    } else if (*branch < 0 && along > kBranchTolerance) {
      wanted = 1;
    }
    if (wanted != *branch) ++flips;
    *branch = wanted;
  };
  for (std::size_t h = 0; h < branches.hole.size(); ++h)
    choose(now.hole_s[h] - from.hole_s[h], from.hole_xi[h], &branches.hole[h]);
  for (std::size_t k = 0; k < branches.conduit.size(); ++k) {
    choose(now.conduit_slip[k] - from.conduit_slip[k], from.conduit_eta[k], &branches.conduit[k]);
  }
  return flips;
}

bool SettledPoseSolver::Newton(double t, const SettledFriction& from, Eigen::VectorXd* x_io) {
  Eigen::VectorXd& x = *x_io;
  // `fresh`: the Jacobian is that of the current x.
  bool fresh = false;
  if (!factorised_) {
    if (!ComputeJacobian(t, from, x)) return false;
    fresh = true;
  }
  if (!Residual(t, from, x, &r_)) return false;
  Eigen::VectorXd dx, dx_bar;
  if (!Correction(r_, &dx)) return false;
  double norm = Norm(dx, x);
  double damping = 1.0;
  double rate = 1.0;  // the last accepted step's contraction
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    ++iterations_;
    // Converged: the correction, or the error it leaves at the contraction
    // seen, rate / (1 - rate) |dx|, is within the tolerance.
    if (norm <= 1.0 || (rate < 1.0 && rate / (1.0 - rate) * norm <= 1.0)) {
      x += dx;
      // The friction state of the final x.
      return Residual(t, from, x, &r_);
    }
    damping = std::min(damping, MaterialStepLimit(x, dx));
    x_try_ = x + damping * dx;
    // Deuflhard's restricted natural monotonicity test: the simplified
    // correction at the trial point, with the same Jacobian, must be
    // shorter than (1 - damping / 4) of the correction.
    double norm_bar = 0.0;
    const bool monotone = Residual(t, from, x_try_, &r_try_) && Correction(r_try_, &dx_bar) &&
                          (norm_bar = Norm(dx_bar, x_try_)) < (1.0 - 0.25 * damping) * norm;
    if (monotone) {
      rate = norm_bar / norm;
      std::swap(x, x_try_);
      std::swap(r_, r_try_);
      dx = dx_bar;
      norm = norm_bar;
      damping = std::min(1.0, 2.0 * damping);
      fresh = false;
      if (rate > kKeepJacobianContraction && norm > 1.0) {
        if (!ComputeJacobian(t, from, x) || !Correction(r_, &dx)) return false;
        norm = Norm(dx, x);
        fresh = true;
      }
      continue;
    }
    // No step improves on an x within a few tolerances of the equilibrium:
    // the floor of the forward differences where a presliding
    // displacement turns from loading to unloading (a kink in the force).
    if (norm <= kStallTolerance) return Residual(t, from, x, &r_);
    if (!fresh) {
      // An old Jacobian: a new one at x before damping.
      if (!ComputeJacobian(t, from, x) || !Correction(r_, &dx)) return false;
      norm = Norm(dx, x);
      fresh = true;
      damping = 1.0;
      continue;
    }
    damping *= 0.5;
    if (damping < 1.0 / 64.0) {
      failure_ = "no monotone Newton step towards the equilibrium";
      return false;
    }
  }
  failure_ = "no equilibrium within " + std::to_string(kMaxIterations) + " Newton iterations";
  return false;
}

namespace {

// Inputs at their first sample beyond this [m] are reached in a lead-in from
// zero: a micrometre, far below the replay's 0.5 mm increments and any
// actuator's resolution (the robot's servos: 15 µm).
constexpr double kLeadInThresholdM = 1e-6;

// The quasi-static replay's loop over the sample times.
class SettledPoseLoop {
 public:
  SettledPoseLoop(const ArmModel& model, const ArmParameters& parameters, const CableInputs& inputs,
                  const SimulationOptions& options)
      : model_(model),
        inputs_(inputs),
        options_(options),
        control_(options),
        dynamics_(model, parameters, inputs, options.solver),
        solver_(model, &dynamics_),
        sampler_(SampleTimes(options)),
        x_(Eigen::VectorXd::Zero(solver_.size())),
        from_(dynamics_.InitialSettledFriction()) {
    x_.head(dynamics_.num_coordinates()) =
        dynamics_.InitialState().head(dynamics_.num_coordinates());
    x_last_ = x_;
  }

  SimulationResult Run() {
    // The arm at rest under the inputs at their start (gravity, a pull
    // there).
    t_ = inputs_.start_time();
    if (!SolveAt(t_)) Stop(solver_.failure() + " at t = " + FormatTime(t_));
    while (running_ && !sampler_.done()) {
      const double t_out = sampler_.next_time();
      if (t_out > t_) Advance(t_out);
      if (!running_) break;
      Sample();
    }
    return Finish();
  }

 private:
  void Stop(const std::string& cause) {
    if (!running_) return;
    running_ = false;
    message_ = cause;
  }

  // The largest path length of any input over (t_, t_out), from 32 points:
  // the increments follow what the inputs do in between, not just their
  // ends.
  double InputTravel(double t_out) const {
    constexpr int kPoints = 32;
    double travel = 0.0;
    for (int c = 0; c < model_.num_cables(); ++c) {
      double path = 0.0, previous = 0.0, rate, accel;
      inputs_.Evaluate(c, t_, &previous, &rate, &accel);
      for (int k = 1; k <= kPoints; ++k) {
        double value;
        inputs_.Evaluate(c, t_ + (t_out - t_) * k / kPoints, &value, &rate, &accel);
        path += std::abs(value - previous);
        previous = value;
      }
      travel = std::max(travel, path);
    }
    return travel;
  }

  void Advance(double t_out) {
    const int increments = std::max(
        1, static_cast<int>(std::ceil(InputTravel(t_out) / options_.quasi_static_increment_m)));
    const double t0 = t_;
    for (int k = 1; k <= increments && running_; ++k) {
      if (!AdvanceTo(t0 + (t_out - t0) * k / increments, 0)) return;
      CheckCancellationAndReport();
    }
    t_ = t_out;  // exactly
  }

  // One increment to t_next, halved when its solve fails.
  bool AdvanceTo(double t_next, int halvings) {
    if (SolveAt(t_next)) return true;
    if (halvings == kMaxHalvings) {
      Stop("no settled pose (" + solver_.failure() + ") at t = " + FormatTime(t_next));
      return false;
    }
    ++rejected_;
    return AdvanceTo(0.5 * (t_ + t_next), halvings + 1) && AdvanceTo(t_next, halvings + 1);
  }

  // The equilibrium at t from the last one's friction: first from the
  // secant through the last two, then from the last.
  bool SolveAt(double t) {
    Eigen::VectorXd x = x_;
    const bool predict = have_secant_ && t_ > t_last_;
    if (predict) x += (x_ - x_last_) * ((t - t_) / (t_ - t_last_));
    bool solved = solver_.Solve(t, from_, &x);
    if (!solved && predict) {
      x = x_;
      solved = solver_.Solve(t, from_, &x);
    }
    if (!solved) return false;
    if (t > t_) {
      x_last_ = x_;
      t_last_ = t_;
      have_secant_ = true;
    }
    x_ = x;
    t_ = t;
    from_ = dynamics_.settled_friction();
    ++steps_;
    return true;
  }

  void CheckCancellationAndReport() {
    // A lead-in's times precede the record's (at 0): its progress is the
    // start's.
    const std::string stop = control_.Check(std::max(t_, 0.0), steps_, 0);
    if (stop.empty() || !running_) return;
    running_ = false;
    cancelled_ = true;
    message_ = stop;
  }

  void Sample() {
    const Eigen::VectorXd y = dynamics_.RestState(x_.data(), from_);
    dynamics_.Observe(t_, y.data(), &frame_);
    sampler_.Record(frame_);
    const std::string past = JointPastRange(model_, frame_);
    if (!past.empty()) Stop(past + " at t = " + FormatTime(t_));
  }

  SimulationResult Finish() {
    const SimulationStatus status = cancelled_ ? SimulationStatus::kCancelled
                                    : running_ ? SimulationStatus::kCompleted
                                               : SimulationStatus::kDiverged;
    return FinishRun(model_, control_,
                     {status, message_, t_, steps_, rejected_, dynamics_.evaluations()}, &sampler_);
  }

  const ArmModel& model_;
  const CableInputs& inputs_;
  const SimulationOptions& options_;
  RunControl control_;
  ArmDynamics dynamics_;
  SettledPoseSolver solver_;
  OutputSampler sampler_;
  TrajectoryFrame frame_;

  // The last equilibrium (t_, x_) with its friction state, and the one
  // before it (for the secant predictor).
  double t_ = 0.0, t_last_ = 0.0;
  Eigen::VectorXd x_, x_last_;
  bool have_secant_ = false;
  SettledFriction from_;

  bool running_ = true, cancelled_ = false;
  std::string message_;
  std::int64_t steps_ = 0, rejected_ = 0;
};

}  // namespace

SimulationResult SimulateSettledPoses(const ArmModel& model, const ArmParameters& parameters,
                                      const CableInputs& inputs, const SimulationOptions& options) {
  const std::string why = WhyNotQuasiStatic(model, parameters, options.solver);
  if (!why.empty()) ThrowInputError("simulation options", "quasi_static", why);
  // Between settled poses the actuators go from one set point to the next:
  // straight lines, not the spline of a continuous motion, whose swings
  // past the samples friction would remember as loops. A record that starts
  // pulled (a log's slice) is reached from the straight arm at zero inputs
  // along a straight line in a lead-in before its first sample, so that the
  // friction there is that of one monotone loading, not of a pull the
  // holes never felt.
  const bool lead_in = inputs.length_change().row(0).cwiseAbs().maxCoeff() > kLeadInThresholdM;
  if (inputs.interpolation() == CableInputs::Interpolation::kLinear && !lead_in)
    return SettledPoseLoop(model, parameters, inputs, options).Run();
  const Eigen::Index n = inputs.time().size();
  const Eigen::Index extra = lead_in ? 1 : 0;
  Eigen::VectorXd time(n + extra);
  Eigen::MatrixXd length(n + extra, inputs.length_change().cols());
  if (lead_in) {
    time[0] = inputs.start_time() - 1.0;
    length.row(0).setZero();
  }
  time.tail(n) = inputs.time();
  length.bottomRows(n) = inputs.length_change();
  const CableInputs lines(std::move(time), std::move(length), CableInputs::Interpolation::kLinear);
  return SettledPoseLoop(model, parameters, lines, options).Run();
}

}  // namespace ccsrm::sim::internal

namespace ccsrm::sim {

// The laws that hold nothing at rest cannot be replayed quasi-statically:
// an arm held only by them would fall through every pose.
std::string WhyNotQuasiStatic(const ArmModel& model, const ArmParameters& parameters,
                              const SolverConfig& solver) {
  const bool holes = solver.hole_friction == HoleFrictionModel::kPresliding ||
                     solver.hole_friction == HoleFrictionModel::kOff ||
                     (parameters.mu == 0.0 && parameters.mu_s == 0.0);
  if (!holes) {
    return "needs solver.hole_friction: presliding or off (events and smoothed friction hold "
           "nothing at rest)";
  }
  bool large_s = false;
  for (const ConnectingPairModel& pair : model.connecting_pairs())
    large_s = large_s || pair.kind == ConnectingKind::kLargeS;
  const bool conduits = !large_s || solver.conduit_friction == ConduitFrictionModel::kPresliding ||
                        (parameters.mu_c == 0.0 && parameters.mu_c_s == 0.0);
  if (!conduits) {
    return "needs solver.conduit_friction: presliding, or no conduit friction (modified Coulomb "
           "friction holds nothing at rest)";
  }
  return "";
}

}  // namespace ccsrm::sim
