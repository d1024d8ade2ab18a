// Identification where friction is real (issue 43): a fast recording with
// static friction above kinetic (0.25 over 0.21 in the holes and conduits),
// generated through the whole pipeline (markers with noise and occlusions,
// the mocap pipeline at load), fitted from the paper's values (static equal
// to kinetic). Before the presliding relaxation was smoothed over the step
// (model notes, row 28) such fits stalled on rejected steps with intervals
// that excluded the truth: the angles were not smooth in the parameters.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/mocap/generate.h"

namespace ccsrm::identify {
namespace {

namespace fs = std::filesystem;

// One reversal of each segment, 2 s moves, segment 2 opposed and out of
// step: the fast-reversals protocol of configs/protocols cut to 8 s.
constexpr const char* kShortReversals = R"(schema: ccsrm-protocol/1
segments:
  1:
    - move: {to: {theta_x_deg: 15}, duration_s: 2}
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: -15}, duration_s: 2}
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: 0}, duration_s: 2}
    - hold: {duration_s: 1}
  2:
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: -18}, duration_s: 2}
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: 18}, duration_s: 2}
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: 0}, duration_s: 2}
    - hold: {duration_s: 0.5}
)";

// The short reversals recorded through the whole pipeline (seed 4) into
// `dir`, loaded as an experiment.
std::vector<Experiment> RecordShortReversals(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteTextFileAtomically((dir / "reversals.yaml").string(), kShortReversals);
  mocap::GenerateOptions g;
  g.run.config_path = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
  g.run.case_number = 2;
  g.run.protocol_path = (dir / "reversals.yaml").string();
  g.run.sets = {"mu_s=0.25", "mu_c_s=0.25"};
  g.recording.seed = 4;
  g.out = (dir / "fast.h5").string();
  const mocap::GeneratedExperiment generated = mocap::GenerateExperiment(g);
  if (!generated.simulation.completed()) {
    ADD_FAILURE() << generated.simulation.message;
    return {};
  }
  return {LoadExperiment(generated.experiment_path, {})};
}

TEST(RealFriction, AFastRecordingWithStaticAboveKineticIsFittedToTheTruth) {
  const fs::path dir = fs::temp_directory_path() / "ccsrm_real_friction_test";
  const std::vector<Experiment> recordings = RecordShortReversals(dir);
  ASSERT_EQ(recordings.size(), 1u);

  IdentificationOptions o;
  o.free_parameters = {"mu_s", "mu_c"};  // start: the paper's 0.21, static equal to kinetic
  o.values = {{"mu_c_s", 0.25}};         // the conduits' static friction, known
  o.threads = 2;
  const IdentificationSummary fit = Identify(recordings, o);
  SCOPED_TRACE(fit.FullReport());
  EXPECT_TRUE(fit.converged());
  EXPECT_TRUE(fit.adequacy.adequate());
  const std::map<std::string, double> truth = {{"mu_s", 0.25}, {"mu_c", 0.21}};
  for (const ParameterEstimate& p : fit.parameters) {
    if (!p.free) continue;
    SCOPED_TRACE(p.name);
    const double t = truth.at(p.name);
    // Issue 43's bound: every free parameter within 1 %, its interval
    // covering the truth.
    EXPECT_LT(std::abs(p.value - t) / t, 0.01);
    EXPECT_LE(p.ci95_lower, t);
    EXPECT_GE(p.ci95_upper, t);
    // The angles are smooth in it there: derivatives at two steps agree.
    EXPECT_LT(p.derivative_step_disagreement, kDerivativeStepLimit);
  }
  fs::remove_all(dir);
}

// At three times the fit's default step the same recording's angles bend
// between r and r/3 in the holes' static coefficient (3.0 % between r/3
// and r/9 against more than 5 % between r and r/3, measured by `ccsrm
// identify --relative-step 0.03` one iteration from the truth with mu and
// T_p free as well): the check takes that column at
// r/3, and the intervals follow it. Their standard errors are those of the
// Jacobian the summary reports, column for column: Ceres' covariance reads
// the same Jacobian the check chose, not the fit's first one.
TEST(RealFriction, ADerivativeThatBendsBetweenTheStepsIsTakenAtTheFinerOneForTheIntervals) {
  const fs::path dir = fs::temp_directory_path() / "ccsrm_real_friction_steps_test";
  const std::vector<Experiment> recordings = RecordShortReversals(dir);
  ASSERT_EQ(recordings.size(), 1u);
  IdentificationOptions o;
  o.free_parameters = {"mu_s", "mu_c"};
  o.values = {{"mu_s", 0.25}, {"mu_c_s", 0.25}};  // at the truth: only the check
  o.max_iterations = 0;
  o.relative_step = 0.03;
  o.threads = 2;
  const IdentificationSummary s = Identify(recordings, o);
  SCOPED_TRACE(s.FullReport());
  const ParameterEstimate* mu_s = s.Find("mu_s");
  ASSERT_NE(mu_s, nullptr);
  EXPECT_DOUBLE_EQ(mu_s->derivative_step, 0.01);
  EXPECT_LT(mu_s->derivative_step_disagreement, kDerivativeStepLimit);
  EXPECT_THAT(s.FullReport(), testing::HasSubstr("whose derivative the intervals take (mu_s"));

  // σ_i = sqrt((JᵀJ)⁻¹_ii · residual variance · N / N_eff) · scale_i.
  const Eigen::MatrixXd& j = s.jacobian;
  ASSERT_EQ(j.cols(), 2);
  const Eigen::MatrixXd inverse = (j.transpose() * j).inverse();
  const double factor =
      s.residual_variance * static_cast<double>(s.residuals) / s.effective_samples;
  int column = 0;
  for (const char* name : {"mu_s", "mu_c"}) {
    const ParameterEstimate* p = s.Find(name);
    ASSERT_NE(p, nullptr);
    const double expected = std::sqrt(inverse(column, column) * factor) * p->scale;
    EXPECT_NEAR(p->std_error, expected, 1e-6 * expected) << name;
    ++column;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ccsrm::identify
