#include "term_discovery.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

namespace ccsrm::identify::internal {

TermSelection SelectTerms(const Eigen::VectorXd& r, const Eigen::MatrixXd& fit_jacobian,
                          const std::vector<TermColumn>& columns, double neff_ratio,
                          double effective_samples, double tie_delta_bic, double share) {
  TermSelection out;
  // Everything beyond the fit's own columns: project them out once, so the
  // path works on the small Gram matrix of what is left of the terms.
  Eigen::MatrixXd basis(r.size(), 0);
  if (fit_jacobian.cols() > 0) {
    Eigen::VectorXd norms = fit_jacobian.colwise().norm().transpose();
    for (Eigen::Index k = 0; k < norms.size(); ++k) norms[k] = norms[k] > 0.0 ? norms[k] : 1.0;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(fit_jacobian *
                                                         norms.cwiseInverse().asDiagonal());
    basis = qr.householderQ() * Eigen::MatrixXd::Identity(r.size(), qr.rank());
  }
  const auto beyond = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return basis.cols() > 0 ? Eigen::VectorXd(v - basis * (basis.transpose() * v)) : v;
  };
  const Eigen::VectorXd r_beyond = beyond(r);
  // Unit columns beyond the fit; a column of which less than 1e-6 of its
  // norm is left is one the fit's parameters already stand for.
  std::vector<std::size_t> kept;
  std::vector<Eigen::VectorXd> unit;
  std::vector<double> scale;  // unit column = beyond(column) / scale
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const double whole = columns[k].weighted.norm();
    const Eigen::VectorXd b = beyond(columns[k].weighted);
    const double left = b.norm();
    if (!(whole > 0.0) || !(left > 1e-6 * whole) || !std::isfinite(left)) {
      out.degenerate.push_back(columns[k].parameter);
      continue;
    }
    kept.push_back(k);
    unit.push_back(b / left);
    scale.push_back(left);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(kept.size());
  if (m == 0) return out;
  Eigen::MatrixXd gram(m, m);
  Eigen::VectorXd rhs(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    rhs[i] = -unit[static_cast<std::size_t>(i)].dot(r_beyond);
    for (Eigen::Index j = 0; j <= i; ++j) {
      gram(i, j) = gram(j, i) =
          unit[static_cast<std::size_t>(i)].dot(unit[static_cast<std::size_t>(j)]);
    }
  }
  const double log_n = std::log(std::max(effective_samples, 1.0));
  std::vector<Eigen::Index> active(static_cast<std::size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) active[static_cast<std::size_t>(i)] = i;
  while (!active.empty()) {
    const Eigen::Index a = static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd g(a, a);
    Eigen::VectorXd b(a);
    for (Eigen::Index i = 0; i < a; ++i) {
      b[i] = rhs[active[static_cast<std::size_t>(i)]];
      for (Eigen::Index j = 0; j < a; ++j) {
        g(i, j) = gram(active[static_cast<std::size_t>(i)], active[static_cast<std::size_t>(j)]);
      }
    }
    // Terms nearly collinear with others (θ and θ³ over small angles): a
    // ridge of 1e-10 of the unit diagonal keeps the solve finite; such a
    // term's Wald statistic is then near 0 and it leaves first.
    const Eigen::MatrixXd regular = g + 1e-10 * Eigen::MatrixXd::Identity(a, a);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(regular);
    const Eigen::VectorXd x = ldlt.solve(b);
    const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(a, a));
    TermSupport s;
    s.delta_chi2_eff = std::max(b.dot(x), 0.0) * neff_ratio;
    s.delta_bic = s.delta_chi2_eff - static_cast<double>(a) * log_n;
    std::vector<double> wald(static_cast<std::size_t>(a));
    for (Eigen::Index i = 0; i < a; ++i) {
      const std::size_t k = static_cast<std::size_t>(active[static_cast<std::size_t>(i)]);
      const TermColumn& c = columns[kept[k]];
      s.parameters.push_back(c.parameter);
      s.complexity += c.complexity;
      // Back to the coefficient: the unit column is beyond(column) / scale,
      // and beyond(column) is what the coefficient moves once the fit's
      // own parameters have moved with it.
      s.linearised[c.parameter] = x[i] / scale[k];
      // Δχ²_eff of dropping it (its Wald statistic in effective units).
      wald[static_cast<std::size_t>(i)] =
          inverse(i, i) > 0.0 ? x[i] * x[i] / inverse(i, i) * neff_ratio : 0.0;
    }
    // The weakest term leaves; of terms whose loss costs within
    // tie_delta_bic of the weakest's, the most complex leaves first
    // (simpler terms win ties, also between terms the data cannot tell
    // apart: both then have a Wald statistic near 0).
    const double floor = *std::min_element(wald.begin(), wald.end());
    const auto complexity = [&](std::size_t i) {
      return columns[kept[static_cast<std::size_t>(active[i])]].complexity;
    };
    std::size_t weakest = wald.size();
    for (std::size_t i = 0; i < wald.size(); ++i) {
      if (wald[i] - floor >= tie_delta_bic) continue;
      if (weakest == wald.size() || complexity(i) > complexity(weakest) ||
          (complexity(i) == complexity(weakest) && wald[i] < wald[weakest])) {
        weakest = i;
      }
    }
    out.path.push_back(std::move(s));
    active.erase(active.begin() + static_cast<std::ptrdiff_t>(weakest));
  }
  // The best linear ΔBIC; ties go to fewer terms, then to simpler ones.
  // A smaller support that removes all but `share` of the best's Δχ²_eff
  // ties with it too: the columns are secants at the fitted point, and a
  // strong term's curvature (θ³ at 20 times its step) leaves a first-order
  // misfit that, on many effective samples, other terms would soak up with
  // a large ΔBIC of their own.
  int best = 0;
  for (int i = 1; i < static_cast<int>(out.path.size()); ++i) {
    if (out.path[static_cast<std::size_t>(i)].delta_bic >
        out.path[static_cast<std::size_t>(best)].delta_bic) {
      best = i;
    }
  }
  int chosen = best;
  for (int i = 0; i < static_cast<int>(out.path.size()); ++i) {
    const TermSupport& s = out.path[static_cast<std::size_t>(i)];
    const TermSupport& c = out.path[static_cast<std::size_t>(chosen)];
    const TermSupport& top = out.path[static_cast<std::size_t>(best)];
    const bool tied = top.delta_bic - s.delta_bic < tie_delta_bic;
    const bool within_linearisation = s.delta_chi2_eff >= (1.0 - share) * top.delta_chi2_eff;
    if (!tied && !within_linearisation) continue;
    if (s.parameters.size() < c.parameters.size() ||
        (s.parameters.size() == c.parameters.size() && s.complexity < c.complexity)) {
      chosen = i;
    }
  }
  out.chosen = chosen;
  return out;
}

}  // namespace ccsrm::identify::internal
