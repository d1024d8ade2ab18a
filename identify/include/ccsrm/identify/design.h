#pragma once
// Experiment design (issue 26): how well a plan of motions would pin the
// free parameters down, before anything is recorded.
//
// A plan is one or more planned experiments (a motion driving the arm,
// recorded at the mocap rate). Its information about the free parameters is
// the Fisher information JᵀΣ⁻¹J of the identification's own residuals: J is
// the Jacobian of the simulated joint angles at the plan's frames with
// respect to the free parameters at their prior values (the
// identification's central finite differences, ccsrm::identify::Identify),
// Σ the measurement noise (white, noise_deg on every angle, the effective
// samples N_eff/N applied as the identification applies them), summed over
// the plan's experiments. Its inverse is the covariance a fit of such
// recordings would report to first order.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/runs.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::identify {

// One experiment of a plan: a motion and the arm it drives.
struct PlannedExperiment {
  std::string name;  // e.g. "paper.yaml (amplitude_deg = 6)"
  // The arm's configuration, its parameters at the prior values (those of
  // the free parameters are where the information is evaluated).
  sim::Config config;
  std::shared_ptr<const sim::ArmModel> model;
  std::shared_ptr<const sim::CableInputs> inputs;
  double duration_s = 0.0;  // recorded from 0 to this time [s]
};

// A candidate plan: experiments recorded and fitted together.
struct DesignCandidate {
  std::string name;
  std::vector<PlannedExperiment> experiments;
  // The protocol text of a proposed plan (ProposeDesign), to write out.
  std::string protocol_yaml;
};

// A range of a parameter's value the design should hold over: the truth
// may be anywhere in it.
struct PriorRange {
  std::string name;  // a parameter (sim::Parameters()), free or not
  double lower = 0.0;
  double upper = 0.0;
};

struct DesignOptions {
  // The parameters a fit would free, by name (sim::Parameters()). Required.
  std::vector<std::string> free_parameters;
  // Standard deviation of every measured joint angle [deg]. Default: the
  // 0.03 deg floor of 0.2 mm marker noise, which identification also uses
  // when a recording says nothing better.
  double noise_deg = kMocapNoiseFloorDeg;
  // N_eff / N of the recordings' residuals: below 1 when the noise of
  // successive frames is correlated (a low-pass, drifting markers), which
  // identification measures and corrects for; a fit.json of a lab's own
  // recordings gives it as effective_samples / residuals. Default 1: white
  // noise.
  double effective_sample_fraction = 1.0;
  // Mocap frames per second: the samples a fit compares. Default 100.
  double frame_rate_hz = 100.0;
  // The zero-lag Butterworth low-pass the planned recordings' angles will
  // pass through (a fit filters its simulated angles alike): cutoff [Hz],
  // order per pass, shortest run filtered [frames]. Default: the mocap
  // pipeline's (mocap::ProcessingOptions: 1 Hz, order 2, 4 frames; a test
  // checks they agree); cutoff
  // 0 for angles measured without one (encoders). The filter removes what a
  // motion tells above the cutoff: on reversals of 4 s moves, a design
  // without it predicted mu_c's error 1.5 times too small.
  double low_pass_hz = 1.0;
  int low_pass_order = 2;
  int low_pass_min_run_frames = 4;
  // The identification's relative finite-difference step. Default 1e-2.
  double relative_step = 1e-2;
  int threads = DefaultThreads();
  // Another backend for the simulations (null: threads on this machine):
  // one over DesignExperiments(candidates, options), every candidate's
  // experiments in the order given (an MPI job's, a journal's).
  std::shared_ptr<SimulationBackend> backend;
  // Called after every simulation; may be empty.
  RunFinishedCallback on_run;
  // Prior uncertainty (robust design): the best robust_candidates plans at
  // the prior are evaluated again at every corner of this box (2^k corners,
  // k <= 6 ranges), each relative error taken against the corner's value,
  // and ranked by their worst case over the prior and the corners, ahead of
  // the plans evaluated at the prior only. Screening at the prior keeps the
  // cost at 2^k × robust_candidates evaluations instead of 2^k × all plans.
  // Empty (default): the prior alone.
  std::vector<PriorRange> prior_box;
  int robust_candidates = 3;
  // The predicted errors are those of a fit only where the joint angles are
  // smooth in the free parameters at the prior; with static friction well
  // above kinetic, fast motions run into stick–slip and are not (docs/
  // model-notes.md, issue 43). So the best plans, in rank order, have their
  // derivatives checked as a fit checks its own (IdentificationOptions::
  // check_derivative_steps: the Jacobian again at a third of relative_step,
  // two runs per experiment and free parameter more): a plan whose
  // derivative for a free parameter moves by more than kDerivativeStepLimit
  // (5 %) is not smooth there, and ranks after every other plan. Checking
  // stops at the first smooth plan or after checked_candidates plans.
  // Default 3: the plan the design recommends, and the next ones only while
  // it is not (at the paper's friction one check, at static friction well
  // above kinetic up to three). 0: no check.
  int checked_candidates = 3;

  // False with the reason naming the field: no free parameter, an unknown or
  // repeated name, noise_deg or frame_rate_hz not positive,
  // effective_sample_fraction outside (0, 1], relative_step outside (0, 0.1],
  // low_pass_hz negative or not below half the frame rate, low_pass_order
  // outside 1..8, low_pass_min_run_frames < 2,
  // threads < 1, a prior_box range not finite or not lower < upper, a name
  // given twice, more than 6 ranges, robust_candidates < 1,
  // checked_candidates < 0.
  bool IsValid(std::string* error) const;
};

// A plan's predicted errors with the parameters at one corner of the prior
// box.
struct CornerInformation {
  std::vector<std::pair<std::string, double>> values;  // the box's parameters there
  bool completed = false;
  std::string message;                     // why not
  std::vector<double> relative_std_error;  // of each free parameter, against its value there
  double worst_relative_std_error = 0.0;
  std::string worst_parameter;
};

// What a candidate plan would tell about the free parameters.
struct CandidateInformation {
  std::string name;
  std::string protocol_yaml;  // a proposed plan's protocol; empty for a given one
  std::vector<std::string> experiments;
  double duration_s = 0.0;              // total recording time [s]
  std::size_t samples = 0;              // measured angles compared (N)
  bool completed = false;               // every run completed
  std::string message;                  // why not
  std::vector<std::string> parameters;  // the free parameters, in the options' order
  std::vector<double> prior;            // their values
  // Predicted standard error of each, in its units, and relative to its
  // prior value; inf along a direction the plan does not inform at all.
  std::vector<double> std_error;
  std::vector<double> relative_std_error;
  // The largest relative standard error, and whose (the default criterion).
  double worst_relative_std_error = 0.0;
  std::string worst_parameter;
  // Over the relative covariance C (parameters relative to their priors):
  // D-criterion det(C)^(1/p) (the geometric mean of its eigenvalues: the
  // volume of the confidence ellipsoid) and A-criterion trace(C)/p (the mean
  // variance), both as a standard error: their square roots.
  double d_criterion = 0.0;
  double a_criterion = 0.0;
  // The worst-determined direction: C's largest eigenvalue (its square root,
  // a relative standard error) and eigenvector, largest component first.
  double worst_direction_relative_std_error = 0.0;
  std::vector<std::pair<std::string, double>> worst_direction;
  // Fisher information in relative units (C = its inverse), p × p.
  Eigen::MatrixXd fisher_relative;
  // At the corners of DesignOptions::prior_box, for the plans evaluated
  // there (empty otherwise), and the worst relative error over the prior
  // and those corners (worst_relative_std_error when there are none).
  std::vector<CornerInformation> corners;
  double robust_worst_relative_std_error = 0.0;
  // Per free parameter, how far its derivative at the prior moves between
  // relative steps r and r/3 (ParameterEstimate::derivative_step_
  // disagreement); empty when not checked (DesignOptions::
  // checked_candidates).
  std::vector<double> derivative_step_disagreement;
  std::int64_t simulations = 0;

  bool derivatives_checked() const { return !derivative_step_disagreement.empty(); }
  // Checked, and every free parameter's derivative within
  // kDerivativeStepLimit.
  bool derivatives_smooth() const;
};

struct DesignSummary {
  std::vector<CandidateInformation> candidates;  // in the order given
  // Candidate indices, smallest worst relative error first: with a prior
  // box, those evaluated at its corners first, by their robust worst.
  std::vector<std::size_t> ranking;
  DesignOptions options;
  int threads = 0;
  std::int64_t simulations = 0;
  double wall_time_s = 0.0;

  // The table: a row per candidate in rank order, a column per parameter.
  std::string FullReport() const;
};

// The motions ProposeDesign searches, each filling budget_s, for every
// amplitude A, in every bending plane, with the segments together and (when
// opposed_segments) neighbouring segments in opposite directions:
// - reversals: every segment swings between +A and −A along quintic moves
//   of move_s, holding hold_s after each, as many moves as fill the budget,
//   the last back to straight. They make the cables slide both ways through
//   their holes and stop between, where the static and kinetic friction and
//   the pre-tension show;
// - sines: A·sin(2π f t) over the whole budget (faded in and out over a
//   period), for every f of sine_frequencies_hz;
// - chirps: A·sin φ(t), the frequency swept linearly over the budget, for
//   every band of chirp_bands_hz.
// Sines and chirps are tried only when given (none by default).
struct ProposalSpace {
  std::vector<double> amplitudes_deg = {5.0, 10.0, 20.0};  // A
  std::vector<double> move_times_s = {2.0, 4.0, 8.0};      // move_s
  std::vector<double> sine_frequencies_hz;                 // f
  std::vector<std::pair<double, double>> chirp_bands_hz;   // (start, end)
  // Bending planes φ [deg] (docs/protocols.md: toward (cos φ, sin φ)).
  // Empty (default): θx alone, the paper's plane.
  std::vector<double> planes_deg;
  // Also try the segments swinging in opposite directions (segment 2 at −A
  // while segment 1 is at +A, ...).
  bool opposed_segments = true;
  double hold_s = 1.0;
  double budget_s = 24.0;  // the recording's length [s]

  // False with the reason naming the field: no amplitude, a value not
  // positive or not finite, a chirp band not start < end, budget_s shorter
  // than two moves and holds when move times are given, no motion at all.
  bool IsValid(std::string* error) const;
};

// One point of the space.
struct ProposedMotion {
  enum class Kind { kReversals, kSine, kChirp };
  Kind kind = Kind::kReversals;
  double amplitude_deg = 0.0;
  double move_s = 0.0;        // reversals
  double frequency_hz = 0.0;  // a sine's, a chirp's start
  double end_hz = 0.0;        // a chirp's end
  bool in_plane = false;      // false: θx; true: the plane plane_deg
  double plane_deg = 0.0;
  bool opposed = false;
};

// The protocol (ccsrm-protocol/1 text) of one point of the space on an arm
// of `segments` segments; its name says the point ("reversals A=10 move=4
// opposed", "sine A=10 f=0.25 plane=45").
std::string ProposalProtocolYaml(const ProposedMotion& motion, const ProposalSpace& space,
                                 int segments, std::string* name);

// One experiment of `protocol` on the arm of `prior` (its parameters the
// prior), recorded over the protocol's duration.
PlannedExperiment PlanExperiment(const sim::Config& prior, const sim::Protocol& protocol,
                                 const std::string& name);

// Evaluates every candidate at the prior (and the best at the corners of
// options.prior_box). Throws InputError for invalid
// options, a free parameter whose prior value is 0 (its relative error has
// no meaning: give a prior), or a candidate without experiments. A run
// that diverges is reported in the candidate (completed = false), not
// thrown.
DesignSummary EvaluateDesigns(const std::vector<DesignCandidate>& candidates,
                              const DesignOptions& options);
// The checks EvaluateDesigns makes before any run, each throwing its
// InputError: for a command to refuse bad input before it writes anything.
void CheckDesign(const std::vector<DesignCandidate>& candidates, const DesignOptions& options);

// Evaluates every point of `space` as a plan of one experiment on the arm of
// `prior`, after `given` (plans to compare with). A point whose protocol the
// checks refuse (a bend past the joints' range, a cable faster than the
// protocol limits) is left out and listed in *skipped with the reason.
DesignSummary ProposeDesign(const sim::Config& prior, const ProposalSpace& space,
                            const std::vector<DesignCandidate>& given, const DesignOptions& options,
                            std::vector<std::string>* skipped);
// The candidates ProposeDesign evaluates: `given`, then every point of
// `space` its checks accept. A function of its arguments alone, so that every
// rank of an MPI job builds the same ones.
std::vector<DesignCandidate> ProposalCandidates(const sim::Config& prior,
                                                const ProposalSpace& space,
                                                const std::vector<DesignCandidate>& given,
                                                std::vector<std::string>* skipped);

// Every candidate's experiments as a backend runs them (DesignOptions::
// backend), candidate after candidate in order: recorded at
// options.frame_rate_hz, with no measured angles yet (zeros: a run takes from
// them only where a measurement is missing, and none is).
std::vector<Experiment> DesignExperiments(const std::vector<DesignCandidate>& candidates,
                                          const DesignOptions& options);

// A proposed motion (its protocol text) as planned on the arm of `prior`,
// sampled at rate_hz from 0 to its end: proposed.inputs.csv, a '#' comment
// line naming it, then the header time_s, cable<k>_m (the input lengths,
// pulled in = positive: the table `--inputs` reads), speed_cable<k>_m_s
// (their rates), planned_thetax<j>_deg and planned_thetay<j>_deg, for the
// lab's controller and the report's page.
std::string PlannedMotionCsv(const sim::Config& prior, const std::string& protocol_yaml,
                             const std::string& name, double rate_hz);

// design.json (schema ccsrm-design/1): every number of the summary.
nlohmann::json ToJson(const DesignSummary& summary);

}  // namespace ccsrm::identify
