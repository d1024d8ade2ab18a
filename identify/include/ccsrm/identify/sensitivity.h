#pragma once
// How the simulated joint angles depend on the named parameters (SPEC 6):
// finite-difference derivatives checked at two steps, and sweeps of one
// parameter fitted by a cubic. Identification differentiates the simulated
// angles by finite differences; these are the instruments that say whether
// such derivatives measure the model or its numerical noise (SPEC 10: "a
// derivative of noise fits noise").
//
// Every run goes through sim::Simulate on one shared ArmModel, one run per
// task on a pool of threads. Each task writes only its own slot, so the
// results do not depend on the number of threads (Simulate is deterministic).
//
// The sampled angles of a run are every frame of its trajectory, every
// joint, θx then θy, in degrees: index (frame * joints + joint) * 2 + axis.
#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/identify/difference.h"
#include "ccsrm/identify/runs.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

struct DerivativeCheckOptions {
  // Parameters to differentiate, by their SPEC 6 names. Default: all of
  // sim::Parameters().
  std::vector<std::string> parameters = AllParameterNames();
  // Relative steps r (at least two, each in (0, 0.5), all different). A
  // parameter of value p is moved by h = r s, where s = |p| (see
  // scale_at_zero), so the trial points of the central difference are
  // p (1 -/+ r). Default: 1e-2 and 3e-3, the pair of issue 10.
  std::vector<double> relative_steps = {1e-2, 3e-3};
  // Runs at a time (each run uses one thread). Default: every core.
  int threads = DefaultThreads();
  // Largest acceptable disagreement ||d1 - d2|| / max(||d1||, ||d2||)
  // between the derivatives of consecutive steps (SPEC 10: 5 %).
  double tolerance = 0.05;
  // A derivative is negligible when a 1 % change of its parameter moves the
  // sampled angles by less than this, RMS over all of them [deg]: when
  // 0.01 * RMS(d) < negligible_change_deg for every step. Default: a tenth
  // of the 0.03 deg mocap noise floor. Why that matters little: a fit that
  // reaches the noise floor has an RMS residual of 0.03 deg; a 1 % error of
  // such a parameter adds at most 0.003 deg in quadrature, raising it by
  // under 0.5 % (sqrt(1 + 0.1^2)), so an error in its Jacobian column can
  // mislead the fit only along a nearly flat valley of the cost. It is not
  // a claim that the data cannot determine the parameter: over many samples
  // of white noise they may (the identifiability check, from singular
  // values, decides that), and a noisy derivative then still spoils its
  // standard error. So its disagreement is still reported; it only does not
  // fail the check. Set 0 to hold every derivative to the tolerance.
  double negligible_change_deg = 0.1 * kMocapNoiseFloorDeg;
  // The scale s of a parameter whose value is 0, where p (1 -/+ r) would
  // not move it: its steps are r s (one-sided, as 0 is a lower bound) and
  // its derivative is s dθ/dp. Unset (the default), or 0 for that
  // parameter: the parameter is reported as not checked.
  std::optional<sim::ArmParameters> scale_at_zero;
  // Called after each run; may be empty. With a backend its label is empty
  // (a backend reports runs as they finish, not which one).
  ProgressCallback progress;
  // Where the runs go (e.g. every rank of an MPI job, ShareRuns): a backend
  // whose experiment 0 is FrameExperiment of the same model, inputs and
  // simulation as DerivativeCheck's (precondition); `threads` is then not
  // used. Null (the default): `threads` threads of this process.
  std::shared_ptr<SimulationBackend> backend;

  // False, with the reason in *error naming the field, when a parameter
  // name is unknown or repeated, there are fewer than two steps or a step is
  // outside (0, 0.5) or repeated, threads < 1, tolerance <= 0, or
  // negligible_change_deg < 0.
  bool IsValid(std::string* error) const;
};

struct TrialRun {
  double value = 0.0;  // the parameter's value in this run
  sim::SimulationSummary summary;
};

// The derivative of one parameter at one relative step.
struct StepDerivative {
  double relative_step = 0.0;  // r
  double step = 0.0;           // h = r s [parameter units]
  DifferenceScheme scheme = DifferenceScheme::kCentral;
  std::vector<TrialRun> trials;  // the two trial points, in the order of the scheme above
  // s dθ/dp of every sampled angle [deg per unit relative change]: the change
  // of the angle, in degrees, per 100 % change of the parameter (to first
  // order). Empty when the base run or a trial did not complete.
  std::vector<double> derivative_deg;
  double rms_deg = 0.0;  // RMS of derivative_deg; 0 when empty
  bool available() const { return !derivative_deg.empty(); }
};

enum class DerivativeStatus {
  kAgrees,      // within the tolerance at every pair of steps
  kDisagrees,   // not negligible and beyond the tolerance
  kNegligible,  // too small to matter (see negligible_change_deg)
  kRunFailed,   // a run diverged or was cancelled: no derivative
  kNotChecked,  // value 0 and no scale (see scale_at_zero)
};
const char* StatusName(DerivativeStatus status);  // "agrees", "DISAGREES", ...

struct ParameterDerivative {
  std::string name;
  std::string units;
  double value = 0.0;                 // p
  double scale = 0.0;                 // s: |p|, or the scale at zero
  std::vector<StepDerivative> steps;  // as DerivativeCheckOptions::relative_steps
  // ||d_k - d_k+1|| / max(||d_k||, ||d_k+1||) for consecutive steps (0 when
  // both derivatives are exactly 0); NaN where a derivative is missing.
  std::vector<double> disagreement;
  double max_disagreement = 0.0;  // NaN when a derivative is missing
  bool negligible = false;
  DerivativeStatus status = DerivativeStatus::kAgrees;
  std::string note;  // why not checked, or which run failed and how
  // The angle change of a 1 % move, RMS over the sampled angles, from the
  // largest of the step derivatives [deg].
  double change_per_percent_deg() const;
};

struct DerivativeCheckSummary {
  std::vector<ParameterDerivative> parameters;
  sim::SimulationSummary base_run;
  std::vector<double> relative_steps;
  double tolerance = 0.0;
  double negligible_change_deg = 0.0;
  std::size_t sampled_angles = 0;  // per run
  std::size_t runs = 0;
  int threads = 0;
  double wall_time_s = 0.0;

  // True when every derivative agrees or is negligible (parameters not
  // checked are listed, but do not fail it).
  bool passed() const;
  // True when every run completed.
  bool all_runs_completed() const;
  // One line; and the table with one row per parameter.
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Differentiates the sampled joint angles of the run (model, base, inputs,
// simulation) with respect to each parameter of `options`, at each relative
// step. One base run plus two trial runs per parameter and step, all in
// parallel. Every trial point lies inside its parameter's bounds: the
// difference is central when p -/+ h fit, else one-sided away from the bound
// (forward from a lower bound, backward from an upper one).
//
// simulation.progress is not called (runs go on several threads; see
// options.progress). A run that diverges is reported in its summary and
// leaves its parameter kRunFailed; it is not thrown. Throws InputError when
// options, base or simulation are invalid, or when a parameter's bounds are
// too narrow for a step on either side.
DerivativeCheckSummary DerivativeCheck(const sim::ArmModel& model, const sim::ArmParameters& base,
                                       const sim::CableInputs& inputs,
                                       const sim::SimulationOptions& simulation,
                                       const DerivativeCheckOptions& options);

struct SweepOptions {
  // The parameter swept, by its SPEC 6 name.
  std::string parameter = "mu";
  // Values p + span s x for x evenly spaced from -1 to 1 (s = |p|, or the
  // scale at zero). At least 5: a cubic has four coefficients, and the
  // residual needs at least one more point. Default 21, an odd number so
  // that the middle point is the base value itself.
  int points = 21;
  // Relative half-width, in (0, 1). Default 0.05 (+-5 %, issue 10).
  double span = 0.05;
  int threads = DefaultThreads();
  // As DerivativeCheckOptions::scale_at_zero.
  std::optional<sim::ArmParameters> scale_at_zero;
  ProgressCallback progress;
  // As DerivativeCheckOptions::backend.
  std::shared_ptr<SimulationBackend> backend;

  // False, with the reason naming the field, for an unknown parameter,
  // points < 5, span outside (0, 1) or threads < 1.
  bool IsValid(std::string* error) const;
};

struct SweepSummary {
  std::string parameter;
  std::string units;
  double value = 0.0;  // p, the middle of the sweep
  double scale = 0.0;  // s
  double span = 0.0;
  std::vector<double> values;                // the swept values, ascending
  std::vector<sim::SimulationSummary> runs;  // one per value
  std::size_t sampled_angles = 0;            // per run
  // Row k: the sampled angles at values[k] [deg]; empty when a run did not
  // complete.
  Eigen::MatrixXd angles_deg;
  // Per swept value: RMS over the sampled angles of the change from the
  // first value, and of the residual to the cubics [deg].
  std::vector<double> change_rms_deg;
  std::vector<double> residual_rms_deg;
  // Over every value and sampled angle [deg]: the residual of a
  // least-squares cubic in the parameter fitted to each angle on its own.
  double residual_rms = 0.0;
  double residual_max = 0.0;
  // Total variation of the angles across the sweep (max - min of each
  // angle): RMS over the angles, and the largest [deg].
  double variation_rms = 0.0;
  double variation_max = 0.0;
  int threads = 0;
  double wall_time_s = 0.0;

  bool all_runs_completed() const;
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Runs the arm at options.points values of one parameter and fits a cubic
// in that parameter to every sampled angle. All runs in parallel. When a
// run does not complete, the fit is not made (residuals and variations are
// NaN) and the run's summary says why. Throws InputError for invalid
// options, base or simulation, for a parameter of value 0 without a scale,
// or when the swept range leaves the parameter's bounds.
SweepSummary ParameterSweep(const sim::ArmModel& model, const sim::ArmParameters& base,
                            const sim::CableInputs& inputs,
                            const sim::SimulationOptions& simulation, const SweepOptions& options);

// The residuals of a least-squares cubic in x fitted to each column of y
// (row k holds the values at x[k]). The fit is made in x mapped to [-1, 1],
// by QR, so large offsets of x (a pre-tension of 100 N) lose no precision.
// Requires at least 4 distinct values of x and y.rows() == x.size()
// (CCSRM_CHECK).
Eigen::MatrixXd CubicFitResiduals(const std::vector<double>& x, const Eigen::MatrixXd& y);

// Machine-readable summaries (every figure of the reports, not the
// derivative vectors).
nlohmann::json ToJson(const DerivativeCheckSummary& summary);
nlohmann::json ToJson(const SweepSummary& summary);

}  // namespace ccsrm::identify
