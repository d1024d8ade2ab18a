#pragma once
// The loop's discovery of terms nobody put in the library (issue 28): which
// few of joint_moment's terms (sim/effects.h, JointMomentTerms) explain the
// residual, by sparse regression on the terms' sensitivity columns.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace ccsrm::identify::internal {

// A term's column: the weighted residual's sensitivity to its coefficient
// (per unit of the coefficient), and how complex the term is.
struct TermColumn {
  std::string parameter;  // "joint_moment.segment1_x_angle3"
  int complexity = 1;     // sim::JointMomentTerm::complexity
  Eigen::VectorXd weighted;
};

// One support on the elimination path.
struct TermSupport {
  std::vector<std::string> parameters;
  std::map<std::string, double> linearised;  // linear estimates
  double delta_chi2_eff = 0.0;  // of the residual it removes beyond the fit's own columns
  double delta_bic = 0.0;       // delta_chi2_eff - k ln N_eff
  int complexity = 0;           // summed over its terms
};

struct TermSelection {
  std::vector<TermSupport> path;  // all terms first, then one fewer each step
  int chosen = -1;                // index in path; -1: no term column to choose from
  // Columns dropped before the path: no part of them beyond what the fit's
  // own columns (or the other terms') already remove.
  std::vector<std::string> degenerate;
};

// Sequentially thresholded least squares on the residual r (the fit's
// weighted residual) with the fit's Jacobian always in (unpenalised):
// starting from every term, the threshold rises to the smallest |t| of the
// terms in (their Wald statistic in effective units, times neff_ratio =
// N_eff / N), that term is dropped and the rest refitted, down to one
// term. The chosen support has the largest linear ΔBIC = Δχ²_eff − k ln
// N_eff; supports within tie_delta_bic of it tie, and so do supports that
// remove at least (1 - share) of its Δχ²_eff (the linearisation's
// tolerance); of those the one with the fewest terms, then the least
// complexity, wins (simpler terms win ties).
TermSelection SelectTerms(const Eigen::VectorXd& r, const Eigen::MatrixXd& fit_jacobian,
                          const std::vector<TermColumn>& columns, double neff_ratio,
                          double effective_samples, double tie_delta_bic, double share);

}  // namespace ccsrm::identify::internal
