// The round's first stages (loop_state.h): the evidence in the residual,
// and the score test of every candidate left.
#include <gsl/gsl_cdf.h>

#include <Eigen/QR>
#include <algorithm>
#include <limits>

#include "ccsrm/sim/effects.h"
#include "loop_state.h"

namespace ccsrm::identify::internal {

namespace {

using Spec = LoopCandidateSpec;

// The sensitivity columns of every remaining candidate's size parameters,
// one per parameter, shared by the candidates that have it (a block and its
// members): a measurement effect's recorded from the fitted run, the
// others' simulated.
void SensitivityColumns(LoopState* s, RoundState* rs) {
  const std::vector<Experiment>& training = s->training;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const sim::ArmSize& arm = s->arm;
  const IdentificationSummary& current = s->current;
  const int round = rs->round;
  const std::vector<Spec>& remaining = rs->remaining;
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
          Eigen::MatrixXd a = Eigen::MatrixXd::Constant(f.simulated.rows(), f.simulated.cols(),
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
    std::vector<RunResult> results = s->training_backend->RunBatch(
        requests, [&](std::size_t finished, std::size_t total, const RunResult&) {
          if (finished == total || finished % 4 == 0) {
            progress(
                round, "scoring", "",
                "  sensitivity runs " + std::to_string(finished) + "/" + std::to_string(total));
          }
        });
    s->simulations += static_cast<std::int64_t>(requests.size());
    for (std::size_t k = 0; k < results.size(); ++k) {
      columns[request_column[k]].angles[requests[k].experiment] = std::move(results[k].simulated);
    }
  }
  for (const Eigen::MatrixXd& a : rs->fitted) rs->base_angles.push_back(&a);
  // Each column in the weighted residual's units, per unit of its parameter.
  for (const Column& col : columns) {
    std::vector<const Eigen::MatrixXd*> ca;
    for (const Eigen::MatrixXd& m : col.angles) ca.push_back(&m);
    rs->weighted_column[col.parameter] = Weighted(training, ca, true, rs->base_angles) / col.step;
  }
}

// Declared values the data cannot tell apart: beyond what the fit's own
// columns remove, their columns are (anti)parallel. A significant one
// stands for the combination.
void MarkIndistinguishable(const LoopOptions& options, RoundState* rs) {
  const Eigen::MatrixXd& jb = rs->jb;
  LoopRound& lr = rs->lr;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jb);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(jb.rows(), qr.rank());
  std::map<std::string, Eigen::VectorXd> beyond;
  for (const CandidateResult& c : lr.candidates) {
    if (c.kind != "declared value") continue;
    const Eigen::VectorXd& v = rs->weighted_column.at(c.parameters.front());
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

}  // namespace

bool GatherEvidence(LoopState* s, RoundState* rs) {
  const std::vector<Experiment>& training = s->training;
  const std::vector<Experiment>& holdout = s->holdout;
  const IdentificationSummary& current = s->current;
  const std::vector<std::string>& effects_on = s->effects_on;
  const std::set<std::string>& taken_back = s->taken_back;
  const std::vector<Spec>& specs = s->specs;
  const int round = rs->round;
  const HoldoutResult& current_holdout = s->current_holdout;
  LoopRound& lr = rs->lr;
  lr.index = round;
  lr.effects_on = effects_on;
  lr.rms_deg = LoopRms(training, current);
  if (!holdout.empty()) lr.holdout_rms_deg = current_holdout.rms_deg;
  std::vector<Eigen::MatrixXd>& fitted = rs->fitted;
  for (const ExperimentFit& f : current.experiments) fitted.push_back(f.simulated);
  lr.evidence = DiagnoseResidual(training, fitted);

  // Not yet added; a block keeps the members not yet added.
  std::vector<Spec>& remaining = rs->remaining;
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
  rs->discovery_left =
      s->discovery_on && !s->IsAdded(kTermsEffect) && !taken_back.count(kTermsEffect);
  if (remaining.empty() && !rs->discovery_left) {
    lr.decision = "every candidate is already in the model.";
    s->summary.rounds.push_back(std::move(lr));
    return false;
  }
  return true;
}

void ScoreCandidates(LoopState* s, RoundState* rs) {
  const LoopOptions& options = s->options;
  const LoopState::ProgressFunction progress = s->ProgressFunctionOf();
  const sim::ArmSize& arm = s->arm;
  const IdentificationSummary& current = s->current;
  const std::vector<Spec>& remaining = rs->remaining;
  LoopRound& lr = rs->lr;
  const int round = rs->round;
  SensitivityColumns(s, rs);
  rs->r = current.weighted_residuals;
  rs->jb = current.jacobian;
  const Eigen::VectorXd& r = rs->r;
  const Eigen::MatrixXd& jb = rs->jb;
  const double n = static_cast<double>(r.size());
  rs->neff_ratio = n > 0.0 && current.effective_samples > 0.0 ? current.effective_samples / n : 1.0;
  const double neff_ratio = rs->neff_ratio;
  const double base_reduction = Reduction(r, jb, nullptr);
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
    const std::vector<std::string>& cols = remaining[c].parameters;
    cand.parameters = cols;
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
        a.col(jb.cols() + static_cast<Eigen::Index>(k)) = rs->weighted_column.at(cols[idx[k]]);
      }
      reduction = Reduction(r, a, &x) - base_reduction;
      bool changed = false;
      for (std::size_t k = 0; k < idx.size(); ++k) {
        const sim::ParameterInfo& info = sim::FindParameter(cols[idx[k]], "loop", arm);
        const double value = x[jb.cols() + static_cast<Eigen::Index>(k)];
        if (value < info.lower || value > info.upper) {
          active[idx[k]] = false;
          changed = true;
        } else {
          cand.linearised[cols[idx[k]]] = value;
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
  MarkIndistinguishable(options, rs);
  for (const CandidateResult& c : lr.candidates) {
    progress(round, "scoring", c.name,
             "  " + c.name + ": score " + Format("%.1f", c.score) + ", p " +
                 Format("%.2g", c.p_value) + (c.significant ? " (significant)" : ""));
  }
}

}  // namespace ccsrm::identify::internal
