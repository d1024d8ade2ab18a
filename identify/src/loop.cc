#include "ccsrm/identify/loop.h"

#include <gsl/gsl_cdf.h>

#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/declared_values.h"
#include "ccsrm/sim/effects.h"
#include "declared_values.h"
#include "loop_backward.h"
#include "term_discovery.h"

namespace ccsrm::identify {
namespace {

constexpr double kDeg = 180.0 / M_PI;

// The candidate name that asks for the discovery of terms, and the effect
// that carries them (sim/effects.h).
constexpr const char* kTermsCandidate = "terms";
constexpr const char* kTermsEffect = "joint_moment";

std::string Format(const char* format, double value) {
  char text[96];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

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

// The secant step of a size parameter in the score test: its realistic
// magnitude, which is inside its bounds and large enough to rise above the
// solver's own noise.
double ScoreStep(const std::string& name, const sim::ArmSize& arm) {
  const sim::ParameterInfo& info = sim::FindParameter(name, "--candidates", arm);
  const double step = std::abs(info.realistic);
  return step > 0.0 ? step : 0.01 * (info.upper - info.lower);
}

// Weighted residual layout of FitProblem: experiment, frame, column, measured
// entries only; (angles - measured) / noise.
Eigen::VectorXd Weighted(const std::vector<Experiment>& experiments,
                         const std::vector<const Eigen::MatrixXd*>& angles, bool difference_only,
                         const std::vector<const Eigen::MatrixXd*>& base = {}) {
  std::vector<double> out;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Experiment& x = experiments[e];
    for (Eigen::Index f = 0; f < x.measured_rad.rows(); ++f) {
      for (Eigen::Index c = 0; c < x.measured_rad.cols(); ++c) {
        if (!std::isfinite(x.measured_rad(f, c))) continue;
        const double reference = difference_only ? (*base[e])(f, c) : x.measured_rad(f, c);
        double v =
            ((*angles[e])(f, c) - reference) * kDeg / x.noise_deg[static_cast<std::size_t>(c / 2)];
        if (!std::isfinite(v)) v = 0.0;
        out.push_back(v);
      }
    }
  }
  return Eigen::Map<Eigen::VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
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

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

struct HoldoutResult {
  std::vector<Eigen::MatrixXd> angles_rad;
  double rms_deg = 0.0;
  double mean_square = 0.0;  // weighted, per sample
  double effective_samples = 0.0;
  ChannelErrors errors;
  bool ok = true;
};

}  // namespace

std::vector<std::string> LoopDeclaredParameterNames() { return {"mu", "mu_c", "T_p"}; }

std::string DiscoveredMoment::Formula() const {
  std::string out =
      (first_joint == last_joint
           ? "joint " + std::to_string(first_joint)
           : "joints " + std::to_string(first_joint) + "-" + std::to_string(last_joint)) +
      " (segment " + std::to_string(segment) + ") " + (axis == 0 ? "θx" : "θy") + ": M =";
  bool first = true;
  for (const Term& t : terms) {
    const double v = t.estimate.value;
    out += first ? " " : (v < 0.0 ? " - " : " + ");
    std::string size = Format("%.3g", first ? v : std::abs(v));
    if (t.estimate.identifiable && std::isfinite(t.estimate.std_error)) {
      size = "(" + size + " ± " + Format("%.2g", t.estimate.std_error) + ")";
    }
    out += size + (t.formula == "1" ? "" : " " + t.formula);
    first = false;
  }
  bool commanded = false;
  for (const Term& t : terms) commanded = commanded || t.name == "input_rate";
  // θ̇_in is named where it appears: it is not the joint's own state.
  return out + " N m (θ in rad, θ̇ in rad/s, t in s" +
         (commanded ? "; θ̇_in: the segment's bending rate its inputs command, rad/s" : "") + ")";
}

bool LoopOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  std::string inner;
  if (!fit.IsValid(&inner)) return fail(inner);
  std::set<std::string> seen;
  for (const std::string& c : candidates) {
    if (c == internal::kDeclaredCandidates || c == kTermsCandidate) {
      if (!seen.insert(c).second) return fail("candidates: '" + c + "' is given twice");
      for (const std::string& name : fit.free_parameters) {
        if (c == kTermsCandidate && name.rfind(std::string(kTermsEffect) + ".", 0) == 0) {
          return fail(
              "candidates: 'terms' would add joint_moment, which already has a free "
              "parameter (" +
              name + ")");
        }
      }
      continue;
    }
    bool known = false;
    for (const sim::EffectInfo& e : sim::Effects()) known = known || (e.library && e.name == c);
    if (!known) {
      std::string names;
      for (const sim::EffectInfo& e : sim::Effects()) {
        if (e.library) names += (names.empty() ? "" : ", ") + e.name;
      }
      return fail("candidates: unknown effect '" + c + "' (known: " + names +
                  "; and declared, for the declared values; terms, for terms found in the data" +
                  (c == kTermsEffect ? ", which joint_moment carries" : "") + ")");
    }
    if (!seen.insert(c).second) return fail("candidates: '" + c + "' is given twice");
    for (const std::string& name : fit.free_parameters) {
      if (name.rfind(c + ".", 0) == 0) {
        return fail("candidates: '" + c + "' already has a free parameter (" + name + ")");
      }
    }
  }
  if (max_rounds < 0) return fail("max_rounds must be >= 0");
  if (refits_per_round < 1) return fail("refits_per_round must be >= 1");
  if (declared_refits_per_round < 0) return fail("declared_refits_per_round must be >= 0");
  if (!(min_excess_share >= 0.0 && min_excess_share <= 1.0)) {
    return fail("min_excess_share must be in [0, 1]");
  }
  if (!(term_share >= 0.0 && term_share < 1.0)) return fail("term_share must be in [0, 1)");
  if (!(score_significance > 0.0 && score_significance < 1.0)) {
    return fail("score_significance must be in (0, 1)");
  }
  if (!(min_delta_bic >= 0.0)) return fail("min_delta_bic must be >= 0");
  if (!(holdout_z >= 0.0)) return fail("holdout_z must be >= 0");
  if (!(tie_delta_bic >= 0.0)) return fail("tie_delta_bic must be >= 0");
  if (!(unexplained_noise_ratio > 0.0)) return fail("unexplained_noise_ratio must be > 0");
  return true;
}

LoopSummary CloseLoop(const std::vector<Experiment>& training,
                      const std::vector<Experiment>& holdout, const LoopOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("loop", "options", error);
  if (training.empty()) ThrowInputError("loop", "--data", "no training experiment");
  for (const Experiment& h : holdout) {
    if (h.joints != training.front().joints) {
      ThrowInputError(h.path, "joints", "the held-out arm differs from the training experiments'");
    }
  }
  const auto progress = [&](int round, const std::string& stage, const std::string& candidate,
                            const std::string& message) {
    if (options.on_progress) options.on_progress({round, stage, candidate, message});
  };

  // The arm of the experiments: how many per-joint parameters a candidate has.
  const sim::ArmSize arm = training.front().config.parameters.arm;
  // The candidates: those given, else every effect the declared model has
  // off and the declared values.
  std::vector<std::string> candidates = options.candidates;
  if (candidates.empty()) {
    for (const sim::EffectInfo& e : sim::Effects()) {
      if (e.library && !training.front().config.parameters.EffectOn(e.name)) {
        candidates.push_back(e.name);
      }
    }
    candidates.push_back(internal::kDeclaredCandidates);
    if (!training.front().config.parameters.EffectOn(kTermsEffect)) {
      candidates.push_back(kTermsCandidate);
    }
  }
  using Spec = internal::LoopCandidateSpec;
  std::vector<Spec> specs;
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
    e.fingerprint = sim::FindEffect(c, "loop").fingerprint;
    specs.push_back(std::move(e));
  }

  LoopSummary summary;
  summary.options = options;
  std::shared_ptr<SimulationBackend> training_backend = options.fit.backend;
  if (!training_backend) training_backend = MakeThreadBackend(&training, options.fit.threads);
  std::shared_ptr<SimulationBackend> holdout_backend = options.holdout_backend;
  if (!holdout_backend) holdout_backend = MakeThreadBackend(&holdout, options.fit.threads);
  summary.threads = training_backend->parallelism();
  std::int64_t simulations = 0;

  // The held-out experiments at a fit's values.
  const auto run_holdout = [&](const std::map<std::string, double>& values) {
    HoldoutResult h;
    if (holdout.empty()) return h;
    std::vector<RunRequest> requests;
    for (std::size_t e = 0; e < holdout.size(); ++e) {
      requests.push_back({e, ParametersFor(holdout[e], values), false, {}});
    }
    std::vector<RunResult> results = holdout_backend->RunBatch(requests, nullptr);
    simulations += static_cast<std::int64_t>(requests.size());
    std::vector<const Experiment*> xs;
    std::vector<const Eigen::MatrixXd*> as;
    for (std::size_t e = 0; e < holdout.size(); ++e) {
      h.ok = h.ok && results[e].summary.completed();
      h.angles_rad.push_back(std::move(results[e].angles_rad));
    }
    std::vector<const Eigen::MatrixXd*> angles;
    for (std::size_t e = 0; e < holdout.size(); ++e) {
      xs.push_back(&holdout[e]);
      angles.push_back(&h.angles_rad[e]);
    }
    h.errors = AngleErrors(xs, angles);
    h.rms_deg = h.errors.rms_deg_overall;
    const Eigen::VectorXd r = Weighted(holdout, angles, false);
    h.mean_square = r.size() > 0 ? r.squaredNorm() / static_cast<double>(r.size()) : 0.0;
    const ResidualDiagnostics d = DiagnoseResidual(holdout, h.angles_rad);
    h.effective_samples = d.effective_samples;
    return h;
  };

  // The training cost (1/2 Σ r², weighted) at values; NaN when a run fails.
  const auto training_cost = [&](const std::map<std::string, double>& values) {
    std::vector<RunRequest> runs;
    for (std::size_t e = 0; e < training.size(); ++e) {
      runs.push_back({e, ParametersFor(training[e], values), false, {}});
    }
    std::vector<RunResult> results = training_backend->RunBatch(runs, nullptr);
    simulations += static_cast<std::int64_t>(runs.size());
    std::vector<const Eigen::MatrixXd*> angles;
    for (const RunResult& run : results) {
      if (!run.summary.completed()) return std::numeric_limits<double>::quiet_NaN();
      angles.push_back(&run.angles_rad);
    }
    return 0.5 * Weighted(training, angles, false).squaredNorm();
  };

  // The declared model.
  progress(0, "declared fit", "", "fitting the declared model");
  IdentificationOptions fit_options = options.fit;
  summary.declared = Identify(training, fit_options);
  simulations += summary.declared.simulations;
  IdentificationSummary current = summary.declared;
  std::vector<std::string> free = fit_options.free_parameters;
  std::map<std::string, double> fixed = fit_options.values;
  for (const std::string& name : free) fixed.erase(name);
  HoldoutResult current_holdout = run_holdout(ValuesOf(current, fixed));
  summary.holdout_declared_rad = current_holdout.angles_rad;
  summary.before = summary.declared.errors;
  summary.rms_before_deg = summary.declared.errors.rms_deg_overall;
  if (!holdout.empty()) {
    summary.holdout_rms_before_deg = current_holdout.rms_deg;
    summary.holdout_before = current_holdout.errors;
  }
  progress(
      0, "declared fit", "",
      "declared model: RMS " + Format("%.4f", summary.rms_before_deg) + " deg (" +
          TerminationName(summary.declared.termination) + ")" +
          (holdout.empty() ? std::string()
                           : ", held out " + Format("%.4f", current_holdout.rms_deg) + " deg"));

  std::vector<std::string> effects_on;  // effects and declared values, in order
  const auto is_added = [&](const std::string& name) {
    return std::find(effects_on.begin(), effects_on.end(), name) != effects_on.end();
  };
  // Each addition's parameters (free in every later fit), and the additions
  // the backward step took back: not tried again, so that a round cannot
  // add what an earlier one took back and the loop cannot cycle.
  std::map<std::string, std::vector<std::string>> added_parameters;
  std::set<std::string> taken_back;
  const bool discovery_on =
      std::find(candidates.begin(), candidates.end(), kTermsCandidate) != candidates.end();

  // The discovered terms' candidate of a round (issue 28): one column per
  // term, segment and axis (a simulation per training experiment, a secant
  // from 0 to the term's realistic coefficient), sparse regression on them
  // (term_discovery.h), and the chosen combination as one candidate.
  const auto discover_terms = [&](int round, const std::vector<Eigen::MatrixXd>& fitted,
                                  const std::vector<const Eigen::MatrixXd*>& base_angles,
                                  const Eigen::VectorXd& r, const Eigen::MatrixXd& jb,
                                  double neff_ratio) {
    CandidateResult cand;
    cand.name = kTermsEffect;
    cand.kind = "discovered terms";
    const sim::ArmConfig& arm_config = training.front().config.arm;
    std::vector<internal::TermColumn> term_columns;
    std::vector<double> steps;
    std::vector<RunRequest> requests;
    std::vector<std::size_t> request_column;
    int first_joint = 1;
    for (int s = 1; s <= static_cast<int>(arm_config.segments.size()); ++s) {
      const int links = arm_config.segments[static_cast<std::size_t>(s - 1)].links;
      for (int axis = 0; axis < 2; ++axis) {
        // A term in the angle or rate of an axis the fitted motion leaves at
        // 0 moves nothing to first order: no column, no simulation. The
        // input rate goes with them: inputs that command a bending of an
        // axis move it.
        double largest = 0.0;
        for (const Eigen::MatrixXd& a : fitted) {
          for (int j = first_joint; j < first_joint + links; ++j) {
            const Eigen::Index c = 2 * (j - 1) + axis;
            if (c >= a.cols()) continue;
            for (Eigen::Index f = 0; f < a.rows(); ++f) {
              if (std::isfinite(a(f, c))) largest = std::max(largest, std::abs(a(f, c)));
            }
          }
        }
        for (const sim::JointMomentTerm& term : sim::JointMomentTerms()) {
          const bool of_state = term.name != "const" && term.name != "time";
          if (of_state && !(largest > 1e-6)) continue;
          const std::string q = sim::JointMomentParameter(s, axis, term.name);
          const double step = sim::FindParameter(q, "loop", arm).realistic;
          for (std::size_t e = 0; e < training.size(); ++e) {
            sim::ArmParameters p = current.experiments[e].parameters;
            sim::SetParameter(q, step, "loop", &p);
            requests.push_back({e, p, false, {}});
            request_column.push_back(term_columns.size());
          }
          term_columns.push_back({q, term.complexity, {}});
          steps.push_back(step);
        }
      }
      first_joint += links;
    }
    progress(round, "discovery", cand.name,
             "  discovery: " + std::to_string(term_columns.size()) + " terms, " +
                 std::to_string(requests.size()) + " sensitivity runs");
    std::vector<std::vector<Eigen::MatrixXd>> angles(term_columns.size(),
                                                     std::vector<Eigen::MatrixXd>(training.size()));
    std::vector<RunResult> results = training_backend->RunBatch(
        requests, [&](std::size_t finished, std::size_t total, const RunResult&) {
          if (finished == total || finished % 8 == 0) {
            progress(round, "discovery", cand.name,
                     "  term sensitivity runs " + std::to_string(finished) + "/" +
                         std::to_string(total));
          }
        });
    simulations += static_cast<std::int64_t>(requests.size());
    cand.simulations = static_cast<std::int64_t>(requests.size());
    bool complete = true;
    for (std::size_t k = 0; k < results.size(); ++k) {
      complete = complete && results[k].summary.completed();
      angles[request_column[k]][requests[k].experiment] = std::move(results[k].angles_rad);
    }
    if (!complete) {
      cand.reason = "a term's sensitivity run failed: no terms sought";
      return cand;
    }
    for (std::size_t c = 0; c < term_columns.size(); ++c) {
      std::vector<const Eigen::MatrixXd*> ca;
      for (const Eigen::MatrixXd& m : angles[c]) ca.push_back(&m);
      term_columns[c].weighted = Weighted(training, ca, true, base_angles) / steps[c];
    }
    const internal::TermSelection selection =
        internal::SelectTerms(r, jb, term_columns, neff_ratio, current.effective_samples,
                              options.tie_delta_bic, options.term_share);
    for (const internal::TermSupport& support : selection.path) {
      cand.term_path.push_back({support.parameters, support.delta_chi2_eff, support.delta_bic});
    }
    if (selection.chosen < 0) {
      cand.reason = "no term moves the angles beyond what the fit's own parameters do";
      return cand;
    }
    const internal::TermSupport& chosen =
        selection.path[static_cast<std::size_t>(selection.chosen)];
    cand.parameters = chosen.parameters;
    cand.linearised = chosen.linearised;
    cand.score = chosen.delta_chi2_eff;
    cand.p_value = gsl_cdf_chisq_Q(cand.score, static_cast<double>(chosen.parameters.size()));
    // Chosen as the best of many supports: its linear ΔBIC must pass the
    // acceptance's own threshold before a refit is worth its runs.
    cand.significant = chosen.delta_bic > options.min_delta_bic;
    progress(round, "discovery", cand.name,
             "  discovery: chose " + Join(cand.parameters) + " (linear ΔBIC " +
                 Format("%.1f", chosen.delta_bic) +
                 (cand.significant ? ")"
                                   : ", not above " + Format("%g", options.min_delta_bic) +
                                         ": nothing to refit)"));
    if (!cand.significant) {
      cand.reason = "the best sparse combination of terms has a linear ΔBIC of " +
                    Format("%.1f", chosen.delta_bic) +
                    " <= " + Format("%g", options.min_delta_bic) +
                    ": no term explains enough of it";
    }
    return cand;
  };
  // The backward step (issue 28), after a round's winner is added: an
  // earlier addition can be made redundant by a later one. On friction that
  // grows with the angle, joint friction was added first (56 % of the
  // excess) and the terms |θ| sign θ̇ next; in their fit joint friction's
  // Coulomb moment went to 0 and its viscous coefficient to 0.0076, neither
  // identifiable, and the conclusion still named it: a lab told its joints
  // have friction they do not have. So every earlier addition is checked
  // in the new fit by the acceptance's own size test; one whose size is
  // indistinguishable from 0, or that the new fit cannot identify (an
  // input-rate drag first taken for softer driving cables: beside the
  // terms the cables' E·A is not identifiable, yet setting it back at the
  // new fit's point costs much), is refitted away from the new fit's point
  // (its parameters off, or a declared value back at the configuration's)
  // and taken back when keeping it is not worth min_delta_bic, the
  // criterion that added it: what the loop would not add now it does not
  // keep. At most one per round, the least useful first (the smallest ΔBIC
  // at 0): taking one back changes the fit the others are judged in, so
  // they are checked again after the next addition. The addition just
  // made is not checked: it has passed every criterion in this fit.
  const auto backward_step = [&](int round, const std::string& winner_label, LoopRound* lr) {
    if (effects_on.size() < 2) return;  // no earlier addition: nothing to check
    const double nres = static_cast<double>(current.residuals);
    const double neff = current.effective_samples;
    std::vector<internal::AdditionCheck> checks;
    for (std::size_t a = 0; a + 1 < effects_on.size(); ++a) {
      BackwardCheck b;
      b.name = effects_on[a];
      b.parameters = added_parameters.at(b.name);
      internal::AdditionCheck c;
      c.parameters = b.parameters.size();
      for (const std::string& q : b.parameters) {
        if (const ParameterEstimate* est = current.Find(q)) {
          c.interval_excludes_zero |= internal::IntervalExcludesZero(*est);
          c.identifiable = c.identifiable && est->identifiable;
        }
      }
      if (!c.interval_excludes_zero) {
        std::map<std::string, double> zeroed = ValuesOf(current, fixed);
        for (const std::string& q : b.parameters) zeroed[q] = 0.0;
        const double cost_zeroed = training_cost(zeroed);
        c.delta_bic_zeroed =
            internal::DeltaBic(cost_zeroed, current.final_cost, neff, nres, c.parameters);
        c.delta_chi2_zeroed =
            c.delta_bic_zeroed + static_cast<double>(c.parameters) * std::log(neff);
      }
      b.delta_chi2_zeroed = c.delta_chi2_zeroed;
      b.size_significant =
          internal::SizeSignificant(c.interval_excludes_zero, c.delta_chi2_zeroed, c.parameters);
      if (!std::isfinite(c.delta_chi2_zeroed) && !c.interval_excludes_zero) {
        b.reason = "its run at 0 failed: not judged, kept";
      } else if (!b.size_significant) {
        b.reason = "its size is indistinguishable from 0 (Δχ²_eff " +
                   Format("%.1f", c.delta_chi2_zeroed) + " at 0)";
      } else if (!c.interval_excludes_zero && !c.identifiable) {
        b.reason = "it is not identifiable beside " + winner_label + " (Δχ²_eff " +
                   Format("%.1f", c.delta_chi2_zeroed) + " at 0 without a refit)";
      } else {
        b.reason = "its size is still distinguishable from 0: kept";
      }
      checks.push_back(c);
      lr->backward.push_back(std::move(b));
    }
    for (std::size_t a : internal::TakeBackOrder(checks)) {
      BackwardCheck& b = lr->backward[a];
      progress(round, "backward", b.name, "  backward step: refitting without " + b.name);
      IdentificationOptions o = options.fit;
      o.free_parameters.clear();
      for (const std::string& q : free) {
        if (std::find(b.parameters.begin(), b.parameters.end(), q) == b.parameters.end()) {
          o.free_parameters.push_back(q);
        }
      }
      o.values = ValuesOf(current, fixed);
      for (const std::string& q : b.parameters) o.values.erase(q);
      IdentificationSummary without = Identify(training, o);
      simulations += without.simulations;
      if (without.termination == IdentificationTermination::kFailed) {
        b.reason += "; the refit without it failed (" + without.message + "): kept";
        continue;
      }
      b.refitted = true;
      b.rms_deg_without = without.errors.rms_deg_overall;
      b.delta_bic_keep =
          internal::DeltaBic(without.final_cost, current.final_cost,
                             std::min(neff, without.effective_samples), nres, b.parameters.size());
      const std::string keep = "ΔBIC of keeping it " + Format("%.1f", b.delta_bic_keep);
      if (b.delta_bic_keep > options.min_delta_bic) {
        b.reason += "; " + keep + " > " + Format("%g", options.min_delta_bic) + ": kept";
        progress(round, "backward", b.name, "  " + b.name + ": " + b.reason);
        continue;
      }
      // Take it back: the refit without it is the current model.
      HoldoutResult h = run_holdout(ValuesOf(without, fixed));
      if (!holdout.empty()) b.holdout_rms_deg_without = h.rms_deg;
      b.taken_back = true;
      b.reason = "took back " + (b.name == kTermsEffect ? "the terms found in the data" : b.name) +
                 ": after " + winner_label +
                 (b.size_significant ? " it is not identifiable"
                                     : " its size is indistinguishable from 0") +
                 " (" + keep + " <= " + Format("%g", options.min_delta_bic) + "; training RMS " +
                 Format("%.4f", current.errors.rms_deg_overall) + " -> " +
                 Format("%.4f", b.rms_deg_without) + " deg" +
                 (holdout.empty() ? std::string()
                                  : ", held out " + Format("%.4f", current_holdout.rms_deg) +
                                        " -> " + Format("%.4f", h.rms_deg) + " deg") +
                 ")";
      progress(round, "backward", b.name, "  " + b.reason);
      lr->decision += " T" + b.reason.substr(1) + ".";  // "took back" -> "Took back"
      for (const std::string& q : b.parameters) {
        free.erase(std::remove(free.begin(), free.end(), q), free.end());
        fixed.erase(q);
      }
      effects_on.erase(std::find(effects_on.begin(), effects_on.end(), b.name));
      added_parameters.erase(b.name);
      taken_back.insert(b.name);
      current = std::move(without);
      current_holdout = std::move(h);
      summary.taken_back.push_back(b);
      break;
    }
    const bool took = std::any_of(lr->backward.begin(), lr->backward.end(),
                                  [](const BackwardCheck& b) { return b.taken_back; });
    for (BackwardCheck& b : lr->backward) {
      if (took && !b.size_significant && !b.refitted && !b.taken_back &&
          std::isfinite(b.delta_chi2_zeroed)) {
        b.reason += "; another was taken back first: checked again after the next addition";
      }
    }
  };
  std::map<std::string, std::vector<std::string>> winner_indistinguishable;
  const bool declared_ok = summary.declared.termination != IdentificationTermination::kFailed &&
                           summary.declared.jacobian.size() > 0;
  for (int round = 1; declared_ok && round <= options.max_rounds; ++round) {
    LoopRound lr;
    lr.index = round;
    lr.effects_on = effects_on;
    lr.rms_deg = current.errors.rms_deg_overall;
    if (!holdout.empty()) lr.holdout_rms_deg = current_holdout.rms_deg;
    std::vector<Eigen::MatrixXd> fitted;
    for (const ExperimentFit& f : current.experiments) fitted.push_back(f.simulated_rad);
    lr.evidence = DiagnoseResidual(training, fitted);

    // Not yet added; a block keeps the members not yet added.
    std::vector<Spec> remaining;
    for (const Spec& c : specs) {
      const auto added = [&](const std::string& n) {
        return std::find(effects_on.begin(), effects_on.end(), n) != effects_on.end();
      };
      if (added(c.name) || taken_back.count(c.name)) continue;
      Spec r = c;
      if (c.kind == Spec::Kind::kDeclaredBlock) {
        r.parameters.clear();
        for (const std::string& q : c.parameters) {
          if (!added(q) && !taken_back.count(q)) r.parameters.push_back(q);
        }
        if (r.parameters.empty()) continue;
      }
      remaining.push_back(std::move(r));
    }
    const bool discovery_left =
        discovery_on && !is_added(kTermsEffect) && !taken_back.count(kTermsEffect);
    if (remaining.empty() && !discovery_left) {
      lr.decision = "every candidate is already in the model.";
      summary.rounds.push_back(std::move(lr));
      break;
    }

    // Score test: sensitivity columns of every candidate's size parameters.
    progress(round, "scoring", "",
             "round " + std::to_string(round) + ": scoring " + std::to_string(remaining.size()) +
                 " candidates");
    // One column per size parameter, shared by the candidates that have it
    // (a block and its members).
    struct Column {
      std::string parameter;
      double step;
      std::vector<Eigen::MatrixXd> angles;  // per experiment
    };
    std::vector<Column> columns;
    std::map<std::string, std::size_t> column_of;
    std::vector<RunRequest> requests;
    std::vector<std::size_t> request_column;
    for (std::size_t c = 0; c < remaining.size(); ++c) {
      const bool measurement = remaining[c].measurement;
      for (const std::string& q : remaining[c].parameters) {
        if (column_of.count(q)) continue;
        column_of[q] = columns.size();
        Column col{q, ScoreStep(q, arm), {}};
        for (std::size_t e = 0; e < training.size(); ++e) {
          sim::ArmParameters p = current.experiments[e].parameters;
          sim::SetParameter(q, col.step, "loop", &p);
          if (measurement) {
            // Recorded from the fitted run: no simulation.
            const ExperimentFit& f = current.experiments[e];
            Eigen::MatrixXd a =
                Eigen::MatrixXd::Constant(f.simulated_rad.rows(), f.simulated_rad.cols(),
                                          std::numeric_limits<double>::quiet_NaN());
            for (std::size_t k = 0;
                 k < f.run.trajectory.size() && static_cast<Eigen::Index>(k) < a.rows(); ++k) {
              const std::vector<Eigen::Vector2d> rec =
                  sim::RecordedJointAngles(p, f.run.trajectory.frames[k]);
              for (std::size_t j = 0; j < rec.size(); ++j) {
                a(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(2 * j)) = rec[j].x();
                a(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(2 * j + 1)) = rec[j].y();
              }
            }
            training[e].AsMeasured(&a);
            col.angles.push_back(std::move(a));
          } else {
            col.angles.emplace_back();
            requests.push_back({e, p, false, {}});
            request_column.push_back(columns.size());
          }
        }
        columns.push_back(std::move(col));
      }
    }
    {
      std::vector<RunResult> results = training_backend->RunBatch(
          requests, [&](std::size_t finished, std::size_t total, const RunResult&) {
            if (finished == total || finished % 4 == 0) {
              progress(
                  round, "scoring", "",
                  "  sensitivity runs " + std::to_string(finished) + "/" + std::to_string(total));
            }
          });
      simulations += static_cast<std::int64_t>(requests.size());
      for (std::size_t k = 0; k < results.size(); ++k) {
        columns[request_column[k]].angles[requests[k].experiment] =
            std::move(results[k].angles_rad);
      }
    }
    std::vector<const Eigen::MatrixXd*> base_angles;
    for (const Eigen::MatrixXd& a : fitted) base_angles.push_back(&a);
    const Eigen::VectorXd r = current.weighted_residuals;
    const Eigen::MatrixXd& jb = current.jacobian;
    const double n = static_cast<double>(r.size());
    const double neff_ratio =
        n > 0.0 && current.effective_samples > 0.0 ? current.effective_samples / n : 1.0;
    const double base_reduction = Reduction(r, jb, nullptr);
    // Each column in the weighted residual's units, per unit of its parameter.
    std::map<std::string, Eigen::VectorXd> weighted_column;
    for (const Column& col : columns) {
      std::vector<const Eigen::MatrixXd*> ca;
      for (const Eigen::MatrixXd& m : col.angles) ca.push_back(&m);
      weighted_column[col.parameter] = Weighted(training, ca, true, base_angles) / col.step;
    }
    // Bonferroni over the effects and the blocks: a declared value is tested
    // only inside a significant block (closed testing), at the same level.
    std::size_t tests = 0;
    for (const Spec& c : remaining) tests += c.kind != Spec::Kind::kDeclaredValue;
    tests = std::max<std::size_t>(tests, 1);
    std::map<std::string, bool> block_significant;
    for (std::size_t c = 0; c < remaining.size(); ++c) {
      CandidateResult cand;
      cand.name = remaining[c].name;
      cand.kind = remaining[c].kind == Spec::Kind::kEffect          ? "effect"
                  : remaining[c].kind == Spec::Kind::kDeclaredBlock ? "declared block"
                                                                    : "declared value";
      std::vector<const Column*> cols;
      for (const std::string& q : remaining[c].parameters) {
        cols.push_back(&columns[column_of.at(q)]);
        cand.parameters.push_back(q);
      }
      // Active set: a size parameter whose linear estimate leaves its bounds
      // (a negative friction) is dropped and the rest refitted.
      std::vector<bool> active(cols.size(), true);
      Eigen::VectorXd x;
      double reduction = 0.0;
      for (std::size_t pass = 0; pass <= cols.size(); ++pass) {
        std::vector<std::size_t> idx;
        for (std::size_t k = 0; k < cols.size(); ++k) {
          if (active[k]) idx.push_back(k);
        }
        Eigen::MatrixXd a(r.size(), jb.cols() + static_cast<Eigen::Index>(idx.size()));
        a.leftCols(jb.cols()) = jb;
        for (std::size_t k = 0; k < idx.size(); ++k) {
          a.col(jb.cols() + static_cast<Eigen::Index>(k)) =
              weighted_column.at(cols[idx[k]]->parameter);
        }
        reduction = Reduction(r, a, &x) - base_reduction;
        bool changed = false;
        for (std::size_t k = 0; k < idx.size(); ++k) {
          const sim::ParameterInfo& info = sim::FindParameter(cols[idx[k]]->parameter, "loop", arm);
          const double value = x[jb.cols() + static_cast<Eigen::Index>(k)];
          if (value < info.lower || value > info.upper) {
            active[idx[k]] = false;
            changed = true;
          } else {
            cand.linearised[cols[idx[k]]->parameter] = value;
          }
        }
        if (!changed) break;
        cand.linearised.clear();
      }
      cand.score = std::max(reduction, 0.0) * neff_ratio;
      const double dof = static_cast<double>(cols.size());
      cand.p_value = dof > 0 ? gsl_cdf_chisq_Q(cand.score, dof) : 1.0;
      cand.significant = cand.p_value < options.score_significance / static_cast<double>(tests);
      if (remaining[c].kind == Spec::Kind::kDeclaredBlock) {
        block_significant[cand.name] = cand.significant;
      } else if (remaining[c].kind == Spec::Kind::kDeclaredValue) {
        cand.significant = cand.significant && block_significant[remaining[c].block];
      }
      for (const std::string& signal : remaining[c].fingerprint) {
        if (const SignalEvidence* ev = lr.evidence.Pooled(signal)) cand.evidence.push_back(*ev);
      }
      lr.candidates.push_back(std::move(cand));
    }
    std::stable_sort(
        lr.candidates.begin(), lr.candidates.end(),
        [](const CandidateResult& a, const CandidateResult& b) { return a.score > b.score; });
    // Declared values the data cannot tell apart: beyond what the fit's own
    // columns remove, their columns are (anti)parallel. A significant one
    // stands for the combination.
    {
      const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jb);
      const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(jb.rows(), qr.rank());
      std::map<std::string, Eigen::VectorXd> beyond;
      for (const CandidateResult& c : lr.candidates) {
        if (c.kind != "declared value") continue;
        const Eigen::VectorXd& v = weighted_column.at(c.parameters.front());
        beyond[c.name] = v - q * (q.transpose() * v);
      }
      for (CandidateResult& c : lr.candidates) {
        if (c.kind != "declared value" || !c.significant) continue;
        const Eigen::VectorXd& a = beyond.at(c.name);
        for (const auto& [other, b] : beyond) {
          if (other == c.name || !(a.norm() > 0.0 && b.norm() > 0.0)) continue;
          // 0.99: the two explain the same residual to within 2 % of its square.
          const bool parallel = std::abs(a.dot(b)) / (a.norm() * b.norm()) > 0.99;
          // Or the data prefer neither: each alone removes as much, within
          // tie_delta_bic (scores are Δχ²_eff of one parameter each, so
          // their difference is the two models' ΔBIC: "not worth more than
          // a bare mention"). On a large-S pulley 5 % large, both
          // segments' large-S wrap angles and pulley radii scored 40.8 to
          // 41.7: each changes the conduits' friction moment alike.
          const auto it = std::find_if(lr.candidates.begin(), lr.candidates.end(),
                                       [&](const CandidateResult& x) { return x.name == other; });
          const bool tied = it != lr.candidates.end() && it->significant &&
                            std::abs(it->score - c.score) < options.tie_delta_bic;
          if (parallel || tied) c.indistinguishable.push_back(other);
        }
      }
    }
    for (const CandidateResult& c : lr.candidates) {
      progress(round, "scoring", c.name,
               "  " + c.name + ": score " + Format("%.1f", c.score) + ", p " +
                   Format("%.2g", c.p_value) + (c.significant ? " (significant)" : ""));
    }

    // Refit the best significant few: effects and declared values each on
    // their own budget; a block is scored only (its members are refitted).
    int refits = 0, declared_refits = 0;
    std::set<std::string> covered;  // declared values a refitted one stands for
    std::map<std::string, IdentificationSummary> refit_fits;
    std::map<std::string, HoldoutResult> refit_holdouts;
    // Refits `cand` with the declared free parameters and its size
    // parameters free, and judges it by the acceptance criteria (above).
    const auto refit_and_judge = [&](CandidateResult& cand) {
      progress(round, "refit", cand.name, "  refitting with " + cand.name);
      IdentificationOptions o = options.fit;
      o.free_parameters = free;
      o.values = ValuesOf(current, fixed);
      o.bounds.clear();
      for (const auto& [name, range] : options.fit.bounds) o.bounds[name] = range;
      for (const std::string& q : cand.parameters) {
        const sim::ParameterInfo& info = sim::FindParameter(q, "loop", arm);
        const double scale = ScoreStep(q, arm);
        double start = cand.linearised.count(q) ? cand.linearised[q] : 0.0;
        // Start inside the bounds with room for a difference step.
        start = std::clamp(start, info.lower, info.upper);
        o.free_parameters.push_back(q);
        o.values[q] = start;
        o.scales[q] = scale;
      }
      IdentificationSummary refit = Identify(training, o);
      simulations += refit.simulations;
      cand.simulations += refit.simulations;
      // Discovered terms: a term whose size the refit cannot tell from 0
      // (its 95 % interval covers 0, or it is not identifiable) is not
      // added. Drop those and refit the rest from the refit's point, up to
      // twice (the first-order selection may have let in terms that only
      // soaked up its own misfit).
      for (int prune = 0; prune < 2 && cand.kind == "discovered terms" &&
                          refit.termination != IdentificationTermination::kFailed;
           ++prune) {
        std::vector<std::string> kept, dropped;
        for (const std::string& q : cand.parameters) {
          const ParameterEstimate* est = refit.Find(q);
          const bool sized = est != nullptr && internal::IntervalExcludesZero(*est);
          (sized ? kept : dropped).push_back(q);
        }
        if (dropped.empty() || kept.empty()) break;
        progress(round, "refit", cand.name,
                 "  " + cand.name + ": dropping " + Join(dropped) +
                     " (indistinguishable from 0) and refitting " + Join(kept));
        o.values = ValuesOf(refit, fixed);
        for (const std::string& q : dropped) {
          o.values.erase(q);
          o.scales.erase(q);
          o.free_parameters.erase(std::find(o.free_parameters.begin(), o.free_parameters.end(), q));
          cand.linearised.erase(q);
        }
        cand.parameters = kept;
        refit = Identify(training, o);
        simulations += refit.simulations;
        cand.simulations += refit.simulations;
      }
      cand.refitted = true;
      cand.termination = TerminationName(refit.termination);
      cand.rms_deg = refit.errors.rms_deg_overall;
      if (refit.termination == IdentificationTermination::kFailed) {
        cand.reason = "refit failed: " + refit.message;
        return;
      }
      // The candidate's own share of the gain: the refit's point with the
      // candidate's size parameters at 0. A refit also moves the declared
      // parameters; where the current fit stopped short of its optimum (a
      // rough cost), that move alone lowers the cost, and must not be
      // credited to the candidate. So the gain is counted from the worse of
      // the current fit and the refit without the candidate.
      std::map<std::string, double> without = ValuesOf(refit, fixed);
      for (const std::string& q : cand.parameters) without[q] = 0.0;
      const double cost_zeroed = training_cost(without);
      const double cost_without = std::isfinite(cost_zeroed)
                                      ? std::max(current.final_cost, cost_zeroed)
                                      : current.final_cost;
      cand.cost_without = cost_without;
      const double neff = std::min(current.effective_samples, refit.effective_samples);
      const double nres = static_cast<double>(refit.residuals);
      cand.delta_bic =
          internal::DeltaBic(cost_without, refit.final_cost, neff, nres, cand.parameters.size());
      // Its size is distinguishable from 0 when one of its parameters'
      // interval excludes 0, or when its parameters together do: removing
      // it at the refit's point raises the effective chi-square beyond the
      // 95 % quantile of a chi-square with as many degrees of freedom (the
      // 95 % confidence region of its size excludes 0). The second serves
      // an effect whose parameters the data determine only in combination
      // (a delay's time constant and dead time both lag the motion, by
      // their sum).
      bool interval_excludes_zero = false;
      for (const std::string& q : cand.parameters) {
        if (const ParameterEstimate* est = refit.Find(q)) {
          cand.estimates[q] = *est;
          interval_excludes_zero |= internal::IntervalExcludesZero(*est);
        }
      }
      cand.size_significant = internal::SizeSignificant(
          interval_excludes_zero, 2.0 * (cost_zeroed - refit.final_cost) * neff / nres,
          cand.parameters.size());
      HoldoutResult h = run_holdout(ValuesOf(refit, fixed));
      if (!holdout.empty()) {
        // Held out likewise: from the worse of the current model and the
        // refit without the candidate.
        const HoldoutResult h_without = run_holdout(without);
        const double before = h_without.ok
                                  ? std::max(current_holdout.mean_square, h_without.mean_square)
                                  : current_holdout.mean_square;
        cand.holdout_rms_deg = h.rms_deg;
        cand.holdout_rms_without_deg = h_without.rms_deg;
        const double needed =
            options.holdout_z * h.mean_square * std::sqrt(2.0 / std::max(h.effective_samples, 1.0));
        cand.holdout_improved = h.ok && before - h.mean_square > needed;
      } else {
        cand.holdout_improved = true;  // nothing held out: the criterion alone decides
      }
      const bool bic_ok = cand.delta_bic > options.min_delta_bic;
      // The partial-explanation rule: in noise units (weighted mean square,
      // 1 at the noise), the share of the current residual's excess over
      // the noise the refit removes, where the residual after it stays
      // above the unexplained level. From the current fit, not from
      // cost_without: a refit that moves the declared parameters far to
      // make room for the candidate has a poor point without it. On a
      // hole circle 0.5 mm small, joint friction's refit took mu_c from
      // 0.21 to 0.09: counted from there it removed 58 % of the excess,
      // of the current residual 3 % (RMS 0.0655 -> 0.0648 deg).
      const double ms_before = 2.0 * current.final_cost / nres;
      cand.mean_square_after = 2.0 * refit.final_cost / nres;
      cand.excess_share =
          ms_before > 1.0 ? (ms_before - cand.mean_square_after) / (ms_before - 1.0) : 1.0;
      const double unexplained_ms =
          options.unexplained_noise_ratio * options.unexplained_noise_ratio;
      cand.partial =
          cand.mean_square_after > unexplained_ms && cand.excess_share < options.min_excess_share;
      cand.accepted = bic_ok && cand.holdout_improved && cand.size_significant && !cand.partial;
      std::string why;
      why += "ΔBIC " + Format("%.1f", cand.delta_bic) + (bic_ok ? " > " : " <= ") +
             Format("%g", options.min_delta_bic);
      if (!holdout.empty()) {
        why += "; held-out RMS " + Format("%.4f", current_holdout.rms_deg) + " -> " +
               Format("%.4f", h.rms_deg) + " deg" +
               (cand.holdout_improved ? " (a real gain)" : " (no gain beyond chance)");
      }
      why += cand.size_significant ? "; its size is distinguishable from 0"
                                   : "; its size is indistinguishable from 0";
      why += "; it removes " + Format("%.0f", 100.0 * cand.excess_share) +
             " % of the residual's excess over the noise";
      if (cand.partial) {
        why += ", below " + Format("%.0f", 100.0 * options.min_excess_share) +
               " %, while the residual stays at " +
               Format("%.1f", std::sqrt(cand.mean_square_after)) +
               "x the noise: a partial explanation, not the cause";
      }
      cand.reason = why;
      progress(round, "refit", cand.name,
               "  " + cand.name + ": RMS " + Format("%.4f", cand.rms_deg) + " deg, " + why +
                   (cand.accepted ? " -> passes" : " -> fails"));
      refit_fits.emplace(cand.name, std::move(refit));
      refit_holdouts.emplace(cand.name, std::move(h));
    };
    for (CandidateResult& cand : lr.candidates) {
      if (!cand.significant) {
        cand.reason = "score test not significant (p " + Format("%.2g", cand.p_value) + ")";
        continue;
      }
      if (cand.kind == "declared block") {
        cand.reason = "a block of declared values: scored as one, its members refitted";
        continue;
      }
      const bool declared = cand.kind == "declared value";
      if (declared && covered.count(cand.name)) {
        cand.reason = "significant, but indistinguishable from a better-scoring declared value";
        continue;
      }
      int& used = declared ? declared_refits : refits;
      const int budget = declared ? options.declared_refits_per_round : options.refits_per_round;
      if (used >= budget) {
        cand.reason = "significant, but not among the best " + std::to_string(budget) +
                      (declared ? " declared values" : " effects") + " of the round";
        continue;
      }
      ++used;
      if (declared) covered.insert(cand.indistinguishable.begin(), cand.indistinguishable.end());
      refit_and_judge(cand);
    }

    // Terms found in the data (issue 28): when no effect of the library
    // earns its place and the residual is still structured (above the
    // unexplained level, or correlated with a signal an effect would
    // leave), a sparse combination of joint_moment's terms, chosen on the
    // terms' sensitivity columns, then refitted and judged like any
    // candidate. The library comes first; a declared value does not: it
    // competes with the terms by ΔBIC. On a cubic joint spring (validation,
    // docs/loop.md) segment 2's hole circle removed 82 % of the excess
    // (ΔBIC 497) and passed every criterion: run only when nothing passes,
    // the discovery came after two wrong corrections of declared values.
    bool effect_accepted = false;
    for (const CandidateResult& c : lr.candidates) {
      effect_accepted |= c.accepted && c.kind == "effect";
    }
    if (!effect_accepted && discovery_left) {
      const double ms_current =
          2.0 * current.final_cost / static_cast<double>(std::max<Eigen::Index>(r.size(), 1));
      bool correlated = false;
      for (const SignalEvidence& e : lr.evidence.pooled) correlated |= e.significant();
      const double unexplained_ms =
          options.unexplained_noise_ratio * options.unexplained_noise_ratio;
      // Or more than a tenth of the joint axes above the unexplained level:
      // a residual the overall mean square dilutes. Null data leave a few
      // (the validation's: 2 of 48, 4 %); friction that grows with the angle,
      // after joint friction took what it could, left 12 of 48.
      std::size_t above = 0;
      for (const ChannelDiagnostics& ch : lr.evidence.channels) {
        above += ch.rms_deg > options.unexplained_noise_ratio * ch.noise_deg;
      }
      const bool widespread = 10 * above > lr.evidence.channels.size();
      if (ms_current > unexplained_ms || correlated || widespread) {
        CandidateResult cand = discover_terms(round, fitted, base_angles, r, jb, neff_ratio);
        if (cand.significant) refit_and_judge(cand);
        lr.candidates.push_back(std::move(cand));
      } else {
        lr.discovery = "no terms sought: the residual is within " +
                       Format("%g", options.unexplained_noise_ratio) +
                       "x the noise overall and on all but " + std::to_string(above) +
                       " joint axes, and follows none of the effects' signals.";
      }
    }

    // The winner: the largest ΔBIC among those that pass; ties go to the simpler.
    const CandidateResult* best = nullptr;
    for (const CandidateResult& c : lr.candidates) {
      if (c.accepted && (best == nullptr || c.delta_bic > best->delta_bic)) best = &c;
    }
    if (best == nullptr) {
      bool any_significant = false;
      for (const CandidateResult& c : lr.candidates) any_significant |= c.significant;
      const CandidateResult* partial = nullptr;
      for (const CandidateResult& c : lr.candidates) {
        if (c.partial && (partial == nullptr || c.delta_bic > partial->delta_bic)) partial = &c;
      }
      lr.decision = any_significant
                        ? "no candidate earns its place: the refitted ones fail a criterion."
                        : "no candidate earns its place: none explains a significant part of "
                          "the residual (score test).";
      if (partial != nullptr) {
        lr.decision += " The residual is not explained: " + partial->name + " would remove only " +
                       Format("%.0f", 100.0 * partial->excess_share) +
                       " % of its excess over the noise and leave it at " +
                       Format("%.1f", std::sqrt(partial->mean_square_after)) +
                       "x the noise; it is not named as the cause.";
      }
      for (CandidateResult& c : lr.candidates) c.accepted = false;
      summary.rounds.push_back(std::move(lr));
      progress(round, "done", "",
               "round " + std::to_string(round) + ": " + summary.rounds.back().decision);
      break;
    }
    const CandidateResult* winner = best;
    for (const CandidateResult& c : lr.candidates) {
      if (&c == best || !c.accepted) continue;
      if (best->delta_bic - c.delta_bic < options.tie_delta_bic) {
        lr.tie.push_back(c.name);
        if (c.parameters.size() < winner->parameters.size()) winner = &c;
      }
    }
    if (!lr.tie.empty()) lr.tie.push_back(best->name);
    lr.winner = winner->name;
    for (CandidateResult& c : lr.candidates) {
      if (c.accepted && c.name != lr.winner) {
        c.accepted = false;
        c.reason += "; passes, but " + lr.winner + " explains more";
      }
    }
    const bool declared_winner = winner->kind == "declared value";
    if (declared_winner) winner_indistinguishable[lr.winner] = winner->indistinguishable;
    std::string winner_name = lr.winner;
    if (winner->kind == "discovered terms")
      winner_name = "terms found in the data (" + Join(winner->parameters) + ")";
    lr.decision =
        (declared_winner ? "corrected " : "added ") + winner_name +
        (winner->indistinguishable.empty()
             ? std::string()
             : " (indistinguishable from " + Join(winner->indistinguishable) +
                   ": the data see their combination)") +
        ": ΔBIC " + Format("%.1f", winner->delta_bic) + ", training RMS " +
        Format("%.4f", lr.rms_deg) + " -> " + Format("%.4f", winner->rms_deg) + " deg" +
        (winner->holdout_rms_deg ? ", held-out " + Format("%.4f", *lr.holdout_rms_deg) + " -> " +
                                       Format("%.4f", *winner->holdout_rms_deg) + " deg"
                                 : std::string()) +
        ".";
    if (!lr.tie.empty()) {
      std::string names;
      for (const std::string& t : lr.tie) names += (names.empty() ? "" : ", ") + t;
      lr.decision += " Tie (ΔBIC within " + Format("%g", options.tie_delta_bic) + "): " + names +
                     "; the one with the fewest parameters is kept.";
    }
    for (const std::string& q : winner->parameters) free.push_back(q);
    effects_on.push_back(lr.winner);
    added_parameters[lr.winner] = winner->parameters;
    current = std::move(refit_fits.at(lr.winner));
    current_holdout = std::move(refit_holdouts.at(lr.winner));
    backward_step(
        round, winner->kind == "discovered terms" ? "the terms found in the data" : lr.winner, &lr);
    progress(round, "done", lr.winner, "round " + std::to_string(round) + ": " + lr.decision);
    summary.rounds.push_back(std::move(lr));
  }

  for (const std::string& name : effects_on) {
    if (name.rfind("declared.", 0) != 0) {
      summary.added_effects.push_back(name);
      continue;
    }
    // "The declared X is off by Δ ± σ".
    DeclaredCorrection d;
    d.parameter = name;
    d.config_key = sim::DeclaredValueKey(name);
    d.label = internal::DeclaredValueLabel(name);
    d.declared = sim::DeclaredValue(training.front().config.arm, name);
    if (const ParameterEstimate* est = current.Find(name)) {
      d.relative = est->value;
      d.identifiable = est->identifiable;
      d.relative_std_error = est->std_error;
      d.relative_ci95_lower = est->ci95_lower;
      d.relative_ci95_upper = est->ci95_upper;
    }
    d.indistinguishable = winner_indistinguishable[name];
    summary.declared_corrections.push_back(d);
  }
  if (is_added(kTermsEffect)) {
    // The discovered moment, per segment and axis, from the final fit.
    const sim::ArmConfig& arm_config = training.front().config.arm;
    int first_joint = 1;
    for (int s = 1; s <= static_cast<int>(arm_config.segments.size()); ++s) {
      const int links = arm_config.segments[static_cast<std::size_t>(s - 1)].links;
      for (int axis = 0; axis < 2; ++axis) {
        DiscoveredMoment m;
        m.segment = s;
        m.first_joint = first_joint;
        m.last_joint = first_joint + links - 1;
        m.axis = axis;
        for (const sim::JointMomentTerm& term : sim::JointMomentTerms()) {
          const ParameterEstimate* est =
              current.Find(sim::JointMomentParameter(s, axis, term.name));
          if (est != nullptr && est->free) {
            m.terms.push_back({term.name, term.formula, term.units, *est});
          }
        }
        if (!m.terms.empty()) summary.discovered_terms.push_back(std::move(m));
      }
      first_joint += links;
    }
  }
  if (!summary.declared_corrections.empty()) {
    // The corrected configuration, with every value of the final model.
    sim::Config c = training.front().config;
    sim::ArmParameters p = ParametersFor(training.front(), ValuesOf(current, fixed));
    c.arm = sim::CorrectedArm(c.arm, p);
    p.declared_deltas.clear();
    c.parameters = p;
    summary.calibrated = c;
  }
  summary.final_fit = current;
  summary.after = current.errors;
  summary.rms_after_deg = current.errors.rms_deg_overall;
  summary.holdout_final_rad = current_holdout.angles_rad;
  if (!holdout.empty()) {
    summary.holdout_rms_after_deg = current_holdout.rms_deg;
    summary.holdout_after = current_holdout.errors;
  }
  {
    std::vector<Eigen::MatrixXd> fitted;
    for (const ExperimentFit& f : current.experiments) fitted.push_back(f.simulated_rad);
    if (!fitted.empty()) summary.final_evidence = DiagnoseResidual(training, fitted);
  }
  // Where the residual remains.
  for (const ChannelDiagnostics& ch : summary.final_evidence.channels) {
    if (!(ch.rms_deg > options.unexplained_noise_ratio * ch.noise_deg)) continue;
    UnexplainedChannel u;
    const ExperimentDiagnostics& ed = summary.final_evidence.experiments[ch.experiment];
    u.experiment = ed.name;
    u.joint = ch.joint;
    u.axis = ch.axis;
    u.rms_deg = ch.rms_deg;
    u.noise_deg = ch.noise_deg;
    for (std::size_t p = 0; p < ch.phase_rms_deg.size() && p < ed.phases.size(); ++p) {
      if (std::isfinite(ch.phase_rms_deg[p]) && ch.phase_rms_deg[p] > u.worst_phase_rms_deg) {
        u.worst_phase_rms_deg = ch.phase_rms_deg[p];
        u.worst_phase = ed.phases[p].name;
      }
    }
    summary.unexplained.push_back(u);
  }
  std::sort(summary.unexplained.begin(), summary.unexplained.end(),
            [](const UnexplainedChannel& a, const UnexplainedChannel& b) {
              return a.rms_deg / a.noise_deg > b.rms_deg / b.noise_deg;
            });
  std::ostringstream conclusion;
  if (!declared_ok) {
    conclusion << "the declared model's fit failed (" << summary.declared.message
               << "); no candidate was tried.";
  } else if (summary.added_effects.empty()) {
    conclusion << "no effect added.";
  } else {
    conclusion << "added ";
    for (std::size_t k = 0; k < summary.added_effects.size(); ++k) {
      conclusion << (k ? ", " : "")
                 << (summary.added_effects[k] == kTermsEffect ? "terms found in the data"
                                                              : summary.added_effects[k]);
    }
    conclusion << ".";
  }
  for (const BackwardCheck& b : summary.taken_back) conclusion << " " << b.reason << ".";
  for (const DiscoveredMoment& m : summary.discovered_terms)
    conclusion << " " << m.Formula() << ".";
  for (const DeclaredCorrection& d : summary.declared_corrections) {
    conclusion << " " << d.Sentence() << ".";
  }
  if (!summary.rounds.empty()) {
    // A partial explanation refused in the last round: say so.
    const std::string& last = summary.rounds.back().decision;
    const std::size_t at = last.find("The residual is not explained");
    if (at != std::string::npos) conclusion << " " << last.substr(at);
  }
  if (declared_ok) {
    if (summary.unexplained.empty()) {
      conclusion << " The residual is at the noise floor: every joint and axis within "
                 << Format("%g", options.unexplained_noise_ratio) << "x its noise.";
    } else {
      const UnexplainedChannel& u = summary.unexplained.front();
      conclusion << " Unexplained residual remains in " << summary.unexplained.size()
                 << " joint axes (above " << Format("%g", options.unexplained_noise_ratio)
                 << "x their noise); the largest: " << u.experiment << " joint " << u.joint
                 << (u.axis == 0 ? " θx " : " θy ") << Format("%.4f", u.rms_deg) << " deg against "
                 << Format("%.4f", u.noise_deg) << ", worst in " << u.worst_phase << ".";
    }
  }
  summary.conclusion = conclusion.str();
  summary.simulations = simulations;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  progress(static_cast<int>(summary.rounds.size()), "done", "", summary.conclusion);
  return summary;
}

}  // namespace ccsrm::identify
