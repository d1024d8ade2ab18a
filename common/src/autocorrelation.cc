#include "ccsrm/common/autocorrelation.h"

#include <algorithm>
#include <string>
#include <vector>

namespace ccsrm {

double AutocorrelationTime(const std::vector<double>& series) {
  const std::size_t n = series.size();
  if (n < 3) return 1.0;
  double mean = 0.0;
  for (double x : series) mean += x;
  mean /= static_cast<double>(n);
  double c0 = 0.0;
  for (double x : series) c0 += (x - mean) * (x - mean);
  if (!(c0 > 0.0)) return 1.0;
  const auto rho = [&](std::size_t lag) {
    double c = 0.0;
    for (std::size_t i = 0; i + lag < n; ++i) c += (series[i] - mean) * (series[i + lag] - mean);
    return c / c0;
  };
  double tau = -1.0;
  for (std::size_t m = 0; 2 * m + 1 < n; ++m) {
    const double pair = (m == 0 ? 1.0 : rho(2 * m)) + rho(2 * m + 1);
    if (!(pair > 0.0)) break;
    tau += 2.0 * pair;
  }
  return std::clamp(tau, 1.0, static_cast<double>(n));
}

double EffectiveSampleSize(const std::vector<std::vector<double>>& series) {
  double total = 0.0;
  for (const std::vector<double>& s : series) {
    if (s.empty()) continue;
    total += static_cast<double>(s.size()) / AutocorrelationTime(s);
  }
  return total;
}

}  // namespace ccsrm
