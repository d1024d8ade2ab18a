#include "ccsrm/identify/loop.h"

#include <cmath>
#include <set>

#include "ccsrm/sim/effects.h"
#include "declared_values.h"
#include "loop_state.h"

namespace ccsrm::identify {

using internal::kTermsCandidate;
using internal::kTermsEffect;

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

// The stages are loop_state.h's, a round at a time.
LoopSummary CloseLoop(const std::vector<Experiment>& training,
                      const std::vector<Experiment>& holdout, const LoopOptions& options) {
  internal::LoopState s(training, holdout, options);
  internal::StartLoop(&s);
  internal::FitDeclaredModel(&s);
  for (int round = 1; s.declared_ok && round <= options.max_rounds; ++round) {
    internal::RoundState r;
    r.round = round;
    if (!internal::GatherEvidence(&s, &r)) break;
    internal::ScoreCandidates(&s, &r);
    internal::RefitSignificant(&s, &r);
    internal::SeekTerms(&s, &r);
    if (!internal::AcceptWinner(&s, &r)) break;
  }
  return internal::Conclude(&s);
}

}  // namespace ccsrm::identify
