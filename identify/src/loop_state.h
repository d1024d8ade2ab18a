#pragma once
// CloseLoop's stages (loop.h) over one loop state, each stage a function:
//   StartLoop          the candidates and the backends
//   FitDeclaredModel   the declared model's fit, training and held out
//   then each round:
//     GatherEvidence     the residual's evidence, the candidates left
//     ScoreCandidates    sensitivity columns and the score test
//     RefitSignificant   the best significant few refitted and judged
//     SeekTerms          terms found in the data, when nothing passes
//     AcceptWinner       the winner added, then the backward step
//   Conclude           the final model, where the residual remains, the
//                      conclusion
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ccsrm/identify/loop.h"
#include "declared_values.h"
#include "text.h"

namespace ccsrm::identify::internal {

inline constexpr double kDeg = 180.0 / M_PI;

// The candidate name that asks for the discovery of terms, and the effect
// that carries them (sim/effects.h).
inline constexpr const char* kTermsCandidate = "terms";
inline constexpr const char* kTermsEffect = "joint_moment";

// The held-out experiments at a fit's values.
struct HoldoutResult {
  std::vector<Eigen::MatrixXd> simulated;
  double rms_deg = 0.0;  // LoopRms: mm over tracked points
  double mean_square = 0.0;  // weighted, per sample
  double effective_samples = 0.0;
  ChannelErrors errors;
  bool ok = true;
};

// Weighted residual layout of FitProblem: experiment, frame, column, measured
// entries only; (angles - measured) / noise, or (angles - base) / noise with
// difference_only.
Eigen::VectorXd Weighted(const std::vector<Experiment>& experiments,
                         const std::vector<const Eigen::MatrixXd*>& angles, bool difference_only,
                         const std::vector<const Eigen::MatrixXd*>& base = {});

// The loop's RMS error of simulated runs (laid out as Experiment::measured):
// of the angles [deg] over every measured joint axis (AngleErrors), or of
// experiments of tracked points the points' Euclidean RMS error [mm] over
// every point and frame measured; and of a fit's final runs.
double LoopRms(const std::vector<const Experiment*>& experiments,
               const std::vector<const Eigen::MatrixXd*>& simulated);
double LoopRms(const std::vector<Experiment>& experiments, const IdentificationSummary& fit);

// How much of r a least-squares fit of columns A removes: ||r||² - min ||r + A x||².
double Reduction(const Eigen::VectorXd& r, const Eigen::MatrixXd& a, Eigen::VectorXd* x);

// The secant step of a size parameter in the score test.
double ScoreStep(const std::string& name, const sim::ArmSize& arm);

// The parameters of an experiment at values (over its nominal configuration).
sim::ArmParameters ParametersFor(const Experiment& e, const std::map<std::string, double>& values);

// Every value a fit leaves: the options' values, then the free estimates.
std::map<std::string, double> ValuesOf(const IdentificationSummary& fit,
                                       const std::map<std::string, double>& fixed);

// What the loop knows between its stages.
struct LoopState {
  LoopState(const std::vector<Experiment>& training, const std::vector<Experiment>& holdout,
            const LoopOptions& options)
      : training(training), holdout(holdout), options(options) {}

  const std::vector<Experiment>& training;
  const std::vector<Experiment>& holdout;
  const LoopOptions& options;
  std::chrono::steady_clock::time_point clock_start = std::chrono::steady_clock::now();
  sim::ArmSize arm;                      // of the experiments
  std::vector<std::string> candidates;   // as given, or every one
  std::vector<LoopCandidateSpec> specs;  // the scored candidates
  bool discovery_on = false;             // 'terms' among the candidates
  std::shared_ptr<SimulationBackend> training_backend, holdout_backend;
  std::int64_t simulations = 0;
  LoopSummary summary;
  bool declared_ok = false;  // the declared fit did not fail

  // The current model: its fit, held out, its free and fixed values.
  IdentificationSummary current;
  HoldoutResult current_holdout;
  std::vector<std::string> free;
  std::map<std::string, double> fixed;
  // Effects and declared values added, in order; each addition's parameters
  // (free in every later fit); those the backward step took back (not tried
  // again, so that the loop cannot cycle); the declared values a winner
  // stands for.
  std::vector<std::string> effects_on;
  std::map<std::string, std::vector<std::string>> added_parameters;
  std::set<std::string> taken_back;
  std::map<std::string, std::vector<std::string>> winner_indistinguishable;

  void Progress(int round, const std::string& stage, const std::string& candidate,
                const std::string& message) const;
  // Progress as a function, for a stage's lines.
  using ProgressFunction =
      std::function<void(int round, const std::string& stage, const std::string& candidate,
                         const std::string& message)>;
  ProgressFunction ProgressFunctionOf() const;
  bool IsAdded(const std::string& name) const;
  HoldoutResult RunHoldout(const std::map<std::string, double>& values);
  // The training cost (1/2 Σ r², weighted) at values; NaN when a run fails.
  double TrainingCost(const std::map<std::string, double>& values);
};

// What one round knows between its stages.
struct RoundState {
  int round = 0;
  LoopRound lr;
  std::vector<Eigen::MatrixXd> fitted;       // the current fit's angles
  std::vector<LoopCandidateSpec> remaining;  // not yet added
  bool discovery_left = false;
  std::vector<const Eigen::MatrixXd*> base_angles;  // into fitted
  Eigen::VectorXd r;                                // the current weighted residual
  Eigen::MatrixXd jb;                               // its Jacobian
  double neff_ratio = 1.0;                          // N_eff / N
  // Each sensitivity column in the weighted residual's units, per unit of
  // its parameter.
  std::map<std::string, Eigen::VectorXd> weighted_column;
  std::map<std::string, IdentificationSummary> refit_fits;
  std::map<std::string, HoldoutResult> refit_holdouts;
};

void StartLoop(LoopState* s);
void FitDeclaredModel(LoopState* s);
// False when nothing is left to try: the round is recorded and the loop ends.
bool GatherEvidence(LoopState* s, RoundState* round);
void ScoreCandidates(LoopState* s, RoundState* round);
void RefitSignificant(LoopState* s, RoundState* round);
void RefitAndJudge(LoopState* s, RoundState* round, CandidateResult* cand);
void SeekTerms(LoopState* s, RoundState* round);
CandidateResult DiscoverTerms(LoopState* s, RoundState* round);
// False when no candidate earns its place: the round is recorded and the
// loop ends.
bool AcceptWinner(LoopState* s, RoundState* round);
void BackwardStep(LoopState* s, int round, const std::string& winner_label, LoopRound* lr);
LoopSummary Conclude(LoopState* s);

}  // namespace ccsrm::identify::internal
