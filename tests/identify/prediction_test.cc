// Prediction (issue 25): a model fitted on the paper protocol's experiments
// predicts a motion it did not see to the noise floor when it is right, and
// shows where it is not when the truth has an effect the fit lacked.
// Experiments: the paper's arm on the compressed protocol of
// synthetic_experiment.h (a run takes about a second), white noise of
// 0.03 deg (the mocap floor) on the true angles, and a twist record of the
// same noise, from which the loader estimates each joint's noise.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/prediction.h"
#include "ccsrm/sim/parameters.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing_support::kDeg;
using testing_support::Nominal;
using testing_support::Record;
using testing_support::Truth;

constexpr double kNoiseDeg = 0.03;

// The paper protocol (compressed) at amplitude `amplitude_deg`, with a ramp
// of `ramp_s`: the experiments record the ramp and a 1 s hold.
sim::Config Motion(double amplitude_deg, double ramp_s) {
  sim::Config c = Nominal();
  c.protocol.amplitude_rad = amplitude_deg / kDeg;
  c.protocol.ramp_s = ramp_s;
  return c;
}

Experiment Recording(const sim::ArmParameters& truth, unsigned seed, const sim::Config& motion,
                     const std::string& name) {
  Experiment e = MakeExperiment(Record(truth, kNoiseDeg, seed, motion), name + ".h5", {});
  e.name = name;
  return e;
}

fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ccsrm_prediction_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// One fit shared by the tests: T_p (truth 65 N, start 45 N) fitted on two
// experiments of the paper protocol, +6 deg and -4 deg over a 2 s ramp,
// written as fit.json the way `ccsrm identify` writes it.
class PredictionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    training_ =
        new std::vector<Experiment>{Recording(Truth(), 1, Motion(6.0, 2.0), "train_plus6"),
                                    Recording(Truth(), 2, Motion(-4.0, 2.0), "train_minus4")};
    IdentificationOptions options;
    options.free_parameters = {"T_p"};
    options.values = {{"T_p", 45.0}};
    options.threads = 2;
    const IdentificationSummary fit = Identify(*training_, options);
    ASSERT_TRUE(fit.converged()) << fit.message;
    right_model_verdict_ = new std::string(fit.adequacy.Verdict());
    right_model_adequate_ = fit.adequacy.adequate();
    fit_json_ = new std::string((Scratch("fit") / "fit.json").string());
    WriteTextFileAtomically(*fit_json_, ToJson(fit).dump(2));
    fitted_tp_ = fit.Find("T_p")->value;
  }
  static void TearDownTestSuite() {
    delete training_;
    delete fit_json_;
    delete right_model_verdict_;
  }

  static PredictionOptions Options() {
    PredictionOptions o;
    o.threads = 2;
    return o;
  }

  static std::vector<Experiment>* training_;
  static std::string* fit_json_;
  static double fitted_tp_;
  static std::string* right_model_verdict_;
  static bool right_model_adequate_;
};
std::string* PredictionTest::right_model_verdict_ = nullptr;
bool PredictionTest::right_model_adequate_ = false;
std::vector<Experiment>* PredictionTest::training_ = nullptr;
std::string* PredictionTest::fit_json_ = nullptr;
double PredictionTest::fitted_tp_ = 0.0;

// A motion the fit did not see: +3 deg over a 1.5 s ramp.
sim::Config NewMotion() { return Motion(3.0, 1.5); }

TEST_F(PredictionTest, TheRightModelPredictsANewMotionToTheNoiseFloor) {
  const PredictionModel model = LoadPredictionModel(*fit_json_);
  EXPECT_EQ(model.kind, "ccsrm-fit/1");
  EXPECT_EQ(model.free, std::vector<std::string>{"T_p"});
  ASSERT_TRUE(model.arm.has_value());
  EXPECT_EQ(model.arm->joints, 12);
  EXPECT_EQ(model.arm->cables, 6);
  EXPECT_DOUBLE_EQ(model.values.at("T_p"), fitted_tp_);

  const std::vector<Experiment> news = {Recording(Truth(), 7, NewMotion(), "new_plus3")};
  const PredictionSummary s = Predict(news, model, Options());
  ASSERT_TRUE(s.completed) << s.message;
  std::printf("%s\n", s.BriefReport().c_str());
  ASSERT_EQ(s.recordings.size(), 1u);
  EXPECT_DOUBLE_EQ(sim::GetParameter(s.recordings[0].parameters, "T_p"), fitted_tp_);
  EXPECT_TRUE(s.effects.empty());
  // At the right model the error is the measurement noise: (predicted -
  // measured) / noise has unit variance. Its mean square over the ~7000
  // samples scatters by sqrt(2/7000) = 0.017, and each joint's noise is
  // estimated from 251 twist samples (relative error of its square
  // sqrt(2/251) = 0.09, 0.026 pooled over 12 joints); the fitted T_p's
  // uncertainty (a fraction of a newton, fitted on ~14 000 samples) adds
  // about 1/14 000 to the variance. So the weighted RMS lies within 0.1 of 1
  // (beyond 6 standard deviations of these).
  EXPECT_NEAR(s.errors.weighted_rms, 1.0, 0.1) << s.FullReport();
  EXPECT_NEAR(s.errors.channels.rms_deg_overall, kNoiseDeg, 0.1 * kNoiseDeg);
  // Each channel's RMS over its noise scatters by about sqrt(1/(2 * 251))
  // = 0.045 (and as much from its noise estimate): 1.5 is 8 deviations
  // above 1, so no channel of 24 stands above it by chance.
  EXPECT_TRUE(s.adequacy.above_noise.empty()) << s.FullReport();
  // White noise of sigma over ~250 samples per channel reaches about 3
  // sigma and (with probability 1 - 1e-6 per channel) not 5.
  EXPECT_LT(s.errors.max_abs_deg_overall, 5.5 * kNoiseDeg);
}

TEST_F(PredictionTest, AModelThatIsWrongStandsAboveTheNoise) {
  // The start of the fit (T_p 45 N against a truth of 65 N): its error on
  // the new motion must show, or the test above could not fail.
  PredictionModel model = LoadPredictionModel(*fit_json_);
  model.values["T_p"] = 45.0;
  const std::vector<Experiment> news = {Recording(Truth(), 7, NewMotion(), "new_plus3")};
  const PredictionSummary s = Predict(news, model, Options());
  ASSERT_TRUE(s.completed) << s.message;
  std::printf("%s\n", s.BriefReport().c_str());
  EXPECT_GT(s.errors.weighted_rms, 1.5) << s.FullReport();
  EXPECT_FALSE(s.adequacy.above_noise.empty());
}

TEST_F(PredictionTest, AMissingEffectShowsOnTheChannelsItTouches) {
  // The truth of the new recording has mocap zero offsets the fit never
  // saw: 3 mrad on joint 3's θx and 2 mrad on joint 9's θy (0.17 and 0.11
  // deg, 5.7 and 3.8 times the noise), nothing elsewhere.
  sim::ArmParameters truth = Truth();
  sim::SetParameter("mocap_offset.joint3_x_rad", 3e-3, "test", &truth);
  sim::SetParameter("mocap_offset.joint9_y_rad", 2e-3, "test", &truth);
  const std::vector<Experiment> news = {Recording(truth, 7, NewMotion(), "new_offsets")};
  const PredictionModel model = LoadPredictionModel(*fit_json_);
  const PredictionSummary s = Predict(news, model, Options());
  ASSERT_TRUE(s.completed) << s.message;
  std::printf("%s\n", s.FullReport().c_str());
  // Exactly the two channels stand above 1.5 x noise ...
  ASSERT_EQ(s.adequacy.above_noise.size(), 2u) << s.FullReport();
  EXPECT_EQ(s.adequacy.above_noise[0].joint, 3);
  EXPECT_EQ(s.adequacy.above_noise[0].axis, 0);
  EXPECT_EQ(s.adequacy.above_noise[1].joint, 9);
  EXPECT_EQ(s.adequacy.above_noise[1].axis, 1);
  // ... by the offset: the RMS of a constant c plus noise sigma is
  // sqrt(c^2 + sigma^2); the noise's sample RMS over ~250 frames is good to
  // 5 %, so 10 % of that holds.
  const auto& e = s.errors.channels.rms_deg;
  EXPECT_NEAR(e[2][0], std::hypot(3e-3 * kDeg, kNoiseDeg),
              0.1 * std::hypot(3e-3 * kDeg, kNoiseDeg));
  EXPECT_NEAR(e[8][1], std::hypot(2e-3 * kDeg, kNoiseDeg),
              0.1 * std::hypot(2e-3 * kDeg, kNoiseDeg));
  // The model given the effect (--effects) predicts it to the floor again.
  PredictionModel with = model;
  with.effects.push_back({"mocap_offset: {joint3_x_rad: 0.003, joint9_y_rad: 0.002}", "e.yaml"});
  const PredictionSummary fixed = Predict(news, with, Options());
  EXPECT_EQ(fixed.effects, std::vector<std::string>{"mocap_offset"});
  EXPECT_TRUE(fixed.adequacy.above_noise.empty()) << fixed.FullReport();
  EXPECT_NEAR(fixed.errors.weighted_rms, 1.0, 0.1);
}

TEST_F(PredictionTest, WritesTheFolderAndReadsAParameterFileToo) {
  const fs::path dir = Scratch("folder");
  const std::string params = (dir / "p.yaml").string();
  WriteTextFileAtomically(params, "T_p: " + std::to_string(fitted_tp_) + "\nmu: {value: 0}\n");
  const PredictionModel model = LoadPredictionModel(params);
  EXPECT_EQ(model.kind, "parameter file");
  EXPECT_FALSE(model.arm.has_value());
  const std::vector<Experiment> news = {Recording(Truth(), 7, NewMotion(), "new_plus3")};
  const PredictionSummary s = Predict(news, model, Options());
  const std::vector<std::string> written =
      WritePredictionDirectory(s, news, (dir / "pred").string());
  EXPECT_EQ(written.size(), 3u);
  for (const char* file : {"pred.json", "new_plus3.pred.h5", "new_plus3.angles.csv"}) {
    EXPECT_TRUE(fs::exists(dir / "pred" / file)) << file;
  }
  const nlohmann::json json =
      nlohmann::json::parse(ReadTextFile((dir / "pred/pred.json").string()));
  EXPECT_EQ(json["schema"], "ccsrm-prediction/1");
  EXPECT_EQ(json["recordings"][0]["angles_file"], "new_plus3.angles.csv");
  EXPECT_EQ(json["errors"]["per_joint"].size(), 12u);
  EXPECT_NEAR(json["weighted_rms"].get<double>(), s.errors.weighted_rms, 1e-12);
  const std::string csv = ReadTextFile((dir / "pred/new_plus3.angles.csv").string());
  EXPECT_THAT(csv, HasSubstr("time_s,measured_thetax1_deg,predicted_thetax1_deg,"
                             "residual_thetax1_deg,measured_thetay1_deg"));
}

TEST_F(PredictionTest, ReadsTheModelFromAFitOrLoopFolderAndAnOlderFitJson) {
  // A loop folder's model is its final fit (final/fit.json beside loop.json).
  const fs::path loop = Scratch("loop");
  fs::create_directories(loop / "final");
  fs::copy_file(*fit_json_, loop / "final" / "fit.json");
  WriteTextFileAtomically((loop / "loop.json").string(), R"({"schema": "ccsrm-loop/1"})");
  for (const fs::path& source : {loop, loop / "loop.json", loop / "final"}) {
    const PredictionModel model = LoadPredictionModel(source.string());
    EXPECT_EQ(model.source, (loop / "final" / "fit.json").string()) << source;
    EXPECT_DOUBLE_EQ(model.values.at("T_p"), fitted_tp_) << source;
  }
  // A fit.json written before fits recorded their arm: the joints of its
  // error table still tell the arm (its cables unknown).
  nlohmann::json old = nlohmann::json::parse(ReadTextFile(*fit_json_));
  old.erase("arm");
  const std::string old_fit = (loop / "old.json").string();
  WriteTextFileAtomically(old_fit, old.dump());
  const PredictionModel model = LoadPredictionModel(old_fit);
  ASSERT_TRUE(model.arm.has_value());
  EXPECT_EQ(model.arm->joints, 12);
  EXPECT_EQ(model.arm->cables, 0);
}

TEST_F(PredictionTest, RefusesAModelOfAnotherArmOrUnknownParameters) {
  const std::vector<Experiment> news = {Recording(Truth(), 7, NewMotion(), "new_plus3")};
  PredictionModel model = LoadPredictionModel(*fit_json_);
  model.arm = sim::ArmSize{9, 9};
  try {
    Predict(news, model, Options());
    FAIL() << "a fit of a 9-joint arm was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("new_plus3.h5: arm: has 12 joints and 6 driving cables, but"));
  }
  const fs::path dir = Scratch("bad_model");
  const std::string bad = (dir / "fit.json").string();
  WriteTextFileAtomically(bad,
                          R"({"schema": "ccsrm-fit/1", "parameters": {"friction": {"value": 1}}})");
  EXPECT_THROW(
      {
        try {
          LoadPredictionModel(bad);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("key 'parameters.friction'"));
          EXPECT_THAT(e.what(), HasSubstr("unknown parameter 'friction'"));
          throw;
        }
      },
      InputError);
  WriteTextFileAtomically(bad, R"({"schema": "ccsrm-run/1"})");
  EXPECT_THROW(LoadPredictionModel(bad), InputError);
  model = LoadPredictionModel(*fit_json_);
  model.values["mocap_offset.joint13_x_rad"] = 0.001;  // the paper's arm has 12 joints
  EXPECT_THROW(Predict(news, model, Options()), InputError);
}

// Issue 44: a fit judges its own model by the rule prediction uses. The
// fixture's fit is of the right model (only T_p free, the truth's effects
// none): every channel within its noise.
TEST_F(PredictionTest, AFitOfTheRightModelSaysItExplainsTheData) {
  EXPECT_TRUE(right_model_adequate_) << *right_model_verdict_;
  EXPECT_EQ(right_model_verdict_->rfind("the model explains the data", 0), 0u)
      << *right_model_verdict_;
}

// On null data (the model right, ten noise seeds) the verdict says
// "explains" at least nine times in ten: the rule's family-wise
// significance is 1 % per recording, so a false alarm in ten is already
// unlikely (a tenth of a percent); the 1.5x size floor guards the noise
// estimate's own error (a twist-based noise good to about 10 %).
TEST_F(PredictionTest, NullDataIsCalledAdequateAtLeastNineTimesInTen) {
  PredictionModel model = LoadPredictionModel(*fit_json_);
  model.values["T_p"] = sim::GetParameter(Truth(), "T_p");
  int adequate = 0;
  std::string verdicts;
  for (unsigned seed = 21; seed < 31; ++seed) {
    const std::vector<Experiment> null = {
        Recording(Truth(), seed, Motion(seed % 2 == 0 ? 5.0 : -5.0, 2.0), "null")};
    const PredictionSummary s = Predict(null, model, Options());
    ASSERT_TRUE(s.completed) << s.message;
    adequate += s.adequacy.adequate();
    verdicts += s.adequacy.Verdict() + "\n";
  }
  std::printf("%s", verdicts.c_str());
  EXPECT_GE(adequate, 9) << verdicts;
}

// A truth whose table is tilted by 0.01 rad, which the fitted model lacks
// (the new user's scenario of issue 44): the fit converges on a biased T_p,
// and says at the top that the model does not explain the data, naming a
// joint axis; its intervals widened by the misfit are at least as wide.
TEST_F(PredictionTest, AFitOfAModelMissingAnEffectSaysItDoesNotExplainTheData) {
  sim::ArmParameters truth = Truth();
  sim::SetParameter("table_tilt.lateral_rad", 0.01, "test", &truth);
  const std::vector<Experiment> tilted = {Recording(truth, 11, Motion(6.0, 2.0), "tilted_plus6"),
                                          Recording(truth, 12, Motion(-4.0, 2.0), "tilted_minus4")};
  IdentificationOptions options;
  options.free_parameters = {"T_p"};
  options.values = {{"T_p", 45.0}};
  options.threads = 2;
  const IdentificationSummary fit = Identify(tilted, options);
  std::printf("%s\n", fit.FullReport().c_str());
  ASSERT_TRUE(fit.adequacy.assessed);
  EXPECT_FALSE(fit.adequacy.adequate());
  const std::string report = fit.FullReport();
  EXPECT_EQ(report.rfind("model: the model does NOT explain the data", 0), 0u) << report;
  EXPECT_NE(fit.BriefReport().find("does NOT explain"), std::string::npos);
  ASSERT_NE(fit.adequacy.Worst(), nullptr);
  EXPECT_GT(fit.adequacy.misfit_scale(), kAboveNoiseRatio);
  const ParameterEstimate& tp = *fit.Find("T_p");
  const std::array<double, 2> wide = fit.MisfitInterval(tp);
  EXPECT_LE(wide[0], tp.ci95_lower);
  EXPECT_GE(wide[1], tp.ci95_upper);
  const nlohmann::json json = ToJson(fit);
  EXPECT_FALSE(json["adequacy"]["adequate"].get<bool>());
  EXPECT_EQ(json["parameters"]["T_p"]["ci95_scaled_by_misfit"][0].get<double>(), wide[0]);
}

}  // namespace
}  // namespace ccsrm::identify
