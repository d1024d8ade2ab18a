// Experiment design (issue 26): the standard errors a plan's Fisher
// information predicts are those identification reports when it fits such a
// recording; information adds over a plan's experiments; what cannot be
// evaluated is refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/design.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/mocap/processing.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::HasSubstr;
using testing_support::Nominal;
using testing_support::Record;
using testing_support::Truth;

// The synthetic recording's motion (the compressed protocol's 3 s) as a
// planned experiment of the arm at `prior`.
PlannedExperiment Planned(const Experiment& recording, const sim::ArmParameters& prior) {
  PlannedExperiment planned;
  planned.name = "compressed protocol";
  planned.config = recording.config;
  planned.config.parameters = prior;
  planned.model = recording.model;
  planned.inputs = recording.inputs;
  planned.duration_s = recording.duration_s();
  return planned;
}

DesignCandidate Candidate(const std::string& name, std::vector<PlannedExperiment> experiments) {
  DesignCandidate candidate;
  candidate.name = name;
  candidate.experiments = std::move(experiments);
  return candidate;
}

// What a lab's fit of the recording reports: mu_c and T_p free, started at
// the truth.
IdentificationSummary FitFromTheTruth(const Experiment& recording,
                                      const sim::ArmParameters& truth) {
  IdentificationOptions fit;
  fit.free_parameters = {"mu_c", "T_p"};
  fit.values = {{"mu_c", truth.mu_c}, {"T_p", truth.T_p}};
  return Identify({recording}, fit);
}

DesignOptions Options() {
  DesignOptions options;
  options.free_parameters = {"mu_c", "T_p"};
  options.noise_deg = 0.03;
  options.low_pass_hz = 0.0;       // the synthetic recordings' angles are not low-passed
  options.checked_candidates = 0;  // the check has its own tests, below
  return options;
}

TEST(Design, PredictsTheStandardErrorsAFitOfSuchARecordingReports) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 7), "seed7.h5", {});
  const DesignSummary design =
      EvaluateDesigns({Candidate("one recording", {Planned(recording, truth)})}, Options());
  ASSERT_EQ(design.candidates.size(), 1u);
  const CandidateInformation& predicted = design.candidates[0];
  ASSERT_TRUE(predicted.completed) << predicted.message;

  const IdentificationSummary realised = FitFromTheTruth(recording, truth);
  ASSERT_TRUE(realised.covariance_available) << realised.covariance_message;
  for (std::size_t i = 0; i < 2; ++i) {
    const ParameterEstimate* estimate = realised.Find(predicted.parameters[i]);
    ASSERT_NE(estimate, nullptr);
    std::printf(
        "%s: predicted standard error %.4g, the fit reports %.4g (N_eff/N %.3f, "
        "residual variance %.3f)\n",
        predicted.parameters[i].c_str(), predicted.std_error[i], estimate->std_error,
        realised.effective_samples / static_cast<double>(realised.residuals),
        realised.residual_variance);
    // The same Jacobian (the identification's own differences), at the
    // truth rather than the estimate, one standard error apart (~1 % of a
    // derivative here); white noise of the given size, so the fit's residual
    // variance and its effective samples differ from 1 and N only by their
    // sampling error (a few %). 10 % holds both with room.
    EXPECT_NEAR(estimate->std_error / predicted.std_error[i], 1.0, 0.1);
  }
}

TEST(Design, PredictsTheErrorsOfALowPassedRecordingWithTheSameFilter) {
  // The mocap pipeline low-passes the measured angles (1 Hz by default) and
  // identification filters its simulated angles alike: the Jacobian a fit
  // sees is that of the filtered angles. The compressed protocol's 2 s ramp
  // has much of its motion near the cutoff.
  constexpr double kCutoffHz = 1.0;
  const sim::ArmParameters truth = Truth();
  const Experiment recording =
      MakeExperiment(Record(truth, 0.03, 7, testing_support::Nominal(), kCutoffHz), "lp.h5", {});
  ASSERT_TRUE(recording.low_pass.has_value());
  DesignOptions filtered = Options();
  filtered.low_pass_hz = kCutoffHz;
  const PlannedExperiment planned = Planned(recording, truth);
  const DesignSummary with = EvaluateDesigns({Candidate("low-passed", {planned})}, filtered);
  const DesignSummary without = EvaluateDesigns({Candidate("raw", {planned})}, Options());
  ASSERT_TRUE(with.candidates[0].completed) << with.candidates[0].message;
  ASSERT_TRUE(without.candidates[0].completed) << without.candidates[0].message;

  const IdentificationSummary realised = FitFromTheTruth(recording, truth);
  ASSERT_TRUE(realised.covariance_available) << realised.covariance_message;
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string& name = with.candidates[0].parameters[i];
    const ParameterEstimate* estimate = realised.Find(name);
    ASSERT_NE(estimate, nullptr);
    const double predicted = with.candidates[0].std_error[i];
    const double unfiltered = without.candidates[0].std_error[i];
    std::printf("%s: predicted %.4g with the filter, %.4g without; the fit reports %.4g\n",
                name.c_str(), predicted, unfiltered, estimate->std_error);
    // As above: the same Jacobian, white noise added after the filter.
    EXPECT_NEAR(estimate->std_error / predicted, 1.0, 0.1);
    // A low-pass's gain is at most 1 at every frequency, so it can only
    // remove information: the errors with it are not smaller (to 1 %, the
    // reflected padding at the record's ends).
    EXPECT_GE(predicted, 0.99 * unfiltered);
  }
}

TEST(Design, InformationAddsOverAPlansExperiments) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 1), "seed1.h5", {});
  const PlannedExperiment planned = Planned(recording, truth);
  const DesignSummary design = EvaluateDesigns(
      {Candidate("once", {planned}), Candidate("twice", {planned, planned})}, Options());
  const CandidateInformation& once = design.candidates[0];
  const CandidateInformation& twice = design.candidates[1];
  ASSERT_TRUE(once.completed && twice.completed) << once.message << twice.message;
  // Two recordings of the same motion: twice the information (the runs are
  // deterministic, so to rounding), errors smaller by √2, and the plan of two
  // ranked first.
  EXPECT_TRUE(twice.fisher_relative.isApprox(2.0 * once.fisher_relative, 1e-12));
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR(twice.std_error[i] * std::sqrt(2.0), once.std_error[i], 1e-9 * once.std_error[i]);
  }
  EXPECT_EQ(design.ranking.front(), 1u);
  EXPECT_DOUBLE_EQ(twice.duration_s, 2.0 * once.duration_s);
  // Half the noise: half the errors.
  DesignOptions quieter = Options();
  quieter.noise_deg = 0.015;
  const DesignSummary quiet = EvaluateDesigns({Candidate("once", {planned})}, quieter);
  EXPECT_NEAR(quiet.candidates[0].std_error[1], 0.5 * once.std_error[1], 1e-9 * once.std_error[1]);
}

TEST(Design, ChecksTheBestPlansDerivativesAsAFitChecksItsOwn) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 1), "seed1.h5", {});
  const PlannedExperiment planned = Planned(recording, truth);
  const std::vector<DesignCandidate> plans = {Candidate("once", {planned}),
                                              Candidate("twice", {planned, planned})};
  // At the paper's friction the angles are smooth in mu_c and T_p: the best
  // plan is checked (and no other, checking stops at a smooth one), with
  // the two runs per experiment and free parameter of the finer step on top
  // of its evaluation again.
  DesignOptions checked = Options();
  checked.checked_candidates = 1;
  const DesignSummary smooth = EvaluateDesigns(plans, checked);
  const CandidateInformation& best = smooth.candidates[smooth.ranking.front()];
  ASSERT_TRUE(best.derivatives_checked());
  EXPECT_TRUE(best.derivatives_smooth());
  EXPECT_FALSE(smooth.candidates[smooth.ranking.back()].derivatives_checked());
  // Every run of an evaluation is per experiment: unchecked, two
  // experiments cost twice one's.
  const CandidateInformation& once = smooth.candidates[smooth.ranking.back()];
  EXPECT_EQ(best.simulations, 2 * (2 * once.simulations) + 2 * 2 * 2);
  EXPECT_THAT(smooth.FullReport(), HasSubstr("twice: smooth (largest disagreement"));
  EXPECT_TRUE(ToJson(smooth)["candidates"][1]["derivatives_smooth"].get<bool>());
  EXPECT_TRUE(ToJson(smooth)["candidates"][0]["derivatives_smooth"].is_null());
}

TEST(Design, RanksAPlanWhoseDerivativesAreNotSmoothLast) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 1), "seed1.h5", {});
  const PlannedExperiment planned = Planned(recording, truth);
  // The paper's stick-slip law in the holes (events: a node sticks or
  // slips by a threshold; these recordings have no hole friction) makes the
  // angles jump with the parameters where a switch moves past a frame, so
  // differences at r and r/3 disagree (docs/model-notes.md, rows 20 and
  // 24): a fit of such a plan would not give its predicted errors. Three
  // recordings of it would rank first; the check calls it not smooth, ranks
  // it last, and checks on to the next.
  PlannedExperiment events = planned;
  events.config.solver.hole_friction = sim::HoleFrictionModel::kEvents;
  events.config.parameters.mu = events.config.parameters.mu_s = 0.21;
  DesignOptions two = Options();
  two.free_parameters = {"mu_c"};  // the one that jumps (10 % between the steps)
  two.checked_candidates = 2;
  const DesignSummary rough = EvaluateDesigns(
      {Candidate("once", {planned}), Candidate("events", {events, events, events})}, two);
  std::printf("%s\n", rough.FullReport().c_str());
  const CandidateInformation& jumping = rough.candidates[1];
  ASSERT_TRUE(jumping.derivatives_checked());
  EXPECT_FALSE(jumping.derivatives_smooth());
  EXPECT_THAT(rough.FullReport(), HasSubstr("events: NOT smooth in"));
  EXPECT_TRUE(rough.candidates[0].derivatives_smooth());
  EXPECT_EQ(rough.ranking.front(), 0u);
}

TEST(Design, ProposesMotionsWithinTheJointsRangeAndWritesWhatItEvaluated) {
  const sim::Config prior = Nominal();
  ProposalSpace space;
  space.amplitudes_deg = {4.0, 45.0};  // 45° is past the paper arm's 41.7° range
  space.move_times_s = {1.0};
  space.hold_s = 0.5;
  space.budget_s = 3.0;  // two moves: out to A, back to straight
  std::vector<std::string> skipped;
  const DesignSummary design = ProposeDesign(prior, space, {}, Options(), &skipped);
  // Together and opposed at 4°; both at 45° refused by the protocol checks.
  ASSERT_EQ(design.candidates.size(), 2u);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_THAT(skipped[0], ::testing::HasSubstr("past its 41.71 deg"));
  for (const CandidateInformation& c : design.candidates) {
    ASSERT_TRUE(c.completed) << c.message;
    EXPECT_DOUBLE_EQ(c.duration_s, 3.0);
    // The text written out (proposed.yaml) is the motion evaluated: its
    // inputs again, to the bit.
    const sim::Protocol again = sim::ParseProtocol(c.protocol_yaml, "proposed.yaml", prior.arm);
    const sim::ArmModel model(prior.arm);
    const sim::CableInputs planned =
        sim::PlanProtocolInputs(model, again, prior.parameters, again.duration_s());
    const PlannedExperiment evaluated = PlanExperiment(prior, again, c.name);
    EXPECT_EQ(planned.length_change(), evaluated.inputs->length_change()) << c.name;
    EXPECT_THAT(c.protocol_yaml, ::testing::HasSubstr("theta_x_deg: 4}"));
  }
  EXPECT_THAT(design.candidates[1].name, ::testing::HasSubstr("opposed"));
}

TEST(Design, RanksTheBestPlansByTheirWorstCornerOfThePriorBox) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 1), "seed1.h5", {});
  const PlannedExperiment all = Planned(recording, truth);
  PlannedExperiment half = all;  // the first half of the motion: less information
  half.duration_s = 0.5 * all.duration_s;
  DesignOptions options = Options();
  // mu_c from the prior to twice it: corner 0 is the prior itself.
  options.prior_box = {{"mu_c", truth.mu_c, 2.0 * truth.mu_c}};
  options.robust_candidates = 1;
  const DesignSummary design =
      EvaluateDesigns({Candidate("half", {half}), Candidate("whole", {all})}, options);
  const CandidateInformation& first_half = design.candidates[0];
  const CandidateInformation& whole = design.candidates[1];
  // Only the best plan at the prior (the whole motion) goes to the corners.
  EXPECT_TRUE(first_half.corners.empty());
  ASSERT_EQ(whole.corners.size(), 2u);
  EXPECT_EQ(design.ranking.front(), 1u);
  // The corner at the prior is the prior's evaluation: the same runs, so the
  // same numbers to the bit.
  ASSERT_TRUE(whole.corners[0].completed) << whole.corners[0].message;
  EXPECT_EQ(whole.corners[0].values.front().second, truth.mu_c);
  EXPECT_EQ(whole.corners[0].relative_std_error, whole.relative_std_error);
  // The other corner is another arm: other errors; the robust criterion is
  // the worst of the prior and both corners.
  ASSERT_TRUE(whole.corners[1].completed) << whole.corners[1].message;
  EXPECT_NE(whole.corners[1].relative_std_error, whole.relative_std_error);
  EXPECT_EQ(whole.robust_worst_relative_std_error,
            std::max(whole.worst_relative_std_error, whole.corners[1].worst_relative_std_error));
  EXPECT_THAT(design.FullReport(), ::testing::HasSubstr("over the prior box (mu_c"));
  const nlohmann::json json = ToJson(design);
  EXPECT_EQ(json["candidates"][1]["corners"].size(), 2u);
  EXPECT_EQ(json["prior_box"][0]["name"], "mu_c");

  // A free parameter's range may not end at 0; a range must be ordered.
  DesignOptions bad = Options();
  bad.prior_box = {{"mu_c", 0.0, 0.2}};
  EXPECT_THROW(EvaluateDesigns({Candidate("half", {half})}, bad), InputError);
  bad.prior_box = {{"mu_c", 0.3, 0.2}};
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("lower < upper"));
}

// The largest |angle| of joint 1's axis `c` over the protocol, sampled at 100 Hz.
double LargestAngleDeg(const sim::Protocol& protocol, int c) {
  double largest = 0.0;
  for (double t = 0.0; t <= protocol.duration_s(); t += 0.01) {
    largest = std::max(largest, std::abs(protocol.PlannedAngles(t)[0][c]) * 180.0 / M_PI);
  }
  return largest;
}

TEST(Design, ProposesSinesChirpsAndReversalsInAnyBendingPlane) {
  const sim::Config prior = Nominal();
  ProposalSpace space;
  space.budget_s = 8.0;
  ProposedMotion m;
  m.amplitude_deg = 10.0;
  // A sine in the plane at 0 deg bends toward +x: θy swings, θx stays 0
  // (docs/protocols.md); it fills the budget.
  m.kind = ProposedMotion::Kind::kSine;
  m.frequency_hz = 0.5;
  m.in_plane = true;
  std::string name;
  sim::Protocol sine =
      sim::ParseProtocol(ProposalProtocolYaml(m, space, 2, &name), name, prior.arm);
  EXPECT_EQ(name, "sine A=10 f=0.5 plane=0");
  EXPECT_DOUBLE_EQ(sine.duration_s(), 8.0);
  EXPECT_NEAR(LargestAngleDeg(sine, 1), 10.0, 0.05);  // a peak at full envelope
  EXPECT_NEAR(LargestAngleDeg(sine, 0), 0.0, 1e-9);
  // A chirp from 0.1 to 1 Hz in θx, segments opposed.
  m.kind = ProposedMotion::Kind::kChirp;
  m.frequency_hz = 0.1;
  m.end_hz = 1.0;
  m.in_plane = false;
  m.opposed = true;
  sim::Protocol chirp =
      sim::ParseProtocol(ProposalProtocolYaml(m, space, 2, &name), name, prior.arm);
  EXPECT_EQ(name, "chirp A=10 f=0.1-1 opposed");
  EXPECT_DOUBLE_EQ(chirp.duration_s(), 8.0);
  EXPECT_GT(LargestAngleDeg(chirp, 0), 9.0);
  // Segment 2 (joint 7) swings against segment 1 (joint 1).
  const double t = 4.0;
  EXPECT_NEAR(chirp.PlannedAngles(t)[6][0], -chirp.PlannedAngles(t)[0][0], 1e-12);
  // Reversals in the plane at 90 deg (toward +y): θx = −A at the first target.
  m.kind = ProposedMotion::Kind::kReversals;
  m.move_s = 2.0;
  m.in_plane = true;
  m.plane_deg = 90.0;
  m.opposed = false;
  sim::Protocol reversals =
      sim::ParseProtocol(ProposalProtocolYaml(m, space, 2, &name), name, prior.arm);
  EXPECT_EQ(name, "reversals A=10 move=2 plane=90");
  EXPECT_NEAR(reversals.PlannedAngles(2.5)[0][0] * 180.0 / M_PI, -10.0, 1e-9);
  // The space refuses a chirp band that does not rise.
  space.chirp_bands_hz = {{1.0, 0.5}};
  std::string error;
  EXPECT_FALSE(space.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("chirp_bands_hz"));
}

TEST(Design, RefusesAPriorOfZeroAndAPlanWithoutExperiments) {
  const sim::ArmParameters truth = Truth();
  const Experiment recording = MakeExperiment(Record(truth, 0.03, 1), "seed1.h5", {});
  DesignOptions options = Options();
  options.free_parameters = {"mu"};  // 0 in case 4's friction
  try {
    EvaluateDesigns({Candidate("once", {Planned(recording, truth)})}, options);
    ADD_FAILURE() << "a prior of 0 was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("its prior value is 0"));
  }
  EXPECT_THROW(EvaluateDesigns({Candidate("empty", {})}, Options()), InputError);
  DesignOptions bad = Options();
  bad.effective_sample_fraction = 1.5;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("effective_sample_fraction"));
  DesignOptions negative = Options();
  negative.checked_candidates = -1;
  EXPECT_FALSE(negative.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("checked_candidates must be >= 0"));
  DesignOptions too_fast = Options();
  // The default filter is the mocap pipeline's, which the recordings go through.
  EXPECT_EQ(DesignOptions().low_pass_hz, mocap::ProcessingOptions().cutoff_hz);
  EXPECT_EQ(DesignOptions().low_pass_order, mocap::ProcessingOptions().filter_order);
  EXPECT_EQ(DesignOptions().low_pass_min_run_frames,
            mocap::ProcessingOptions().min_filter_run_frames);
  too_fast.low_pass_hz = 50.0;  // half the frame rate: no digital low-pass
  EXPECT_FALSE(too_fast.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("low_pass_hz"));
}

}  // namespace
}  // namespace ccsrm::identify
