#pragma once
// Residual statistics of a fit: how many independent samples autocorrelated
// residuals are worth, the t quantile of the intervals, and which
// parameters and directions the data leave undetermined.
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "ccsrm/common/autocorrelation.h"

namespace ccsrm::identify::internal {

// Moved to common (the clock alignment uses them too); named here as before.
using ::ccsrm::AutocorrelationTime;
using ::ccsrm::EffectiveSampleSize;

// The 97.5 % quantile of Student's t with `dof` degrees of freedom (1.96 for
// large dof); NaN for dof < 1.
double StudentT975(double dof);

// What the data cannot pin down, from the SVD of the scaled Jacobian: v's
// columns are the singular directions, direction_error[d] the standard
// error along direction d (σ_res / σ_d, inf for σ_d = 0), relative_scale[i]
// turns an error of parameter i in scaled units into one relative to its
// estimate. A parameter is identifiable when its relative standard error,
// over all directions, is at most `threshold`.
struct Identifiability {
  struct Direction {
    int column = 0;            // of v
    std::vector<int> members;  // parameters it names, in increasing order
  };
  std::vector<bool> identifiable;       // per parameter
  std::vector<Direction> named;         // in increasing column order
  std::vector<double> direction_worst;  // per direction: the largest relative
                                        // error it gives any parameter
};
// Named: every direction that alone gives some parameter more than the
// threshold, with the parameters whose component is at least
// `component_floor`. An undetermined parameter that no such direction holds
// (its error spread over several directions, or leaking into another
// parameter's null direction through a small component) is added as a
// member to the direction that contributes most to its error, so that every
// undetermined parameter is named in some combination.
Identifiability AssessIdentifiability(const Eigen::MatrixXd& v,
                                      const Eigen::VectorXd& direction_error,
                                      const std::vector<double>& relative_scale, double threshold,
                                      double component_floor);

// Per column: ||a - b|| / max(||a||, ||b||); NaN where b is not finite (not
// checked), 0 where both are zero.
std::vector<double> ColumnDisagreement(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// The derivative check of a fit's final point, and the step each free
// parameter's column is taken at. `jacobian` is the weighted residuals'
// Jacobian at the fit's relative step r, `at_third` at r/3. A column that
// differs between them by more than `limit` is either no derivative (the
// angles jump with the parameter) or one that bends on a scale between r/3
// and r (the conduits' static coefficient on fast reversals at static above
// kinetic friction: 5.7 % at relative steps 1e-2 and 3e-3, 2.2 % at 3e-3
// and 1e-3). Only then is `at_ninth` asked for the Jacobian at r/9 (false:
// not available); where r/3 and r/9 agree within `limit`, the r/3 column
// replaces the fit's in *jacobian and its disagreement is r/3's against r/9.
struct DerivativeSteps {
  std::vector<double> disagreement;   // per column, of the step it is taken at
  std::vector<double> relative_step;  // per column: r, or r/3 where chosen
};
DerivativeSteps ChooseDerivativeSteps(double relative_step, const Eigen::MatrixXd& at_third,
                                      const std::function<bool(Eigen::MatrixXd*)>& at_ninth,
                                      double limit, Eigen::MatrixXd* jacobian);

}  // namespace ccsrm::identify::internal
