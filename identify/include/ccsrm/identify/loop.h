#pragma once
// Closing the loop (SPEC 7): fit the declared model, find the evidence its
// residual leaves, trace it to an effect of the effect library, add the
// effect, refit, and report the error before and after.
//
// One round:
//  1. Diagnose the residual of the current fit (diagnostics.h): the
//     evidence reported beside each candidate.
//  2. Score every candidate not yet added, cheaply: at the fitted point, the
//     sensitivity of the simulated angles to each of the candidate's size
//     parameters (one simulation per parameter and training experiment, a
//     secant from 0 to the parameter's realistic magnitude; a measurement
//     effect's columns come from the fitted runs, with no simulation) is
//     added to the fitted Jacobian, and the score is how much of the
//     weighted residual the augmented linear model removes beyond the
//     declared one, in effective chi-square units (times N_eff / N): the
//     score test. Its p-value is that of a chi-square with as many degrees
//     of freedom as the candidate has size parameters.
//  3. Refit the best few whose score is significant (p below
//     score_significance over the number of candidates: Bonferroni), with
//     the declared free parameters and the candidate's size parameters
//     free, starting from the linearised estimate.
//  4. Accept a refit only if all three hold:
//     - information criterion: ΔBIC = Δχ²_eff - k ln N_eff > min_delta_bic
//       (10: "very strong" evidence on Kass & Raftery's scale), with
//       Δχ²_eff = 2 (cost before - cost after) N_eff / N and N_eff the
//       smaller of the two fits' (the more autocorrelated residual: the
//       conservative count). "Before" is the larger of the current fit's
//       cost and the cost at the refit's point with the candidate's size
//       parameters at 0: a refit also moves the declared parameters, and
//       where the current fit stopped short of its optimum that move alone
//       lowers the cost; it is not the candidate's gain;
//     - held-out error (when held-out experiments are given): their mean
//       square error falls, from the same "before", by more than holdout_z
//       standard errors of a mean square of N_eff,holdout independent
//       samples, MS_after · sqrt(2 / N_eff) (2: chance alone gives such a
//       gain about 2 % of the time);
//     - size: at least one of its size parameters is identifiable with a
//       95 % interval that excludes 0, or together they are: removing the
//       effect at the refit's point raises the effective chi-square beyond
//       the 95 % quantile of a chi-square of k degrees of freedom (its
//       size's 95 % confidence region excludes 0; for an effect whose
//       parameters the data see only in combination, like a delay's time
//       constant and dead time). An effect indistinguishable from absent is
//       not added.
//     And it must explain the residual, not a sliver of it (issue 28): when
//     the residual after its refit is still above unexplained_noise_ratio
//     times the noise (weighted mean square above its square), it must
//     remove at least min_excess_share of the current fit's excess mean
//     square over the noise, (MS_current - MS_after) / (MS_current - 1) in
//     noise units (from the current fit, not from "before": a refit that
//     moves the declared parameters far has a poor point without it);
//     otherwise it is not named as the cause and the residual is reported
//     as not explained.
//  5. The winner has the largest ΔBIC. Candidates within tie_delta_bic of
//     it (2: "not worth more than a bare mention") tie; of those the one
//     with the fewest parameters wins, and the tie is reported.
//  6. Backward step (issue 28): after the winner is added, every earlier
//     addition (effect, declared value, discovered terms) is checked in the
//     new fit by the size test of step 4. One whose size is now
//     indistinguishable from 0 is refitted away (its parameters back at
//     their declared value or off) from the new fit's point, and taken back
//     when keeping it is not worth min_delta_bic (ΔBIC of keeping it, the
//     refit without it against the new fit, <= 10): at most one per round,
//     the least useful first; the others are checked again after the next
//     addition. A taken-back candidate is not tried again (no cycles).
// Rounds repeat until no candidate earns its place or max_rounds.
//
// Declared values (issue 28, sim/declared_values.h): the configuration's
// measured values (a segment's hole circle radius, link length, mass and
// inertia, pulley radii and wrap angle; the joint disk gap, the cables'
// E·A, the input offset) are candidates too, "declared.<value>", a relative
// error of the declared value. They are scored in blocks (a segment, the
// arm-wide values: the block's columns together) and one by one; a value
// is refitted only when its block is significant, and values whose
// sensitivity the data cannot tell apart (their columns, beyond what the
// fit's own remove, correlate above 0.99, or their scores differ by less
// than tie_delta_bic) are reported together as a combination: the best
// scoring one is refitted and stands for them. A value that earns its place is reported as "the
// declared X is off by Δ ± σ", and the corrected configuration is written (calibrated.yaml).
//
// Terms found in the data (issue 28, "terms"): when no effect of the library
// earns its place in a round (a declared value may: the terms then compete
// with it by ΔBIC) and the residual is still structured (its weighted mean
// square above unexplained_noise_ratio², or correlated with one of the
// effects' signals), a moment at every joint axis is sought as a sparse
// combination of joint_moment's terms in the joint's own angle and rate, the
// bending rate its inputs command, and time (sim::JointMomentTerms(); one
// coefficient per segment, axis and term). Each term's column is one
// simulation per training experiment; sequentially thresholded least squares
// on them (term_discovery.h) picks the combination with the best linear ΔBIC,
// simpler terms winning ties; if that ΔBIC passes min_delta_bic the
// combination is refitted and judged by every criterion above, held-out error
// and the partial-explanation rule included. Reported as a formula per
// segment's joints and axis (LoopSummary::discovered_terms).
//
// Experiments of tracked points (issue 46) go through the same rounds: the
// residual, the scores and the refits are the fit's (each run placed in the
// capture frame by its best rigid motion), the evidence is per point
// coordinate, and every RMS figure is the points' Euclidean RMS error in mm
// (LoopSummary::unit). Measurement effects act on recorded joint angles:
// they are no candidates there. The loop takes one kind at a time.
//
// At the end, every (experiment, joint, axis) whose residual stands above its
// noise by the verdict's rule (adequacy.h: RMS beyond unexplained_noise_ratio,
// 1.5, times its noise and beyond chance) is reported as unexplained, with
// the phase of the protocol where it is largest.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/identify/diagnostics.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"

namespace ccsrm::identify {

// The loop's default declared free parameters: the kinetic friction of the
// driving and the connecting cables and the connecting cables' pre-tension,
// the three that every case of the paper's arm is sensitive to and that
// effects most often trade with. Fewer than SPEC 6's nine keep every
// candidate's refit affordable (each Jacobian is 2 runs per free parameter
// and experiment).
std::vector<std::string> LoopDeclaredParameterNames();

struct LoopProgress {
  int round = 0;          // 0: the declared model's fit
  std::string stage;      // "declared fit", "scoring", "refit", "holdout", "done"
  std::string candidate;  // when it concerns one
  std::string message;    // one line for the terminal
};

struct LoopOptions {
  // The declared model's fit: free parameters (default
  // LoopDeclaredParameterNames()), values, bounds, threads, solver settings.
  // Every refit uses the same settings with the candidate's size parameters
  // added.
  IdentificationOptions fit = [] {
    IdentificationOptions o;
    o.free_parameters = LoopDeclaredParameterNames();
    return o;
  }();
  // The backend of the held-out experiments (null: threads on this machine);
  // fit.backend is the training experiments'.
  std::shared_ptr<SimulationBackend> holdout_backend;
  // The candidate effects, by name, "declared" for every declared value of
  // the arm, and "terms" for terms found in the data. Default: every effect
  // of the library (sim::Effects() with `library`) that the declared model
  // does not have on, the declared values, and terms.
  std::vector<std::string> candidates;
  // At most this many rounds (effects added). Default 3.
  int max_rounds = 3;
  // Refits per round: the best-scoring significant effects. Default 2.
  int refits_per_round = 2;
  // And the best-scoring significant declared values (their own budget, so
  // that they never take an effect's refit). Default 1.
  int declared_refits_per_round = 1;
  // Family-wise significance of the score test over a round's candidates.
  // Default 0.01.
  double score_significance = 0.01;
  // Acceptance thresholds (see above). Defaults 10, 2, 2.
  double min_delta_bic = 10.0;
  double holdout_z = 2.0;
  double tie_delta_bic = 2.0;
  // A channel is unexplained above this RMS over its noise (and beyond
  // chance: AssessModelAdequacy). Default 1.5.
  double unexplained_noise_ratio = 1.5;
  // The partial-explanation rule (above): a candidate after whose refit the
  // residual stays above unexplained_noise_ratio times the noise must
  // remove at least this share of the excess mean square. Default 1/3: of
  // two effects of equal size, the first found removes about half
  // (validation: table tilt with a delay, 48 %); the joint friction
  // on an arm of wrong geometry removed about a quarter.
  double min_excess_share = 1.0 / 3.0;
  // Terms found in the data: a smaller combination of terms that removes
  // all but this share of the best combination's linear Δχ²_eff ties with
  // it (the sensitivity columns are secants: first order). Default 0.05.
  double term_share = 0.05;
  std::function<void(const LoopProgress&)> on_progress;

  bool IsValid(std::string* error) const;
};

struct CandidateResult {
  std::string name;
  // "effect", "declared block" (scored only), "declared value" or
  // "discovered terms".
  std::string kind = "effect";
  // Declared values whose sensitivity the data cannot tell apart from this
  // one's: it stands for their combination.
  std::vector<std::string> indistinguishable;
  std::vector<std::string> parameters;  // its size parameters (free in its refit)
  // Score test.
  double score = 0.0;  // Δχ²_eff the linearised candidate removes
  double p_value = 1.0;
  bool significant = false;
  std::map<std::string, double> linearised;  // its size parameters' linear estimates
  // Its fingerprint's signals in the residual (pooled), for the report.
  std::vector<SignalEvidence> evidence;
  // Refit (when refitted).
  bool refitted = false;
  // The cost (1/2 Σ r²) its gain is counted from: the larger of the current
  // fit's and the refit's with the candidate's size parameters at 0.
  double cost_without = 0.0;
  double delta_bic = 0.0;
  double rms_deg = 0.0;  // training, after its refit
  std::optional<double> holdout_rms_deg;
  std::optional<double> holdout_rms_without_deg;  // the refit without the candidate, held out
  bool holdout_improved = false;
  bool size_significant = false;
  // The partial-explanation rule: the share of the excess mean square over
  // the noise its refit removes, the weighted mean square after (noise
  // units), and whether the rule refused it.
  double excess_share = 0.0;
  double mean_square_after = 0.0;
  bool partial = false;
  std::string termination;
  // Discovered terms: the sparse regression's elimination path, every
  // support from all terms down to one, with its linear Δχ²_eff and ΔBIC.
  struct TermSupport {
    std::vector<std::string> parameters;
    double delta_chi2_eff = 0.0;
    double delta_bic = 0.0;
  };
  std::vector<TermSupport> term_path;
  std::map<std::string, ParameterEstimate> estimates;  // its size parameters
  std::int64_t simulations = 0;
  bool accepted = false;
  std::string reason;  // why (not) accepted, one line
};

// The backward step's check of an earlier addition after a round's winner
// was added (issue 28).
struct BackwardCheck {
  std::string name;  // as in added_effects: an effect, declared.<value>, joint_moment
  std::vector<std::string> parameters;
  // The size test in the new fit: an interval excludes 0, or setting its
  // parameters to 0 at the new fit's point costs more than the 95 %
  // quantile (delta_chi2_zeroed, effective units; NaN when not needed).
  bool size_significant = true;
  double delta_chi2_zeroed = std::numeric_limits<double>::quiet_NaN();
  // The refit without it, from the new fit's point (when refitted).
  bool refitted = false;
  double delta_bic_keep = std::numeric_limits<double>::quiet_NaN();  // of keeping it
  double rms_deg_without = std::numeric_limits<double>::quiet_NaN();
  std::optional<double> holdout_rms_deg_without;  // when taken back
  bool taken_back = false;
  std::string reason;  // one line; when taken back: "took back X: ..."
};

struct LoopRound {
  int index = 1;
  std::vector<std::string> effects_on;  // at the round's start
  double rms_deg = 0.0;                 // training, at the round's start
  std::optional<double> holdout_rms_deg;
  ResidualDiagnostics evidence;
  std::vector<CandidateResult> candidates;  // by score, best first
  std::string winner;                       // empty: none
  std::vector<std::string> tie;             // candidates tied with the winner
  std::string decision;                     // one or two sentences
  // Why no terms were sought when none of the others earned its place.
  std::string discovery;
  // The backward step after the winner's addition: every earlier addition
  // checked (empty when there was none); at most one taken back.
  std::vector<BackwardCheck> backward;
};

// A discovered term's moment on one axis of a segment's joints (issue 28):
// "joints 1-6 θx: M = (-196 ± 12) θ³ N m".
struct DiscoveredMoment {
  int segment = 0;  // 1-based
  int first_joint = 0, last_joint = 0;
  int axis = 0;  // 0 θx, 1 θy
  struct Term {
    std::string name;            // sim::JointMomentTerm::name
    std::string formula;         // "θ³"
    std::string units;           // of the coefficient
    ParameterEstimate estimate;  // the coefficient (joint_moment.segment<k>_<a>_<name>)
  };
  std::vector<Term> terms;
  std::string Formula() const;
};

// A channel (ChannelDiagnostics) whose residual stays above its noise: a
// joint's axis, or a tracked point's coordinate (its fields in deg then in
// mm).
struct UnexplainedChannel {
  std::string experiment;
  int joint = 0;      // 0 for a tracked point's coordinate
  int axis = 0;       // 0 θx, 1 θy; of a tracked point 0 x, 1 y, 2 z
  std::string point;  // the tracked point's name
  double rms_deg = 0.0;
  double noise_deg = 0.0;
  std::string worst_phase;
  double worst_phase_rms_deg = 0.0;
};

// A declared value the loop corrected: "the declared X is off by Δ ± σ".
struct DeclaredCorrection {
  std::string parameter;   // "declared.segment2.link_length"
  std::string config_key;  // "arm.segments[1].link_length_m"
  std::string label;       // "segment 2 link length"
  double declared = 0.0;   // the configuration's value (SI; an angle in rad)
  double relative = 0.0;   // Δ / declared
  double relative_std_error = std::numeric_limits<double>::quiet_NaN();
  double relative_ci95_lower = std::numeric_limits<double>::quiet_NaN();
  double relative_ci95_upper = std::numeric_limits<double>::quiet_NaN();
  bool identifiable = false;
  std::vector<std::string> indistinguishable;  // reported as a combination with these
  double delta() const { return declared * relative; }
  double corrected() const { return declared * (1.0 + relative); }
  std::string Sentence() const;  // "the declared segment 2 link length (...) is off by ..."
};

struct LoopSummary {
  LoopOptions options;  // what the loop ran with (its thresholds go to loop.json)
  // The unit of every RMS figure of the loop (the fields named _deg, and
  // their diagnostics): "deg" over joint angles, "mm" over experiments of
  // tracked points (issue 46; LoopRms: the points' Euclidean RMS error).
  std::string unit = "deg";
  std::vector<LoopRound> rounds;
  // Effects (and joint_moment, the discovered terms) in the final model, in
  // order; an addition the backward step took back is not among them.
  std::vector<std::string> added_effects;
  // Additions the backward step took back (BackwardCheck::taken_back), in order.
  std::vector<BackwardCheck> taken_back;
  std::vector<DeclaredCorrection> declared_corrections;
  // The terms found in the data, when the discovered terms were added
  // (joint_moment among added_effects).
  std::vector<DiscoveredMoment> discovered_terms;
  // The configuration with the corrections and the final fit's values
  // (calibrated.yaml); set when a declared value was corrected.
  std::optional<sim::Config> calibrated;
  IdentificationSummary declared;   // the declared model's fit
  IdentificationSummary final_fit;  // the final model's (== declared when nothing was added)
  double rms_before_deg = 0.0, rms_after_deg = 0.0;
  std::optional<double> holdout_rms_before_deg, holdout_rms_after_deg;
  // Per joint and axis, overall over the experiments: before and after.
  ChannelErrors before, after;
  std::optional<ChannelErrors> holdout_before, holdout_after;
  // Held-out runs of the declared and the final model (for reports).
  std::vector<Eigen::MatrixXd> holdout_declared_rad, holdout_final_rad;
  ResidualDiagnostics final_evidence;
  std::vector<UnexplainedChannel> unexplained;
  std::string conclusion;  // what was found, or that nothing explains the residual
  std::int64_t simulations = 0;
  double wall_time_s = 0.0;
  int threads = 0;

  std::string FullReport() const;
};

// Runs the loop. Throws InputError for invalid options or experiments
// before any simulation runs.
LoopSummary CloseLoop(const std::vector<Experiment>& training,
                      const std::vector<Experiment>& holdout, const LoopOptions& options);

// loop.json (schema ccsrm-loop/1).
nlohmann::json ToJson(const LoopSummary& summary, const std::vector<Experiment>& training,
                      const std::vector<Experiment>& holdout);

// Writes the loop folder: loop.json; calibrated.yaml when a declared value
// was corrected (LoopSummary::calibrated); declared/ and final/ (fit folders of
// the declared and the final model, WriteFitDirectory); holdout/ with, per
// held-out experiment, <name>.angles.csv (time, measured, declared, final
// θx and θy of every joint, deg; of tracked points <name>.declared.points.csv
// and <name>.final.points.csv, mm). Returns the paths written.
std::vector<std::string> WriteLoopDirectory(const LoopSummary& summary,
                                            const std::vector<Experiment>& training,
                                            const std::vector<Experiment>& holdout,
                                            const std::string& directory);

}  // namespace ccsrm::identify
