// The loop's last stage (loop_state.h): the final model, where the
// residual remains, and the conclusion.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "ccsrm/sim/declared_values.h"
#include "ccsrm/sim/effects.h"
#include "loop_state.h"

namespace ccsrm::identify::internal {

namespace {

// The additions as the summary lists them: effects, declared corrections
// ("the declared X is off by Δ ± σ"), the discovered moment per segment
// and axis, and the corrected configuration.
void ListAdditions(LoopState* state) {
  const std::vector<Experiment>& training = state->training;
  LoopSummary& summary = state->summary;
  const IdentificationSummary& current = state->current;
  const std::map<std::string, double>& fixed = state->fixed;
  const std::vector<std::string>& effects_on = state->effects_on;
  std::map<std::string, std::vector<std::string>>& winner_indistinguishable =
      state->winner_indistinguishable;
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
  if (state->IsAdded(kTermsEffect)) {
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
}

// The final model's errors and evidence, and the joint axes whose residual
// stands above its noise: by the rule of the verdict every fit and
// prediction gives (AssessModelAdequacy: beyond unexplained_noise_ratio and
// beyond chance), so the loop never lists an axis its final model's verdict
// calls explained.
void FindUnexplained(LoopState* s) {
  const std::vector<Experiment>& training = s->training;
  const LoopOptions& options = s->options;
  LoopSummary& summary = s->summary;
  const IdentificationSummary& current = s->current;
  const HoldoutResult& current_holdout = s->current_holdout;
  const std::vector<Experiment>& holdout = s->holdout;
  summary.final_fit = current;
  summary.after = current.errors;
  summary.rms_after_deg = LoopRms(training, current);
  summary.holdout_final_rad = current_holdout.simulated;
  if (!holdout.empty()) {
    summary.holdout_rms_after_deg = current_holdout.rms_deg;
    summary.holdout_after = current_holdout.errors;
  }
  std::vector<Eigen::MatrixXd> fitted;
  for (const ExperimentFit& f : current.experiments) fitted.push_back(f.simulated);
  if (fitted.empty()) return;
  summary.final_evidence = DiagnoseResidual(training, fitted);
  std::vector<const Experiment*> recordings;
  std::vector<const Eigen::MatrixXd*> simulated;
  for (std::size_t e = 0; e < training.size() && e < fitted.size(); ++e) {
    recordings.push_back(&training[e]);
    simulated.push_back(&fitted[e]);
  }
  const ModelAdequacy adequacy = AssessModelAdequacy(
      recordings, simulated, options.unexplained_noise_ratio, kAboveNoiseSignificance);
  const auto above_noise = [&](const std::string& name, const ChannelDiagnostics& ch) {
    return std::any_of(adequacy.above_noise.begin(), adequacy.above_noise.end(),
                       [&](const ChannelAboveNoise& c) {
                         return c.recording == name && c.joint == ch.joint && c.axis == ch.axis &&
                                c.point == ch.point;
                       });
  };
  // Where the residual remains.
  for (const ChannelDiagnostics& ch : summary.final_evidence.channels) {
    const ExperimentDiagnostics& ed = summary.final_evidence.experiments[ch.experiment];
    if (!above_noise(ed.name, ch)) continue;
    UnexplainedChannel u;
    u.experiment = ed.name;
    u.joint = ch.joint;
    u.axis = ch.axis;
    u.point = ch.point;
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
}

}  // namespace

LoopSummary Conclude(LoopState* s) {
  ListAdditions(s);
  FindUnexplained(s);
  const LoopOptions& options = s->options;
  LoopSummary& summary = s->summary;
  const bool declared_ok = s->declared_ok;
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
    const bool points = summary.unit == "mm";
    const char* axis = points ? "point coordinate" : "joint axis";
    const char* axes = points ? "point coordinates" : "joint axes";
    if (summary.unexplained.empty()) {
      conclusion << " The residual is at the noise floor: no " << axis
                 << " stands above its noise (beyond "
                 << Format("%g", options.unexplained_noise_ratio) << "x it and beyond chance).";
    } else {
      const UnexplainedChannel& u = summary.unexplained.front();
      conclusion << " Unexplained residual remains in " << summary.unexplained.size() << " " << axes
                 << " (beyond " << Format("%g", options.unexplained_noise_ratio)
                 << "x their noise and beyond chance); the largest: " << u.experiment << " "
                 << ChannelName(u.joint, u.axis, u.point) << " " << Format("%.4f", u.rms_deg) << " "
                 << summary.unit << " against " << Format("%.4f", u.noise_deg) << ", worst in "
                 << u.worst_phase << ".";
    }
  }
  summary.conclusion = conclusion.str();
  summary.simulations = s->simulations;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - s->clock_start).count();
  s->Progress(static_cast<int>(summary.rounds.size()), "done", "", summary.conclusion);
  return std::move(summary);
}

}  // namespace ccsrm::identify::internal
