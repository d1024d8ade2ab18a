// `ccsrm derivatives` as a user runs it: the table, the JSON file, and one
// line naming the option for every bad value, before any run starts.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/experiment_file.h"
#include "run_ccsrm.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::CountLines;
using ccsrm::testing::RunCcsrm;
using ccsrm::testing::ScratchDirectory;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

// 0.05 s of case 3: quick runs; mu_c and mu_c_s are 0 there, so they are
// stepped relative to the configuration's 0.21.
TEST(DerivativesCommand, PrintsTheTableAndWritesJson) {
  const fs::path dir = ScratchDirectory("identify_cli_table");
  const std::string json_path = (dir / "d.json").string();
  const Outcome o = RunCcsrm("derivatives --config " + Paper() +
                             " --case 3 --duration 0.05 --parameters mu,mu_c,T_p --threads 2 "
                             "--set mu_s=0.25 --quiet --json " +
                             json_path);
  ASSERT_TRUE(o.status == 0 || o.status == 4) << o.all();
  EXPECT_THAT(o.out, HasSubstr("case 3"));
  EXPECT_THAT(o.out, HasSubstr("--set mu_s=0.25"));
  EXPECT_THAT(o.out, HasSubstr("derivative check"));
  EXPECT_THAT(o.out, HasSubstr("T_p "));
  EXPECT_THAT(o.out, HasSubstr("value 0, steps relative to s = 0.21"));
  const nlohmann::json json = nlohmann::json::parse(ccsrm::ReadTextFile(json_path));
  EXPECT_EQ(json["schema"], "ccsrm-derivatives/1");
  ASSERT_EQ(json["parameters"].size(), 3u);
  EXPECT_EQ(json["parameters"][1]["name"], "mu_c");
  EXPECT_EQ(json["parameters"][1]["steps"][0]["scheme"], "forward");
  EXPECT_EQ(json["run"]["case"], 3);
  EXPECT_EQ(json["runs"], 1 + 3 * 2 * 2);
  EXPECT_EQ(o.status == 0, json["passed"].get<bool>());
  // Only the JSON file in the output directory.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(DerivativesCommand, SweepsOneParameter) {
  const Outcome o = RunCcsrm("derivatives --config " + Paper() +
                             " --case 2 --duration 0.05 --sweep T_d0 --points 5 --span 0.02 "
                             "--threads 2 --quiet");
  ASSERT_EQ(o.status, 0) << o.all();
  EXPECT_THAT(o.out, HasSubstr("sweep of T_d0"));
  EXPECT_THAT(o.out, HasSubstr("5 values from 98 to 102"));
  EXPECT_THAT(o.out, HasSubstr("residual to the cubics"));
}

// The fast motions that pin kinetic friction are protocol files (issue 43):
// the command follows one, with its parameters after '@', and records it.
TEST(DerivativesCommand, FollowsAProtocolFileAndRecordsIt) {
  const fs::path dir = ScratchDirectory("identify_cli_protocol");
  const std::string json_path = (dir / "d.json").string();
  const std::string protocol =
      std::string(CCSRM_SOURCE_DIR) + "/configs/protocols/paper.yaml@amplitude_deg=-4";
  const Outcome o =
      RunCcsrm("derivatives --config " + Paper() + " --case 3 --protocol " + protocol +
               " --duration 0.05 --parameters T_p --threads 2 --quiet --json " + json_path);
  ASSERT_TRUE(o.status == 0 || o.status == 4) << o.all();
  EXPECT_THAT(o.out, HasSubstr("protocol 'paper'"));
  const nlohmann::json json = nlohmann::json::parse(ccsrm::ReadTextFile(json_path));
  // The protocol as followed: its amplitude parameter as set after '@' [rad].
  EXPECT_THAT(json["run"]["protocol_yaml"].get<std::string>(), HasSubstr("amplitude_deg"));
  EXPECT_EQ(json["run"]["duration_s"], 0.05);
  const Outcome bad = RunCcsrm("derivatives --config " + Paper() + " --protocol " + protocol +
                               ",speed_deg=3 --duration 0.05 --parameters T_p");
  EXPECT_EQ(bad.status, 2) << bad.all();
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_THAT(bad.err, HasSubstr("speed_deg"));
}

TEST(DerivativesCommand, BadOptionsExitWithOneLineNamingTheOption) {
  const std::string run = "derivatives --config " + Paper() + " --case 2 --duration 0.05 ";
  const struct {
    std::string args, option;
  } cases[] = {
      {"--steps 1e-2", "--steps"},
      {"--steps 1e-2,x", "--steps"},
      {"--steps 1e-2,,3e-3", "--steps"},
      {"--parameters mu,friction", "--parameters"},
      {"--threads 0", "--threads"},
      {"--threads two", "--threads"},
      {"--sweep friction", "--sweep"},
      {"--sweep mu --points 3", "--points"},
      {"--sweep mu --span 1.5", "--span"},
      {"--span 0.05", "--span"},
      {"--sweep mu --parameters mu", "--parameters"},
      {"--negligible-deg -1", "--negligible-deg"},
      {"--set mu=-1", "--set"},
      {"--json /nonexistent-dir/d.json", "does not exist"},
  };
  for (const auto& c : cases) {
    const Outcome o = RunCcsrm(run + c.args);
    EXPECT_EQ(o.status, 2) << c.args << "\n" << o.all();
    EXPECT_EQ(CountLines(o.err), 1) << c.args << "\n" << o.err;
    EXPECT_THAT(o.err, HasSubstr(c.option)) << c.args;
    EXPECT_EQ(o.out, "") << c.args << ": nothing may run before the options are checked";
  }
}

// A generated experiment (no measured angles: the pipeline runs first), one
// free parameter, two iterations: fit.json with the keys, the fitted
// run and the angles table, and an exit status that says whether it converged.
TEST(IdentifyCommand, FitsAGeneratedExperimentAndWritesTheFitFolder) {
  const fs::path dir = ScratchDirectory("identify_cli_fit");
  const std::string exp = (dir / "g.h5").string();
  const Outcome g = RunCcsrm("generate --config " + Paper() +
                             " --case 4 --duration 2 --set T_p=60 --quiet --out " + exp);
  ASSERT_EQ(g.status, 0) << g.all();
  const std::string out = (dir / "fit").string();
  const Outcome o = RunCcsrm("identify --data " + exp +
                             " --free T_p --set mu=0 --set mu_s=0 --max-iterations 2 --threads 2 "
                             "--quiet --out " +
                             out);
  ASSERT_TRUE(o.status == 0 || o.status == 4) << o.all();
  EXPECT_THAT(o.out, HasSubstr("computed by the mocap pipeline with default settings"));
  EXPECT_THAT(o.out, HasSubstr("T_p"));
  const nlohmann::json fit = nlohmann::json::parse(ccsrm::ReadTextFile(out + "/fit.json"));
  for (const char* key : {"parameters", "rms_deg", "fit_percent", "converged", "iterations",
                          "simulations", "wall_time_s", "correlation", "singular_values"}) {
    EXPECT_TRUE(fit.contains(key)) << key;
  }
  EXPECT_EQ(fit["converged"].get<bool>(), o.status == 0);
  const nlohmann::json& tp = fit["parameters"]["T_p"];
  for (const char* key : {"value", "std_error", "ci95", "identifiable"}) {
    EXPECT_TRUE(tp.contains(key)) << key;
  }
  EXPECT_FALSE(fit["parameters"]["mu"]["free"].get<bool>());
  EXPECT_EQ(fit["parameters"]["mu"]["value"].get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(out + "/g.fit.h5"));
  EXPECT_TRUE(fs::exists(out + "/g.angles.csv"));
  // The input is never modified.
  EXPECT_TRUE(fs::exists(exp));
}

// The real-file path (issue 11): the markers of a generated experiment
// written as a C3D file, processed with the arm's configuration and the
// recorded inputs, fit the same as the HDF5 experiment they came from. C3D
// stores float coordinates (1e-4 mm at an arm's size, far below the 0.2 mm
// marker noise) and marks occluded markers, so the pipeline sees the same
// markers and the two fits may differ only by rounding.
TEST(IdentifyCommand, AC3dRecordingFitsLikeTheExperimentItCameFrom) {
  const fs::path dir = ScratchDirectory("identify_cli_c3d_route");
  const std::string exp = (dir / "g.h5").string();
  // The loop sample's arm: the paper's, with a 9 s protocol whose first 4.5 s
  // (ramp and hold) pin T_p down.
  const std::string sample_arm = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/arm.yaml";
  Outcome o = RunCcsrm("generate --config " + sample_arm +
                       " --case 4 --duration 4.5 --set T_p=60 --seed 7 --quiet --out " + exp);
  ASSERT_EQ(o.status, 0) << o.all();
  // The arm's configuration as a user keeps it: here the experiment's own.
  const std::string arm = (dir / "arm.yaml").string();
  ccsrm::WriteTextFileAtomically(arm, ccsrm::datasets::ReadExperimentFile(exp).config_yaml);
  const std::string c3d = (dir / "recording.c3d").string();
  o = RunCcsrm("mocap export --in " + exp + " --out " + c3d);
  ASSERT_EQ(o.status, 0) << o.all();
  const std::string recorded = (dir / "recording.h5").string();
  o = RunCcsrm("mocap process --quiet --in " + c3d + " --config " + arm + " --inputs " + exp +
               " --out " + recorded);
  ASSERT_EQ(o.status, 0) << o.all();

  const std::string fit = " --free T_p --max-iterations 3 --threads 2 --quiet --out ";
  const Outcome from_h5 = RunCcsrm("identify --data " + exp + fit + (dir / "fit_h5").string());
  const Outcome from_c3d =
      RunCcsrm("identify --data " + recorded + fit + (dir / "fit_c3d").string());
  ASSERT_TRUE(from_h5.status == 0 || from_h5.status == 4) << from_h5.all();
  EXPECT_EQ(from_c3d.status, from_h5.status) << from_c3d.all();
  const nlohmann::json a =
      nlohmann::json::parse(ccsrm::ReadTextFile((dir / "fit_h5" / "fit.json").string()));
  const nlohmann::json b =
      nlohmann::json::parse(ccsrm::ReadTextFile((dir / "fit_c3d" / "fit.json").string()));
  const nlohmann::json& ta = a["parameters"]["T_p"];
  const nlohmann::json& tb = b["parameters"]["T_p"];
  ASSERT_TRUE(ta["identifiable"].get<bool>());
  ASSERT_TRUE(tb["identifiable"].get<bool>());
  // Rounding may move the estimate, but by far less than the data can tell.
  EXPECT_LT(std::abs(ta["value"].get<double>() - tb["value"].get<double>()),
            0.05 * ta["std_error"].get<double>());
  EXPECT_NEAR(b["rms_deg"].get<double>(), a["rms_deg"].get<double>(),
              0.01 * a["rms_deg"].get<double>());
  EXPECT_EQ(b["residuals"].get<int>(), a["residuals"].get<int>());
  EXPECT_EQ(b["iterations"].get<int>(), a["iterations"].get<int>());
}

TEST(IdentifyCommand, BadInputExitsWithOneLineBeforeAnySimulation) {
  const fs::path dir = ScratchDirectory("identify_cli_bad");
  const std::string truncated = (dir / "truncated.h5").string();
  ccsrm::WriteTextFileAtomically(truncated, "HDF5 but not really");
  const std::string params = (dir / "p.yaml").string();
  ccsrm::WriteTextFileAtomically(params, "T_p: {bounds: [60, 80]}\n");
  const std::string exp = (dir / "e.h5").string();
  const Outcome g =
      RunCcsrm("generate --config " + Paper() + " --case 4 --duration 0.5 --quiet --out " + exp);
  ASSERT_EQ(g.status, 0) << g.all();
  const std::string out = " --out " + (dir / "fit").string();
  const struct {
    std::string args, message;
  } cases[] = {
      {"--data /nonexistent.h5", "/nonexistent.h5"},
      {"--data " + truncated, truncated},
      {"--data " + exp + " --free mu,friction", "unknown parameter 'friction'"},
      // The start (50 N) is the experiment's own value: its file is named.
      {"--data " + exp + " --free T_p --params " + params,
       exp + ": parameter 'T_p': start value 50 is outside the bounds"},
      {"--data " + exp + " --set beta=3", "parameter 'beta' = 3 is outside"},
      {"--data " + exp + " --threads 0", "--threads"},
  };
  for (const auto& c : cases) {
    const Outcome o = RunCcsrm("identify " + c.args + out);
    EXPECT_EQ(o.status, 2) << c.args << "\n" << o.all();
    EXPECT_EQ(CountLines(o.err), 1) << c.args << "\n" << o.err;
    EXPECT_THAT(o.err, HasSubstr(c.message)) << c.args;
    EXPECT_FALSE(fs::exists(dir / "fit")) << c.args;
  }
}

}  // namespace
