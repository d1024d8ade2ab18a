// The round's refits (loop_state.h): the best significant candidates
// refitted and judged by the acceptance criteria.
#include <algorithm>
#include <cmath>

#include "ccsrm/sim/parameters.h"
#include "loop_backward.h"
#include "loop_state.h"

namespace ccsrm::identify::internal {

namespace {

// The refit's gain in plain words: the residual's RMS over the noise before
// and after, and the share of its excess over the noise removed (all of it
// when the refit ends at or below the noise; a share above 100 % says only
// that).
std::string ExcessWords(double ms_before, double ms_after) {
  const std::string from = Format("%.2f", std::sqrt(ms_before)) + "x";
  const std::string to = Format("%.2f", std::sqrt(ms_after)) + "x the noise";
  if (!(ms_before > 1.0)) return "the residual was at the noise already (" + from + ")";
  if (ms_after <= 1.0) {
    return "it brings the residual from " + from + " to " + to +
           ": all of its excess over the noise";
  }
  return "it brings the residual from " + from + " to " + to + " (" +
         Format("%.0f", 100.0 * (ms_before - ms_after) / (ms_before - 1.0)) +
         " % of its excess over the noise)";
}

// Refits `cand` with the declared free parameters and its size parameters
// free; discovered terms the refit cannot size are dropped and the rest
// refitted.
IdentificationSummary Refit(LoopState* s, RoundState* rs, CandidateResult& cand) {
  const std::vector<Experiment>& training = s->training;
  const LoopOptions& options = s->options;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const sim::ArmSize& arm = s->arm;
  const IdentificationSummary& current = s->current;
  const std::map<std::string, double>& fixed = s->fixed;
  const int round = rs->round;
  std::int64_t& simulations = s->simulations;
  const std::vector<std::string>& free = s->free;
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
  // The refit is judged by its cost and intervals; the check that the
  // angles are smooth in each parameter is the declared and final fits'.
  o.check_derivative_steps = false;
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
  return refit;
}

}  // namespace

void RefitAndJudge(LoopState* s, RoundState* rs, CandidateResult* target) {
  const LoopOptions& options = s->options;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const std::vector<Experiment>& holdout = s->holdout;
  const IdentificationSummary& current = s->current;
  const HoldoutResult& current_holdout = s->current_holdout;
  const std::map<std::string, double>& fixed = s->fixed;
  const int round = rs->round;
  CandidateResult& cand = *target;
  progress(round, "refit", cand.name, "  refitting with " + cand.name);
  IdentificationSummary refit = Refit(s, rs, cand);
  cand.refitted = true;
  cand.termination = TerminationName(refit.termination);
  cand.rms_deg = LoopRms(s->training, refit);
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
  const double cost_zeroed = s->TrainingCost(without);
  const double cost_without =
      std::isfinite(cost_zeroed) ? std::max(current.final_cost, cost_zeroed) : current.final_cost;
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
  HoldoutResult h = s->RunHoldout(ValuesOf(refit, fixed));
  if (!holdout.empty()) {
    // Held out likewise: from the worse of the current model and the
    // refit without the candidate.
    const HoldoutResult h_without = s->RunHoldout(without);
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
  const double unexplained_ms = options.unexplained_noise_ratio * options.unexplained_noise_ratio;
  cand.partial =
      cand.mean_square_after > unexplained_ms && cand.excess_share < options.min_excess_share;
  cand.accepted = bic_ok && cand.holdout_improved && cand.size_significant && !cand.partial;
  std::string why;
  why += "ΔBIC " + Format("%.1f", cand.delta_bic) + (bic_ok ? " > " : " <= ") +
         Format("%g", options.min_delta_bic);
  if (!holdout.empty()) {
    why += "; held-out RMS " + Format("%.4f", current_holdout.rms_deg) + " -> " +
           Format("%.4f", h.rms_deg) + " " + s->summary.unit +
           (cand.holdout_improved ? " (a real gain)" : " (no gain beyond chance)");
  }
  why += cand.size_significant ? "; its size is distinguishable from 0"
                               : "; its size is indistinguishable from 0";
  why += "; " + ExcessWords(ms_before, cand.mean_square_after);
  if (cand.partial) {
    why += ", below " + Format("%.0f", 100.0 * options.min_excess_share) +
           " %, while the residual stays at " + Format("%.1f", std::sqrt(cand.mean_square_after)) +
           "x the noise: a partial explanation, not the cause";
  }
  cand.reason = why;
  progress(round, "refit", cand.name,
           "  " + cand.name + ": RMS " + Format("%.4f", cand.rms_deg) + " " + s->summary.unit +
               ", " + why + (cand.accepted ? " -> passes" : " -> fails"));
  rs->refit_fits.emplace(cand.name, std::move(refit));
  rs->refit_holdouts.emplace(cand.name, std::move(h));
}

void RefitSignificant(LoopState* s, RoundState* rs) {
  const LoopOptions& options = s->options;
  // Refit the best significant few: effects and declared values each on
  // their own budget; a block is scored only (its members are refitted).
  int refits = 0, declared_refits = 0;
  std::set<std::string> covered;  // declared values a refitted one stands for
  for (CandidateResult& cand : rs->lr.candidates) {
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
    RefitAndJudge(s, rs, &cand);
  }
}

}  // namespace ccsrm::identify::internal
