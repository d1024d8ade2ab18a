// Runs the ccsrm program as a user would and checks what it prints.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/run_file.h"
#include "run_ccsrm.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::RunCcsrm;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ccsrm_cli_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int Lines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
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
  EXPECT_EQ(Lines(o.err), 1) << o.err;
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
  EXPECT_NE(RunCcsrm("simulate --config " + Paper() + " --case 5 --out /tmp/x.h5").status, 0);
  const Outcome no_dir =
      RunCcsrm("simulate --config " + Paper() + " --case 1 --out /nonexistent-dir/run.h5");
  EXPECT_EQ(no_dir.status, 2);
  EXPECT_THAT(no_dir.err, HasSubstr("does not exist"));
  const Outcome bad_duration =
      RunCcsrm("simulate --config " + Paper() + " --duration -1 --out /tmp/x.h5");
  EXPECT_EQ(bad_duration.status, 2);
  EXPECT_THAT(bad_duration.err, HasSubstr("--duration"));
}

TEST(Cli, DatasetInspectRejectsANonHdf5File) {
  const fs::path dir = FreshDir("inspect");
  const std::string fake = (dir / "fake.h5").string();
  ccsrm::WriteTextFileAtomically(fake, "not an hdf5 file\n");
  const Outcome o = RunCcsrm("dataset inspect " + fake);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(Lines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr(fake));
}

}  // namespace
