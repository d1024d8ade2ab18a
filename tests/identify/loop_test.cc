// The loop finds an effect the declared model lacks, adds nothing when the
// declared model is right, and its residual diagnostics see what they are
// built to see. Experiments: the paper's arm on the compressed protocol of
// synthetic_experiment.h (a run takes about a second), white noise of
// 0.03 deg, the mocap floor.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/diagnostics.h"
#include "ccsrm/identify/loop.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "declared_values.h"
#include "loop_recordings.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing_support::LoopRecordings;
using testing_support::LoopTestOptions;
using testing_support::Nominal;
using testing_support::Record;

constexpr double kNoiseDeg = testing_support::kLoopNoiseDeg;

// The experiment's own angles shifted back by `frames`, plus a pattern.
Eigen::MatrixXd Shifted(const Experiment& e, int frames) {
  Eigen::MatrixXd out = e.measured;
  for (Eigen::Index f = 0; f < out.rows(); ++f) {
    const Eigen::Index g = std::clamp<Eigen::Index>(f + frames, 0, out.rows() - 1);
    out.row(f) = e.measured.row(g);
  }
  return out;
}

// The loop lists as unexplained exactly the joint axes its final fit's
// verdict calls above the noise (issue 44: one rule, so a page never says
// "the model explains the data" above a list of unexplained axes).
void ExpectUnexplainedIsWhatTheVerdictCallsAboveNoise(const LoopSummary& s) {
  ASSERT_TRUE(s.final_fit.adequacy.assessed);
  std::set<std::tuple<std::string, int, int>> listed, above;
  for (const UnexplainedChannel& u : s.unexplained) listed.insert({u.experiment, u.joint, u.axis});
  for (const ChannelAboveNoise& c : s.final_fit.adequacy.above_noise) {
    above.insert({c.recording, c.joint, c.axis});
  }
  EXPECT_EQ(listed, above);
  std::size_t beyond_ratio = 0;
  for (const ChannelDiagnostics& ch : s.final_evidence.channels) {
    beyond_ratio += ch.rms_deg > 1.5 * ch.noise_deg;
  }
  std::printf("final model: %zu unexplained, %zu beyond 1.5x the noise, worst %.2fx\n",
              listed.size(), beyond_ratio, s.final_fit.adequacy.worst_ratio);
}

TEST(ResidualDiagnostics, WhiteNoiseIsWhiteAndAConstantOffsetIsNamed) {
  const std::vector<Experiment> x = LoopRecordings(Nominal().parameters, {3});
  // The "simulation" is the recording plus fresh white noise of 0.03 deg,
  // except on joint 4 θy, which it misses by a constant 0.05 deg.
  Eigen::MatrixXd simulated = x[0].measured;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kNoiseDeg * M_PI / 180.0);
  for (Eigen::Index f = 0; f < simulated.rows(); ++f) {
    for (Eigen::Index c = 0; c < simulated.cols(); ++c) simulated(f, c) += noise(rng);
    simulated(f, 2 * 3 + 1) -= 0.05 * M_PI / 180.0;
  }
  const ResidualDiagnostics d = DiagnoseResidual(x, {simulated});
  ASSERT_EQ(d.channels.size(), 24u);
  for (const ChannelDiagnostics& ch : d.channels) {
    // White noise: about 5 % of the autocorrelation lags leave the 95 % band
    // (the difference of two white series is white); 20 % would be colour.
    EXPECT_LT(ch.lags_outside_band, 0.2) << "joint " << ch.joint << " axis " << ch.axis;
    const SignalEvidence& constant = ch.evidence[6];
    ASSERT_EQ(constant.signal, "constant");
    if (ch.joint == 4 && ch.axis == 1) {
      EXPECT_TRUE(constant.significant());
      // Simulated - measured: the simulation misses low. 0.03 deg of noise
      // over 301 samples: ±0.002.
      EXPECT_NEAR(ch.mean_deg, -0.05, 0.01);
    } else {
      EXPECT_NEAR(ch.rms_deg, kNoiseDeg, 0.006);  // 301 samples: ±4 % (1σ)
    }
  }
}

TEST(ResidualDiagnostics, FindsTheLagOfALateArm) {
  const std::vector<Experiment> x = LoopRecordings(Nominal().parameters, {4});
  // The measured arm lags the simulation by 10 frames (0.1 s): the simulated
  // motion is the measured one 10 frames earlier.
  const ResidualDiagnostics d = DiagnoseResidual(x, {Shifted(x[0], 10)});
  EXPECT_NEAR(d.experiments[0].lag_s, 0.1, 0.011);
  EXPECT_GT(d.experiments[0].lag_explained, 0.5);
  // A lag leaves a residual (simulated - measured) that follows the rate:
  // the simulation is ahead of the arm.
  const SignalEvidence* rate = d.Pooled("rate");
  ASSERT_NE(rate, nullptr);
  EXPECT_GT(rate->value, 0.5);
  EXPECT_TRUE(rate->significant());
}

TEST(ResidualDiagnostics, SplitsTheProtocolIntoMotionAndHold) {
  const std::vector<Experiment> x = LoopRecordings(Nominal().parameters, {5});
  const std::vector<ProtocolPhase> phases = ProtocolPhases(x[0]);
  // The compressed protocol's 2 s ramp, then its 1 s hold. The quintic
  // ramp's rate, 30 s²(1 - s)² of its mean, falls below 2 % of its peak
  // (1.875) at s = 0.963: the hold starts at 1.93 s.
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_EQ(phases[0].name, "motion 1");
  EXPECT_EQ(phases[1].name, "hold 1");
  EXPECT_NEAR(phases[1].start_s, 1.93, 0.015);
}

TEST(DiscoveredMoment, FormulaGivesEachTermWithItsErrorAndSaysWhatTheInputRateIs) {
  DiscoveredMoment m;
  m.segment = 2;
  m.first_joint = 7;
  m.last_joint = 12;
  const auto term = [](const std::string& name, double value, double std_error) {
    DiscoveredMoment::Term t;
    t.name = name;
    for (const sim::JointMomentTerm& known : sim::JointMomentTerms()) {
      if (known.name == name) t.formula = known.formula;
    }
    t.estimate.value = value;
    t.estimate.std_error = std_error;
    return t;
  };
  m.terms = {term("angle3", -201.0, 9.0)};
  EXPECT_EQ(m.Formula(),
            "joints 7-12 (segment 2) θx: M = (-201 ± 9) θ³ N m (θ in rad, θ̇ in rad/s, t in s)");
  // θ̇_in is no state of the joint: the formula says what it is.
  m.terms.push_back(term("input_rate", -0.52, 0.04));
  EXPECT_EQ(m.Formula(),
            "joints 7-12 (segment 2) θx: M = (-201 ± 9) θ³ - (0.52 ± 0.04) θ̇_in N m (θ in rad, "
            "θ̇ in rad/s, t in s; θ̇_in: the segment's bending rate its inputs command, rad/s)");
}

TEST(LoopOptions, RefusesUnknownAndDeclaredCandidates) {
  std::string error;
  LoopOptions o = LoopTestOptions({"joint_friction", "friction_of_the_table"});
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("unknown effect 'friction_of_the_table'"));
  o = LoopTestOptions({"table_tilt"});
  o.fit.free_parameters = {"T_p", "table_tilt.lateral_rad"};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("'table_tilt' already has a free parameter"));
  o = LoopTestOptions({"backlash", "backlash"});
  EXPECT_FALSE(o.IsValid(&error));
  // The discovered terms' carrier is no candidate effect: 'terms' asks for it.
  o = LoopTestOptions({"joint_moment"});
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("terms, for terms found in the data, which joint_moment carries"));
  o = LoopTestOptions({"terms"});
  o.fit.free_parameters = {"T_p", "joint_moment.segment1_x_angle"};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("joint_moment, which already has a free parameter"));
}

TEST(LoopOptions, DeclaredValuesAreThoseTheArmHas) {
  // The paper's arm has every declared value; the tendon-driven robot's
  // backbone segments have no small or large S, whose radii and wrap angle
  // are then no candidates (a correction of nothing changes nothing).
  auto names = [](const std::string& config) {
    std::vector<std::string> out;
    const sim::Config c = sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/" + config);
    for (const auto& spec : internal::DeclaredValueCandidates(c.arm)) out.push_back(spec.name);
    return out;
  };
  const std::vector<std::string> paper = names("paper.yaml");
  EXPECT_THAT(paper, ::testing::Contains("declared.segment2.large_s_wrap_angle"));
  EXPECT_EQ(paper.size(), 4u + 1u + 2u * (1u + 7u));  // arm block + 4, per segment block + 7
  const std::vector<std::string> robot = names("ftdcr_v4.yaml");
  for (const std::string& name : robot) {
    EXPECT_EQ(name.find("_s_"), std::string::npos) << name;
  }
  EXPECT_THAT(robot, ::testing::Contains("declared.segment3.link_length"));
}

TEST(Loop, FindsAnUndeclaredMocapOffsetAndReachesTheNoise) {
  sim::ArmParameters truth = Nominal().parameters;
  sim::EnableEffectAtRealisticMagnitude("mocap_offset", "test", &truth);
  const std::vector<Experiment> training = LoopRecordings(truth, {1, 2});
  const std::vector<Experiment> holdout = LoopRecordings(truth, {3});
  const LoopSummary s = CloseLoop(
      training, holdout, LoopTestOptions({"table_tilt", "mocap_offset", "actuator_delay"}));
  ASSERT_FALSE(s.rounds.empty());
  EXPECT_EQ(s.rounds[0].candidates.front().name, "mocap_offset");  // ranked first
  EXPECT_THAT(s.added_effects, ElementsAre("mocap_offset"));
  // The bar: after within 1.5x the noise floor, before at least
  // twice after, on the held-out experiment too.
  EXPECT_LT(s.rms_after_deg, 1.5 * kNoiseDeg);
  EXPECT_GE(s.rms_before_deg, 2.0 * s.rms_after_deg);
  ASSERT_TRUE(s.holdout_rms_after_deg && s.holdout_rms_before_deg);
  EXPECT_LT(*s.holdout_rms_after_deg, 1.5 * kNoiseDeg);
  EXPECT_GE(*s.holdout_rms_before_deg, 2.0 * *s.holdout_rms_after_deg);
  // Every offset within 20 % of the truth or the truth inside its interval.
  int checked = 0;
  for (const std::string& name : sim::EffectParameterNames("mocap_offset", truth.arm)) {
    const ParameterEstimate* p = s.final_fit.Find(name);
    ASSERT_NE(p, nullptr) << name;
    const double t = sim::GetParameter(truth, name);
    const bool close = std::abs(p->value - t) <= 0.2 * std::abs(t);
    const bool covered = p->identifiable && p->ci95_lower <= t && t <= p->ci95_upper;
    EXPECT_TRUE(close || covered) << name << " = " << p->value << " (truth " << t << ")";
    ++checked;
  }
  EXPECT_EQ(checked, 24);
  EXPECT_TRUE(s.unexplained.empty());
  ExpectUnexplainedIsWhatTheVerdictCallsAboveNoise(s);
  // The decision is written down, and the evidence that pointed to it.
  EXPECT_THAT(s.rounds[0].decision, HasSubstr("added mocap_offset"));
  EXPECT_EQ(s.rounds[0].candidates.front().evidence.front().signal, "constant");
  EXPECT_TRUE(s.rounds[0].candidates.front().evidence.front().significant());
}

TEST(Loop, AddsNothingWhenTheDeclaredModelIsRight) {
  sim::ArmParameters truth = Nominal().parameters;
  truth.T_p = 55.0;  // a declared parameter away from its start: the fit finds it
  const std::vector<Experiment> training = LoopRecordings(truth, {1, 2});
  const std::vector<Experiment> holdout = LoopRecordings(truth, {3});
  // Terms too: null data must not make the discovery add anything.
  const LoopSummary s = CloseLoop(
      training, holdout, LoopTestOptions({"table_tilt", "mocap_offset", "backlash", "terms"}));
  EXPECT_TRUE(s.added_effects.empty());
  EXPECT_TRUE(s.discovered_terms.empty());
  ASSERT_EQ(s.rounds.size(), 1u);
  for (const CandidateResult& c : s.rounds[0].candidates) EXPECT_FALSE(c.accepted) << c.name;
  EXPECT_THAT(s.rounds[0].decision, HasSubstr("no candidate earns its place"));
  EXPECT_THAT(s.conclusion, HasSubstr("no effect added"));
  EXPECT_TRUE(s.unexplained.empty());
  ExpectUnexplainedIsWhatTheVerdictCallsAboveNoise(s);
  EXPECT_DOUBLE_EQ(s.rms_after_deg, s.rms_before_deg);
  EXPECT_NEAR(s.final_fit.Find("T_p")->value, 55.0, 0.55);
}

TEST(Loop, NamesWhatItCannotExplainByTheVerdictsRule) {
  // A table tilt of 0.01 rad (the new user's scenario of issue 44) and a
  // loop allowed no round: the declared model is the final one, its
  // residual stays, and the loop says where, as the verdict does. (With a
  // round, an actuator delay took part of it; some axes beyond 1.5x the
  // noise were not beyond chance: 6 unexplained of 7.)
  sim::ArmParameters truth = Nominal().parameters;
  sim::SetParameter("table_tilt.lateral_rad", 0.01, "test", &truth);
  const std::vector<Experiment> training = LoopRecordings(truth, {1, 2});
  LoopOptions options = LoopTestOptions({"actuator_delay"});
  options.max_rounds = 0;
  const LoopSummary s = CloseLoop(training, {}, options);
  EXPECT_FALSE(s.final_fit.adequacy.adequate());
  EXPECT_FALSE(s.unexplained.empty());
  ExpectUnexplainedIsWhatTheVerdictCallsAboveNoise(s);
  EXPECT_THAT(s.conclusion, HasSubstr("beyond chance"));
}

}  // namespace
}  // namespace ccsrm::identify
