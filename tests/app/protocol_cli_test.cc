// ccsrm simulate / generate with --protocol and --inputs, as a user runs
// them: a protocol file drives the run and is recorded in it; bad protocol
// and input files each get one line naming the file and exit status 2, and
// nothing is written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/run_file.h"
#include "run_ccsrm.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::CountLines;
using ccsrm::testing::RunCcsrm;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

const std::string kConfigs = std::string(CCSRM_SOURCE_DIR) + "/configs";

std::vector<std::string> Entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST(ProtocolCli, SimulateFollowsAProtocolFileAndRecordsItInTheRunFile) {
  const fs::path dir = ccsrm::testing::ScratchDirectory("protocol_cli_run");
  const std::string out = (dir / "run.h5").string();
  const Outcome o = RunCcsrm("simulate --case 1 --protocol " + kConfigs +
                             "/protocols/two-axis.yaml --duration 0.5 --quiet --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr("protocol:                  'two-axis'"));
  const ccsrm::datasets::RunFile run = ccsrm::datasets::ReadRunFile(out);
  EXPECT_THAT(run.protocol_yaml, HasSubstr("name: two-axis"));
  EXPECT_TRUE(run.inputs_file.empty());
}

TEST(ProtocolCli, DefaultRunRecordsNoProtocolBesideItsConfiguration) {
  // The paper protocol of the configuration's protocol: section is what
  // every earlier run file followed; config_yaml records it.
  const fs::path dir = ccsrm::testing::ScratchDirectory("protocol_cli_default");
  const std::string out = (dir / "run.h5").string();
  const Outcome o = RunCcsrm("simulate --case 1 --duration 0.2 --quiet --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr("θx of every joint 0 → 6° along a quintic"));
  EXPECT_TRUE(ccsrm::datasets::ReadRunFile(out).protocol_yaml.empty());
}

struct BadFile {
  std::string label;     // what is wrong
  std::string option;    // --protocol or --inputs
  std::string name;      // file name
  std::string content;   // the file
  std::string expected;  // part of the one line
};

// Protocols and tables, each wrong in one way.
std::vector<BadFile> BadFiles() {
  const std::string head = "schema: ccsrm-protocol/1\nsegments:\n  all:\n";
  const std::string table = "time_s,cable1_mm,cable2_mm,cable3_mm,cable4_mm,cable5_mm,cable6_mm\n";
  return {
      {"unknown key", "--protocol", "typo.yaml", head + "    - hold: {duraton_s: 1}\n",
       "line 4, key 'segments.all[0].hold.duraton_s': unknown key"},
      {"negative duration", "--protocol", "negative.yaml",
       head + "    - move: {to: {theta_x_deg: 3}, duration_s: -2}\n",
       "key 'segments.all[0].move.duration_s': must be > 0"},
      {"jump in rate", "--protocol", "jump.yaml",
       head +
           "    - sine: {amplitude: {theta_x_deg: 1}, frequency_hz: 0.5, cycles: 1, fade_s: 0}\n",
       "key 'segments.all[0].sine': starts with a jump in rate"},
      {"bend beyond the joints' range", "--protocol", "bend.yaml",
       head + "    - move: {to: {theta_x_deg: 45}, duration_s: 30}\n", "past its 41.71 deg"},
      {"cable too fast", "--protocol", "fast.yaml",
       head + "    - step: {to: {theta_x_deg: 10}, rise_s: 0.5, duration_s: 1}\n",
       "beyond limits.cable_speed_mps = 0.1"},
      {"cable accelerating too hard", "--protocol", "hard.yaml",
       head + "    - step: {to: {theta_x_deg: 6}, rise_s: 0.05, duration_s: 0.4}\n",
       "beyond limits.cable_acceleration_mps2 = 1"},
      {"segment the arm lacks", "--protocol", "segments.yaml",
       "schema: ccsrm-protocol/1\nsegments:\n  1: [{hold: {duration_s: 1}}]\n  2: [{hold: "
       "{duration_s: 1}}]\n  3: [{hold: {duration_s: 1}}]\n",
       "key 'segments.3': the arm has 2 segments"},
      {"per-joint list of the wrong length", "--protocol", "joints.yaml",
       head + "    - move: {to: {theta_y_deg: [1, 2, 3]}, duration_s: 5}\n",
       "has 3 values, the segment has 6 joints"},
      {"unknown schema version", "--protocol", "version.yaml",
       "schema: ccsrm-protocol/9\nsegments: {all: [{hold: {duration_s: 1}}]}\n",
       "unsupported version"},
      {"YAML syntax", "--protocol", "syntax.yaml", head + "    - hold: {duration_s: 1\n",
       "YAML syntax error"},
      {"unknown planning", "--protocol", "planning.yaml",
       "schema: ccsrm-protocol/1\nplanning: dynamic\nsegments: {all: [{hold: {duration_s: 1}}]}\n",
       "line 2, key 'planning': expected kinematic or static_equilibrium, found 'dynamic'"},
      {"non-monotonic time", "--inputs", "backwards.csv",
       table + "0,0,0,0,0,0,0\n0.02,0,0,0,0,0,0\n0.01,0,0,0,0,0,0\n",
       "line 4, column 'time_s': time 0.01 s does not increase"},
      {"missing cable column", "--inputs", "missing.csv",
       "time_s,cable1_mm,cable2_mm,cable4_mm,cable5_mm,cable6_mm,cable7_mm\n0,0,0,0,0,0,0\n",
       "no column for cable 3"},
      {"cable count unlike the arm's", "--inputs", "five.tsv",
       "time_s\tcable1_m\tcable2_m\tcable3_m\tcable4_m\tcable5_m\n0\t0\t0\t0\t0\t0\n0."
       "01\t0\t0\t0\t0\t0\n",
       "has 5 cable columns, the arm has 6 driving cables"},
      {"NaN", "--inputs", "nan.csv", table + "0,0,0,0,0,0,0\n0.01,0,0,NaN,0,0,0\n",
       "line 3, column 'cable3_mm': 'NaN' is not a finite number"},
      {"gap above the limit", "--inputs", "gap.csv",
       table + "0,0,0,0,0,0,0\n0.01,0,0,0,0,0,0\n0.6,0,0,0,0,0,0\n",
       "line 4, column 'time_s': a gap of 0.59 s"},
      {"missing unit", "--inputs", "unit.csv",
       "time_s,cable1,cable2,cable3,cable4,cable5,cable6\n0,0,0,0,0,0,0\n", "needs its unit"},
      {"short row", "--inputs", "short.csv", table + "0,0,0,0,0,0,0\n0.01,0,0,0\n",
       "line 3: has 4 fields"},
  };
}

TEST(ProtocolCli, BadProtocolAndInputFilesEachGetOneLineAndExitTwoWritingNothing) {
  for (const std::string command : {"simulate", "generate"}) {
    for (const BadFile& bad : BadFiles()) {
      const fs::path dir = ccsrm::testing::ScratchDirectory("protocol_cli_bad");
      const std::string file = (dir / bad.name).string();
      ccsrm::WriteTextFileAtomically(file, bad.content);
      const Outcome o = RunCcsrm(command + " --case 1 " + bad.option + " " + file +
                                 " --duration 0.3 --quiet --out " + (dir / "out.h5").string());
      SCOPED_TRACE(command + ": " + bad.label);
      EXPECT_EQ(o.status, 2) << o.all();
      EXPECT_EQ(CountLines(o.err), 1) << o.err;
      EXPECT_THAT(o.err, HasSubstr(file + ": ")) << "names the file";
      EXPECT_THAT(o.err, HasSubstr(bad.expected));
      EXPECT_TRUE(o.out.empty()) << o.out;
      // Nothing written: the folder holds the input alone, unchanged.
      EXPECT_EQ(Entries(dir), std::vector<std::string>{bad.name});
      EXPECT_EQ(ccsrm::ReadTextFile(file), bad.content);
    }
  }
}

TEST(ProtocolCli, MisusedMotionOptionsGetOneLineAndExitTwo) {
  const fs::path dir = ccsrm::testing::ScratchDirectory("protocol_cli_options");
  const std::string out = " --out " + (dir / "run.h5").string();
  const std::string two_axis = kConfigs + "/protocols/two-axis.yaml";
  const std::string csv = (dir / "in.csv").string();
  ccsrm::WriteTextFileAtomically(csv, "time_s,cable1_m\n0,0\n0.1,0\n");
  struct Case {
    std::string args, expected;
  };
  for (const Case& c : std::vector<Case>{
           {"--protocol " + two_axis + " --inputs " + csv, "excludes"},
           // two-axis.yaml declares no amplitude_deg for --amplitude to set.
           {"--protocol " + two_axis + " --amplitude 3",
            "--amplitude: the protocol " + two_axis + " has no parameter 'amplitude_deg'"},
           {"--inputs " + csv + " --amplitude 3", "--amplitude: applies to a protocol"},
       }) {
    const Outcome o = RunCcsrm("simulate --case 1 --quiet " + c.args + out);
    EXPECT_EQ(o.status, 2) << c.args << "\n" << o.all();
    EXPECT_EQ(CountLines(o.err), 1) << o.err;
    EXPECT_THAT(o.err, HasSubstr(c.expected)) << c.args;
    EXPECT_FALSE(fs::exists(dir / "run.h5"));
  }
}

}  // namespace
