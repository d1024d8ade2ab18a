// Runs the ccsrm program as a user would and checks what it prints.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "c3d_test_files.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "run_ccsrm.h"
#include "shared_data.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::RunCcsrm;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

fs::path FreshDir(const std::string& name) {
  return ccsrm::testing::ScratchDirectory("cli_" + name);
}

TEST(Cli, ConfigCheckAcceptsThePaperConfiguration) {
  const Outcome o = RunCcsrm("config check " + Paper());
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr(": ok"));
  EXPECT_THAT(o.out, HasSubstr("links: 12"));
  EXPECT_THAT(o.out, HasSubstr("driving cables: 6"));
}

TEST(Cli, ConfigCheckRejectsATypoWithOneLine) {
  const fs::path dir = FreshDir("typo");
  std::string text = ccsrm::ReadTextFile(Paper());
  text.replace(text.find("pretension_n: 100.0"), 19, "pretensoin_n: 100.0");
  const std::string bad = (dir / "bad.yaml").string();
  ccsrm::WriteTextFileAtomically(bad, text);
  const Outcome o = RunCcsrm("config check " + bad);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr(bad + ": line "));
  EXPECT_THAT(o.err, HasSubstr("driving_cables.pretensoin_n"));
}

TEST(Cli, MissingFileAndUnknownSubcommandFail) {
  const Outcome missing = RunCcsrm("config check /nonexistent/arm.yaml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_THAT(missing.err, HasSubstr("/nonexistent/arm.yaml: cannot open for reading"));
  EXPECT_NE(RunCcsrm("frobnicate").status, 0);
  EXPECT_EQ(RunCcsrm("--help").status, 0);
  EXPECT_EQ(RunCcsrm("simulate --help").status, 0);
  EXPECT_EQ(RunCcsrm("dataset inspect --help").status, 0);
}

TEST(Cli, SimulateWritesARunFileThatInspectReads) {
  const fs::path dir = FreshDir("simulate");
  const std::string run = (dir / "run.h5").string();
  const Outcome sim =
      RunCcsrm("simulate --config " + Paper() + " --case 1 --duration 0.05 --quiet --out " + run);
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_THAT(sim.out, HasSubstr("simulation completed"));
  EXPECT_THAT(sim.out, HasSubstr("real-time factor"));
  EXPECT_THAT(sim.out, HasSubstr("stick-slip switches"));
  // Issue 44: the error to the plan per segment, and the stuck nodes the
  // run's states hold, whatever the law.
  EXPECT_THAT(sim.out, HasSubstr("error to the plan, seg. 1: RMS"));
  EXPECT_THAT(sim.out, HasSubstr("error to the plan, seg. 2: RMS"));
  EXPECT_THAT(sim.out, HasSubstr("stuck hole nodes:          at most"));
  const ccsrm::datasets::RunFile file = ccsrm::datasets::ReadRunFile(run);
  EXPECT_EQ(file.frames(), 6u);  // 0 .. 0.05 s at 100 Hz
  EXPECT_EQ(file.case_name, "1");
  const Outcome text = RunCcsrm("dataset inspect " + run);
  EXPECT_EQ(text.status, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("ccsrm-run/1"));
  const Outcome json = RunCcsrm("dataset inspect --json " + run);
  EXPECT_EQ(json.status, 0);
  EXPECT_THAT(json.out, HasSubstr("\"schema\": \"ccsrm-run/1\""));
  // Nothing but the output file in the output directory.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(Cli, SimulateRejectsBadArgumentsBeforeRunning) {
  EXPECT_EQ(RunCcsrm("simulate --config " + Paper() + " --case 5 --out /tmp/x.h5").status, 2);
  const Outcome no_dir =
      RunCcsrm("simulate --config " + Paper() + " --case 1 --out /nonexistent-dir/run.h5");
  EXPECT_EQ(no_dir.status, 2);
  EXPECT_THAT(no_dir.err, HasSubstr("does not exist"));
  const Outcome bad_duration =
      RunCcsrm("simulate --config " + Paper() + " --duration -1 --out /tmp/x.h5");
  EXPECT_EQ(bad_duration.status, 2);
  EXPECT_THAT(bad_duration.err, HasSubstr("--duration"));
}

// One out-of-range value of a range-checked option, and the option the
// message must name.
struct BadOption {
  std::string args;
  std::string option;
};

// Every range-checked option of every subcommand. Each is refused with
// status 2 and one line naming the option, before anything runs or is
// written: the input files need not even exist.
TEST(Cli, OutOfRangeOptionsOfEveryCommandExitTwoWithOneLineNamingTheOption) {
  const fs::path dir = FreshDir("bad_options");
  const std::string out = (dir / "out.h5").string();
  const std::string simulate = "simulate --config " + Paper() + " --out " + out + " ";
  const std::string generate = "generate --config " + Paper() + " --out " + out + " ";
  const std::string bench = "bench --config " + Paper() + " ";
  const std::string process = "mocap process --in /nonexistent/m.c3d --out " + out + " ";
  const std::string render = "cameras render --in /nonexistent/run.h5 --out " + out + " ";
  const std::string board = "cameras render-board --out " + (dir / "boards").string() + " ";
  const std::string calibrate_board =
      "cameras calibrate board --images /nonexistent/a.png --out " + out + " ";
  const std::string calibrate_markers =
      "cameras calibrate markers --cameras /nonexistent/c.yaml "
      "--video /nonexistent/v.avi --config " +
      Paper() + " --out " + out + " ";
  const std::vector<BadOption> cases = {
      {simulate + "--case 7", "--case"},
      {simulate + "--case 0", "--case"},
      {simulate + "--amplitude=1e9", "--amplitude"},
      {simulate + "--amplitude -60.5", "--amplitude"},
      {simulate + "--amplitude nan", "--amplitude"},
      {simulate + "--duration 0", "--duration"},
      {simulate + "--duration -1", "--duration"},
      {simulate + "--output-rate 0", "--output-rate"},
      {simulate + "--output-rate 1e6", "--output-rate"},
      {generate + "--case 5", "--case"},
      {generate + "--amplitude 100", "--amplitude"},
      {generate + "--duration -3", "--duration"},
      {generate + "--noise-mm -1", "--noise-mm"},
      {bench + "--case 9", "--case"},
      {bench + "--duration -1", "--duration"},
      {bench + "--repeat 0", "--repeat"},
      {process + "--cutoff-hz -1", "--cutoff-hz"},
      {process + "--order 0", "--order"},
      {process + "--order 9", "--order"},
      {process + "--max-spline-gap -1", "--max-spline-gap"},
      {render + "--noise-px -0.1", "--noise-px"},
      {render + "--drop-probability 1.5", "--drop-probability"},
      {render + "--stride 0", "--stride"},
      {board + "--square-mm -4", "--square-mm"},
      {board + "--world-square-mm 0", "--world-square-mm"},
      {board + "--views 0", "--views"},
      {calibrate_board + "--square-mm 0", "--square-mm"},
      {calibrate_board + "--world-square-mm -1", "--world-square-mm"},
      {calibrate_markers + "--frames 0", "--frames"},
  };
  for (const BadOption& c : cases) {
    SCOPED_TRACE(c.args);
    const Outcome o = RunCcsrm(c.args);
    EXPECT_EQ(o.status, 2);
    EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
    EXPECT_EQ(o.err.rfind("ccsrm: " + c.option + ": ", 0), 0u) << o.err;
    // The value came from the command line, not from the configuration.
    EXPECT_THAT(o.err, ::testing::Not(HasSubstr("paper.yaml"))) << o.err;
    EXPECT_EQ(o.out, "");
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Cli, ParseErrorsAreOneLineWithStatusTwoAndHelpStillWorks) {
  const std::string simulate = "simulate --config " + Paper() + " ";
  for (const std::string& args :
       {simulate + "--out /tmp/x.h5 --frobnicate", simulate,
        simulate + "--amplitude abc --out x.h5", std::string("mocap inspect"), std::string("")}) {
    SCOPED_TRACE(args);
    const Outcome o = RunCcsrm(args);
    EXPECT_EQ(o.status, 2);
    EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
    EXPECT_EQ(o.err.rfind("ccsrm: ", 0), 0u) << o.err;
  }
  EXPECT_THAT(RunCcsrm(simulate).err, HasSubstr("--out"));  // the missing option
  const Outcome help = RunCcsrm("simulate --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_THAT(help.out, HasSubstr("--amplitude FLOAT:in [-60, 60] deg"));
  EXPECT_EQ(help.err, "");
  EXPECT_EQ(RunCcsrm("--version").status, 0);
}

// A C3D file whose parameter section declares fewer blocks than its records
// fill (as some vendors write them) opens; mocap inspect says so.
TEST(Cli, MocapInspectOpensAC3dFileThatDisagreesWithItselfAndWarns) {
  const fs::path dir = FreshDir("self_disagreeing_c3d");
  const std::vector<std::uint8_t> correct =
      ccsrm::mocap::EncodeC3d(ccsrm::testing::LongLabelTable(128, 40));
  ASSERT_EQ(ccsrm::testing::DataStartBlock(correct), 8);
  const std::vector<std::uint8_t> defective =
      ccsrm::testing::WithDeclaredParameterBlocks(correct, 3);
  const std::string good = (dir / "good.c3d").string();
  const std::string bad = (dir / "three_blocks.c3d").string();
  std::ofstream(good, std::ios::binary)
      .write(reinterpret_cast<const char*>(correct.data()), correct.size());
  std::ofstream(bad, std::ios::binary)
      .write(reinterpret_cast<const char*>(defective.data()), defective.size());

  const Outcome text = RunCcsrm("mocap inspect " + bad);
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("warning: the parameter section (byte 514) declares 3 block(s), "
                                  "but its records fill blocks 2-7"));
  const Outcome a = RunCcsrm("mocap inspect --json " + good);
  const Outcome b = RunCcsrm("mocap inspect --json " + bad);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  nlohmann::json ja = nlohmann::json::parse(a.out);
  nlohmann::json jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(ja["warnings"].size(), 0u);
  ASSERT_EQ(jb["warnings"].size(), 1u);
  for (const char* key : {"frames", "labels", "first_frame", "rate_hz", "invalid_points"}) {
    EXPECT_EQ(ja[key], jb[key]) << key;
  }
  EXPECT_EQ(jb["frames"], 40);
  EXPECT_EQ(jb["labels"].size(), 128u);
}

// A real vendor file through the command line (skipped, naming the file,
// on a clone without the shared folder).
TEST(Cli, MocapInspectJsonOfAVendorC3dHasTheDocumentedKeys) {
  CCSRM_SHARED_FILE_OR_SKIP(pc_real, "data/mocap/c3d/pc_real.c3d");
  const Outcome o = RunCcsrm("mocap inspect --json " + pc_real);
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  for (const char* key : {"format", "frames", "rate_hz", "labels", "units_in_file",
                          "invalid_points", "longest_gap_frames", "first_frame"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["format"], "c3d");
  EXPECT_EQ(j["frames"], 89);
  const std::string text = RunCcsrm("mocap inspect " + pc_real).out;
  EXPECT_THAT(text, HasSubstr("longest gap"));
}

TEST(Cli, DatasetInspectRejectsANonHdf5File) {
  const fs::path dir = FreshDir("inspect");
  const std::string fake = (dir / "fake.h5").string();
  ccsrm::WriteTextFileAtomically(fake, "not an hdf5 file\n");
  const Outcome o = RunCcsrm("dataset inspect " + fake);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr(fake));
}

}  // namespace
