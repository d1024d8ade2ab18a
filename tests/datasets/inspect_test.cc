#include "ccsrm/datasets/inspect.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "test_util.h"

namespace ccsrm::datasets {
namespace {
using ::ccsrm::datasets::testing::FreshDir;
using ::ccsrm::datasets::testing::InputErrorMessage;
using ::ccsrm::datasets::testing::MakeExperimentFile;
using ::ccsrm::datasets::testing::MakeRunFile;
using ::ccsrm::datasets::testing::SetUnits;
using ::testing::AllOf;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

std::string WriteRun(const std::string& name) {
  const std::string path = (FreshDir(name) / "run.h5").string();
  WriteRunFile(path, MakeRunFile());  // 7 frames, -0.02 s to 0.04 s
  return path;
}

std::string WriteExperiment(const std::string& name) {
  const std::string path = (FreshDir(name) / "exp.h5").string();
  WriteExperimentFile(path, MakeExperimentFile());  // 9 inputs to 0.04 s, 6 frames
  return path;
}

TEST(InspectFile, RunTextShowsSchemaFramesTimeSpanAndDatasets) {
  const std::string path = WriteRun("inspect_run_text");
  const std::string text = ToText(InspectFile(path));
  std::cout << text;
  EXPECT_THAT(text, HasSubstr("ccsrm-run/1 (simulation run)"));
  EXPECT_THAT(text, ContainsRegex("frames +7"));
  EXPECT_THAT(text, ContainsRegex("/time +7 samples, -0.02 s to 0.04 s"));
  EXPECT_THAT(text, ContainsRegex("/joint_angles +7×3×2 +float64 +rad"));
  EXPECT_THAT(text, ContainsRegex("/cables/2/slip_velocity +7×2 +float64 +m/s"));
  EXPECT_THAT(text, ContainsRegex("config_yaml +4 lines"));
  EXPECT_THAT(text, ContainsRegex("status +diverged"));
  EXPECT_THAT(text, Not(HasSubstr("friction:")));  // the YAML text itself is not shown
}

TEST(InspectFile, RunJsonShowsSchemaFramesTimeSpanAndDatasets) {
  const std::string path = WriteRun("inspect_run_json");
  const nlohmann::json json = ToJson(InspectFile(path));
  EXPECT_EQ(json["schema"], "ccsrm-run/1");
  EXPECT_EQ(json["kind"], "run");
  EXPECT_EQ(json["counts"]["frames"], 7);
  EXPECT_EQ(json["counts"]["cables"], 2);
  ASSERT_EQ(json["time_bases"].size(), 1u);
  EXPECT_EQ(json["time_bases"][0]["path"], "/time");
  EXPECT_EQ(json["time_bases"][0]["frames"], 7);
  EXPECT_DOUBLE_EQ(json["time_bases"][0]["first"].get<double>(), -0.02);
  EXPECT_NEAR(json["time_bases"][0]["last"].get<double>(), 0.04, 1e-15);
  EXPECT_EQ(json["attributes"]["steps"], "4321");
  EXPECT_EQ(json["attributes"]["config_yaml"], "4 lines");
  EXPECT_EQ(json["datasets"][1]["path"], "/joint_angles");
  EXPECT_EQ(json["datasets"][1]["shape"], nlohmann::json::array({7, 3, 2}));
  EXPECT_EQ(json["datasets"][1]["units"], "rad");
}

TEST(InspectFile, ExperimentShowsBothTimeBasesAndFrameCounts) {
  const std::string path = WriteExperiment("inspect_experiment");
  const FileSummary summary = InspectFile(path);
  const std::string text = ToText(summary);
  std::cout << text;
  EXPECT_THAT(text, HasSubstr("ccsrm-dataset/1 (experiment)"));
  EXPECT_THAT(text, ContainsRegex("mocap_frames +6"));
  EXPECT_THAT(text, ContainsRegex("/input/time +9 samples, 0 s to 0.04 s"));
  EXPECT_THAT(text, ContainsRegex("/mocap/time +6 samples, 0.001 s to 0.051 s"));
  EXPECT_THAT(text, ContainsRegex("/mocap/marker_names +4 +string"));
  const nlohmann::json json = ToJson(summary);
  EXPECT_EQ(json["schema"], "ccsrm-dataset/1");
  EXPECT_EQ(json["kind"], "experiment");
  EXPECT_EQ(json["counts"]["mocap_frames"], 6);
  EXPECT_EQ(json["counts"]["input_samples"], 9);
  ASSERT_EQ(json["time_bases"].size(), 2u);
  EXPECT_EQ(json["time_bases"][1]["path"], "/mocap/time");
  EXPECT_DOUBLE_EQ(json["time_bases"][1]["first"].get<double>(), 0.001);
  EXPECT_EQ(json["attributes"]["source"], "generated");
}

TEST(InspectFile, ValidatesTheFileFirst) {
  const std::string path = WriteRun("inspect_invalid");
  SetUnits(path, "/diagnostics/energy", "kJ");
  EXPECT_EQ(InputErrorMessage([&] { InspectFile(path); }),
            path + ": /diagnostics/energy: units attribute is 'kJ', expected 'J'");
  const std::string text_file = (FreshDir("inspect_text_file") / "notes.h5").string();
  std::ofstream(text_file) << "hello";
  EXPECT_THAT(InputErrorMessage([&] { InspectFile(text_file); }),
              AllOf(StartsWith(text_file + ": "), HasSubstr("not an HDF5 file")));
}

}  // namespace
}  // namespace ccsrm::datasets
