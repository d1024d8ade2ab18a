#include "ccsrm/identify/design.h"

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
  e.measured_rad = Eigen::MatrixXd::Zero(frames, 2 * e.joints);
  e.measured_samples = static_cast<std::size_t>(e.measured_rad.size());
  e.noise_deg.assign(static_cast<std::size_t>(e.joints), options.noise_deg);
  e.noise_source = "given (design)";
  return e;
}

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
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
  if (threads < 1) return fail("threads must be >= 1");
  return true;
}

DesignSummary EvaluateDesigns(const std::vector<DesignCandidate>& candidates,
                              const DesignOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("design options", "", error);
  const auto clock_start = std::chrono::steady_clock::now();
  DesignSummary summary;
  summary.options = options;
  summary.threads = options.backend ? options.backend->parallelism() : options.threads;
  for (const DesignCandidate& candidate : candidates) {
    if (candidate.experiments.empty()) {
      ThrowInputError("design candidate '" + candidate.name + "'", "", "has no experiments");
    }
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
    const sim::Config& first = candidate.experiments.front().config;
    const sim::ArmSize arm = first.arm.size();
    IdentificationOptions fit;
    fit.free_parameters = options.free_parameters;
    for (const std::string& name : options.free_parameters) {
      sim::FindParameter(name, "--free", arm);  // throws for an unknown name
      const double prior = sim::GetParameter(first.parameters, name);
      if (prior == 0.0 || !std::isfinite(prior)) {
        ThrowInputError("--free", name,
                        "its prior value is 0, where a relative standard error means nothing: "
                        "give a prior (--set " +
                            name + "=..., --params)");
      }
      info.prior.push_back(prior);
      // The scaled space is relative to the prior: u = p / |prior|.
      fit.scales[name] = std::abs(prior);
    }
    fit.relative_step = options.relative_step;
    fit.threads = options.threads;
    fit.backend = options.backend;
    fit.on_run = options.on_run;

    // The prior's own angles as the measurement: one run per experiment.
    {
      std::unique_ptr<SimulationBackend> own;
      SimulationBackend* backend = options.backend.get();
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
        experiments[e].measured_rad = runs[e].angles_rad;
      }
    }
    if (info.message.empty()) {
      // No iteration: the Jacobian at the start, second order, is all that
      // is wanted.
      fit.max_iterations = 0;
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
      std::sort(direction.begin(), direction.end(), [](const auto& a, const auto& b) {
        return std::abs(a.second) > std::abs(b.second);
      });
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
    summary.simulations += info.simulations;
    summary.candidates.push_back(std::move(info));
  }
  summary.ranking.resize(summary.candidates.size());
  std::iota(summary.ranking.begin(), summary.ranking.end(), std::size_t{0});
  std::stable_sort(summary.ranking.begin(), summary.ranking.end(),
                   [&](std::size_t a, std::size_t b) {
                     const CandidateInformation& x = summary.candidates[a];
                     const CandidateInformation& y = summary.candidates[b];
                     if (x.completed != y.completed) return x.completed;
                     return x.worst_relative_std_error < y.worst_relative_std_error;
                   });
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return summary;
}

bool ProposalSpace::IsValid(std::string* error) const {
  const auto fail = [error](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  if (amplitudes_deg.empty()) return fail("amplitudes_deg: none given");
  if (move_times_s.empty()) return fail("move_times_s: none given");
  for (const double a : amplitudes_deg) {
    if (!(a > 0.0) || !std::isfinite(a)) return fail("amplitudes_deg: each must be > 0");
  }
  for (const double m : move_times_s) {
    if (!(m > 0.0) || !std::isfinite(m)) return fail("move_times_s: each must be > 0");
  }
  if (!(hold_s >= 0.0) || !std::isfinite(hold_s)) return fail("hold_s must be >= 0");
  const double shortest = *std::min_element(move_times_s.begin(), move_times_s.end());
  if (!(budget_s >= 2.0 * (shortest + hold_s)) || !std::isfinite(budget_s)) {
    return fail("budget_s must hold at least two moves and holds (" +
                Format("%.3g", 2.0 * (shortest + hold_s)) + " s)");
  }
  return true;
}

std::string ReversalProtocolYaml(double amplitude_deg, double move_s, bool opposed,
                                 const ProposalSpace& space, int segments, std::string* name) {
  const int moves = static_cast<int>(std::floor(space.budget_s / (move_s + space.hold_s) + 1e-9));
  *name = "reversals A=" + Format("%g", amplitude_deg) + " move=" + Format("%g", move_s) +
          (opposed ? " opposed" : "");
  std::string text = "schema: ccsrm-protocol/1\nname: " + *name +
                     "\ndescription: every segment swings between +" + Format("%g", amplitude_deg) +
                     " and -" + Format("%g", amplitude_deg) + " deg in theta_x, " +
                     std::to_string(moves) + " moves of " + Format("%g", move_s) + " s" +
                     (opposed ? ", neighbouring segments in opposite directions" : "") +
                     " (ccsrm design)\nsegments:\n";
  for (int s = 0; s < (opposed ? segments : 1); ++s) {
    text += opposed ? "  " + std::to_string(s + 1) + ":\n" : std::string("  all:\n");
    const double sign = (opposed && s % 2 == 1) ? -1.0 : 1.0;
    for (int k = 0; k < moves; ++k) {
      // +A, −A, +A, ... and the last move back to straight.
      const double target = k + 1 == moves ? 0.0 : sign * (k % 2 == 0 ? 1.0 : -1.0) * amplitude_deg;
      text += "    - move: {to: {theta_x_deg: " + Format("%.17g", target + 0.0) +
              "}, duration_s: " + Format("%.17g", move_s) + "}\n";
      text += "    - hold: {duration_s: " + Format("%.17g", space.hold_s) + "}\n";
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
  std::string error;
  if (!space.IsValid(&error)) ThrowInputError("design proposal space", "", error);
  std::vector<DesignCandidate> candidates = given;
  const int segments = static_cast<int>(prior.arm.segments.size());
  for (const bool opposed : {false, true}) {
    if (opposed && (!space.opposed_segments || segments < 2)) continue;
    for (const double amplitude : space.amplitudes_deg) {
      for (const double move_s : space.move_times_s) {
        if (space.budget_s < 2.0 * (move_s + space.hold_s)) continue;
        std::string name;
        const std::string text =
            ReversalProtocolYaml(amplitude, move_s, opposed, space, segments, &name);
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
    }
  }
  return EvaluateDesigns(candidates, options);
}

std::string DesignSummary::FullReport() const {
  std::string out;
  out += "design: " + std::to_string(candidates.size()) + " candidate plan" +
         (candidates.size() == 1 ? "" : "s") + ", noise " + Format("%.3g", options.noise_deg) +
         " deg per angle at " + Format("%.4g", options.frame_rate_hz) + " Hz, N_eff/N " +
         Format("%.3g", options.effective_sample_fraction) + "; " + std::to_string(simulations) +
         " simulations on " + std::to_string(threads) + " thread" + (threads == 1 ? "" : "s") +
         ", " + Format("%.1f", wall_time_s) + " s\n";
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
         {"simulations", c.simulations}});
  }
  return {{"schema", "ccsrm-design/1"},
          {"free_parameters", s.options.free_parameters},
          {"noise_deg", s.options.noise_deg},
          {"effective_sample_fraction", s.options.effective_sample_fraction},
          {"frame_rate_hz", s.options.frame_rate_hz},
          {"relative_step", s.options.relative_step},
          {"ranking", s.ranking},
          {"threads", s.threads},
          {"simulations", s.simulations},
          {"wall_time_s", s.wall_time_s},
          {"candidates", candidates}};
}

}  // namespace ccsrm::identify
