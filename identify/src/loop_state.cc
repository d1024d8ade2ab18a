// CloseLoop's state, its first stages and the helpers every stage shares
// (loop_state.h).
#include "loop_state.h"

#include <Eigen/QR>
#include <algorithm>
#include <cstdio>
#include <limits>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "text.h"

namespace ccsrm::identify::internal {

namespace {

// An effect's size parameters: those whose default while on is the neutral
// value and differs from the realistic magnitude (friction, tilt, delay, a
// dead band, a creep fraction, drag, offsets). Shape parameters (a smoothing
// rate, a creep's time constant) default to their realistic value; they
// stay there: at zero size they have no effect to fit.
std::vector<std::string> SizeParameters(const std::string& effect, const sim::ArmSize& arm) {
  std::vector<std::string> out;
  for (const std::string& name : sim::EffectParameterNames(effect, arm, "--candidates")) {
    const sim::ParameterInfo& info = sim::FindParameter(name, "--candidates", arm);
    const bool shape = info.absent_value != 0.0 && info.absent_value == info.realistic;
    if (!shape) out.push_back(name);
  }
  return out;
}

}  // namespace

// The secant step of a size parameter in the score test: its realistic
// magnitude, which is inside its bounds and large enough to rise above the
// solver's own noise.
double ScoreStep(const std::string& name, const sim::ArmSize& arm) {
  const sim::ParameterInfo& info = sim::FindParameter(name, "--candidates", arm);
  const double step = std::abs(info.realistic);
  return step > 0.0 ? step : 0.01 * (info.upper - info.lower);
}

// Weighted residual layout of FitProblem: experiment, frame, column, measured
// entries only; (simulated - measured) / noise (Experiment::WeightedResidual:
// an angle's in deg, a tracked point's in mm).
Eigen::VectorXd Weighted(const std::vector<Experiment>& experiments,
                         const std::vector<const Eigen::MatrixXd*>& angles, bool difference_only,
                         const std::vector<const Eigen::MatrixXd*>& base) {
  std::vector<double> out;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Experiment& x = experiments[e];
    for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
      for (Eigen::Index c = 0; c < x.measured.cols(); ++c) {
        if (!std::isfinite(x.measured(f, c))) continue;
        double v = x.WeightedResidual(f, c, (*angles[e])(f, c));
        if (difference_only) v -= x.WeightedResidual(f, c, (*base[e])(f, c));
        if (!std::isfinite(v)) v = 0.0;
        out.push_back(v);
      }
    }
  }
  return Eigen::Map<Eigen::VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
}

double LoopRms(const std::vector<const Experiment*>& experiments,
               const std::vector<const Eigen::MatrixXd*>& simulated) {
  if (experiments.empty()) return 0.0;
  if (experiments.front()->tracked_points.empty()) {
    return AngleErrors(experiments, simulated).rms_deg_overall;
  }
  double sq = 0.0, frames = 0.0;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const TrackedPointErrors p = PointErrors(*experiments[e], *simulated[e]);
    for (std::size_t k = 0; k < p.rms_mm.size(); ++k) {
      if (p.frames[k] == 0) continue;
      sq += p.rms_mm[k] * p.rms_mm[k] * static_cast<double>(p.frames[k]);
      frames += static_cast<double>(p.frames[k]);
    }
  }
  return frames > 0.0 ? std::sqrt(sq / frames) : std::numeric_limits<double>::quiet_NaN();
}

double LoopRms(const std::vector<Experiment>& experiments, const IdentificationSummary& fit) {
  if (experiments.empty() || experiments.front().tracked_points.empty()) {
    return fit.errors.rms_deg_overall;
  }
  std::vector<const Experiment*> xs;
  std::vector<const Eigen::MatrixXd*> simulated;
  for (std::size_t e = 0; e < experiments.size() && e < fit.experiments.size(); ++e) {
    xs.push_back(&experiments[e]);
    simulated.push_back(&fit.experiments[e].simulated);
  }
  return LoopRms(xs, simulated);
}

// How much of r a least-squares fit of columns A removes: ||r||² - min ||r + A x||².
double Reduction(const Eigen::VectorXd& r, const Eigen::MatrixXd& a, Eigen::VectorXd* x) {
  if (a.cols() == 0) {
    if (x != nullptr) x->resize(0);
    return 0.0;
  }
  // Columns scaled to unit norm: the fitted Jacobian's and the candidates'
  // differ by orders of magnitude.
  Eigen::VectorXd norms = a.colwise().norm().transpose();
  for (Eigen::Index k = 0; k < norms.size(); ++k) {
    if (!(norms[k] > 0.0)) norms[k] = 1.0;
  }
  const Eigen::MatrixXd scaled = a * norms.cwiseInverse().asDiagonal();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
  const Eigen::VectorXd y = qr.solve(-r);
  if (x != nullptr) *x = y.cwiseQuotient(norms);
  return r.squaredNorm() - (r + scaled * y).squaredNorm();
}

// The parameters of an experiment at values (over its nominal configuration).
sim::ArmParameters ParametersFor(const Experiment& e, const std::map<std::string, double>& values) {
  sim::ArmParameters p = e.config.parameters;
  for (const auto& [name, value] : values) sim::SetParameter(name, value, "loop", &p);
  return p;
}

// Every value a fit leaves: the options' values, then the free estimates.
std::map<std::string, double> ValuesOf(const IdentificationSummary& fit,
                                       const std::map<std::string, double>& fixed) {
  std::map<std::string, double> values = fixed;
  for (const ParameterEstimate& p : fit.parameters) {
    if (p.free) values[p.name] = p.value;
  }
  return values;
}

void LoopState::Progress(int round, const std::string& stage, const std::string& candidate,
                         const std::string& message) const {
  if (options.on_progress) options.on_progress({round, stage, candidate, message});
}

LoopState::ProgressFunction LoopState::ProgressFunctionOf() const {
  return [this](int round, const std::string& stage, const std::string& candidate,
                const std::string& message) { Progress(round, stage, candidate, message); };
}

bool LoopState::IsAdded(const std::string& name) const {
  return std::find(effects_on.begin(), effects_on.end(), name) != effects_on.end();
}

HoldoutResult LoopState::RunHoldout(const std::map<std::string, double>& values) {
  HoldoutResult h;
  if (holdout.empty()) return h;
  std::vector<RunRequest> requests;
  for (std::size_t e = 0; e < holdout.size(); ++e) {
    requests.push_back({e, ParametersFor(holdout[e], values), false, {}});
  }
  std::vector<RunResult> results = holdout_backend->RunBatch(requests, nullptr);
  simulations += static_cast<std::int64_t>(requests.size());
  std::vector<const Experiment*> xs;
  for (std::size_t e = 0; e < holdout.size(); ++e) {
    h.ok = h.ok && results[e].summary.completed();
    h.simulated.push_back(std::move(results[e].simulated));
  }
  std::vector<const Eigen::MatrixXd*> angles;
  for (std::size_t e = 0; e < holdout.size(); ++e) {
    xs.push_back(&holdout[e]);
    angles.push_back(&h.simulated[e]);
  }
  h.errors = AngleErrors(xs, angles);
  h.rms_deg = LoopRms(xs, angles);
  const Eigen::VectorXd r = Weighted(holdout, angles, false);
  h.mean_square = r.size() > 0 ? r.squaredNorm() / static_cast<double>(r.size()) : 0.0;
  const ResidualDiagnostics d = DiagnoseResidual(holdout, h.simulated);
  h.effective_samples = d.effective_samples;
  return h;
}

double LoopState::TrainingCost(const std::map<std::string, double>& values) {
  std::vector<RunRequest> runs;
  for (std::size_t e = 0; e < training.size(); ++e) {
    runs.push_back({e, ParametersFor(training[e], values), false, {}});
  }
  std::vector<RunResult> results = training_backend->RunBatch(runs, nullptr);
  simulations += static_cast<std::int64_t>(runs.size());
  std::vector<const Eigen::MatrixXd*> angles;
  for (const RunResult& run : results) {
    if (!run.summary.completed()) return std::numeric_limits<double>::quiet_NaN();
    angles.push_back(&run.simulated);
  }
  return 0.5 * Weighted(training, angles, false).squaredNorm();
}

void StartLoop(LoopState* s) {
  const std::vector<Experiment>& training = s->training;
  const std::vector<Experiment>& holdout = s->holdout;
  const LoopOptions& options = s->options;
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("loop", "options", error);
  if (training.empty()) ThrowInputError("loop", "--data", "no training experiment");
  for (const Experiment& h : holdout) {
    if (h.joints != training.front().joints) {
      ThrowInputError(h.path, "joints", "the held-out arm differs from the training experiments'");
    }
  }
  // One kind of measurement: the residual's figures are in one unit.
  const bool points = !training.front().tracked_points.empty();
  for (const std::vector<Experiment>* set : {&training, &holdout}) {
    for (const Experiment& x : *set) {
      if (x.tracked_points.empty() == !points) continue;
      ThrowInputError(x.path, "/mocap",
                      std::string(points ? "holds joint angles" : "holds tracked points") +
                          " where " + training.front().path + " holds " +
                          (points ? "tracked points" : "joint angles") +
                          ": the loop judges one kind of measurement at a time");
    }
  }
  s->summary.unit = points ? "mm" : "deg";
  // The arm of the experiments: how many per-joint parameters a candidate has.
  s->arm = training.front().config.parameters.arm;
  const sim::ArmSize& arm = s->arm;
  // The candidates: those given, else every effect the declared model has
  // off and the declared values.
  std::vector<std::string>& candidates = s->candidates;
  candidates = options.candidates;
  if (candidates.empty()) {
    for (const sim::EffectInfo& e : sim::Effects()) {
      // A measurement effect acts on recorded joint angles: none of tracked points.
      if (e.library && !(points && e.measurement) &&
          !training.front().config.parameters.EffectOn(e.name)) {
        candidates.push_back(e.name);
      }
    }
    candidates.push_back(internal::kDeclaredCandidates);
    if (!training.front().config.parameters.EffectOn(kTermsEffect)) {
      candidates.push_back(kTermsCandidate);
    }
  }
  using Spec = internal::LoopCandidateSpec;
  std::vector<Spec>& specs = s->specs;
  for (const std::string& c : candidates) {
    if (c == kTermsCandidate) continue;  // the discovery step, not a scored candidate
    if (c == internal::kDeclaredCandidates) {
      // A declared value the fit already frees is no candidate, nor in its block.
      const auto is_free = [&](const std::string& name) {
        return std::find(options.fit.free_parameters.begin(), options.fit.free_parameters.end(),
                         name) != options.fit.free_parameters.end();
      };
      for (Spec& d : internal::DeclaredValueCandidates(training.front().config.arm)) {
        d.parameters.erase(std::remove_if(d.parameters.begin(), d.parameters.end(), is_free),
                           d.parameters.end());
        if (!d.parameters.empty()) specs.push_back(std::move(d));
      }
      continue;
    }
    Spec e;
    e.name = c;
    e.parameters = SizeParameters(c, arm);
    e.measurement = sim::FindEffect(c, "--candidates").measurement;
    if (points && e.measurement) {
      ThrowInputError("--candidates", c,
                      "a measurement effect acts on recorded joint angles; " +
                          training.front().path + " holds tracked points");
    }
    e.fingerprint = sim::FindEffect(c, "loop").fingerprint;
    specs.push_back(std::move(e));
  }

  s->discovery_on =
      std::find(candidates.begin(), candidates.end(), kTermsCandidate) != candidates.end();
  LoopSummary& summary = s->summary;
  summary.options = options;
  std::shared_ptr<SimulationBackend>& training_backend = s->training_backend;
  training_backend = options.fit.backend;
  if (!training_backend) training_backend = MakeThreadBackend(&training, options.fit.threads);
  std::shared_ptr<SimulationBackend>& holdout_backend = s->holdout_backend;
  holdout_backend = options.holdout_backend;
  if (!holdout_backend) holdout_backend = MakeThreadBackend(&holdout, options.fit.threads);
  summary.threads = training_backend->parallelism();
}

void FitDeclaredModel(LoopState* s) {
  const std::vector<Experiment>& holdout = s->holdout;
  LoopSummary& summary = s->summary;
  s->Progress(0, "declared fit", "", "fitting the declared model");
  IdentificationOptions fit_options = s->options.fit;
  summary.declared = Identify(s->training, fit_options);
  s->simulations += summary.declared.simulations;
  s->current = summary.declared;
  s->free = fit_options.free_parameters;
  s->fixed = fit_options.values;
  for (const std::string& name : s->free) s->fixed.erase(name);
  s->current_holdout = s->RunHoldout(ValuesOf(s->current, s->fixed));
  summary.holdout_declared_rad = s->current_holdout.simulated;
  summary.before = summary.declared.errors;
  summary.rms_before_deg = LoopRms(s->training, summary.declared);
  if (!holdout.empty()) {
    summary.holdout_rms_before_deg = s->current_holdout.rms_deg;
    summary.holdout_before = s->current_holdout.errors;
  }
  const std::string unit = " " + summary.unit;
  s->Progress(
      0, "declared fit", "",
      "declared model: RMS " + Format("%.4f", summary.rms_before_deg) + unit + " (" +
          TerminationName(summary.declared.termination) + ")" +
          (holdout.empty() ? std::string()
                           : ", held out " + Format("%.4f", s->current_holdout.rms_deg) + unit));
  s->declared_ok = summary.declared.termination != IdentificationTermination::kFailed &&
                   summary.declared.jacobian.size() > 0;
}

}  // namespace ccsrm::identify::internal
