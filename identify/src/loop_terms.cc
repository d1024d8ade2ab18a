// Terms found in the data (loop_state.h; issue 28).
#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>

#include "ccsrm/sim/effects.h"
#include "loop_state.h"
#include "term_discovery.h"

namespace ccsrm::identify::internal {

namespace {

// The largest |angle| of `axis` over joints first_joint .. first_joint +
// links - 1 in the current fit: over the measured frames of recorded angles
// (`fitted`, laid out as measured), over the fitted runs' frames for an
// experiment of tracked points, which measures no angle.
double LargestAngle(const std::vector<Experiment>& training, const IdentificationSummary& current,
                    const std::vector<Eigen::MatrixXd>& fitted, int first_joint, int links,
                    int axis) {
  double largest = 0.0;
  for (std::size_t e = 0; e < training.size() && e < fitted.size(); ++e) {
    const Eigen::MatrixXd& a = fitted[e];
    for (int j = first_joint; j < first_joint + links; ++j) {
      if (!training[e].tracked_points.empty()) {
        for (const sim::TrajectoryFrame& frame : current.experiments[e].run.trajectory.frames) {
          const std::size_t k = static_cast<std::size_t>(j - 1);
          if (k < frame.joint_angles.size() && std::isfinite(frame.joint_angles[k][axis]))
            largest = std::max(largest, std::abs(frame.joint_angles[k][axis]));
        }
        continue;
      }
      const Eigen::Index c = 2 * (j - 1) + axis;
      if (c >= a.cols()) continue;
      for (Eigen::Index f = 0; f < a.rows(); ++f) {
        if (std::isfinite(a(f, c))) largest = std::max(largest, std::abs(a(f, c)));
      }
    }
  }
  return largest;
}

}  // namespace

// The discovered terms' candidate of a round (issue 28): one column per
// term, segment and axis (a simulation per training experiment, a secant
// from 0 to the term's realistic coefficient), sparse regression on them
// (term_discovery.h), and the chosen combination as one candidate.
CandidateResult DiscoverTerms(LoopState* state, RoundState* rs) {
  const std::vector<Experiment>& training = state->training;
  const LoopOptions& options = state->options;
  const LoopState::ProgressFunction progress = state->ProgressFunctionOf();
  const sim::ArmSize& arm = state->arm;
  const IdentificationSummary& current = state->current;
  const int round = rs->round;
  const std::vector<Eigen::MatrixXd>& fitted = rs->fitted;
  const std::vector<const Eigen::MatrixXd*>& base_angles = rs->base_angles;
  const Eigen::VectorXd& r = rs->r;
  const Eigen::MatrixXd& jb = rs->jb;
  const double neff_ratio = rs->neff_ratio;
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
      const double largest = LargestAngle(training, current, fitted, first_joint, links, axis);
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
  std::vector<RunResult> results = state->training_backend->RunBatch(
      requests, [&](std::size_t finished, std::size_t total, const RunResult&) {
        if (finished == total || finished % 8 == 0) {
          progress(
              round, "discovery", cand.name,
              "  term sensitivity runs " + std::to_string(finished) + "/" + std::to_string(total));
        }
      });
  state->simulations += static_cast<std::int64_t>(requests.size());
  cand.simulations = static_cast<std::int64_t>(requests.size());
  bool complete = true;
  for (std::size_t k = 0; k < results.size(); ++k) {
    complete = complete && results[k].summary.completed();
    angles[request_column[k]][requests[k].experiment] = std::move(results[k].simulated);
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
    cand.reason = std::string("no term moves the ") +
                  (state->summary.unit == "mm" ? "tracked points" : "angles") +
                  " beyond what the fit's own parameters do";
    return cand;
  }
  const internal::TermSupport& chosen = selection.path[static_cast<std::size_t>(selection.chosen)];
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
                  Format("%.1f", chosen.delta_bic) + " <= " + Format("%g", options.min_delta_bic) +
                  ": no term explains enough of it";
  }
  return cand;
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
void SeekTerms(LoopState* s, RoundState* rs) {
  const LoopOptions& options = s->options;
  const IdentificationSummary& current = s->current;
  LoopRound& lr = rs->lr;
  const Eigen::VectorXd& r = rs->r;
  bool effect_accepted = false;
  for (const CandidateResult& c : lr.candidates) {
    effect_accepted |= c.accepted && c.kind == "effect";
  }
  if (!effect_accepted && rs->discovery_left) {
    const double ms_current =
        2.0 * current.final_cost / static_cast<double>(std::max<Eigen::Index>(r.size(), 1));
    bool correlated = false;
    for (const SignalEvidence& e : lr.evidence.pooled) correlated |= e.significant();
    const double unexplained_ms = options.unexplained_noise_ratio * options.unexplained_noise_ratio;
    // Or more than a tenth of the joint axes above the unexplained level:
    // a residual the overall mean square dilutes. Null data leave a few
    // (the validation's: 2 of 48, 4 %); friction that grows with the angle,
    // after joint friction took what it could, left 12 of 48.
    std::size_t above = 0;
    for (const ChannelDiagnostics& ch : lr.evidence.channels) {
      above += ch.rms_deg > options.unexplained_noise_ratio * ch.noise_deg;
    }
    const bool widespread = 10 * above > lr.evidence.channels.size();
    // No work past the answer (issue 44): a residual at or below the noise
    // overall, on nearly every axis, holds nothing the noise cannot; a
    // signal it still follows is one the noise can follow by chance too
    // (the loop sample of issue 44 sought terms for 108 runs at 0.0282 deg
    // against 0.0329 deg of noise).
    const bool at_noise = ms_current <= 1.0 && !widespread;
    const std::string channels = s->summary.unit == "mm" ? " point coordinates" : " joint axes";
    if (at_noise) {
      lr.discovery = "no terms sought: the residual is at the noise (weighted mean square " +
                     Format("%.3g", ms_current) + ", 1 = the noise) on all but " +
                     std::to_string(above) + channels + ".";
    } else if (ms_current > unexplained_ms || correlated || widespread) {
      CandidateResult cand = DiscoverTerms(s, rs);
      if (cand.significant) RefitAndJudge(s, rs, &cand);
      lr.candidates.push_back(std::move(cand));
    } else {
      lr.discovery = "no terms sought: the residual is within " +
                     Format("%g", options.unexplained_noise_ratio) +
                     "x the noise overall and on all but " + std::to_string(above) + channels +
                     ", and follows none of the effects' signals.";
    }
  }
}

}  // namespace ccsrm::identify::internal
