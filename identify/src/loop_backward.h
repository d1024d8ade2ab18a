#pragma once
// The loop's size test and its backward step (issue 28): whether an
// addition's size is distinguishable from 0, and which earlier addition a
// round may take back once a later one made it redundant.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "ccsrm/identify/identification.h"

namespace ccsrm::identify::internal {

// True when the estimate is identifiable and its 95 % interval excludes 0.
bool IntervalExcludesZero(const ParameterEstimate& estimate);

// The loop's size test: an addition's size is distinguishable from 0 when
// one of its parameters' interval excludes 0 (interval_excludes_zero), or
// when its k parameters together do: setting them to 0 at the fit's point
// raises the effective chi-square (delta_chi2_zeroed) beyond the 95 %
// quantile of a chi-square with k degrees of freedom. NaN (the run at 0
// failed) passes only by the interval.
bool SizeSignificant(bool interval_excludes_zero, double delta_chi2_zeroed, std::size_t k);

// Δχ²_eff - k ln N_eff of a model with an addition of k parameters (cost
// cost_with, 1/2 Σ r²) against one without it (cost_without), over
// `residuals` weighted residuals of which neff are effectively independent:
// the loop's information criterion. Forward it is the gain of adding; in the
// backward step, of keeping.
double DeltaBic(double cost_without, double cost_with, double neff, double residuals,
                std::size_t k);

// An earlier addition as the fit after a later one sees it.
struct AdditionCheck {
  std::size_t parameters = 0;
  bool interval_excludes_zero = false;
  // Its parameters set to 0 at the new fit's point: Δχ²_eff, and that less
  // k ln N_eff (how much it still earns there, before any refit).
  double delta_chi2_zeroed = std::numeric_limits<double>::quiet_NaN();
  double delta_bic_zeroed = std::numeric_limits<double>::quiet_NaN();
  // Every one of its parameters identifiable in the new fit. One that is
  // not lies (nearly) along a flat direction of the fit: setting it to 0
  // without a refit moves off that direction, and the cost there says
  // nothing about what a refit without it would lose.
  bool identifiable = true;
};

// The additions to try taking back, least useful first: those whose size
// is indistinguishable from 0 (SizeSignificant), and those with a
// parameter the new fit cannot identify (whatever the cost at 0: only the
// refit without them can tell), by delta_bic_zeroed, the smallest first.
// One whose run at 0 failed is not judged, so not listed.
std::vector<std::size_t> TakeBackOrder(const std::vector<AdditionCheck>& checks);

}  // namespace ccsrm::identify::internal
