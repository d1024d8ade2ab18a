// `ccsrm loop` as a user runs it: one line naming the option or file for
// every bad input, before any simulation. (The README's main job on the
// bundled sample: loop_sample_slow_test.cc.)
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

const std::string kSample = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/";

void ExpectOneLine(const Outcome& o, const std::string& text) {
  EXPECT_EQ(o.status, 2) << o.all();
  EXPECT_EQ(CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr(text));
}

TEST(LoopCommand, RefusesBadInputInOneLine) {
  const fs::path dir = ScratchDirectory("loop_cli_bad");
  const std::string data = " --data " + kSample + "train1.h5 ";
  const std::string out = " --out " + (dir / "loop").string();
  ExpectOneLine(RunCcsrm("loop" + data + "--candidates backlash,gremlins" + out),
                "unknown effect 'gremlins'");
  ExpectOneLine(RunCcsrm("loop" + data + "--free mu_c,friction" + out), "friction");
  ExpectOneLine(RunCcsrm("loop --data " + (dir / "missing.h5").string() + out), "missing.h5");
  ExpectOneLine(
      RunCcsrm("loop" + data + "--candidates backlash --free T_p,backlash.dead_band_rad" + out),
      "'backlash' already has a free parameter");
  ExpectOneLine(RunCcsrm("loop" + data + "--max-rounds -1" + out), "max_rounds");
  // An output that is a file, and an output that is the input.
  ccsrm::WriteTextFileAtomically((dir / "file").string(), "x");
  ExpectOneLine(RunCcsrm("loop" + data + "--out " + (dir / "file").string()), "not a folder");
  // Nothing was written.
  EXPECT_FALSE(fs::exists(dir / "loop"));
}

}  // namespace
