#pragma once
// Residual statistics of a fit: how many independent samples autocorrelated
// residuals are worth, and the t quantile of the intervals.
#include <vector>

namespace ccsrm::identify::internal {

// Integrated autocorrelation time of one series, by Geyer's initial positive
// sequence: tau = -1 + 2 Σ_m (ρ_2m + ρ_2m+1), summed while the pair sums stay
// positive. At least 1 (white noise), at most the series' length.
double AutocorrelationTime(const std::vector<double>& series);

// Σ over the series of length / autocorrelation time: the number of
// independent samples they carry. Series shorter than 3 count as their length.
double EffectiveSampleSize(const std::vector<std::vector<double>>& series);

// The 97.5 % quantile of Student's t with `dof` degrees of freedom (1.96 for
// large dof); NaN for dof < 1.
double StudentT975(double dof);

}  // namespace ccsrm::identify::internal
