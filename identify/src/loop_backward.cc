#include "loop_backward.h"

#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>

namespace ccsrm::identify::internal {

bool IntervalExcludesZero(const ParameterEstimate& e) {
  return e.identifiable && (e.ci95_lower > 0.0 || e.ci95_upper < 0.0);
}

bool SizeSignificant(bool interval_excludes_zero, double delta_chi2_zeroed, std::size_t k) {
  if (interval_excludes_zero) return true;
  if (k == 0 || !std::isfinite(delta_chi2_zeroed)) return false;
  return delta_chi2_zeroed > gsl_cdf_chisq_Pinv(0.95, static_cast<double>(k));
}

double DeltaBic(double cost_without, double cost_with, double neff, double residuals,
                std::size_t k) {
  return 2.0 * (cost_without - cost_with) * neff / residuals -
         static_cast<double>(k) * std::log(neff);
}

std::vector<std::size_t> TakeBackOrder(const std::vector<AdditionCheck>& checks) {
  std::vector<std::size_t> order;
  for (std::size_t a = 0; a < checks.size(); ++a) {
    const AdditionCheck& c = checks[a];
    if (c.interval_excludes_zero || !std::isfinite(c.delta_chi2_zeroed)) continue;
    if (!c.identifiable || !SizeSignificant(false, c.delta_chi2_zeroed, c.parameters)) {
      order.push_back(a);
    }
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return checks[a].delta_bic_zeroed < checks[b].delta_bic_zeroed;
  });
  return order;
}

}  // namespace ccsrm::identify::internal
