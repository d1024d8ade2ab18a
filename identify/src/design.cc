#include "ccsrm/identify/design.h"
#include "ccsrm/identify/runs.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <set>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim/parameters.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The planned experiment as identification takes it: recorded at the
// frame rate from 0 to its duration, every angle measured with the given
// noise. The measured angles are the prior's own (filled in by the caller
// from a run): the Jacobian does not depend on them, but a fit at the
// prior then starts at a zero residual, as a fit of noise-free recordings
// would.
Experiment AsExperiment(const PlannedExperiment& planned, const DesignOptions& options) {
  Experiment e;
  e.name = planned.name;
  e.path = planned.name;
  e.config = planned.config;
  e.model = planned.model;
  e.inputs = planned.inputs;
  e.joints = planned.model->num_joints();
  const int frames =
      static_cast<int>(std::floor(planned.duration_s * options.frame_rate_hz + 1e-9)) + 1;
  for (int f = 0; f < frames; ++f) {
    const double t = f / options.frame_rate_hz;
    e.frame_time_s.push_back(t);
    e.sample_time_s.push_back(t);
  }
  e.measured = Eigen::MatrixXd::Zero(frames, 2 * e.joints);
  e.measured_samples = static_cast<std::size_t>(e.measured.size());
  e.noise_deg.assign(static_cast<std::size_t>(e.joints), options.noise_deg);
  e.noise_source = "given (design)";
  // The recordings' low-pass, which a fit applies to its simulated angles:
  // its Jacobian is that of the filtered angles.
  if (options.low_pass_hz > 0.0) {
    e.low_pass = Experiment::LowPass{options.low_pass_hz, options.low_pass_order,
                                     options.low_pass_min_run_frames, options.frame_rate_hz};
  }
  SetRelativeNoise(&e);
  return e;
}

}  // namespace

bool DesignOptions::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  if (free_parameters.empty()) return fail("free_parameters: none given");
  std::set<std::string> seen;
  for (const std::string& name : free_parameters) {
    if (!seen.insert(name).second) return fail("free_parameters: '" + name + "' given twice");
  }
  if (!(noise_deg > 0.0) || !std::isfinite(noise_deg)) return fail("noise_deg must be > 0");
  if (!(effective_sample_fraction > 0.0) || effective_sample_fraction > 1.0) {
    return fail("effective_sample_fraction must be in (0, 1]");
  }
  if (!(frame_rate_hz > 0.0) || !std::isfinite(frame_rate_hz)) {
    return fail("frame_rate_hz must be > 0");
  }
  if (!(relative_step > 0.0) || relative_step > 0.1) {
    return fail("relative_step must be in (0, 0.1]");
  }
  if (!(low_pass_hz >= 0.0) || !(low_pass_hz < 0.5 * frame_rate_hz)) {
    return fail("low_pass_hz must be >= 0 and below half the frame rate");
  }
  if (low_pass_order < 1 || low_pass_order > 8) return fail("low_pass_order must be in 1..8");
  if (low_pass_min_run_frames < 2) return fail("low_pass_min_run_frames must be >= 2");
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    return fail(problem);
  }
  std::set<std::string> boxed;
  for (const PriorRange& range : prior_box) {
    if (!boxed.insert(range.name).second) {
      return fail("prior_box: '" + range.name + "' given twice");
    }
    if (!std::isfinite(range.lower) || !std::isfinite(range.upper) ||
        !(range.lower < range.upper)) {
      return fail("prior_box: '" + range.name + "' needs finite lower < upper");
    }
  }
  if (prior_box.size() > 6) return fail("prior_box: at most 6 ranges (64 corners)");
  if (robust_candidates < 1) return fail("robust_candidates must be >= 1");
  if (checked_candidates < 0) return fail("checked_candidates must be >= 0");
  return true;
}

std::vector<Experiment> DesignExperiments(const std::vector<DesignCandidate>& candidates,
                                          const DesignOptions& options) {
  std::vector<Experiment> experiments;
  for (const DesignCandidate& candidate : candidates) {
    for (const PlannedExperiment& planned : candidate.experiments) {
      experiments.push_back(AsExperiment(planned, options));
    }
  }
  return experiments;
}

namespace {

// The prior values of the free parameters in a candidate's first experiment.
// Throws InputError for an unknown name or a prior of 0.
std::vector<double> FreePriors(const DesignCandidate& candidate, const DesignOptions& options) {
  const sim::Config& first = candidate.experiments.front().config;
  std::vector<double> priors;
  for (const std::string& name : options.free_parameters) {
    sim::FindParameter(name, "--free", first.arm.size());  // throws for an unknown name
    const double prior = sim::GetParameter(first.parameters, name);
    if (prior == 0.0 || !std::isfinite(prior)) {
      ThrowInputError("--free", name,
                      "its prior value is 0, where a relative standard error means nothing: "
                      "give a prior (--set " +
                          name + "=..., --params)");
    }
    priors.push_back(prior);
  }
  return priors;
}

// DesignOptions::backend as one candidate's: its experiment k is the
// backend's first + k.
class CandidateBackend final : public SimulationBackend {
 public:
  CandidateBackend(std::shared_ptr<SimulationBackend> all, std::size_t first)
      : all_(std::move(all)), first_(first) {}
  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    std::vector<RunRequest> shifted = requests;
    for (RunRequest& r : shifted) r.experiment += first_;
    return all_->RunBatch(shifted, on_finished);
  }
  int parallelism() const override { return all_->parallelism(); }

 private:
  std::shared_ptr<SimulationBackend> all_;
  std::size_t first_;
};

// One candidate with the parameters of its experiments' configurations;
// `first_experiment`: the index of its first experiment in DesignExperiments.
// `check_derivatives`: the Jacobian again at a third of the step
// (DesignOptions::checked_candidates).
CandidateInformation EvaluateCandidate(const DesignCandidate& candidate,
                                       const DesignOptions& options, std::size_t first_experiment,
                                       bool check_derivatives = false) {
  CandidateInformation info;
  info.name = candidate.name;
  info.protocol_yaml = candidate.protocol_yaml;
  info.parameters = options.free_parameters;
  std::vector<Experiment> experiments;
  for (const PlannedExperiment& planned : candidate.experiments) {
    experiments.push_back(AsExperiment(planned, options));
    info.experiments.push_back(planned.name);
    info.duration_s += planned.duration_s;
  }
  IdentificationOptions fit;
  fit.free_parameters = options.free_parameters;
  info.prior = FreePriors(candidate, options);
  for (std::size_t i = 0; i < info.prior.size(); ++i) {
    // The scaled space is relative to the prior: u = p / |prior|.
    fit.scales[options.free_parameters[i]] = std::abs(info.prior[i]);
  }
  fit.relative_step = options.relative_step;
  fit.threads = options.threads;
  if (options.backend)
    fit.backend = std::make_shared<CandidateBackend>(options.backend, first_experiment);
  fit.on_run = options.on_run;

  // The prior's own angles as the measurement: one run per experiment.
  {
    std::unique_ptr<SimulationBackend> own;
    SimulationBackend* backend = fit.backend.get();
    if (backend == nullptr) {
      own = MakeThreadBackend(&experiments, options.threads);
      backend = own.get();
    }
    std::vector<RunRequest> requests(experiments.size());
    for (std::size_t e = 0; e < experiments.size(); ++e) {
      requests[e].experiment = e;
      requests[e].parameters = candidate.experiments[e].config.parameters;
    }
    const std::vector<RunResult> runs = backend->RunBatch(requests, options.on_run);
    info.simulations += static_cast<std::int64_t>(runs.size());
    for (std::size_t e = 0; e < experiments.size(); ++e) {
      if (!runs[e].summary.completed()) {
        info.message = experiments[e].name +
                       ": the run at the prior did not complete: " + runs[e].summary.message;
        break;
      }
      experiments[e].measured = runs[e].simulated;
    }
  }
  if (info.message.empty()) {
    // No iteration: the Jacobian at the start, second order, is all that
    // is wanted.
    fit.max_iterations = 0;
    // The Fisher information at the step the fits take; checked at a third
    // of it on request.
    fit.check_derivative_steps = check_derivatives;
    fit.converged_step_fraction = 0.0;
    fit.min_effective_chi2_decrease = 0.0;
    const IdentificationSummary at_prior = Identify(experiments, fit);
    info.simulations += at_prior.simulations;
    if (at_prior.jacobian.size() == 0) {
      info.message = "the Jacobian at the prior failed: " + at_prior.covariance_message;
    } else {
      const Eigen::MatrixXd& j = at_prior.jacobian;  // residuals / noise per relative change
      info.samples = static_cast<std::size_t>(j.rows());
      info.fisher_relative = options.effective_sample_fraction * j.transpose() * j;
      info.completed = true;
      if (check_derivatives) {
        for (const std::string& name : options.free_parameters) {
          const ParameterEstimate* estimate = at_prior.Find(name);
          info.derivative_step_disagreement.push_back(
              estimate != nullptr ? estimate->derivative_step_disagreement : kInf);
        }
      }
    }
  }
  const std::size_t p = options.free_parameters.size();
  info.std_error.assign(p, kInf);
  info.relative_std_error.assign(p, kInf);
  info.worst_relative_std_error = kInf;
  info.d_criterion = info.a_criterion = info.worst_direction_relative_std_error = kInf;
  if (info.completed) {
    // C = F⁻¹ through F's eigen-decomposition: an eigenvalue below 1e-12 of
    // the largest is a direction the plan does not inform (infinite error).
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(info.fisher_relative);
    const Eigen::VectorXd lambda = eigen.eigenvalues();  // ascending
    const Eigen::MatrixXd v = eigen.eigenvectors();
    const double floor = 1e-12 * std::max(lambda.maxCoeff(), 0.0);
    Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(p, p);
    bool informed = lambda.minCoeff() > floor;
    if (informed) {
      covariance = v * lambda.cwiseInverse().asDiagonal() * v.transpose();
      double log_det = 0.0;
      for (Eigen::Index k = 0; k < lambda.size(); ++k) log_det -= std::log(lambda[k]);
      info.d_criterion = std::sqrt(std::exp(log_det / static_cast<double>(p)));
      info.a_criterion = std::sqrt(covariance.trace() / static_cast<double>(p));
      info.worst_direction_relative_std_error = 1.0 / std::sqrt(lambda[0]);
    }
    // The worst direction: the least informed eigenvector, in any case.
    std::vector<std::pair<std::string, double>> direction;
    for (std::size_t i = 0; i < p; ++i) direction.emplace_back(info.parameters[i], v(i, 0));
    std::sort(direction.begin(), direction.end(),
              [](const auto& a, const auto& b) { return std::abs(a.second) > std::abs(b.second); });
    if (!direction.empty() && direction.front().second < 0.0) {
      for (auto& [name, c] : direction) c = -c;
    }
    info.worst_direction = direction;
    info.worst_relative_std_error = 0.0;
    for (std::size_t i = 0; i < p; ++i) {
      const double relative = informed ? std::sqrt(covariance(i, i)) : kInf;
      info.relative_std_error[i] = relative;
      info.std_error[i] = relative * std::abs(info.prior[i]);
      if (!(relative <= info.worst_relative_std_error)) {
        info.worst_relative_std_error = relative;
        info.worst_parameter = info.parameters[i];
      }
    }
  }
  info.robust_worst_relative_std_error = info.worst_relative_std_error;
  return info;
}

// The values of the box's parameters at corner `index` (bit k: range k's
// upper end).
std::vector<std::pair<std::string, double>> Corner(const std::vector<PriorRange>& box,
                                                   std::size_t index) {
  std::vector<std::pair<std::string, double>> values;
  for (std::size_t k = 0; k < box.size(); ++k) {
    values.emplace_back(box[k].name, (index >> k) & 1U ? box[k].upper : box[k].lower);
  }
  return values;
}

}  // namespace

void CheckDesign(const std::vector<DesignCandidate>& candidates, const DesignOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("design options", "", error);
  for (const DesignCandidate& candidate : candidates) {
    if (candidate.experiments.empty()) {
      ThrowInputError("design candidate '" + candidate.name + "'", "", "has no experiments");
    }
    FreePriors(candidate, options);
  }
  // The box's values are checked against the arm's parameter table before
  // any run.
  for (const PriorRange& range : options.prior_box) {
    for (const DesignCandidate& candidate : candidates) {
      sim::ArmParameters check = candidate.experiments.front().config.parameters;
      for (const double value : {range.lower, range.upper}) {
        sim::SetParameter(range.name, value, "--prior-box", &check);
      }
      const auto& free = options.free_parameters;
      if (std::find(free.begin(), free.end(), range.name) != free.end() &&
          (range.lower == 0.0 || range.upper == 0.0)) {
        ThrowInputError("--prior-box", range.name,
                        "a free parameter's range ends at 0, where a relative standard error "
                        "means nothing");
      }
    }
  }
}

namespace {

// The best plans' derivatives at the prior, in rank order, until one is
// smooth or options.checked_candidates were checked; those not smooth rank
// last (DesignOptions::checked_candidates). A checked plan is evaluated
// again with the check: the same runs and Fisher information, and the
// finer step's.
void CheckDerivatives(const std::vector<DesignCandidate>& candidates, const DesignOptions& options,
                      const std::vector<std::size_t>& first, DesignSummary* summary) {
  int checked = 0;
  for (const std::size_t k : summary->ranking) {
    if (checked == options.checked_candidates) break;
    CandidateInformation& info = summary->candidates[k];
    if (!info.completed) continue;
    const CandidateInformation again = EvaluateCandidate(candidates[k], options, first[k], true);
    ++checked;
    info.simulations += again.simulations;
    summary->simulations += again.simulations;
    info.derivative_step_disagreement = again.completed
                                            ? again.derivative_step_disagreement
                                            : std::vector<double>(info.parameters.size(), kInf);
    if (info.derivatives_smooth()) break;
  }
  std::stable_partition(summary->ranking.begin(), summary->ranking.end(), [&](std::size_t k) {
    const CandidateInformation& c = summary->candidates[k];
    return !c.derivatives_checked() || c.derivatives_smooth();
  });
}

}  // namespace

bool CandidateInformation::derivatives_smooth() const {
  if (!derivatives_checked()) return false;
  for (const double d : derivative_step_disagreement) {
    if (!(d <= kDerivativeStepLimit)) return false;
  }
  return true;
}

DesignSummary EvaluateDesigns(const std::vector<DesignCandidate>& candidates,
                              const DesignOptions& options) {
  CheckDesign(candidates, options);
  const auto clock_start = std::chrono::steady_clock::now();
  DesignSummary summary;
  summary.options = options;
  summary.threads = options.backend ? options.backend->parallelism() : options.threads;
  std::vector<std::size_t> first(candidates.size(), 0);  // index in DesignExperiments
  for (std::size_t k = 1; k < candidates.size(); ++k) {
    first[k] = first[k - 1] + candidates[k - 1].experiments.size();
  }
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    summary.candidates.push_back(EvaluateCandidate(candidates[k], options, first[k]));
    summary.simulations += summary.candidates.back().simulations;
  }
  const auto by_worst = [&](std::size_t a, std::size_t b) {
    const CandidateInformation& x = summary.candidates[a];
    const CandidateInformation& y = summary.candidates[b];
    if (x.completed != y.completed) return x.completed;
    return x.worst_relative_std_error < y.worst_relative_std_error;
  };
  summary.ranking.resize(summary.candidates.size());
  std::iota(summary.ranking.begin(), summary.ranking.end(), std::size_t{0});
  std::stable_sort(summary.ranking.begin(), summary.ranking.end(), by_worst);
  if (!options.prior_box.empty()) {
    // The best at the prior, again at every corner of the box.
    const std::size_t corners = std::size_t{1} << options.prior_box.size();
    std::vector<std::size_t> robust;
    for (const std::size_t k : summary.ranking) {
      if (robust.size() == static_cast<std::size_t>(options.robust_candidates)) break;
      if (summary.candidates[k].completed) robust.push_back(k);
    }
    for (const std::size_t k : robust) {
      CandidateInformation& info = summary.candidates[k];
      for (std::size_t c = 0; c < corners; ++c) {
        DesignCandidate at_corner = candidates[k];
        CornerInformation corner;
        corner.values = Corner(options.prior_box, c);
        for (PlannedExperiment& e : at_corner.experiments) {
          for (const auto& [name, value] : corner.values) {
            sim::SetParameter(name, value, "--prior-box", &e.config.parameters);
          }
        }
        const CandidateInformation there = EvaluateCandidate(at_corner, options, first[k]);
        info.simulations += there.simulations;
        summary.simulations += there.simulations;
        corner.completed = there.completed;
        corner.message = there.message;
        corner.relative_std_error = there.relative_std_error;
        corner.worst_relative_std_error = there.worst_relative_std_error;
        corner.worst_parameter = there.worst_parameter;
        info.robust_worst_relative_std_error =
            std::max(info.robust_worst_relative_std_error,
                     there.completed ? there.worst_relative_std_error : kInf);
        info.corners.push_back(std::move(corner));
      }
    }
    // Those evaluated at the corners first, by their worst case.
    std::stable_sort(
        summary.ranking.begin(), summary.ranking.end(), [&](std::size_t a, std::size_t b) {
          const CandidateInformation& x = summary.candidates[a];
          const CandidateInformation& y = summary.candidates[b];
          if (x.corners.empty() != y.corners.empty()) return !x.corners.empty();
          if (!x.corners.empty()) {
            return x.robust_worst_relative_std_error < y.robust_worst_relative_std_error;
          }
          return by_worst(a, b);
        });
  }
  CheckDerivatives(candidates, options, first, &summary);
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return summary;
}

bool ProposalSpace::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  const auto positive = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(),
                       [](double v) { return v > 0.0 && std::isfinite(v); });
  };
  if (amplitudes_deg.empty()) return fail("amplitudes_deg: none given");
  if (!positive(amplitudes_deg)) return fail("amplitudes_deg: each must be > 0");
  if (!positive(move_times_s)) return fail("move_times_s: each must be > 0");
  if (!positive(sine_frequencies_hz)) return fail("sine_frequencies_hz: each must be > 0");
  for (const auto& [start, end] : chirp_bands_hz) {
    if (!(start > 0.0) || !(start < end) || !std::isfinite(end)) {
      return fail("chirp_bands_hz: each must be 0 < start < end");
    }
  }
  for (const double plane : planes_deg) {
    if (!std::isfinite(plane)) return fail("planes_deg: each must be finite");
  }
  if (move_times_s.empty() && sine_frequencies_hz.empty() && chirp_bands_hz.empty()) {
    return fail("no motion to try: give move times, sine frequencies or chirp bands");
  }
  if (!(hold_s >= 0.0) || !std::isfinite(hold_s)) return fail("hold_s must be >= 0");
  if (!(budget_s > 0.0) || !std::isfinite(budget_s)) return fail("budget_s must be > 0");
  if (!move_times_s.empty()) {
    const double shortest = *std::min_element(move_times_s.begin(), move_times_s.end());
    if (budget_s < 2.0 * (shortest + hold_s)) {
      return fail("budget_s must hold at least two moves and holds (" +
                  Format("%.3g", 2.0 * (shortest + hold_s)) + " s)");
    }
  }
  return true;
}

std::string ProposalProtocolYaml(const ProposedMotion& m, const ProposalSpace& space, int segments,
                                 std::string* name) {
  using Kind = ProposedMotion::Kind;
  const std::string a = Format("%g", m.amplitude_deg);
  const std::string plane = m.in_plane ? " plane=" + Format("%g", m.plane_deg) : "";
  const std::string opposed = m.opposed ? " opposed" : "";
  // A bending state of `value` degrees in the motion's plane.
  const auto state = [&](double value) {
    const std::string v = Format("%.17g", value + 0.0);
    return m.in_plane ? "{plane_deg: " + Format("%.17g", m.plane_deg) + ", bend_deg: " + v + "}"
                      : "{theta_x_deg: " + v + "}";
  };
  const std::string where =
      m.in_plane ? "in the plane at " + Format("%g", m.plane_deg) + " deg" : "in theta_x";
  const std::string together =
      m.opposed ? ", neighbouring segments in opposite directions" : std::string();
  std::string description;
  std::vector<std::string> pieces;  // of a segment swinging with sign +1; {S} is the sign
  int moves = 0;
  switch (m.kind) {
    case Kind::kReversals:
      moves = static_cast<int>(std::floor(space.budget_s / (m.move_s + space.hold_s) + 1e-9));
      *name = "reversals A=" + a + " move=" + Format("%g", m.move_s) + plane + opposed;
      description = "every segment swings between +" + a + " and -" + a + " deg " + where + ", " +
                    std::to_string(moves) + " moves of " + Format("%g", m.move_s) + " s";
      break;
    case Kind::kSine:
      *name = "sine A=" + a + " f=" + Format("%g", m.frequency_hz) + plane + opposed;
      description = "every segment swings " + a + " deg " + where + " at " +
                    Format("%g", m.frequency_hz) + " Hz for " + Format("%g", space.budget_s) + " s";
      break;
    case Kind::kChirp:
      *name = "chirp A=" + a + " f=" + Format("%g", m.frequency_hz) + "-" + Format("%g", m.end_hz) +
              plane + opposed;
      description = "every segment swings " + a + " deg " + where + ", the frequency swept from " +
                    Format("%g", m.frequency_hz) + " to " + Format("%g", m.end_hz) + " Hz over " +
                    Format("%g", space.budget_s) + " s";
      break;
  }
  std::string text = "schema: ccsrm-protocol/1\nname: " + *name + "\ndescription: " + description +
                     together + " (ccsrm design)\nsegments:\n";
  for (int s = 0; s < (m.opposed ? segments : 1); ++s) {
    text += m.opposed ? "  " + std::to_string(s + 1) + ":\n" : std::string("  all:\n");
    const double sign = (m.opposed && s % 2 == 1) ? -1.0 : 1.0;
    switch (m.kind) {
      case Kind::kReversals:
        for (int k = 0; k < moves; ++k) {
          // +A, −A, +A, ... and the last move back to straight.
          const double target =
              k + 1 == moves ? 0.0 : sign * (k % 2 == 0 ? 1.0 : -1.0) * m.amplitude_deg;
          text += "    - move: {to: " + state(target) +
                  ", duration_s: " + Format("%.17g", m.move_s) + "}\n";
          text += "    - hold: {duration_s: " + Format("%.17g", space.hold_s) + "}\n";
        }
        break;
      case Kind::kSine:
        text += "    - sine: {amplitude: " + state(sign * m.amplitude_deg) +
                ", frequency_hz: " + Format("%.17g", m.frequency_hz) +
                ", duration_s: " + Format("%.17g", space.budget_s) + "}\n";
        break;
      case Kind::kChirp:
        text += "    - chirp: {amplitude: " + state(sign * m.amplitude_deg) +
                ", start_hz: " + Format("%.17g", m.frequency_hz) +
                ", end_hz: " + Format("%.17g", m.end_hz) +
                ", duration_s: " + Format("%.17g", space.budget_s) + "}\n";
        break;
    }
  }
  return text;
}

PlannedExperiment PlanExperiment(const sim::Config& prior, const sim::Protocol& protocol,
                                 const std::string& name) {
  PlannedExperiment e;
  e.name = name;
  e.config = prior;
  auto model = std::make_shared<sim::ArmModel>(prior.arm);
  e.duration_s = protocol.duration_s();
  e.inputs = std::make_shared<const sim::CableInputs>(
      sim::PlanProtocolInputs(*model, protocol, prior.parameters, e.duration_s));
  e.model = std::move(model);
  return e;
}

DesignSummary ProposeDesign(const sim::Config& prior, const ProposalSpace& space,
                            const std::vector<DesignCandidate>& given, const DesignOptions& options,
                            std::vector<std::string>* skipped) {
  return EvaluateDesigns(ProposalCandidates(prior, space, given, skipped), options);
}

std::vector<DesignCandidate> ProposalCandidates(const sim::Config& prior,
                                                const ProposalSpace& space,
                                                const std::vector<DesignCandidate>& given,
                                                std::vector<std::string>* skipped) {
  std::string error;
  if (!space.IsValid(&error)) ThrowInputError("design proposal space", "", error);
  std::vector<DesignCandidate> candidates = given;
  const int segments = static_cast<int>(prior.arm.segments.size());
  std::vector<ProposedMotion> motions;
  std::vector<std::pair<bool, double>> planes;  // (in a plane, its angle)
  if (space.planes_deg.empty()) planes.emplace_back(false, 0.0);
  for (const double plane : space.planes_deg) planes.emplace_back(true, plane);
  for (const bool opposed : {false, true}) {
    if (opposed && (!space.opposed_segments || segments < 2)) continue;
    for (const auto& [in_plane, plane] : planes) {
      for (const double amplitude : space.amplitudes_deg) {
        ProposedMotion m;
        m.amplitude_deg = amplitude;
        m.in_plane = in_plane;
        m.plane_deg = plane;
        m.opposed = opposed;
        for (const double move_s : space.move_times_s) {
          if (space.budget_s < 2.0 * (move_s + space.hold_s)) continue;
          m.kind = ProposedMotion::Kind::kReversals;
          m.move_s = move_s;
          motions.push_back(m);
        }
        for (const double f : space.sine_frequencies_hz) {
          m.kind = ProposedMotion::Kind::kSine;
          m.frequency_hz = f;
          motions.push_back(m);
        }
        for (const auto& [start, end] : space.chirp_bands_hz) {
          m.kind = ProposedMotion::Kind::kChirp;
          m.frequency_hz = start;
          m.end_hz = end;
          motions.push_back(m);
        }
      }
    }
  }
  for (const ProposedMotion& m : motions) {
    std::string name;
    const std::string text = ProposalProtocolYaml(m, space, segments, &name);
    try {
      const sim::Protocol protocol = sim::ParseProtocol(text, name, prior.arm);
      DesignCandidate candidate;
      candidate.name = name;
      candidate.protocol_yaml = text;
      candidate.experiments.push_back(PlanExperiment(prior, protocol, name));
      candidates.push_back(std::move(candidate));
    } catch (const InputError& e) {
      // Past the joints' range or the cable limits: not a motion to run.
      if (skipped != nullptr) skipped->push_back(e.what());
    }
  }
  return candidates;
}

std::string PlannedMotionCsv(const sim::Config& prior, const std::string& protocol_yaml,
                             const std::string& name, double rate_hz) {
  const sim::Protocol protocol = sim::ParseProtocol(protocol_yaml, name, prior.arm);
  const PlannedExperiment planned = PlanExperiment(prior, protocol, name);
  const int cables = planned.inputs->num_cables();
  const int joints = planned.model->num_joints();
  std::string csv = "# " + name +
                    " (proposed.yaml) as ccsrm design planned it on the prior arm: cable input "
                    "lengths (pulled in = positive; ccsrm simulate --inputs reads them), their "
                    "speeds, and the planned joint angles\ntime_s";
  for (int c = 1; c <= cables; ++c) csv += ",cable" + std::to_string(c) + "_m";
  for (int c = 1; c <= cables; ++c) csv += ",speed_cable" + std::to_string(c) + "_m_s";
  for (int j = 1; j <= joints; ++j) {
    csv +=
        ",planned_thetax" + std::to_string(j) + "_deg,planned_thetay" + std::to_string(j) + "_deg";
  }
  csv += "\n";
  const int frames = static_cast<int>(std::floor(planned.duration_s * rate_hz + 1e-9)) + 1;
  char cell[40];
  for (int f = 0; f < frames; ++f) {
    const double t = f / rate_hz;
    std::snprintf(cell, sizeof(cell), "%.6f", t);
    csv += cell;
    std::vector<double> rates(static_cast<std::size_t>(cables));
    for (int c = 0; c < cables; ++c) {
      double value = 0.0, accel = 0.0;
      planned.inputs->Evaluate(c, t, &value, &rates[static_cast<std::size_t>(c)], &accel);
      std::snprintf(cell, sizeof(cell), ",%.9g", std::abs(value) < 1e-15 ? 0.0 : value);
      csv += cell;
    }
    for (const double rate : rates) {
      // The spline's rate at rest is a denormal, not a speed: below a nm/s
      // it is written as 0 (a reader may refuse denormals).
      std::snprintf(cell, sizeof(cell), ",%.6g", std::abs(rate) < 1e-9 ? 0.0 : rate);
      csv += cell;
    }
    for (const Eigen::Vector2d& angle : protocol.PlannedAngles(t)) {
      std::snprintf(cell, sizeof(cell), ",%.6f,%.6f", angle.x() * 180.0 / M_PI,
                    angle.y() * 180.0 / M_PI);
      csv += cell;
    }
    csv += "\n";
  }
  return csv;
}

namespace {

// A checked plan's line of the report: smooth, with its largest
// disagreement, or the parameters it is not smooth in.
std::string DerivativeCheckLine(const CandidateInformation& c, const DesignOptions& options) {
  std::string largest, rough;
  double worst = -1.0;
  for (std::size_t i = 0; i < c.parameters.size(); ++i) {
    const double d = c.derivative_step_disagreement[i];
    if (!(d <= kDerivativeStepLimit)) {
      rough += (rough.empty() ? "" : ", ") + c.parameters[i] + " " +
               (std::isfinite(d) ? Format("%.3g %%", 100.0 * d) : std::string("not computed"));
    } else if (d > worst) {
      worst = d;
      largest = c.parameters[i] + " " + Format("%.3g %%", 100.0 * d);
    }
  }
  return "  derivatives at the prior (relative steps " + Format("%.3g", options.relative_step) +
         " and a third of it, as a fit checks its own), " + c.name + ": " +
         (c.derivatives_smooth()
              ? "smooth (largest disagreement " + largest + ")\n"
              : "NOT smooth in " + rough + " (limit " +
                    Format("%.0f", 100.0 * kDerivativeStepLimit) +
                    " %): a fit of its recordings would not give these errors (the angles jump "
                    "with the parameters there, as in stick-slip: docs/model-notes.md, issue "
                    "43); ranked last\n");
}

}  // namespace

std::string DesignSummary::FullReport() const {
  std::string out;
  out +=
      "design: " + std::to_string(candidates.size()) + " candidate plan" +
      (candidates.size() == 1 ? "" : "s") + ", noise " + Format("%.3g", options.noise_deg) +
      " deg per angle at " + Format("%.4g", options.frame_rate_hz) + " Hz" +
      (options.low_pass_hz > 0.0 ? " low-passed at " + Format("%.3g", options.low_pass_hz) + " Hz"
                                 : std::string(", not low-passed")) +
      ", N_eff/N " + Format("%.3g", options.effective_sample_fraction) + "; " +
      std::to_string(simulations) + " simulations on " + std::to_string(threads) + " thread" +
      (threads == 1 ? "" : "s") + ", " + Format("%.1f", wall_time_s) + " s\n";
  out += "  predicted relative standard errors (%), best plan first:\n";
  char line[512];
  std::snprintf(line, sizeof(line), "  %-4s %-28s %8s", "rank", "plan", "time [s]");
  out += line;
  for (const std::string& name : options.free_parameters) {
    std::snprintf(line, sizeof(line), " %9s", name.c_str());
    out += line;
  }
  out += "    worst      D      A  worst direction\n";
  const auto percent = [](double x) {
    return std::isfinite(x) ? Format("%9.3g", 100.0 * x) : std::string("      inf");
  };
  for (std::size_t r = 0; r < ranking.size(); ++r) {
    const CandidateInformation& c = candidates[ranking[r]];
    std::string name = c.name.size() > 28 ? c.name.substr(0, 25) + "..." : c.name;
    std::snprintf(line, sizeof(line), "  %-4zu %-28s %8.1f", r + 1, name.c_str(), c.duration_s);
    out += line;
    if (!c.completed) {
      out += "  not evaluated: " + c.message + "\n";
      continue;
    }
    for (const double x : c.relative_std_error) out += " " + percent(x);
    out += " " + percent(c.worst_relative_std_error).substr(1) + " " +
           percent(c.d_criterion).substr(3) + " " + percent(c.a_criterion).substr(3) + "  ";
    for (std::size_t k = 0; k < c.worst_direction.size(); ++k) {
      const auto& [name_k, component] = c.worst_direction[k];
      if (k > 0 && std::abs(component) < 0.2) break;  // smaller shares left out of the name
      out += (k == 0 ? Format("%.2f ", component)
                     : (component < 0 ? " - " : " + ") + Format("%.2f ", std::abs(component))) +
             name_k;
    }
    out += "\n";
  }
  // A name the table cut is given whole below it: a plan is its name.
  bool cut = false;
  for (const std::size_t k : ranking) cut |= candidates[k].name.size() > 28;
  if (cut) {
    out += "  plans in full:\n";
    for (std::size_t r = 0; r < ranking.size(); ++r) {
      out += "  " + Format("%-4zu", r + 1) + " " + candidates[ranking[r]].name + "\n";
    }
  }
  for (const std::size_t k : ranking) {
    if (candidates[k].derivatives_checked()) out += DerivativeCheckLine(candidates[k], options);
  }
  if (!options.prior_box.empty()) {
    std::string box;
    for (const PriorRange& r : options.prior_box) {
      box += (box.empty() ? "" : ", ") + r.name + " " + Format("%.4g", r.lower) + ".." +
             Format("%.4g", r.upper);
    }
    out += "  over the prior box (" + box + "; " +
           std::to_string(std::size_t{1} << options.prior_box.size()) +
           " corners), the best plans at the prior: worst relative standard error (%)\n";
    for (const std::size_t k : ranking) {
      const CandidateInformation& c = candidates[k];
      if (c.corners.empty()) continue;
      const CornerInformation* worst = nullptr;
      for (const CornerInformation& corner : c.corners) {
        if (worst == nullptr || !(corner.completed && corner.worst_relative_std_error <=
                                                          worst->worst_relative_std_error)) {
          worst = &corner;
        }
      }
      std::string at;
      for (const auto& [name, value] : worst->values) {
        at += (at.empty() ? "" : ", ") + name + " = " + Format("%.4g", value);
      }
      std::snprintf(line, sizeof(line), "  %-32s at the prior %s, over the box %s (%s at %s)\n",
                    (c.name.size() > 32 ? c.name.substr(0, 29) + "..." : c.name).c_str(),
                    percent(c.worst_relative_std_error).c_str(),
                    percent(c.robust_worst_relative_std_error).c_str(),
                    worst->completed ? worst->worst_parameter.c_str() : "not evaluated",
                    at.c_str());
      out += line;
    }
  }
  return out;
}

nlohmann::json ToJson(const DesignSummary& s) {
  const auto number = [](double x) -> nlohmann::json {
    if (std::isfinite(x)) return x;
    return nullptr;  // JSON has no inf: null, documented as "not informed"
  };
  nlohmann::json candidates = nlohmann::json::array();
  for (const CandidateInformation& c : s.candidates) {
    nlohmann::json parameters = nlohmann::json::array();
    for (std::size_t i = 0; i < c.parameters.size(); ++i) {
      parameters.push_back(
          {{"name", c.parameters[i]},
           {"prior", c.prior[i]},
           {"std_error", c.completed ? number(c.std_error[i]) : nullptr},
           {"relative_std_error", c.completed ? number(c.relative_std_error[i]) : nullptr}});
    }
    nlohmann::json direction = nlohmann::json::array();
    for (const auto& [name, component] : c.worst_direction) {
      direction.push_back({{"name", name}, {"component", component}});
    }
    nlohmann::json corners = nlohmann::json::array();
    for (const CornerInformation& corner : c.corners) {
      nlohmann::json values = nlohmann::json::object();
      for (const auto& [name, value] : corner.values) values[name] = value;
      nlohmann::json relative = nlohmann::json::array();
      for (const double x : corner.relative_std_error) relative.push_back(number(x));
      corners.push_back({{"values", values},
                         {"completed", corner.completed},
                         {"message", corner.message},
                         {"relative_std_error", relative},
                         {"worst_relative_std_error", number(corner.worst_relative_std_error)},
                         {"worst_parameter", corner.worst_parameter}});
    }
    nlohmann::json disagreement = nullptr;  // not checked
    if (c.derivatives_checked()) {
      disagreement = nlohmann::json::array();
      for (const double d : c.derivative_step_disagreement) disagreement.push_back(number(d));
    }
    nlohmann::json fisher = nlohmann::json::array();
    for (Eigen::Index i = 0; i < c.fisher_relative.rows(); ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index k = 0; k < c.fisher_relative.cols(); ++k) {
        row.push_back(c.fisher_relative(i, k));
      }
      fisher.push_back(row);
    }
    candidates.push_back(
        {{"name", c.name},
         {"protocol_yaml", c.protocol_yaml},
         {"experiments", c.experiments},
         {"duration_s", c.duration_s},
         {"samples", c.samples},
         {"completed", c.completed},
         {"message", c.message},
         {"parameters", parameters},
         {"worst_relative_std_error", number(c.worst_relative_std_error)},
         {"worst_parameter", c.worst_parameter},
         {"d_criterion", number(c.d_criterion)},
         {"a_criterion", number(c.a_criterion)},
         {"worst_direction_relative_std_error", number(c.worst_direction_relative_std_error)},
         {"worst_direction", direction},
         {"fisher_relative", fisher},
         {"corners", corners},
         {"robust_worst_relative_std_error", number(c.robust_worst_relative_std_error)},
         {"derivative_step_disagreement", disagreement},
         {"derivatives_smooth",
          c.derivatives_checked() ? nlohmann::json(c.derivatives_smooth()) : nullptr},
         {"simulations", c.simulations}});
  }
  nlohmann::json box = nlohmann::json::array();
  for (const PriorRange& r : s.options.prior_box) {
    box.push_back({{"name", r.name}, {"lower", r.lower}, {"upper", r.upper}});
  }
  return {{"schema", "ccsrm-design/1"},
          {"free_parameters", s.options.free_parameters},
          {"noise_deg", s.options.noise_deg},
          {"effective_sample_fraction", s.options.effective_sample_fraction},
          {"frame_rate_hz", s.options.frame_rate_hz},
          {"low_pass",
           {{"cutoff_hz", s.options.low_pass_hz},
            {"order", s.options.low_pass_order},
            {"min_run_frames", s.options.low_pass_min_run_frames}}},
          {"relative_step", s.options.relative_step},
          {"prior_box", box},
          {"robust_candidates", s.options.robust_candidates},
          {"checked_candidates", s.options.checked_candidates},
          {"ranking", s.ranking},
          {"threads", s.threads},
          {"simulations", s.simulations},
          {"wall_time_s", s.wall_time_s},
          {"candidates", candidates}};
}

}  // namespace ccsrm::identify
