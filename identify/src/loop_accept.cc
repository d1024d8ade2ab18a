// The round's last stages (loop_state.h): the winner added, then the
// backward step (issue 28).
#include <algorithm>
#include <cmath>

#include "loop_backward.h"
#include "loop_state.h"

namespace ccsrm::identify::internal {

bool AcceptWinner(LoopState* s, RoundState* rs) {
  const LoopOptions& options = s->options;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const int round = rs->round;
  LoopRound& lr = rs->lr;
  LoopSummary& summary = s->summary;
  IdentificationSummary& current = s->current;
  HoldoutResult& current_holdout = s->current_holdout;
  std::vector<std::string>& free = s->free;
  std::vector<std::string>& effects_on = s->effects_on;
  std::map<std::string, std::vector<std::string>>& added_parameters = s->added_parameters;
  std::map<std::string, std::vector<std::string>>& winner_indistinguishable =
      s->winner_indistinguishable;
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
    return false;
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
  lr.decision = (declared_winner ? "corrected " : "added ") + winner_name +
                (winner->indistinguishable.empty()
                     ? std::string()
                     : " (indistinguishable from " + Join(winner->indistinguishable) +
                           ": the data see their combination)") +
                ": ΔBIC " + Format("%.1f", winner->delta_bic) + ", training RMS " +
                Format("%.4f", lr.rms_deg) + " -> " + Format("%.4f", winner->rms_deg) + " " +
                s->summary.unit +
                (winner->holdout_rms_deg
                     ? ", held-out " + Format("%.4f", *lr.holdout_rms_deg) + " -> " +
                           Format("%.4f", *winner->holdout_rms_deg) + " " + s->summary.unit
                     : std::string()) +
                ".";
  if (!lr.tie.empty()) {
    lr.decision += " Tie (ΔBIC within " + Format("%g", options.tie_delta_bic) +
                   "): " + Join(lr.tie) + "; the one with the fewest parameters is kept.";
  }
  for (const std::string& q : winner->parameters) free.push_back(q);
  effects_on.push_back(lr.winner);
  added_parameters[lr.winner] = winner->parameters;
  current = std::move(rs->refit_fits.at(lr.winner));
  current_holdout = std::move(rs->refit_holdouts.at(lr.winner));
  BackwardStep(s, round,
               winner->kind == "discovered terms" ? "the terms found in the data" : lr.winner, &lr);
  progress(round, "done", lr.winner, "round " + std::to_string(round) + ": " + lr.decision);
  summary.rounds.push_back(std::move(lr));
  return true;
}

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
void BackwardStep(LoopState* s, int round, const std::string& winner_label, LoopRound* lr) {
  const std::vector<Experiment>& training = s->training;
  const LoopOptions& options = s->options;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const std::vector<Experiment>& holdout = s->holdout;
  IdentificationSummary& current = s->current;
  HoldoutResult& current_holdout = s->current_holdout;
  std::vector<std::string>& free = s->free;
  std::map<std::string, double>& fixed = s->fixed;
  std::vector<std::string>& effects_on = s->effects_on;
  std::map<std::string, std::vector<std::string>>& added_parameters = s->added_parameters;
  std::int64_t& simulations = s->simulations;
  LoopSummary& summary = s->summary;
  std::set<std::string>& taken_back = s->taken_back;
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
      const double cost_zeroed = s->TrainingCost(zeroed);
      c.delta_bic_zeroed =
          internal::DeltaBic(cost_zeroed, current.final_cost, neff, nres, c.parameters);
      c.delta_chi2_zeroed = c.delta_bic_zeroed + static_cast<double>(c.parameters) * std::log(neff);
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
    o.check_derivative_steps = false;  // only its cost is compared
    IdentificationSummary without = Identify(training, o);
    simulations += without.simulations;
    if (without.termination == IdentificationTermination::kFailed) {
      b.reason += "; the refit without it failed (" + without.message + "): kept";
      continue;
    }
    b.refitted = true;
    b.rms_deg_without = LoopRms(training, without);
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
    HoldoutResult h = s->RunHoldout(ValuesOf(without, fixed));
    if (!holdout.empty()) b.holdout_rms_deg_without = h.rms_deg;
    b.taken_back = true;
    b.reason =
        "took back " + (b.name == kTermsEffect ? "the terms found in the data" : b.name) +
        ": after " + winner_label +
        (b.size_significant ? " it is not identifiable" : " its size is indistinguishable from 0") +
        " (" + keep + " <= " + Format("%g", options.min_delta_bic) + "; training RMS " +
        Format("%.4f", LoopRms(training, current)) + " -> " + Format("%.4f", b.rms_deg_without) +
        " " + s->summary.unit +
        (holdout.empty() ? std::string()
                         : ", held out " + Format("%.4f", current_holdout.rms_deg) + " -> " +
                               Format("%.4f", h.rms_deg) + " " + s->summary.unit) +
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
}

}  // namespace ccsrm::identify::internal
