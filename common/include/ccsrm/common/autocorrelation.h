#pragma once
// How many independent samples autocorrelated residuals are worth: shared
// by identification (its standard errors) and the clock alignment (the
// uncertainty of an estimated offset).
#include <vector>

namespace ccsrm {

// Integrated autocorrelation time of one series, by Geyer's initial positive
// sequence: tau = -1 + 2 Σ_m (ρ_2m + ρ_2m+1), summed while the pair sums stay
// positive. At least 1 (white noise), at most the series' length.
double AutocorrelationTime(const std::vector<double>& series);

// Σ over the series of length / autocorrelation time: the number of
// independent samples they carry. Series shorter than 3 count as their length.
double EffectiveSampleSize(const std::vector<std::vector<double>>& series);

}  // namespace ccsrm
