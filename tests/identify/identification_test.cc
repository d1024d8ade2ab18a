// Identification recovers parameters it generated data from, names what the
// data cannot determine, checks its input before any simulation runs, and
// gives the same answer on any number of threads. The experiments are made
// here: the paper's arm on a compressed protocol (case 4, connecting-cable
// friction only: a run takes about a second), recorded as white noise of a
// known size on the true angles.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::HasSubstr;
using testing_support::Nominal;
using testing_support::Record;
using testing_support::Truth;

const Experiment& Recorded() {
  static const Experiment e =
      MakeExperiment(Record(Truth(), 0.03, 7), "synthetic.h5", ExperimentLoadOptions());
  return e;
}

// Settled poses (issue 46): a recording whose rows are static equilibria
// (motion: settled_poses) is replayed quasi-statically by every run of a
// fit, and the fit recovers the truth from it: here T_p (65 N against the
// nominal 50), which sets the conduits' friction limit, from 13 poses of
// the compressed protocol's ramp and hold with 0.03 deg of noise. The bound
// is the fit's own: within three of its standard errors, and 1 %.
TEST(Identification, RecoversThePretensionFromSettledPoses) {
  const Experiment e =
      MakeExperiment(Record(Truth(), 0.03, 11, testing_support::Nominal(), 0.0, 0.25), "settled.h5",
                     ExperimentLoadOptions());
  ASSERT_TRUE(e.settled_poses);
  EXPECT_EQ(e.frame_time_s.size(), 13u);
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.threads = 2;
  const IdentificationSummary s = Identify({e}, o);
  const ParameterEstimate* t_p = s.Find("T_p");
  ASSERT_NE(t_p, nullptr);
  const double truth = Truth().T_p;
  EXPECT_LE(std::abs(t_p->value - truth), 3.0 * t_p->std_error) << t_p->value;
  EXPECT_LE(std::abs(t_p->value - truth), 0.01 * truth) << t_p->value;
  std::printf("T_p %.4f N (truth %.1f), std error %.3g N, %lld runs\n", t_p->value, truth,
              t_p->std_error, static_cast<long long>(s.simulations));
}

// A backend whose `fail`-th run fails (a replay that finds no settled pose
// at one parameter value); the others run on this machine.
class FailingBackend final : public SimulationBackend {
 public:
  FailingBackend(const std::vector<Experiment>* experiments, std::size_t fail)
      : inner_(MakeThreadBackend(experiments, 1)), fail_(fail) {}
  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    std::vector<RunResult> results = inner_->RunBatch(requests, on_finished);
    for (RunResult& r : results) {
      if (++runs_ != fail_) continue;
      r.summary.status = sim::SimulationStatus::kDiverged;
      r.summary.message = "no settled pose (test)";
      r.simulated.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    return results;
  }
  int parallelism() const override { return 1; }

 private:
  std::unique_ptr<SimulationBackend> inner_;
  std::size_t fail_ = 0, runs_ = 0;
};

// A fit one of whose finite-difference runs fails after it has accepted a
// step (its sixth run here: a derivative after the first accepted step)
// reports the last point it accepted (Ceres leaves a failed solve's
// parameters at the start): the work done is not lost, and the fit still
// says it failed.
TEST(Identification, AFitWhoseRunsFailKeepsItsLastAcceptedPoint) {
  const std::vector<Experiment> experiments = {
      MakeExperiment(Record(Truth(), 0.03, 11, testing_support::Nominal(), 0.0, 0.25), "settled.h5",
                     ExperimentLoadOptions())};
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.threads = 1;
  o.backend = std::make_shared<FailingBackend>(&experiments, 6);
  const IdentificationSummary s = Identify(experiments, o);
  EXPECT_EQ(s.termination, IdentificationTermination::kFailed);
  EXPECT_THAT(s.message, HasSubstr("the values are those of the last accepted iteration"));
  const ParameterEstimate* t_p = s.Find("T_p");
  ASSERT_NE(t_p, nullptr);
  // From the nominal 50 N towards the truth's 65 N.
  EXPECT_GT(t_p->value, t_p->start + 1.0) << s.message;
}

// A backend that only counts what it is asked to run.
class CountingBackend final : public SimulationBackend {
 public:
  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback&) override {
    runs += requests.size();
    return std::vector<RunResult>(requests.size());
  }
  int parallelism() const override { return 1; }
  std::size_t runs = 0;
};

TEST(ExperimentLoading, EstimatesTheNoiseFromTheTwistAndKeepsEveryFrame) {
  const Experiment& e = Recorded();
  EXPECT_EQ(e.frame_time_s.size(), 301u);
  EXPECT_EQ(e.measured_samples, 301u * 12 * 2);
  EXPECT_EQ(e.noise_source, "joint twist scatter");
  for (double s : e.noise_deg) EXPECT_NEAR(s, 0.03, 0.006);  // 301 samples: ±4 % (1σ)
  EXPECT_FALSE(e.angles_from_pipeline);
  EXPECT_FALSE(e.low_pass.has_value());  // the synthetic record has no filter
}

TEST(ExperimentLoading, RefusesAnExperimentWithoutInputs) {
  datasets::ExperimentFile file = Record(Nominal().parameters, 0.03, 1);
  file.input_time = datasets::Array({1}, 0.0);
  file.input_length_change = datasets::Array({1, 0});
  try {
    MakeExperiment(file, "x.h5", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.h5: /input/length_change: has no cable columns"));
  }
}

TEST(ExperimentLoading, RefusesInputsForAnotherArm) {
  datasets::ExperimentFile file = Record(Nominal().parameters, 0.03, 1);
  file.input_length_change = datasets::Array({file.input_time.rows(), 4});
  EXPECT_THROW(MakeExperiment(file, "x.h5", {}), InputError);
  file = Record(Nominal().parameters, 0.03, 1);
  file.config_yaml.clear();
  try {
    MakeExperiment(file, "x.h5", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.h5: attribute 'config_yaml'"));
  }
}

// Issue 33: angles no universal joint can take (|θx| <= π, |θy| <= π/2 is
// the range of the X–Y Cardan pair) are refused when the experiment is
// loaded, not fitted to a "converged" RMS of 1e30 degrees; so are angles of
// which none is finite.
TEST(ExperimentLoading, RefusesMeasuredAnglesOutsideAUniversalJointsRange) {
  const datasets::ExperimentFile recorded = Record(Nominal().parameters, 0.03, 1);
  datasets::ExperimentFile file = recorded;
  for (double& v : file.measured_joint_angles->values) v *= 1e30;
  try {
    MakeExperiment(file, "x.h5", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.h5: /measured/joint_angles: frame index 0 (t = 0 s), "
                                    "joint 1, θx = "));
    EXPECT_THAT(e.what(), HasSubstr("outside the universal joint's range |θx| <= π"));
  }
  // Just past π/2 on θy is refused too; NaN (lost) is not a range error.
  file = recorded;
  file.measured_joint_angles->values[0] = std::nan("");
  file.measured_joint_angles->values[2 * 3 + 1] = M_PI / 2 + 1e-9;
  try {
    MakeExperiment(file, "x.h5", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.h5: /measured/joint_angles: frame index 0 (t = 0 s), "
                                    "joint 4, θy = 1.5708 rad"));
  }
  file = recorded;
  for (double& v : file.measured_joint_angles->values) v = std::nan("");
  try {
    MakeExperiment(file, "x.h5", {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.h5: /measured/joint_angles: has no finite value"));
  }
}

TEST(IdentificationOptions, NameTheFieldOfEveryProblem) {
  std::string error;
  IdentificationOptions o;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.free_parameters = {"mu", "nope"};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("unknown parameter 'nope'"));
  o.free_parameters = {"mu", "mu"};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("'mu' is repeated"));
  o.free_parameters = {"mu"};
  o.bounds["T_p"] = {10.0, 20.0};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("'T_p' is not a free parameter"));
  o.bounds.clear();
  o.bounds["mu"] = {0.0, 3.0};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("leave its own bounds [0, 2]"));
  o.bounds.clear();
  o.values["beta"] = 5.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("parameter 'beta' = 5 is outside [0, 0.1] s"));
}

TEST(ParameterFile, ReadsValuesFreeFlagsAndBounds) {
  IdentificationOptions o;
  o.free_parameters = {"mu"};
  ApplyParameterFile(
      "mu: 0.2\nT_p: {value: 60, free: true, bounds: [20, 120]}\n"
      "mu_s: {free: false}\n",
      "p.yaml", &o);
  EXPECT_EQ(o.values.at("mu"), 0.2);
  EXPECT_EQ(o.values.at("T_p"), 60.0);
  EXPECT_EQ(o.free_parameters, (std::vector<std::string>{"mu", "T_p"}));
  EXPECT_EQ(o.bounds.at("T_p"), std::make_pair(20.0, 120.0));
  // A truth file's parameters are values.
  ApplyParameterFile("schema: ccsrm-truth/1\nparameters:\n  c_sc: 0.07\n", "t.yaml", &o);
  EXPECT_EQ(o.values.at("c_sc"), 0.07);
}

TEST(ParameterFile, NamesLineAndKeyOfABadEntryAndChangesNothing) {
  const struct {
    std::string text, message;
  } cases[] = {
      {"mu: 0.2\nfoo: 1\n", "p.yaml: line 2, key 'foo': unknown parameter"},
      {"T_p: {bounds: [200, 100]}\n", "p.yaml: line 1, key 'T_p.bounds': [200, 100] must be"},
      {"T_p: {valu: 3}\n", "p.yaml: line 1, key 'T_p.valu': unknown field"},
      {"mu: high\n", "p.yaml: line 1, key 'mu': expected a number"},
      {"beta: 2\n", "p.yaml: line 1, key 'beta': parameter 'beta' = 2 is outside"},
      {"- mu\n", "p.yaml: expected a mapping"},
  };
  for (const auto& c : cases) {
    IdentificationOptions o;
    const IdentificationOptions before = o;
    try {
      ApplyParameterFile(c.text, "p.yaml", &o);
      ADD_FAILURE() << "no error for " << c.text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(c.message)) << c.text;
    }
    EXPECT_EQ(o.values, before.values);
    EXPECT_EQ(o.free_parameters, before.free_parameters);
  }
}

TEST(ParameterFile, StartOutsideItsBoundsNamesTheFileAndKey) {
  const struct {
    std::string text, message;
  } cases[] = {
      {"T_p: {value: 50, free: true, bounds: [60, 80]}\n",
       "p.yaml: line 1, key 'T_p.value': start value 50 is outside the bounds [60, 80] N"},
      {"mu: 0.2\nT_p:\n  free: true\n  bounds: [20, 40]\n  value: 45\n",
       "p.yaml: line 5, key 'T_p.value': start value 45 is outside the bounds [20, 40] N"},
  };
  for (const auto& c : cases) {
    IdentificationOptions o;
    try {
      ApplyParameterFile(c.text, "p.yaml", &o);
      ADD_FAILURE() << "no error for " << c.text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.what(), c.message) << c.text;
    }
    EXPECT_TRUE(o.values.empty());
  }
  // A start given before the file (a value set earlier) must fit bounds the file gives.
  IdentificationOptions o;
  o.values["T_p"] = 90.0;
  try {
    ApplyParameterFile("T_p: {free: true, bounds: [20, 40]}\n", "p.yaml", &o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("p.yaml: line 1, key 'T_p.bounds': start value 90 is outside"));
  }
}

TEST(ParameterFile, DuplicateKeyNamesBothLines) {
  IdentificationOptions o;
  try {
    ApplyParameterFile("mu: 0.2\nT_p:\n  value: 60\n  value: 70\n", "p.yaml", &o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "p.yaml: line 4, key 'T_p.value': duplicate key (first at line 3)");
  }
}

// Issue 32: a θy "fit %" of -11.9 % on an axis planned to stay at 0. Fit
// percent divides by the axis's own motion; it is given only where the
// axis moves, and the motion is given everywhere to read an RMS against.
TEST(AngleErrors, FitPercentOnlyWhereTheAxisMoves) {
  // One joint, 200 frames: θx swings 5° (RMS about its mean 5/√2 = 3.5°),
  // θy wobbles 0.05° about 0.2° (under a tenth of θx's motion); joint 2
  // barely moves either way (0.05° RMS in θx, within 3 x its 0.03° noise).
  Experiment e;
  e.joints = 2;
  e.noise_deg = {0.03, 0.03};
  const int frames = 200;
  e.measured = Eigen::MatrixXd(frames, 4);
  Eigen::MatrixXd simulated(frames, 4);
  const double rad = M_PI / 180.0;
  for (int f = 0; f < frames; ++f) {
    const double phase = 2.0 * M_PI * f / frames;
    e.measured.row(f) << 5.0 * std::sin(phase), 0.2 + 0.05 * std::sin(3 * phase),
        0.05 * std::sqrt(2.0) * std::sin(phase), 0.0;
    e.measured.row(f) *= rad;
    // The fit is off by 0.1° everywhere: 98 % of θx's motion, but more than
    // θy's whole motion (a fit percent of -183 % there).
    simulated.row(f) = e.measured.row(f).array() + 0.1 * rad;
  }
  const ChannelErrors errors = AngleErrors({&e}, {&simulated});
  EXPECT_NEAR(errors.motion_rms_deg[0][0], 5.0 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(errors.motion_rms_deg[0][1], 0.05 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(errors.rms_deg[0][1], 0.1, 1e-12);
  EXPECT_NEAR(errors.fit_percent[0][0], 100.0 * (1.0 - 0.1 / (5.0 / std::sqrt(2.0))), 1e-9);
  EXPECT_TRUE(std::isnan(errors.fit_percent[0][1]));  // a tenth of θx's motion: no %
  EXPECT_NEAR(errors.motion_rms_deg[1][0], 0.05, 1e-9);
  EXPECT_TRUE(std::isnan(errors.fit_percent[1][0]));  // under 3 x the noise: no %
  EXPECT_TRUE(std::isnan(errors.fit_percent[1][1]));  // no motion at all
  // Overall: over θx of joint 1 only, the one axis that moves.
  EXPECT_NEAR(errors.fit_percent_overall, errors.fit_percent[0][0], 1e-9);
  EXPECT_NEAR(errors.rms_deg_overall, 0.1, 1e-12);  // the RMS is over everything
}

TEST(Identification, RefusesAStartOutsideItsBoundsBeforeAnyRun) {
  auto backend = std::make_shared<CountingBackend>();
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.bounds["T_p"] = {60.0, 80.0};  // the start, 50 N, lies below
  o.backend = backend;
  try {
    Identify({Recorded()}, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    // The start is the experiment's configured value: the message names it.
    EXPECT_THAT(e.what(), HasSubstr("synthetic.h5: parameter 'T_p': start value 50 is outside "
                                    "the bounds [60, 80]"));
  }
  EXPECT_EQ(backend->runs, 0u);
}

// Each run writes only its own result, and Simulate is deterministic: the
// start point's analysis gives the same numbers, to the bit, on one thread or two.
TEST(Identification, GivesTheSameAnswerOnAnyNumberOfThreads) {
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.max_iterations = 0;  // the start, one Jacobian, the statistics
  o.threads = 1;
  const IdentificationSummary one = Identify({Recorded()}, o);
  o.threads = 2;
  const IdentificationSummary two = Identify({Recorded()}, o);
  EXPECT_EQ(one.Find("T_p")->value, two.Find("T_p")->value);
  EXPECT_EQ(one.final_cost, two.final_cost);
  EXPECT_EQ(one.singular_values, two.singular_values);
  EXPECT_EQ(one.simulations, two.simulations);
}

// The final Jacobian is second order whether the descent differenced
// forward or not, and the forward Jacobian's p + h run is reused for it: with
// no iterations, both ways run the start, two trial points and the final
// point (4 runs), then the derivative check's two at a third of the step, and
// give the same uncertainty to the bit. The paper protocol is smooth in T_p:
// its derivatives at the two steps agree (`ccsrm derivatives`: 0.05 %).
TEST(Identification, DescendsOnForwardDifferencesAndReportsASecondOrderJacobian) {
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.max_iterations = 0;
  o.threads = 2;
  const IdentificationSummary forward = Identify({Recorded()}, o);
  o.central_differences_throughout = true;
  const IdentificationSummary central = Identify({Recorded()}, o);
  EXPECT_EQ(forward.simulations, 6);
  EXPECT_EQ(central.simulations, 6);
  EXPECT_LT(forward.Find("T_p")->derivative_step_disagreement, 0.01);
  ASSERT_EQ(forward.jacobian.size(), central.jacobian.size());
  EXPECT_TRUE(forward.jacobian == central.jacobian);
  EXPECT_EQ(forward.Find("T_p")->std_error, central.Find("T_p")->std_error);
}

// Where the angles jump with a parameter, the fit says its derivatives are
// not smooth rather than give intervals as if they were: the paper's
// stick-slip law in the holes (events: a node sticks or slips by a
// threshold) moves its switches past frames as mu_c changes, and mu_c's
// differences at r and r/3 disagree by about 10 % on this motion (the design
// test's plan of the same runs; docs/model-notes.md rows 20 and 24). At the
// fast reversals with static friction at 0.30 above kinetic 0.18 the
// default law does the same (85-104 %: issue 43's notes), at a run too long
// for this suite.
TEST(Identification, SaysItsDerivativesAreNotSmoothWhereTheAnglesJump) {
  sim::Config events = Nominal();
  events.solver.hole_friction = sim::HoleFrictionModel::kEvents;
  sim::ArmParameters truth = Truth();
  truth.mu = truth.mu_s = 0.21;  // hole friction, which these recordings lack
  events.parameters = truth;     // the fit's nominal values
  const Experiment e = MakeExperiment(Record(truth, 0.03, 7, events), "events.h5", {});
  IdentificationOptions o;
  o.free_parameters = {"mu_c"};
  o.max_iterations = 0;
  o.threads = 2;
  const IdentificationSummary s = Identify({e}, o);
  const ParameterEstimate* mu_c = s.Find("mu_c");
  ASSERT_NE(mu_c, nullptr);
  EXPECT_GT(mu_c->derivative_step_disagreement, kDerivativeStepLimit);
  EXPECT_THAT(s.BriefReport(), HasSubstr("derivatives NOT smooth in mu_c"));
  EXPECT_THAT(s.FullReport(), HasSubstr("derivative check: NOT smooth"));
}

}  // namespace
}  // namespace ccsrm::identify
