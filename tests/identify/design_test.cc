// Experiment design (issue 26): the standard errors a plan's Fisher
// information predicts are those identification reports when it fits such a
// recording; information adds over a plan's experiments; what cannot be
// evaluated is refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/design.h"
#include "ccsrm/identify/identification.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

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

DesignOptions Options() {
  DesignOptions options;
  options.free_parameters = {"mu_c", "T_p"};
  options.noise_deg = 0.03;
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

  IdentificationOptions fit;
  fit.free_parameters = {"mu_c", "T_p"};
  fit.values = {{"mu_c", truth.mu_c}, {"T_p", truth.T_p}};
  const IdentificationSummary realised = Identify({recording}, fit);
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
}

}  // namespace
}  // namespace ccsrm::identify
