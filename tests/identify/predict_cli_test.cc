// `ccsrm predict` as a user runs it (issue 25): experiments generated on the
// paper protocol, identified, then a motion the fit did not see predicted,
// and its report; and bad input, one line each, nothing written.
//
// The arm: the loop sample's (the paper's, case 4, a 9 s protocol); every
// experiment records the ramp and the hold of its amplitude (the protocol's
// 3 s ramp), with 0.2 mm marker noise and occlusions, and goes through the
// mocap pipeline when loaded, as a real recording would.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "run_ccsrm.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::CountLines;
using ccsrm::testing::RunCcsrm;
using ccsrm::testing::ScratchDirectory;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

const std::string kArm = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/arm.yaml";

nlohmann::json ReadJson(const fs::path& path) {
  return nlohmann::json::parse(ccsrm::ReadTextFile(path.string()));
}

// Generates the experiments and the fit once: T_p (truth 60 N, nominal and
// start 50 N) fitted on +6 and -4 deg, 4.5 s each (about half a minute).
class PredictCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(ScratchDirectory("predict_cli"));
    const std::string generate = "generate --config " + kArm + " --case 4 --set T_p=60 --quiet ";
    const struct {
      std::string args, name;
    } experiments[] = {
        {"--duration 4.5 --amplitude 6 --seed 1", "train_plus6"},
        {"--duration 4.5 --amplitude -4 --seed 2", "train_minus4"},
        // The new motion: +3 deg, ramp and half the hold.
        {"--duration 3.5 --amplitude 3 --seed 3", "new"},
        // The same recording of an arm on a table tilted by 20 mrad.
        {"--duration 3.5 --amplitude 3 --seed 3 --effect table_tilt:lateral_rad=0.02", "tilted"},
    };
    for (const auto& e : experiments) {
      const Outcome o = RunCcsrm(generate + e.args + " --out " + Path(e.name + ".h5"));
      ASSERT_EQ(o.status, 0) << o.all();
    }
    const Outcome fit =
        RunCcsrm("identify --data " + Path("train_plus6.h5") + " " + Path("train_minus4.h5") +
                 " --free T_p --threads 2 --max-iterations 6 --quiet --out " + Path("fit"));
    ASSERT_EQ(fit.status, 0) << fit.all();
  }
  static void TearDownTestSuite() { delete dir_; }

  static std::string Path(const std::string& name) { return (*dir_ / name).string(); }

  static fs::path* dir_;
};
fs::path* PredictCommand::dir_ = nullptr;

// The per-recording errors of a pred.json, by name.
const nlohmann::json& Recording(const nlohmann::json& pred, const std::string& name) {
  for (const nlohmann::json& r : pred["recordings"]) {
    if (r["name"] == name) return r;
  }
  ADD_FAILURE() << "no recording " << name;
  return pred;
}

TEST_F(PredictCommand, PredictsANewMotionAtTheFloorAndShowsWhereATiltIsMissing) {
  const Outcome o = RunCcsrm("predict --data " + Path("new.h5") + " " + Path("tilted.h5") +
                             " --params " + Path("fit") + " --threads 2 --out " + Path("pred"));
  ASSERT_EQ(o.status, 0) << o.all();
  EXPECT_THAT(o.out, HasSubstr("predicting 2 recordings with"));
  EXPECT_THAT(o.err, HasSubstr("simulation 2 / 2"));  // progress, as the fits show it
  const nlohmann::json pred = ReadJson(*dir_ / "pred" / "pred.json");
  EXPECT_EQ(pred["schema"], "ccsrm-prediction/1");
  EXPECT_EQ(pred["model"]["free"], nlohmann::json({"T_p"}));
  for (const char* file :
       {"new.pred.h5", "new.angles.csv", "tilted.pred.h5", "tilted.angles.csv"}) {
    EXPECT_TRUE(fs::exists(*dir_ / "pred" / file)) << file;
  }

  // The floor: the same recordings predicted with their true parameters
  // (the truth files, the tilt included), which no model can beat.
  const Outcome truth =
      RunCcsrm("predict --data " + Path("new.h5") + " --params " + Path("new.truth.yaml") +
               " --threads 2 --quiet --out " + Path("pred_truth"));
  ASSERT_EQ(truth.status, 0) << truth.all();
  const Outcome tilt_truth =
      RunCcsrm("predict --data " + Path("tilted.h5") + " --params " + Path("tilted.truth.yaml") +
               " --threads 2 --quiet --out " + Path("pred_tilt_truth"));
  ASSERT_EQ(tilt_truth.status, 0) << tilt_truth.all();
  const double floor = ReadJson(*dir_ / "pred_truth" / "pred.json")["weighted_rms"].get<double>();
  const nlohmann::json tilt_floor = ReadJson(*dir_ / "pred_tilt_truth" / "pred.json");
  EXPECT_EQ(tilt_floor["effects"], nlohmann::json({"table_tilt"}));
  // The noise model: the weighted error (error / noise) has unit variance;
  // over ~200 effective samples (24 channels of 3.5 s filtered at 1 Hz) its
  // RMS scatters by 0.05, and the noise, estimated per joint from the
  // twist, can understate a channel of it. The truth sits within 0.3 of 1.
  EXPECT_NEAR(floor, 1.0, 0.3);
  // Same noise and occlusions (same seed): the tilted arm's truth leaves
  // the same floor, to the scatter above.
  EXPECT_NEAR(tilt_floor["weighted_rms"].get<double>(), floor, 0.05);

  // The fitted model on the motion it did not see: at the floor. Its T_p
  // is within a fraction of a newton of the truth; the angles move by about
  // 0.005 deg per newton, so its error adds well under 1 % of the noise's
  // variance: 0.05 is the chance scatter above.
  const nlohmann::json& clean = Recording(pred, "new");
  std::printf("new: weighted RMS %.3f (floor %.3f), RMS %.4f deg\n",
              clean["errors"]["weighted_rms"].get<double>(), floor,
              clean["errors"]["rms_deg"].get<double>());
  EXPECT_NEAR(clean["errors"]["weighted_rms"].get<double>(), floor, 0.05);

  // The tilt the fit lacks: a lateral tilt pulls every link across the arm
  // in the table plane, so it bends joints about x (θx) and leaves θy alone,
  // most at the root, which carries the whole arm's load.
  const nlohmann::json& tilted = Recording(pred, "tilted");
  const double tilted_rms = tilted["errors"]["weighted_rms"].get<double>();
  std::printf("tilted: weighted RMS %.3f (floor %.3f)\n", tilted_rms, floor);
  EXPECT_GT(tilted_rms, 1.5 * floor);
  int tilted_channels = 0;
  double worst_ratio = 0.0;
  int worst_joint = 0;
  for (const nlohmann::json& c : pred["above_noise"]) {
    if (c["recording"] != "tilted") continue;
    ++tilted_channels;
    EXPECT_EQ(c["axis"], "x") << c.dump();
    const double ratio = c["rms_deg"].get<double>() / c["noise_deg"].get<double>();
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst_joint = c["joint"].get<int>();
    }
  }
  // A few seconds of recording know each joint's noise to a quarter or so
  // (its twist's N_eff about 10: the verdict's F test), so only channels far
  // above it stand out beyond chance; the root's, carrying the whole arm's
  // load, is one (8x).
  EXPECT_GE(tilted_channels, 1) << pred["above_noise"].dump();
  EXPECT_EQ(worst_joint, 1);
  EXPECT_GT(worst_ratio, 3.0);

  // The page: measured against predicted, the error table, the model.
  const Outcome report = RunCcsrm("report --in " + Path("pred") + " --out " + Path("report"));
  ASSERT_EQ(report.status, 0) << report.all();
  const nlohmann::json summary = ReadJson(*dir_ / "report" / "summary.json");
  EXPECT_EQ(summary["kind"], "prediction");
  const std::string html = ccsrm::ReadTextFile(Path("report/index.html"));
  for (const char* text : {"Measured and predicted angles: tilted", "Errors per joint",
                           "Above the noise", "figures/angles_x_new_1.png", "T_p"}) {
    EXPECT_THAT(html, HasSubstr(text));
  }
  // --config: the arm's configuration as the user keeps it (here the file
  // the recordings were generated from) gives the same prediction.
  const Outcome with_config =
      RunCcsrm("predict --data " + Path("new.h5") + " --params " + Path("fit") + " --config " +
               kArm + " --threads 2 --quiet --out " + Path("pred_config"));
  ASSERT_EQ(with_config.status, 0) << with_config.all();
  EXPECT_NEAR(ReadJson(*dir_ / "pred_config" / "pred.json")["weighted_rms"].get<double>(),
              clean["errors"]["weighted_rms"].get<double>(), 1e-9);
  // A second run replaces its own folder; the inputs stay as they were.
  EXPECT_EQ(RunCcsrm("predict --data " + Path("new.h5") + " --params " + Path("fit/fit.json") +
                     " --threads 2 --quiet --out " + Path("pred"))
                .status,
            0);
  EXPECT_TRUE(fs::exists(Path("fit/fit.json")));
}

TEST_F(PredictCommand, BadInputGetsOneLineAndWritesNothing) {
  const fs::path bad = *dir_ / "bad";
  fs::create_directories(bad);
  const std::string truncated = (bad / "truncated.h5").string();
  ccsrm::WriteTextFileAtomically(truncated, "HDF5 but not really");
  // A fit.json of another arm: the fit of this arm with the arm changed.
  nlohmann::json other = ReadJson(*dir_ / "fit" / "fit.json");
  other["arm"] = {{"joints", 9}, {"driving_cables", 9}};
  const std::string other_arm = (bad / "other_arm.json").string();
  ccsrm::WriteTextFileAtomically(other_arm, other.dump());
  nlohmann::json unknown = ReadJson(*dir_ / "fit" / "fit.json");
  unknown["parameters"]["friction"] = {{"value", 1.0}};
  const std::string unknown_parameter = (bad / "unknown.json").string();
  ccsrm::WriteTextFileAtomically(unknown_parameter, unknown.dump());
  const std::string effects = (bad / "effects.yaml").string();
  ccsrm::WriteTextFileAtomically(effects, "gremlins: {}\n");
  const std::string mine = (bad / "mine").string();
  fs::create_directories(mine);
  ccsrm::WriteTextFileAtomically(mine + "/notes.txt", "mine");
  // A recording of another arm (three segments, nine cables): a short one.
  const std::string arm3 = (bad / "arm3.h5").string();
  const Outcome g =
      RunCcsrm("generate --config " + std::string(CCSRM_SOURCE_DIR) +
               "/configs/three-segment.yaml --case 4 --duration 0.3 --quiet --out " + arm3);
  ASSERT_EQ(g.status, 0) << g.all();

  const std::string data = " --data " + Path("new.h5");
  const std::string params = " --params " + Path("fit");
  const std::string out = " --out " + (bad / "pred").string();
  const struct {
    std::string args, message;
  } cases[] = {
      {" --data " + (bad / "missing.h5").string() + params + out, "missing.h5"},
      {" --data " + truncated + params + out, truncated + ": not an HDF5 file"},
      // A run file is not an experiment: the fitted run of the fit folder.
      {" --data " + Path("fit/train_plus6.fit.h5") + params + out, "expected ccsrm-dataset"},
      {data + " --params " + (bad / "missing.json").string() + out, "missing.json"},
      {data + " --params " + other_arm + out,
       "new.h5: arm: has 12 joints and 6 driving cables, but " + other_arm +
           " was fitted on an arm of 9 joints and 9 driving cables"},
      {data + " --params " + unknown_parameter + out, "key 'parameters.friction'"},
      {" --data " + arm3 + params + out, "arm3.h5: arm: has 12 joints and 9 driving cables"},
      {data + " --config " + std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml" +
           params + out,
       "new.h5: attribute 'config_yaml': describes an arm of 12 joints and 6 driving cables"},
      {data + params + " --effects " + effects + out, "key 'gremlins': unknown effect"},
      {data + params + " --threads 0" + out, "--threads"},
      // Outputs: a folder that is not ccsrm's, a folder inside an input.
      {data + params + " --out " + mine, "exists and is not a ccsrm prediction folder"},
      {data + params + " --out " + Path("fit/pred"), "--out"},
  };
  for (const auto& c : cases) {
    const Outcome o = RunCcsrm("predict" + c.args);
    EXPECT_EQ(o.status, 2) << c.args << "\n" << o.all();
    EXPECT_EQ(CountLines(o.err), 1) << c.args << "\n" << o.err;
    EXPECT_THAT(o.err, HasSubstr(c.message)) << c.args;
    EXPECT_FALSE(fs::exists(bad / "pred")) << c.args;
    EXPECT_FALSE(fs::exists(Path("fit/pred"))) << c.args;
  }
  EXPECT_TRUE(fs::exists(mine + "/notes.txt"));
}

}  // namespace
