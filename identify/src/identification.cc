#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/runs.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "finite_difference.h"
#include "statistics.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One free parameter in the scaled space u = p / scale.
struct FreeParameter {
  std::string name;
  double lower = 0.0, upper = 0.0;  // [parameter units]
  double start = 0.0;
  double scale = 1.0;
  // A measurement effect's parameter (mocap_offset): its trial points are
  // the base runs recorded again, not new simulations.
  bool measurement = false;
};

// Where each residual comes from: experiment, frame, column (2 joint + axis).
struct ResidualIndex {
  std::uint32_t experiment;
  std::uint32_t frame;
  std::uint16_t column;
};

// The simulated angles of every experiment at one point of u.
struct Evaluation {
  std::vector<double> u;
  std::vector<Eigen::MatrixXd> simulated;  // per experiment, laid out as Experiment::measured
  std::vector<sim::SimulationSummary> summaries;
  // Per free parameter of a measurement effect (others: empty), per
  // difference-plan trial, per experiment: the base runs recorded at the
  // trial value.
  std::vector<std::array<std::vector<Eigen::MatrixXd>, 2>> measurement_trials;
  Eigen::VectorXd residuals;  // weighted
  bool ok = false;
  std::string failure;
};

// One finite-difference run: experiment, free values, simulated angles.
struct DifferenceRun {
  std::size_t experiment = 0;
  std::vector<double> values;
  Eigen::MatrixXd simulated;
};

class FitProblem {
 public:
  FitProblem(const std::vector<Experiment>& experiments, const IdentificationOptions& options,
             std::vector<sim::ArmParameters> base, std::vector<FreeParameter> free,
             SimulationBackend* backend)
      : experiments_(experiments),
        options_(options),
        base_(std::move(base)),
        free_(std::move(free)),
        backend_(backend) {
    for (std::size_t e = 0; e < experiments_.size(); ++e) {
      const Experiment& x = experiments_[e];
      for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
        for (Eigen::Index c = 0; c < x.measured.cols(); ++c) {
          if (std::isfinite(x.measured(f, c))) {
            index_.push_back({static_cast<std::uint32_t>(e), static_cast<std::uint32_t>(f),
                              static_cast<std::uint16_t>(c)});
          }
        }
      }
    }
  }

  std::size_t num_residuals() const { return index_.size(); }
  // The parameters each run fits in closed form rather than the minimiser:
  // a rotation and an offset per experiment placed in the capture frame.
  std::size_t EliminatedParameters() const {
    std::size_t n = 0;
    for (const Experiment& x : experiments_) {
      if (!x.tracked_points.empty() && x.point_placement == PointPlacement::kFittedRigidMotion) {
        n += 6;
      }
    }
    return n;
  }
  std::size_t num_free() const { return free_.size(); }
  const std::vector<ResidualIndex>& index() const { return index_; }
  const std::vector<FreeParameter>& free() const { return free_; }
  std::int64_t simulations() const { return simulations_; }

  // The parameters of experiment e at the free values p.
  sim::ArmParameters ParametersAt(std::size_t e, const std::vector<double>& p) const {
    sim::ArmParameters out = base_[e];
    for (std::size_t i = 0; i < free_.size(); ++i) {
      sim::SetParameter(free_[i].name, p[i], "identification", &out);
    }
    return out;
  }

  std::vector<double> ValuesAt(const double* u) const {
    std::vector<double> p(free_.size());
    for (std::size_t i = 0; i < free_.size(); ++i) {
      // Ceres keeps u inside the bounds; clamping only removes the last-bit
      // rounding of p = u s.
      p[i] = std::clamp(u[i] * free_[i].scale, free_[i].lower, free_[i].upper);
    }
    return p;
  }

  // The base evaluation at u (cached: Ceres asks for the same point twice,
  // once for the cost and once for the Jacobian).
  Evaluation Evaluate(const double* u, bool keep_trajectories = false) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      for (const Evaluation& e : cache_) {
        if (!keep_trajectories && std::equal(e.u.begin(), e.u.end(), u)) return e;
      }
    }
    Evaluation ev;
    ev.u.assign(u, u + free_.size());
    const std::vector<double> p = ValuesAt(u);
    std::vector<RunRequest> requests;
    for (std::size_t e = 0; e < experiments_.size(); ++e) {
      RunRequest request{e, ParametersAt(e, p), keep_trajectories, {}};
      for (std::size_t i = 0; i < free_.size(); ++i) {
        if (!free_[i].measurement) continue;
        for (const double trial : PlanFor(i, p[i]).trial_values) {
          std::vector<double> q = p;
          q[i] = trial;
          request.measurement_variants.push_back(ParametersAt(e, q));
        }
      }
      requests.push_back(std::move(request));
    }
    std::vector<RunResult> results = Run(requests);
    ev.measurement_trials.resize(free_.size());
    for (std::size_t e = 0; e < results.size(); ++e) {
      std::size_t v = 0;
      for (std::size_t i = 0; i < free_.size(); ++i) {
        if (!free_[i].measurement) continue;
        for (int t = 0; t < 2; ++t) {
          ev.measurement_trials[i][static_cast<std::size_t>(t)].push_back(
              std::move(results[e].variant_simulated[v++]));
        }
      }
    }
    ev.ok = true;
    for (std::size_t e = 0; e < results.size(); ++e) {
      if (!results[e].summary.completed() && ev.ok) {
        ev.ok = false;
        ev.failure = experiments_[e].name + ": " + results[e].summary.message;
      }
      ev.simulated.push_back(std::move(results[e].simulated));
      ev.summaries.push_back(results[e].summary);
      if (keep_trajectories) trajectories_.push_back(std::move(results[e].trajectory));
    }
    if (ev.ok) ev.residuals = Residuals(ev.simulated);
    const std::lock_guard<std::mutex> lock(mutex_);
    cache_.push_back(std::move(ev));
    if (cache_.size() > 8) cache_.erase(cache_.begin());
    return cache_.back();
  }

  // Jacobian of the weighted residuals with respect to u by finite
  // differences: second order (the difference plans) once UseSecondOrder()
  // was called or with central_differences_throughout, else first-order
  // forward differences; false (with *failure) when a run failed.
  bool Jacobian(const double* u, Eigen::MatrixXd* jacobian, std::string* failure) {
    bool second_order = false;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      second_order = second_order_;
      if (jacobian_u_.size() == free_.size() && jacobian_second_order_ == second_order &&
          std::equal(jacobian_u_.begin(), jacobian_u_.end(), u)) {
        *jacobian = jacobian_;
        return true;
      }
    }
    std::vector<DifferenceRun> runs;
    if (!DifferenceJacobian(u, second_order, options_.relative_step, jacobian, &runs, failure)) {
      return false;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    jacobian_u_.assign(u, u + free_.size());
    jacobian_second_order_ = second_order;
    jacobian_ = *jacobian;
    trial_runs_ = std::move(runs);
    return true;
  }

  // The second-order Jacobian at `relative_step` instead of the fit's, for
  // the check that the angles are smooth in each parameter (nothing cached).
  // A measurement parameter's column is NaN: it re-records one run, exact
  // at any step, and its trials are the fit's.
  bool JacobianAtStep(const double* u, double relative_step, Eigen::MatrixXd* jacobian,
                      std::string* failure) {
    std::vector<DifferenceRun> runs;
    return DifferenceJacobian(u, true, relative_step, jacobian, &runs, failure);
  }

  // What Jacobian(u) returns from now on: the final point's, whose columns
  // the derivative check may have taken at a finer step (Ceres' covariance
  // asks for it through the cost function).
  void SetJacobianAt(const double* u, const Eigen::MatrixXd& jacobian) {
    const std::lock_guard<std::mutex> lock(mutex_);
    jacobian_u_.assign(u, u + free_.size());
    jacobian_second_order_ = second_order_;
    jacobian_ = jacobian;
  }

  // From now on every Jacobian is second order (the final point's).
  void UseSecondOrder() {
    const std::lock_guard<std::mutex> lock(mutex_);
    second_order_ = true;
  }

  // Jacobian at u by finite differences of `relative_step` (second order or
  // first-order forward), reusing the cached trial runs of the last
  // Jacobian at the same point; the runs it used in *runs.
  bool DifferenceJacobian(const double* u, bool second_order, double relative_step,
                          Eigen::MatrixXd* jacobian, std::vector<DifferenceRun>* runs_used,
                          std::string* failure) {
    const bool fit_step = relative_step == options_.relative_step;
    const Evaluation base = Evaluate(u);
    if (!base.ok) {
      *failure = base.failure;
      return false;
    }
    const std::vector<double> p = ValuesAt(u);
    const std::size_t ne = experiments_.size();
    // Per free parameter: its difference plan and the trial values it runs.
    std::vector<internal::DifferencePlan> plans;
    std::vector<std::vector<double>> trials(free_.size());
    for (std::size_t i = 0; i < free_.size(); ++i) {
      plans.push_back(PlanFor(i, p[i], relative_step));
      if (free_[i].measurement) continue;  // recorded with the base runs
      if (second_order) {
        trials[i].assign(plans[i].trial_values.begin(), plans[i].trial_values.end());
      } else {
        // The same expression as the central plan's p + h, so that the final
        // second-order Jacobian finds these runs again.
        const double h = relative_step * free_[i].scale;
        trials[i] = {p[i] + h <= free_[i].upper ? p[i] + h : p[i] - h};
      }
    }
    // Runs of the last Jacobian at the same point are not repeated.
    std::vector<DifferenceRun> runs;
    std::vector<RunRequest> requests;
    std::vector<std::size_t> request_of;  // index into runs of each request
    for (std::size_t i = 0; i < free_.size(); ++i) {
      for (const double value : trials[i]) {
        std::vector<double> q = p;
        q[i] = value;
        for (std::size_t e = 0; e < ne; ++e) {
          DifferenceRun run{e, q, {}};
          const std::lock_guard<std::mutex> lock(mutex_);
          const auto cached = std::find_if(
              trial_runs_.begin(), trial_runs_.end(),
              [&](const DifferenceRun& t) { return t.experiment == e && t.values == q; });
          if (cached != trial_runs_.end()) {
            run.simulated = cached->simulated;
          } else {
            requests.push_back({e, ParametersAt(e, q), false, {}});
            request_of.push_back(runs.size());
          }
          runs.push_back(std::move(run));
        }
      }
    }
    const std::vector<RunResult> results = Run(requests);
    for (std::size_t k = 0; k < results.size(); ++k) {
      DifferenceRun& run = runs[request_of[k]];
      if (!results[k].summary.completed()) {
        std::size_t i = 0;
        while (run.values[i] == p[i]) ++i;
        *failure = "finite difference of " + free_[i].name + ": " +
                   experiments_[run.experiment].name + ": " + results[k].summary.message;
        return false;
      }
      run.simulated = results[k].simulated;
    }
    jacobian->resize(static_cast<Eigen::Index>(index_.size()),
                     static_cast<Eigen::Index>(free_.size()));
    std::size_t next = 0;  // into runs, in the order they were laid out
    for (std::size_t i = 0; i < free_.size(); ++i) {
      std::vector<Eigen::VectorXd> r;  // weighted residuals at each trial
      if (free_[i].measurement && !fit_step) {
        jacobian->col(static_cast<Eigen::Index>(i)).setConstant(kNaN);
        continue;
      }
      for (std::size_t t = 0; t < (free_[i].measurement ? 2 : trials[i].size()); ++t) {
        if (free_[i].measurement) {
          r.push_back(Residuals(base.measurement_trials[i][t]));
          continue;
        }
        std::vector<Eigen::MatrixXd> angles;
        for (std::size_t e = 0; e < ne; ++e) angles.push_back(runs[next++].simulated);
        r.push_back(Residuals(angles));
      }
      Eigen::VectorXd column;
      if (r.size() == 1) {
        // dr/du = s (r(t) - r(p)) / (t - p), first order.
        column = (r[0] - base.residuals) * (free_[i].scale / (trials[i][0] - p[i]));
      } else {
        // dr/du = s dr/dp; h dr/dp = (w_b r(p) + w_0 r(t_0) + w_1 r(t_1)) / 2.
        const internal::DifferencePlan& plan = plans[i];
        const double h = relative_step * free_[i].scale;
        column = (plan.base_weight * base.residuals + plan.trial_weights[0] * r[0] +
                  plan.trial_weights[1] * r[1]) *
                 (free_[i].scale / (2.0 * h));
      }
      jacobian->col(static_cast<Eigen::Index>(i)) = column;
    }
    *runs_used = std::move(runs);
    return true;
  }

  // The difference plan of free parameter i at value p_i, at the fit's
  // relative step unless another is given.
  internal::DifferencePlan PlanFor(std::size_t i, double p_i, double relative_step = 0.0) const {
    const double h =
        (relative_step > 0.0 ? relative_step : options_.relative_step) * free_[i].scale;
    const std::optional<internal::DifferencePlan> plan =
        internal::PlanDifference(p_i, h, free_[i].lower, free_[i].upper);
    CCSRM_CHECK(plan.has_value());  // Identify checked the bounds' width
    return *plan;
  }

  // (simulated - measured) / noise at every residual index (the frame's own
  // noise: Experiment::NoiseDeg).
  Eigen::VectorXd Residuals(const std::vector<Eigen::MatrixXd>& angles_rad) const {
    Eigen::VectorXd r(static_cast<Eigen::Index>(index_.size()));
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const ResidualIndex& at = index_[k];
      const Experiment& x = experiments_[at.experiment];
      r[static_cast<Eigen::Index>(k)] =
          x.WeightedResidual(at.frame, at.column, angles_rad[at.experiment](at.frame, at.column));
    }
    return r;
  }

  // RMS of the unweighted residuals of the angles [deg], or with `points`
  // the tracked points' Euclidean RMS error [mm] (the sum of their three
  // coordinates' squares over the points measured); NaN without any.
  double Rms(const std::vector<Eigen::MatrixXd>& simulated, bool points) const {
    double sum = 0.0;
    std::size_t n = 0;
    for (const ResidualIndex& at : index_) {
      const Experiment& x = experiments_[at.experiment];
      if (x.IsPointColumn(at.column) != points) continue;
      ++n;
      const double d =
          (simulated[at.experiment](at.frame, at.column) - x.measured(at.frame, at.column)) *
          (points ? 1e3 : kDeg);
      sum += d * d;
    }
    const double per = points ? static_cast<double>(n) / 3.0 : static_cast<double>(n);
    return n > 0 ? std::sqrt(sum / per) : kNaN;
  }

  // N_eff of weighted residuals laid out as index(): every (experiment,
  // joint, axis) series over its measured frames.
  double EffectiveSamples(const Eigen::VectorXd& residuals) const {
    std::vector<std::vector<double>> series;
    std::size_t k = 0;
    for (std::size_t e = 0; e < experiments_.size(); ++e) {
      std::vector<std::vector<double>> per_column(
          static_cast<std::size_t>(experiments_[e].measured.cols()));
      for (; k < index_.size() && index_[k].experiment == e; ++k) {
        per_column[index_[k].column].push_back(residuals[static_cast<Eigen::Index>(k)]);
      }
      for (auto& c : per_column) series.push_back(std::move(c));
    }
    return internal::EffectiveSampleSize(series);
  }

  std::optional<Eigen::VectorXd> CachedResiduals(const double* u) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const Evaluation& e : cache_) {
      if (e.ok && std::equal(e.u.begin(), e.u.end(), u)) return e.residuals;
    }
    return std::nullopt;
  }

  // Rms of the cached evaluation at u.
  std::optional<double> CachedRms(const double* u, bool points) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const Evaluation& e : cache_) {
      if (e.ok && std::equal(e.u.begin(), e.u.end(), u)) return Rms(e.simulated, points);
    }
    return std::nullopt;
  }

  std::optional<Eigen::MatrixXd> CachedJacobian(const double* u) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (jacobian_u_.size() == free_.size() &&
        std::equal(jacobian_u_.begin(), jacobian_u_.end(), u)) {
      return jacobian_;
    }
    return std::nullopt;
  }

  std::vector<sim::Trajectory> TakeTrajectories() { return std::move(trajectories_); }

 private:
  std::vector<RunResult> Run(const std::vector<RunRequest>& requests) {
    std::vector<RunResult> results = backend_->RunBatch(requests, options_.on_run);
    simulations_ += static_cast<std::int64_t>(requests.size());
    return results;
  }

  const std::vector<Experiment>& experiments_;
  const IdentificationOptions& options_;
  std::vector<sim::ArmParameters> base_;
  std::vector<FreeParameter> free_;
  SimulationBackend* backend_;
  std::vector<ResidualIndex> index_;
  std::mutex mutex_;
  std::vector<Evaluation> cache_;
  bool second_order_ = options_.central_differences_throughout;
  std::vector<double> jacobian_u_;
  bool jacobian_second_order_ = false;
  Eigen::MatrixXd jacobian_;
  std::vector<DifferenceRun> trial_runs_;  // of the last Jacobian
  std::vector<sim::Trajectory> trajectories_;
  std::int64_t simulations_ = 0;
};

// The whole problem as one residual block of one parameter block: every
// evaluation is a batch of simulations that the backend spreads out.
class SimulatedAnglesCost final : public ceres::CostFunction {
 public:
  explicit SimulatedAnglesCost(FitProblem* problem) : problem_(problem) {
    set_num_residuals(static_cast<int>(problem->num_residuals()));
    mutable_parameter_block_sizes()->push_back(static_cast<std::int32_t>(problem->num_free()));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    try {
      const Evaluation ev = problem_->Evaluate(parameters[0]);
      if (!ev.ok) {
        last_failure_ = ev.failure;
        return false;
      }
      Eigen::Map<Eigen::VectorXd>(residuals, ev.residuals.size()) = ev.residuals;
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        Eigen::MatrixXd j;
        if (!problem_->Jacobian(parameters[0], &j, &last_failure_)) return false;
        // Ceres' Jacobians are row-major.
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[0], j.rows(), j.cols()) = j;
      }
      return true;
    } catch (const std::exception& error) {
      last_failure_ = error.what();
      return false;
    }
  }

  const std::string& last_failure() const { return last_failure_; }

 private:
  FitProblem* problem_;
  mutable std::string last_failure_;
};

std::string StepRuleMessage(double fraction) {
  char text[160];
  std::snprintf(text, sizeof(text),
                "the last step moved every parameter by less than %g of its standard error",
                fraction);
  return text;
}

class IterationReporter final : public ceres::IterationCallback {
 public:
  // `checkpoint` holds what a checkpoint keeps besides the minimiser's
  // state (its start, damping floor, and, when resuming, the iterations and
  // simulations done before).
  IterationReporter(FitProblem* problem, const double* u, const IdentificationOptions& options,
                    std::chrono::steady_clock::time_point start, std::vector<double>* costs,
                    FitCheckpoint checkpoint)
      : problem_(problem),
        u_(u),
        options_(options),
        start_(start),
        costs_(costs),
        checkpoint_(std::move(checkpoint)),
        iterations_before_(checkpoint_.iterations),
        simulations_before_(checkpoint_.simulations) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    // A resumed fit's start is the checkpoint's point, whose cost is in the history.
    const bool resumed_start = s.iteration == 0 && options_.resume;
    if ((s.step_is_successful || s.iteration == 0) && !resumed_start) costs_->push_back(s.cost);
    Report(s);
    if (s.iteration == 0) previous_.assign(u_, u_ + problem_->num_free());
    if (s.iteration == 0 || !s.step_is_successful) {
      if (s.iteration == 0) previous_cost_ = s.cost;
      if (s.iteration == 0 && !resumed_start) Save(s);
      return ceres::SOLVER_CONTINUE;
    }
    const bool small = StepWithinStandardErrors(s.cost);
    const bool insignificant = DecreaseInsignificant(s.cost);
    previous_.assign(u_, u_ + problem_->num_free());
    last_accepted_iteration_ = iterations_before_ + s.iteration;
    previous_cost_ = s.cost;
    if (small) stop_reason_ = StepRuleMessage(options_.converged_step_fraction);
    if (!small && insignificant) {
      char text[200];
      std::snprintf(text, sizeof(text),
                    "the last step lowered the effective chi-square by less than %g "
                    "(a difference the data cannot tell apart)",
                    options_.min_effective_chi2_decrease);
      stop_reason_ = text;
    }
    if (small || insignificant) return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    // Only a state the fit goes on from: resumed, a state where a rule
    // stopped the fit would not stop again (the rules judge a step).
    Save(s);
    return ceres::SOLVER_CONTINUE;
  }

  // Why the callback stopped the fit; empty when it did not.
  const std::string& stop_reason() const { return stop_reason_; }
  // The point of the last accepted step (the start before one), and the
  // iteration that took it (0: none).
  const std::vector<double>& last_accepted() const { return previous_; }
  int last_accepted_iteration() const { return last_accepted_iteration_; }
  int iterations_before() const { return iterations_before_; }
  std::int64_t simulations_before() const { return simulations_before_; }

 private:
  void Save(const ceres::IterationSummary& s) {
    if (!options_.on_checkpoint) return;
    checkpoint_.iterations = iterations_before_ + s.iteration;
    checkpoint_.u.assign(u_, u_ + problem_->num_free());
    checkpoint_.values = problem_->ValuesAt(u_);
    // After an accepted step Ceres has already updated the radius for the next.
    checkpoint_.trust_region_radius = s.trust_region_radius;
    checkpoint_.simulations = simulations_before_ + problem_->simulations();
    checkpoint_.cost_history = *costs_;
    options_.on_checkpoint(checkpoint_);
  }

  // The statistical stopping rule: the last step moved every free parameter
  // by less than options.converged_step_fraction of its standard error, as
  // the summary will report it (Jacobian at the new point, residual variance
  // 2 cost / (N - p), times N / N_eff). Further steps would move the
  // estimate by amounts the data cannot tell apart, so the fit stops instead
  // of creeping along a flat valley, a whole Jacobian per step.
  bool StepWithinStandardErrors(double cost) const {
    const std::optional<Eigen::MatrixXd> jacobian = problem_->CachedJacobian(u_);
    const std::optional<Eigen::VectorXd> residuals = problem_->CachedResiduals(u_);
    const std::size_t p = problem_->num_free();
    const double n = static_cast<double>(problem_->num_residuals());
    if (!jacobian || !residuals || n <= static_cast<double>(p)) return false;
    const double n_eff = problem_->EffectiveSamples(*residuals);
    const double inflation = n_eff > 0.0 ? n / n_eff : 1.0;
    const Eigen::MatrixXd h = jacobian->transpose() * *jacobian;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(h);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(h.rows(), h.cols()));
    const double variance = 2.0 * cost / (n - static_cast<double>(p)) * inflation;
    for (std::size_t i = 0; i < p; ++i) {
      const double se =
          std::sqrt(variance * inverse(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)));
      const double step = std::abs(u_[i] - previous_[i]);
      // A direction the data do not determine (se not finite) does not hold the fit back.
      if (std::isfinite(se) && step > options_.converged_step_fraction * se) return false;
    }
    return true;
  }

  // The second statistical rule: the accepted step lowered the cost by an
  // amount the data cannot tell apart, 2 (cost before - cost after) N_eff / N
  // below options.min_effective_chi2_decrease. Where the cost is slightly
  // rough in a poorly determined parameter, Levenberg-Marquardt otherwise
  // zigzags along the valley at a constant RMS, a whole Jacobian per step.
  bool DecreaseInsignificant(double cost) const {
    if (!(options_.min_effective_chi2_decrease > 0.0)) return false;
    const std::optional<Eigen::VectorXd> residuals = problem_->CachedResiduals(u_);
    if (!residuals) return false;
    const double n = static_cast<double>(problem_->num_residuals());
    const double n_eff = problem_->EffectiveSamples(*residuals);
    // In units of the residual variance 2 cost / (N - p), as the standard
    // errors are: where the model cannot reach the noise (a missing effect)
    // every residual is that much larger than the noise, and so are the
    // cost differences chance makes.
    const double p = static_cast<double>(problem_->num_free());
    const double variance = n > p ? std::max(2.0 * cost / (n - p), 1.0) : 1.0;
    return 2.0 * (previous_cost_ - cost) * (n_eff / n) / variance <
           options_.min_effective_chi2_decrease;
  }

  void Report(const ceres::IterationSummary& s) {
    if (options_.on_iteration) {
      IterationProgress p;
      p.iteration = iterations_before_ + s.iteration;
      p.cost = s.cost;
      p.rms_deg = problem_->CachedRms(u_, false).value_or(kNaN);
      p.rms_mm = problem_->CachedRms(u_, true).value_or(kNaN);
      p.relative_decrease = s.iteration == 0 ? 0.0 : s.relative_decrease;
      p.trust_region_radius = s.trust_region_radius;
      p.step_accepted = s.step_is_successful;
      p.simulations = simulations_before_ + problem_->simulations();
      p.wall_time_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      const std::vector<double> values = problem_->ValuesAt(u_);
      for (std::size_t i = 0; i < values.size(); ++i) {
        p.values.emplace_back(problem_->free()[i].name, values[i]);
      }
      options_.on_iteration(p);
    }
  }

  FitProblem* problem_;
  const double* u_;
  const IdentificationOptions& options_;
  std::chrono::steady_clock::time_point start_;
  std::vector<double>* costs_;
  FitCheckpoint checkpoint_;
  int iterations_before_ = 0;
  std::int64_t simulations_before_ = 0;
  std::vector<double> previous_;
  int last_accepted_iteration_ = 0;
  double previous_cost_ = 0.0;
  std::string stop_reason_;
};

IdentificationTermination FromCeres(ceres::TerminationType type) {
  switch (type) {
    case ceres::CONVERGENCE:
    case ceres::USER_SUCCESS:
      return IdentificationTermination::kConverged;
    case ceres::NO_CONVERGENCE:
      return IdentificationTermination::kNoConvergence;
    default:
      return IdentificationTermination::kFailed;
  }
}

}  // namespace

ChannelErrors AngleErrors(const std::vector<const Experiment*>& experiments,
                          const std::vector<const Eigen::MatrixXd*>& simulated) {
  const int joints = experiments.front()->joints;
  ChannelErrors out;
  out.rms_deg.assign(static_cast<std::size_t>(joints), {kNaN, kNaN});
  out.fit_percent.assign(static_cast<std::size_t>(joints), {kNaN, kNaN});
  out.motion_rms_deg.assign(static_cast<std::size_t>(joints), {kNaN, kNaN});
  out.samples.assign(static_cast<std::size_t>(joints), {0, 0});
  // Per joint and axis: squared error and squared spread about each
  // series' mean [deg^2] summed over the experiments, and the samples.
  std::vector<std::array<double, 2>> sq(static_cast<std::size_t>(joints), {0.0, 0.0});
  std::vector<std::array<double, 2>> spread(static_cast<std::size_t>(joints), {0.0, 0.0});
  std::vector<double> noise(static_cast<std::size_t>(joints), 0.0);
  for (int j = 0; j < joints; ++j) {
    const std::size_t jj = static_cast<std::size_t>(j);
    std::size_t with_noise = 0;
    for (const Experiment* x : experiments) {
      if (x->joints == joints && jj < x->noise_deg.size()) {
        noise[jj] += x->noise_deg[jj];
        ++with_noise;
      }
    }
    if (with_noise > 0) noise[jj] /= static_cast<double>(with_noise);
    for (int a = 0; a < 2; ++a) {
      const std::size_t aa = static_cast<std::size_t>(a);
      std::size_t n = 0;
      for (std::size_t e = 0; e < experiments.size(); ++e) {
        const Eigen::MatrixXd& meas = experiments[e]->measured;
        if (experiments[e]->joints != joints) continue;
        // Each experiment's own mean: fit percent compares with a constant
        // per series, not a mean across experiments.
        double mean = 0.0;
        std::size_t count = 0;
        for (Eigen::Index f = 0; f < meas.rows(); ++f) {
          if (std::isfinite(meas(f, 2 * j + a))) {
            mean += meas(f, 2 * j + a);
            ++count;
          }
        }
        if (count == 0) continue;
        mean /= static_cast<double>(count);
        for (Eigen::Index f = 0; f < meas.rows(); ++f) {
          const double m = meas(f, 2 * j + a);
          if (!std::isfinite(m)) continue;
          const double d = ((*simulated[e])(f, 2 * j + a) - m) * kDeg;
          sq[jj][aa] += d * d;
          spread[jj][aa] += (m - mean) * (m - mean) * kDeg * kDeg;
          ++n;
        }
      }
      out.samples[jj][aa] = n;
      if (n > 0) {
        out.rms_deg[jj][aa] = std::sqrt(sq[jj][aa] / static_cast<double>(n));
        out.motion_rms_deg[jj][aa] = std::sqrt(spread[jj][aa] / static_cast<double>(n));
      }
    }
  }
  double total_sq = 0.0, total_spread = 0.0, fitted_sq = 0.0;
  std::size_t total_n = 0;
  for (std::size_t j = 0; j < out.rms_deg.size(); ++j) {
    const double larger = std::max(out.motion_rms_deg[j][0], out.motion_rms_deg[j][1]);
    for (std::size_t a = 0; a < 2; ++a) {
      total_sq += sq[j][a];
      total_n += out.samples[j][a];
      const double motion = out.motion_rms_deg[j][a];
      // ChannelErrors says when an axis moves enough for a fit percent.
      if (!(motion > 0.0) || motion < kFitMotionShare * larger ||
          motion < kFitMotionNoiseRatio * noise[j]) {
        continue;
      }
      out.fit_percent[j][a] = 100.0 * (1.0 - std::sqrt(sq[j][a] / spread[j][a]));
      fitted_sq += sq[j][a];
      total_spread += spread[j][a];
    }
  }
  out.rms_deg_overall = total_n > 0 ? std::sqrt(total_sq / static_cast<double>(total_n)) : kNaN;
  out.fit_percent_overall =
      total_spread > 0.0 ? 100.0 * (1.0 - std::sqrt(fitted_sq / total_spread)) : kNaN;
  return out;
}

std::vector<std::string> Spec6ParameterNames() {
  return {"mu", "mu_s", "mu_c", "mu_c_s", "beta", "c_sc", "c_lc", "T_p", "T_d0"};
}

const char* TerminationName(IdentificationTermination termination) {
  switch (termination) {
    case IdentificationTermination::kConverged:
      return "converged";
    case IdentificationTermination::kNoConvergence:
      return "no convergence";
    case IdentificationTermination::kFailed:
      return "failed";
  }
  return "?";
}

bool IdentificationOptions::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& message) {
    *error = message;
    return false;
  };
  if (free_parameters.empty()) return fail("free parameters: none given");
  std::set<std::string> seen;
  for (const std::string& name : free_parameters) {
    try {
      sim::FindParameter(name, "free parameters");
    } catch (const InputError& e) {
      return fail(e.what());
    }
    if (!seen.insert(name).second) return fail("free parameters: '" + name + "' is repeated");
  }
  for (const auto& [name, value] : values) {
    try {
      const sim::ParameterInfo& info = sim::FindParameter(name, "values");
      const std::string problem = sim::ParameterValueProblem(info, value);
      if (!problem.empty()) return fail("values: " + problem);
    } catch (const InputError& e) {
      return fail(e.what());
    }
  }
  for (const auto& [name, range] : bounds) {
    if (seen.count(name) == 0) {
      return fail("bounds: '" + name + "' is not a free parameter");
    }
    const sim::ParameterInfo& info = sim::FindParameter(name, "bounds");
    if (!(range.first < range.second) || !std::isfinite(range.first) ||
        !std::isfinite(range.second)) {
      return fail("bounds of '" + name + "': the lower bound must be below the upper one");
    }
    if (range.first < info.lower || range.second > info.upper) {
      char text[256];
      std::snprintf(text, sizeof(text), "bounds of '%s': [%g, %g] leave its own bounds [%g, %g]",
                    name.c_str(), range.first, range.second, info.lower, info.upper);
      return fail(text);
    }
  }
  for (const auto& [name, scale] : scales) {
    if (seen.count(name) == 0) return fail("scales: '" + name + "' is not a free parameter");
    if (!(scale > 0.0) || !std::isfinite(scale)) {
      return fail("scales: the scale of '" + name + "' must be > 0");
    }
  }
  if (!(relative_step > 0.0 && relative_step <= 0.1)) {
    return fail("relative_step must be in (0, 0.1]");
  }
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    return fail(problem);
  }
  if (max_iterations < 0) return fail("max_iterations must be >= 0");
  if (!(function_tolerance > 0.0) || !(parameter_tolerance > 0.0) || !(gradient_tolerance > 0.0)) {
    return fail("tolerances must be > 0");
  }
  if (!(max_relative_standard_error > 0.0)) return fail("max_relative_standard_error must be > 0");
  if (!(converged_step_fraction >= 0.0)) return fail("converged_step_fraction must be >= 0");
  if (!(min_relative_damping >= 0.0 && min_relative_damping <= 1.0)) {
    return fail("min_relative_damping must be in [0, 1]");
  }
  if (!(initial_trust_region_radius > 0.0)) return fail("initial_trust_region_radius must be > 0");
  if (!(min_effective_chi2_decrease >= 0.0))
    return fail("min_effective_chi2_decrease must be >= 0");
  return true;
}

const ParameterEstimate* IdentificationSummary::Find(const std::string& name) const {
  for (const ParameterEstimate& p : parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

namespace {

// The stages of Identify, in order.

// Options valid, experiments given, all of one arm.
void CheckFitInputs(const std::vector<Experiment>& experiments,
                    const IdentificationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("identification", "options", error);
  if (experiments.empty()) ThrowInputError("identification", "experiments", "none given");
  for (const Experiment& e : experiments) {
    if (e.joints != experiments.front().joints) {
      ThrowInputError(e.path, "joints",
                      "the experiments' arms differ (" + std::to_string(e.joints) + " against " +
                          std::to_string(experiments.front().joints) + " joints)");
    }
  }
}

// Every experiment's parameters: its nominal values with options.values.
std::vector<sim::ArmParameters> BaseParameters(const std::vector<Experiment>& experiments,
                                               const IdentificationOptions& options) {
  std::vector<sim::ArmParameters> base;
  for (const Experiment& e : experiments) {
    sim::ArmParameters p = e.config.parameters;
    // Names are checked against the experiments' arm here, where it is known.
    for (const auto& [name, value] : options.values) {
      SetParameter(name, value, "the values given (--set, --params), on the arm of " + e.path, &p);
    }
    base.push_back(p);
  }
  return base;
}

// The free parameters, each starting from the first experiment's value,
// with its bounds and scale.
std::vector<FreeParameter> FreeParametersOf(const std::vector<Experiment>& experiments,
                                            const IdentificationOptions& options,
                                            const sim::ArmParameters& first) {
  const sim::ArmSize arm = first.arm;
  std::vector<FreeParameter> free;
  for (const std::string& name : options.free_parameters) {
    const sim::ParameterInfo& info =
        sim::FindParameter(name, "--free, on the arm of " + experiments.front().path, arm);
    FreeParameter f;
    f.name = name;
    f.lower = info.lower;
    f.upper = info.upper;
    if (const auto it = options.bounds.find(name); it != options.bounds.end()) {
      f.lower = it->second.first;
      f.upper = it->second.second;
    }
    f.start = sim::GetParameter(first, name);
    if (f.start < f.lower || f.start > f.upper) {
      // Name where the start came from: a value given for the fit (--set,
      // --params), else the first experiment's configuration.
      const bool given = options.values.count(name) != 0;
      char text[320];
      std::snprintf(text, sizeof(text), "start value %g is outside the bounds [%g, %g]%s%s",
                    f.start, f.lower, f.upper, info.units == "1" ? "" : (" " + info.units).c_str(),
                    given ? ""
                          : "; the start is this experiment's configured value: give one "
                            "inside (--set or --params)");
      const std::string& path = experiments.front().path;
      ThrowInputError(given ? "the values given (--set, --params)"
                            : (path.empty() ? "the first experiment" : path),
                      "parameter '" + name + "'", text);
    }
    const double nominal = sim::GetParameter(experiments.front().config.parameters, name);
    f.scale = f.start != 0.0   ? std::abs(f.start)
              : nominal != 0.0 ? std::abs(nominal)
                               : 0.01 * (f.upper - f.lower);
    if (const auto it = options.scales.find(name); it != options.scales.end()) f.scale = it->second;
    f.measurement = info.is_effect() && sim::FindEffect(info.effect, "--free").measurement;
    // Every difference plan must fit inside the bounds (see PlanDifference):
    // within h of one bound, a one-sided plan needs 2h towards the other.
    if (f.upper - f.lower < 4.0 * options.relative_step * f.scale) {
      ThrowInputError("parameter '" + name + "'", "bounds",
                      "too narrow for a finite-difference step of " +
                          std::to_string(options.relative_step * f.scale));
    }
    free.push_back(f);
  }
  return free;
}

// The start point first: a start that does not run is an answer in itself.
// A resumed fit has its start's runs in the checkpoint, and goes on from
// the checkpoint's point (*u set to it).
Evaluation EvaluateStart(FitProblem& problem, const std::vector<Experiment>& experiments,
                         const FitCheckpoint* resume, std::vector<double>* u) {
  if (resume == nullptr) return problem.Evaluate(u->data());
  if (resume->u.size() != u->size() || resume->start_angles_rad.size() != experiments.size()) {
    ThrowInputError("identification", "resume",
                    "the checkpoint is of another fit (free parameters or experiments)");
  }
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Eigen::MatrixXd& a = resume->start_angles_rad[e];
    if (a.rows() != experiments[e].measured.rows() || a.cols() != experiments[e].measured.cols()) {
      ThrowInputError("identification", "resume",
                      "the checkpoint's runs do not match experiment " + experiments[e].name);
    }
  }
  Evaluation start;
  start.u = *u;
  start.simulated = resume->start_angles_rad;
  start.summaries.resize(experiments.size());
  start.residuals = problem.Residuals(start.simulated);
  start.ok = true;
  *u = resume->u;
  return start;
}

// Levenberg-Marquardt from *u (left at the best point accepted): the
// termination, message, iterations and costs into *summary. Returns the
// simulations of a resumed fit before it was stopped.
std::int64_t Minimise(FitProblem& problem, ceres::Problem& ceres_problem,
                      const SimulatedAnglesCost& cost, const IdentificationOptions& options,
                      std::chrono::steady_clock::time_point clock_start,
                      const Evaluation& start_eval, std::vector<double>* u,
                      IdentificationSummary* summary) {
  const FitCheckpoint* resume = options.resume.get();
  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;
  // The damping floor, from the start's Jacobian (which iteration 0 then
  // finds cached). Without Jacobi scaling Ceres damps by the squared
  // column norms clipped to [min_lm_diagonal, max_lm_diagonal]: with
  // scaling on, the same norms of unit columns.
  Eigen::MatrixXd start_jacobian;
  std::string ignored;  // a failed run stops the minimiser at iteration 0
  if (resume != nullptr) {
    solver.initial_trust_region_radius = resume->trust_region_radius;
    solver.jacobi_scaling = resume->jacobi_scaling;
    solver.min_lm_diagonal = resume->min_lm_diagonal;
    solver.max_num_iterations = std::max(options.max_iterations - resume->iterations, 0);
  } else if (options.min_relative_damping > 0.0 &&
             problem.Jacobian(u->data(), &start_jacobian, &ignored)) {
    solver.jacobi_scaling = false;
    solver.min_lm_diagonal =
        std::max(options.min_relative_damping * start_jacobian.colwise().squaredNorm().maxCoeff(),
                 solver.min_lm_diagonal);
  }
  FitCheckpoint checkpoint;
  if (resume != nullptr) {
    checkpoint = *resume;
    summary->cost_history = resume->cost_history;
  } else {
    checkpoint.start_angles_rad = start_eval.simulated;
    checkpoint.min_lm_diagonal = solver.min_lm_diagonal;
    checkpoint.jacobi_scaling = solver.jacobi_scaling;
  }
  solver.num_threads = 1;  // the parallelism is in the backend
  solver.logging_type = ceres::SILENT;
  solver.update_state_every_iteration = true;
  // Steps are projected onto the bounds, without Ceres' projected line
  // search: its every trial point asks for a gradient, i.e. a whole
  // finite-difference Jacobian, and one bound-hugging fit spent 50
  // simulations there for no gain.
  solver.max_num_line_search_step_size_iterations = 0;
  IterationReporter progress(&problem, u->data(), options, clock_start, &summary->cost_history,
                             std::move(checkpoint));
  solver.callbacks.push_back(&progress);
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver, &ceres_problem, &ceres_summary);
  summary->termination = FromCeres(ceres_summary.termination_type);
  summary->message =
      progress.stop_reason().empty() ? ceres_summary.message : progress.stop_reason();
  if (summary->termination == IdentificationTermination::kFailed && !cost.last_failure().empty()) {
    summary->message += " (" + cost.last_failure() + ")";
  }
  // Ceres leaves a failed solve's parameters where they started: the fit
  // reports the last point it accepted instead, where every run completed.
  if (summary->termination == IdentificationTermination::kFailed &&
      progress.last_accepted_iteration() > 0) {
    *u = progress.last_accepted();
    summary->message += "; the values are those of the last accepted iteration (" +
                        std::to_string(progress.last_accepted_iteration()) + ")";
  }
  summary->iterations =
      progress.iterations_before() + static_cast<int>(ceres_summary.iterations.size()) - 1;
  // Ceres counts only the iterations since the resume in its message.
  const std::string counted = "Number of iterations: ";
  if (const std::size_t at = summary->message.find(counted);
      resume != nullptr && at != std::string::npos) {
    summary->message =
        summary->message.substr(0, at) + counted + std::to_string(summary->iterations) + ".";
  }
  summary->initial_cost = ceres_summary.initial_cost;
  summary->final_cost = ceres_summary.final_cost;
  return progress.simulations_before();
}

// What the fit's final point says of its parameters' uncertainty.
struct Uncertainty {
  Eigen::MatrixXd covariance_u;  // free × free, scaled space, times σ_res²
  std::vector<bool> identifiable;
  std::vector<double> derivative_step_disagreement;  // per free parameter; empty: not checked
  std::vector<double> derivative_step;               // per free parameter, as the check chose
};

// The residual statistics, singular values, unidentifiable directions and
// covariance at the final point `u` (values p_final) into *summary.
Uncertainty UncertaintyAt(FitProblem& problem, ceres::Problem& ceres_problem,
                          const std::vector<FreeParameter>& free,
                          const std::vector<double>& p_final, const Evaluation& final_eval,
                          const IdentificationOptions& options, std::vector<double>* u,
                          IdentificationSummary* summary) {
  const std::size_t p_count = free.size();
  Uncertainty out;
  out.identifiable.assign(p_count, true);
  if (!final_eval.ok) {
    summary->covariance_message = "the run at the final point did not complete";
    return out;
  }
  Eigen::MatrixXd& covariance_u = out.covariance_u;
  std::vector<bool>& identifiable = out.identifiable;
  summary->effective_samples = problem.EffectiveSamples(final_eval.residuals);
  const double n = static_cast<double>(summary->residuals);
  // The placements eliminated from the fit use up degrees of freedom too.
  const double fitted = static_cast<double>(p_count + problem.EliminatedParameters());
  summary->residual_variance = n > fitted ? 2.0 * summary->final_cost / (n - fitted) : kNaN;
  const double inflation = summary->effective_samples > 0.0 ? n / summary->effective_samples : 1.0;
  const double variance_factor = summary->residual_variance * inflation;

  // Singular values of the scaled Jacobian, and what the data cannot pin
  // down: a second-order Jacobian from here on.
  problem.UseSecondOrder();
  Eigen::MatrixXd jacobian;
  std::string failure;
  if (problem.Jacobian(u->data(), &jacobian, &failure)) {
    summary->weighted_residuals = final_eval.residuals;
    Eigen::MatrixXd third;
    std::string unused;
    if (options.check_derivative_steps &&
        problem.JacobianAtStep(u->data(), options.relative_step / 3.0, &third, &unused)) {
      const internal::DerivativeSteps steps = internal::ChooseDerivativeSteps(
          options.relative_step, third,
          [&](Eigen::MatrixXd* ninth) {
            return problem.JacobianAtStep(u->data(), options.relative_step / 9.0, ninth, &unused);
          },
          kDerivativeStepLimit, &jacobian);
      out.derivative_step_disagreement = steps.disagreement;
      out.derivative_step = steps.relative_step;
      problem.SetJacobianAt(u->data(), jacobian);
    }
    summary->jacobian = jacobian;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    const Eigen::MatrixXd v = svd.matrixV();
    summary->singular_values.assign(sv.data(), sv.data() + sv.size());
    const double sigma_res = std::sqrt(variance_factor);
    const double tiny = sv.size() > 0 ? sv[0] * 1e-8 : 0.0;
    int null_rank = 0;
    Eigen::VectorXd direction_error(sv.size());
    for (Eigen::Index d = 0; d < sv.size(); ++d) {
      direction_error[d] =
          sv[d] > tiny ? sigma_res / sv[d] : std::numeric_limits<double>::infinity();
      if (!(sv[d] > tiny)) ++null_rank;
    }
    // Errors relative to the estimate (u is in units of the start's
    // magnitude), with a floor of a tenth of that magnitude, so that an
    // estimate the data pin near zero is not called undetermined for
    // being small.
    std::vector<double> relative_scale(p_count);
    for (std::size_t i = 0; i < p_count; ++i) {
      relative_scale[i] = free[i].scale / std::max(std::abs(p_final[i]), 0.1 * free[i].scale);
    }
    constexpr double kComponentFloor = 0.2;  // smaller shares are left out of a name
    const internal::Identifiability assessed = internal::AssessIdentifiability(
        v, direction_error, relative_scale, options.max_relative_standard_error, kComponentFloor);
    identifiable = assessed.identifiable;
    for (const internal::Identifiability::Direction& named : assessed.named) {
      const int d = named.column;
      UnidentifiableDirection dir;
      dir.singular_value = sv[d];
      dir.relative_std_error = assessed.direction_worst[static_cast<std::size_t>(d)];
      std::vector<std::pair<std::string, double>> parts;
      for (const int i : named.members) {
        parts.emplace_back(free[static_cast<std::size_t>(i)].name, v(i, d));
      }
      std::sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) {
        return std::abs(a.second) > std::abs(b.second);
      });
      dir.components = std::move(parts);
      summary->unidentifiable.push_back(std::move(dir));
    }

    // Covariance by Ceres, exact null directions dropped.
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.null_space_rank = null_rank;
    cov_options.min_reciprocal_condition_number = 1e-16;
    cov_options.apply_loss_function = false;
    cov_options.num_threads = 1;
    ceres::Covariance ceres_covariance(cov_options);
    std::vector<std::pair<const double*, const double*>> blocks = {{u->data(), u->data()}};
    if (ceres_covariance.Compute(blocks, &ceres_problem)) {
      covariance_u.resize(static_cast<Eigen::Index>(p_count), static_cast<Eigen::Index>(p_count));
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(
          static_cast<Eigen::Index>(p_count), static_cast<Eigen::Index>(p_count));
      ceres_covariance.GetCovarianceBlock(u->data(), u->data(), c.data());
      covariance_u = c * variance_factor;
      summary->covariance_available = true;
    } else {
      summary->covariance_message = "ceres::Covariance failed at the final point";
    }
  } else {
    summary->covariance_message = "the Jacobian at the final point failed: " + failure;
  }
  return out;
}

// The parameter table, free ones first (estimates, errors, 95 % intervals)
// then every other named parameter of `first` (effects only when on), and
// the free parameters' correlations.
void TabulateParameters(const std::vector<FreeParameter>& free, const std::vector<double>& p_final,
                        const Uncertainty& uncertainty, const sim::ArmParameters& first,
                        IdentificationSummary* summary) {
  const sim::ArmSize arm = first.arm;
  const std::size_t p_count = free.size();
  const Eigen::MatrixXd& covariance_u = uncertainty.covariance_u;
  const std::vector<bool>& identifiable = uncertainty.identifiable;
  const double t975 =
      internal::StudentT975(summary->effective_samples - static_cast<double>(p_count));
  for (std::size_t i = 0; i < p_count; ++i) {
    const sim::ParameterInfo& info = sim::FindParameter(free[i].name, "--free", arm);
    ParameterEstimate est;
    est.name = free[i].name;
    est.units = info.units;
    est.free = true;
    est.start = free[i].start;
    est.value = p_final[i];
    est.lower = free[i].lower;
    est.upper = free[i].upper;
    est.scale = free[i].scale;
    const double span = free[i].upper - free[i].lower;
    est.at_bound = std::abs(est.value - est.lower) <= 1e-9 * span ||
                   std::abs(est.value - est.upper) <= 1e-9 * span;
    est.identifiable = summary->covariance_available && identifiable[i];
    if (est.identifiable) {
      est.std_error =
          std::sqrt(std::max(
              covariance_u(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)), 0.0)) *
          free[i].scale;
      est.ci95_lower = std::max(est.value - t975 * est.std_error, est.lower);
      est.ci95_upper = std::min(est.value + t975 * est.std_error, est.upper);
    }
    if (i < uncertainty.derivative_step_disagreement.size()) {
      est.derivative_step_disagreement = uncertainty.derivative_step_disagreement[i];
      est.derivative_step = uncertainty.derivative_step[i];
    }
    summary->parameters.push_back(est);
  }
  // Fixed: every model parameter, and the parameters of the effects that are on.
  for (const sim::ParameterInfo& info_entry : sim::AllParameters(arm)) {
    const std::string& name = info_entry.name;
    if (std::find(summary->free_names.begin(), summary->free_names.end(), name) !=
        summary->free_names.end()) {
      continue;
    }
    const std::size_t dot = name.find('.');
    if (dot != std::string::npos && !first.EffectOn(name.substr(0, dot))) continue;
    const sim::ParameterInfo& info = sim::FindParameter(name, "parameters", arm);
    ParameterEstimate est;
    est.name = name;
    est.units = info.units;
    est.free = false;
    est.start = est.value = sim::GetParameter(first, name);
    est.lower = info.lower;
    est.upper = info.upper;
    est.identifiable = false;
    summary->parameters.push_back(est);
  }
  summary->correlation = Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(p_count),
                                                   static_cast<Eigen::Index>(p_count), kNaN);
  if (summary->covariance_available) {
    for (std::size_t i = 0; i < p_count; ++i) {
      for (std::size_t j = 0; j < p_count; ++j) {
        if (!identifiable[i] || !identifiable[j]) continue;
        const Eigen::Index a = static_cast<Eigen::Index>(i), b = static_cast<Eigen::Index>(j);
        const double d = std::sqrt(covariance_u(a, a) * covariance_u(b, b));
        summary->correlation(a, b) = d > 0.0 ? covariance_u(a, b) / d : kNaN;
      }
    }
  }
}

// Errors per experiment and overall, at the start and at the end, with the
// fitted runs.
void TabulateErrors(const std::vector<Experiment>& experiments, const FitProblem& problem,
                    const Evaluation& start_eval, const Evaluation& final_eval,
                    const std::vector<double>& p_final, std::vector<sim::Trajectory> trajectories,
                    IdentificationSummary* summary) {
  std::vector<const Experiment*> all;
  std::vector<const Eigen::MatrixXd*> start_angles, final_angles;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    ExperimentFit fit;
    fit.name = experiments[e].name;
    fit.path = experiments[e].path;
    fit.angles_from_pipeline = experiments[e].angles_from_pipeline;
    fit.noise_deg = experiments[e].noise_deg;
    fit.noise_source = experiments[e].noise_source;
    if (start_eval.ok || !start_eval.simulated.empty()) {
      fit.start = AngleErrors({&experiments[e]}, {&start_eval.simulated[e]});
    }
    fit.fitted = AngleErrors({&experiments[e]}, {&final_eval.simulated[e]});
    fit.run.summary = final_eval.summaries[e];
    if (e < trajectories.size()) fit.run.trajectory = std::move(trajectories[e]);
    if (!experiments[e].tracked_points.empty()) {
      fit.points = experiments[e].tracked_points;
      fit.placed_in_capture_frame =
          experiments[e].point_placement == PointPlacement::kFittedRigidMotion;
      if (!start_eval.simulated.empty()) {
        fit.start_points = PointErrors(experiments[e], start_eval.simulated[e]);
      }
      fit.fitted_points = PointErrors(experiments[e], final_eval.simulated[e]);
      Eigen::MatrixXd placed = final_eval.simulated[e];
      fit.placement = RecordTrackedPoints(experiments[e], fit.run.trajectory, &placed);
    }
    fit.parameters = problem.ParametersAt(e, p_final);
    fit.simulated = final_eval.simulated[e];
    summary->experiments.push_back(std::move(fit));
    all.push_back(&experiments[e]);
    start_angles.push_back(&start_eval.simulated[e]);
    final_angles.push_back(&final_eval.simulated[e]);
  }
  summary->start_errors = AngleErrors(all, start_angles);
  summary->errors = AngleErrors(all, final_angles);
  if (final_eval.ok) summary->adequacy = AssessModelAdequacy(all, final_angles);
}

}  // namespace

IdentificationSummary Identify(const std::vector<Experiment>& experiments,
                               const IdentificationOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  CheckFitInputs(experiments, options);
  const std::vector<sim::ArmParameters> base = BaseParameters(experiments, options);
  const std::vector<FreeParameter> free = FreeParametersOf(experiments, options, base.front());
  std::string error;
  for (const sim::ArmParameters& p : base) {
    if (!p.IsValid(&error)) ThrowInputError("identification", "parameters", error);
  }

  std::unique_ptr<SimulationBackend> own_backend;
  SimulationBackend* backend = options.backend.get();
  if (backend == nullptr) {
    own_backend = MakeThreadBackend(&experiments, options.threads);
    backend = own_backend.get();
  }
  FitProblem problem(experiments, options, base, free, backend);

  IdentificationSummary summary;
  summary.threads = backend->parallelism();
  summary.relative_step = options.relative_step;
  summary.central_differences_throughout = options.central_differences_throughout;
  summary.residuals = problem.num_residuals();
  for (const FreeParameter& f : free) summary.free_names.push_back(f.name);

  std::vector<double> u(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) u[i] = free[i].start / free[i].scale;
  const Evaluation start_eval = EvaluateStart(problem, experiments, options.resume.get(), &u);

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  SimulatedAnglesCost cost(&problem);
  ceres_problem.AddResidualBlock(&cost, nullptr, u.data());
  for (std::size_t i = 0; i < free.size(); ++i) {
    ceres_problem.SetParameterLowerBound(u.data(), static_cast<int>(i),
                                         free[i].lower / free[i].scale);
    ceres_problem.SetParameterUpperBound(u.data(), static_cast<int>(i),
                                         free[i].upper / free[i].scale);
  }
  std::int64_t simulations_before = 0;  // a resumed fit's, before it was stopped
  if (!start_eval.ok) {
    summary.termination = IdentificationTermination::kFailed;
    summary.message = "the run at the start values did not complete: " + start_eval.failure;
  } else {
    simulations_before =
        Minimise(problem, ceres_problem, cost, options, clock_start, start_eval, &u, &summary);
  }

  // The final point: runs with their trajectories, residual statistics.
  const std::vector<double> p_final = problem.ValuesAt(u.data());
  const Evaluation final_eval = problem.Evaluate(u.data(), /*keep_trajectories=*/true);
  std::vector<sim::Trajectory> trajectories = problem.TakeTrajectories();
  if (!start_eval.ok) {
    summary.initial_cost = summary.final_cost = kNaN;
  } else if (final_eval.ok) {
    summary.final_cost = 0.5 * final_eval.residuals.squaredNorm();
    summary.initial_cost = 0.5 * start_eval.residuals.squaredNorm();
  }
  const Uncertainty uncertainty =
      UncertaintyAt(problem, ceres_problem, free, p_final, final_eval, options, &u, &summary);
  TabulateParameters(free, p_final, uncertainty, base.front(), &summary);
  TabulateErrors(experiments, problem, start_eval, final_eval, p_final, std::move(trajectories),
                 &summary);
  summary.simulations = simulations_before + problem.simulations();
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  if (!final_eval.ok && summary.termination != IdentificationTermination::kFailed) {
    summary.termination = IdentificationTermination::kFailed;
    summary.message = "the run at the final point did not complete: " + final_eval.failure;
  }
  return summary;
}

}  // namespace ccsrm::identify
