#include "statistics.h"

#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ccsrm::identify::internal {

double StudentT975(double dof) {
  if (!(dof >= 1.0)) return std::numeric_limits<double>::quiet_NaN();
  return gsl_cdf_tdist_Pinv(0.975, dof);
}

Identifiability AssessIdentifiability(const Eigen::MatrixXd& v,
                                      const Eigen::VectorXd& direction_error,
                                      const std::vector<double>& relative_scale, double threshold,
                                      double component_floor) {
  const Eigen::Index p = v.rows(), k = v.cols();
  Identifiability out;
  out.identifiable.assign(static_cast<std::size_t>(p), true);
  out.direction_worst.assign(static_cast<std::size_t>(k), 0.0);
  // share(i, d): the relative error direction d gives parameter i.
  const auto share = [&](Eigen::Index i, Eigen::Index d) {
    const double c = std::abs(v(i, d));
    return c == 0.0 ? 0.0 : c * direction_error[d] * relative_scale[static_cast<std::size_t>(i)];
  };
  for (Eigen::Index i = 0; i < p; ++i) {
    double var = 0.0;
    for (Eigen::Index d = 0; d < k; ++d) var += share(i, d) * share(i, d);
    const double relative = std::sqrt(var);
    out.identifiable[static_cast<std::size_t>(i)] =
        std::isfinite(relative) && relative <= threshold;
  }
  // members[d]: the parameters direction d names; it is named when any.
  std::vector<std::vector<int>> members(static_cast<std::size_t>(k));
  const auto name_large_components = [&](Eigen::Index d) {
    for (Eigen::Index i = 0; i < p; ++i) {
      if (std::abs(v(i, d)) >= component_floor) {
        members[static_cast<std::size_t>(d)].push_back(static_cast<int>(i));
      }
    }
  };
  for (Eigen::Index d = 0; d < k; ++d) {
    double worst = 0.0;
    for (Eigen::Index i = 0; i < p; ++i) worst = std::max(worst, share(i, d));
    out.direction_worst[static_cast<std::size_t>(d)] = worst;
    if (worst > threshold) name_large_components(d);
  }
  for (Eigen::Index i = 0; i < p; ++i) {
    if (out.identifiable[static_cast<std::size_t>(i)]) continue;
    bool held = false;
    Eigen::Index largest = -1;
    for (Eigen::Index d = 0; d < k; ++d) {
      const std::vector<int>& m = members[static_cast<std::size_t>(d)];
      if (std::find(m.begin(), m.end(), static_cast<int>(i)) != m.end()) held = true;
      if (largest < 0 || share(i, d) > share(i, largest)) largest = d;
    }
    if (held || largest < 0) continue;
    std::vector<int>& m = members[static_cast<std::size_t>(largest)];
    if (m.empty()) name_large_components(largest);  // newly named: its own components too
    if (std::find(m.begin(), m.end(), static_cast<int>(i)) == m.end()) {
      m.insert(std::upper_bound(m.begin(), m.end(), static_cast<int>(i)), static_cast<int>(i));
    }
  }
  for (Eigen::Index d = 0; d < k; ++d) {
    if (members[static_cast<std::size_t>(d)].empty()) continue;
    out.named.push_back({static_cast<int>(d), std::move(members[static_cast<std::size_t>(d)])});
  }
  return out;
}

std::vector<double> ColumnDisagreement(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  std::vector<double> out;
  for (Eigen::Index i = 0; i < a.cols(); ++i) {
    const double scale = std::max(a.col(i).norm(), b.col(i).norm());
    out.push_back(!b.col(i).allFinite() ? std::numeric_limits<double>::quiet_NaN()
                  : scale > 0.0         ? (a.col(i) - b.col(i)).norm() / scale
                                        : 0.0);
  }
  return out;
}

DerivativeSteps ChooseDerivativeSteps(double relative_step, const Eigen::MatrixXd& at_third,
                                      const std::function<bool(Eigen::MatrixXd*)>& at_ninth,
                                      double limit, Eigen::MatrixXd* jacobian) {
  DerivativeSteps out;
  out.disagreement = ColumnDisagreement(*jacobian, at_third);
  out.relative_step.assign(out.disagreement.size(), relative_step);
  const bool rough = std::any_of(out.disagreement.begin(), out.disagreement.end(),
                                 [limit](double d) { return d > limit; });
  Eigen::MatrixXd ninth;
  if (!rough || !at_ninth(&ninth)) return out;
  const std::vector<double> finer = ColumnDisagreement(at_third, ninth);
  for (std::size_t i = 0; i < out.disagreement.size(); ++i) {
    if (!(out.disagreement[i] > limit && finer[i] <= limit)) continue;
    const Eigen::Index c = static_cast<Eigen::Index>(i);
    jacobian->col(c) = at_third.col(c);
    out.disagreement[i] = finer[i];
    out.relative_step[i] = relative_step / 3.0;
  }
  return out;
}

}  // namespace ccsrm::identify::internal
