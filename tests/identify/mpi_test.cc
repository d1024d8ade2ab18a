// `mpirun -n 3 ccsrm identify|design|derivatives` (issue 29): the same
// result as on threads, to the bit, and a rank that dies or hangs mid-job
// ends it with one line and exit status 7 within the run timeout, without a
// result. Skips when the build has no MPI or mpirun is missing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "run_ccsrm.h"
#include "same_result.h"
#include "small_design.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::CountLines;
using ccsrm::testing::RunCcsrm;
using ccsrm::testing::RunCommand;
using ccsrm::testing::ScratchDirectory;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

// mpirun as these tests call it: as root in CI containers (Open MPI refuses
// root without these two), three ranks on however many cores there are,
// shared memory between ranks on one node, no help blocks (-q), and a rank
// that exits early does not make mpirun end the job before rank 0 can say
// which rank and run it lost (docs/cluster.md).
std::string Mpirun(int ranks) {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  return std::string(CCSRM_MPIEXEC) + " -q --oversubscribe --mca btl self,vader --mca " +
         "orte_abort_on_non_zero_status 0 -n " + std::to_string(ranks) + " " + CCSRM_PROGRAM;
}

bool MpiMissing(std::string* why) {
  if (!CCSRM_HAVE_MPI) {
    *why = "this build has no MPI (libopenmpi-dev not found)";
  } else if (!fs::exists(CCSRM_MPIEXEC)) {
    *why = std::string("mpirun not found (") + CCSRM_MPIEXEC + ", openmpi-bin)";
  }
  return !why->empty();
}

// What differs between two runs of the same fit by design: clocks, and how
// many runs went at a time.
void DropMachineFields(nlohmann::json* j) {
  ccsrm::testing::DropKeys(j, {"wall_time_s", "real_time_factor", "threads"});
}

// Two experiments of different lengths (so the ranks get unequal work) of
// the loop sample's arm, whose first seconds ramp every joint: T_p and c_sc
// free, three iterations.
struct SmallFit {
  fs::path dir;
  std::string args;
};

// Generated once per test program; each test writes its own output folder.
const SmallFit& MakeSmallFit() {
  static const SmallFit made = [] {
    SmallFit fit;
    // Per process: CTest may run this program's tests at once.
    fit.dir = ScratchDirectory("mpi_small_fit_" + std::to_string(getpid()));
    const std::string arm = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/arm.yaml";
    std::string data;
    for (const auto& [file, duration, seed] :
         {std::tuple{"long.h5", "1.5", "7"}, std::tuple{"short.h5", "1", "8"}}) {
      const std::string path = (fit.dir / file).string();
      const Outcome g = RunCcsrm("generate --config " + arm + " --case 4 --duration " + duration +
                                 " --set T_p=60 --seed " + seed + " --quiet --out " + path);
      EXPECT_EQ(g.status, 0) << g.all();
      data += " " + path;
    }
    fit.args = "identify --data" + data + " --free T_p,c_sc --max-iterations 3 --threads 1 --quiet";
    return fit;
  }();
  return made;
}

TEST(MpiIdentify, ThreeRanksGiveTheThreadBackendsFitToTheBit) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  const SmallFit& fit = MakeSmallFit();
  const std::string threads_out = (fit.dir / "threads").string();
  fs::remove_all(threads_out);
  const std::string ranks_out = (fit.dir / "ranks").string();
  fs::remove_all(ranks_out);
  const Outcome t = RunCcsrm(fit.args + " --out " + threads_out);
  ASSERT_TRUE(t.status == 0 || t.status == 4) << t.all();
  const Outcome m = RunCommand(Mpirun(3) + " " + fit.args + " --out " + ranks_out);
  ASSERT_EQ(m.status, t.status) << m.all();
  EXPECT_THAT(m.out, HasSubstr("runs on 3 MPI ranks"));
  // Printed once (rank 0), not once per rank.
  EXPECT_EQ(m.out.find("fitting T_p"), m.out.rfind("fitting T_p")) << m.out;

  nlohmann::json a = nlohmann::json::parse(ccsrm::ReadTextFile(threads_out + "/fit.json"));
  nlohmann::json b = nlohmann::json::parse(ccsrm::ReadTextFile(ranks_out + "/fit.json"));
  // The fit moved: the comparison is of a real descent, not of the start.
  EXPECT_NE(a["parameters"]["T_p"]["value"], a["parameters"]["T_p"]["start"]);
  EXPECT_EQ(a["simulations"], b["simulations"]);
  // Every number of the fit (JSON doubles round-trip: 17 significant
  // digits), estimates, standard errors, costs, RMS, singular values.
  DropMachineFields(&a);
  DropMachineFields(&b);
  EXPECT_EQ(a, b) << nlohmann::json::diff(a, b).dump(1);
  for (const char* table : {"/long.angles.csv", "/short.angles.csv"}) {
    EXPECT_EQ(ccsrm::ReadTextFile(threads_out + table), ccsrm::ReadTextFile(ranks_out + table))
        << table << ": the residuals differ";
  }
}

// Rank 2 lost once it has run `runs` runs (`mode` exit or hang): rank 0
// waits for its run no longer than --run-timeout, then says which rank and
// which run in one line and ends the job with status 7 (README), writing no
// `result` (the command's output, given after `args`).
void ExpectLostRankEndsTheJob(const std::string& args, int runs, const std::string& mode,
                              const std::string& result) {
  setenv("CCSRM_MPI_TEST_LOSE_RANK", ("2:" + std::to_string(runs) + ":" + mode).c_str(), 1);
  // `timeout` only guards the test against a job that hangs (its 124 fails it).
  const Outcome m = RunCommand("timeout 300 " + Mpirun(3) + " " + args + " --run-timeout 5 " +
                               (result.empty() ? "" : result));
  unsetenv("CCSRM_MPI_TEST_LOSE_RANK");
  EXPECT_EQ(m.status, 7) << m.all();
  EXPECT_EQ(CountLines(m.err), 1) << m.err;
  EXPECT_THAT(m.err, HasSubstr("ccsrm: rank 2 did not return run "));
  EXPECT_THAT(m.err, HasSubstr("within 5 s (--run-timeout)"));
}

void ExpectLostRankEndsTheFit(const std::string& mode) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  const SmallFit& fit = MakeSmallFit();
  const std::string out = (fit.dir / ("lost_" + mode)).string();
  ExpectLostRankEndsTheJob(fit.args, 3, mode, "--out " + out);
  EXPECT_FALSE(fs::exists(out + "/fit.json")) << "no result from a job that lost a rank";
}

TEST(MpiIdentify, ARankThatDiesEndsTheJobWithOneLine) { ExpectLostRankEndsTheFit("exit"); }
TEST(MpiIdentify, ARankThatHangsEndsTheJobWithOneLine) { ExpectLostRankEndsTheFit("hang"); }

// `mpirun -n 3 ccsrm design`: every rank builds the plans from the command
// line, rank 0 ranks them, every rank simulates; design.json is the thread
// run's on as many threads (3), to the bit, but for the clock.
TEST(MpiDesign, ThreeRanksGiveTheThreadRunsDesignToTheBit) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  const fs::path dir = ScratchDirectory("mpi_design_" + std::to_string(getpid()));
  // Two plans of unequal length (one of two experiments).
  const std::string design = ccsrm::testing::SmallDesign(dir) + "--quiet --out ";
  const std::string threads_out = (dir / "threads").string();
  const std::string ranks_out = (dir / "ranks").string();
  const Outcome t = RunCcsrm(design + threads_out + " --threads 3");
  ASSERT_EQ(t.status, 0) << t.all();
  const Outcome m = RunCommand(Mpirun(3) + " " + design + ranks_out + " --threads 1");
  ASSERT_EQ(m.status, 0) << m.all();
  EXPECT_THAT(m.out, HasSubstr("runs on 3 MPI ranks"));
  nlohmann::json a = nlohmann::json::parse(ccsrm::ReadTextFile(threads_out + "/design.json"));
  nlohmann::json b = nlohmann::json::parse(ccsrm::ReadTextFile(ranks_out + "/design.json"));
  EXPECT_TRUE(a["candidates"][0]["completed"].get<bool>()) << "a real evaluation is compared";
  // Every run went through the ranks (rank 0's closing line).
  EXPECT_THAT(m.out, HasSubstr("MPI: " + std::to_string(a["simulations"].get<long long>()) +
                               " runs on 3 ranks"));
  ccsrm::testing::DropKeys(&a, {"wall_time_s"});
  ccsrm::testing::DropKeys(&b, {"wall_time_s"});
  EXPECT_EQ(a, b) << nlohmann::json::diff(a, b).dump(1);
}

// `mpirun -n 3 ccsrm derivatives`: every rank prepares the run from the
// command line, rank 0 forms the derivatives, every rank simulates. The
// first 0.3 s of the paper's case 2 (about 0.1 s per run): the angles move
// little yet, but they move (asserted), and the JSON's 17 digits tell runs
// that differ in any bit apart.
std::string Derivatives() {
  return "derivatives --config " + std::string(CCSRM_SOURCE_DIR) +
         "/configs/paper.yaml --case 2 --duration 0.3 --quiet ";
}

// The JSON of a thread run on 3 threads and of 3 ranks of 1 thread each:
// equal but for the clocks (and the status, printed and exited alike).
// `moved` points at a figure that is > 0 when the runs saw the parameter.
void ExpectSameJsonOnThreeRanks(const std::string& args, const std::string& name,
                                const std::string& moved) {
  const fs::path dir = ScratchDirectory("mpi_" + name + "_" + std::to_string(getpid()));
  const std::string threads_json = (dir / "threads.json").string();
  const std::string ranks_json = (dir / "ranks.json").string();
  const Outcome t = RunCcsrm(Derivatives() + args + " --threads 3 --json " + threads_json);
  ASSERT_TRUE(t.status == 0 || t.status == 4) << t.all();
  const Outcome m =
      RunCommand(Mpirun(3) + " " + Derivatives() + args + " --threads 1 --json " + ranks_json);
  ASSERT_EQ(m.status, t.status) << m.all();
  EXPECT_THAT(m.out, HasSubstr("runs on 3 MPI ranks, 3 at a time"));
  nlohmann::json a = nlohmann::json::parse(ccsrm::ReadTextFile(threads_json));
  nlohmann::json b = nlohmann::json::parse(ccsrm::ReadTextFile(ranks_json));
  EXPECT_GT(a.at(nlohmann::json::json_pointer(moved)).get<double>(), 0.0)
      << "a real comparison: the angles depend on the parameter";
  // Every run went through the ranks (rank 0's closing line).
  const std::size_t runs =
      a.contains("runs") && a["runs"].is_number() ? a["runs"].get<std::size_t>() : a["runs"].size();
  EXPECT_THAT(m.out, HasSubstr("MPI: " + std::to_string(runs) + " runs on 3 ranks"));
  ccsrm::testing::DropKeys(&a, {"wall_time_s", "real_time_factor"});
  ccsrm::testing::DropKeys(&b, {"wall_time_s", "real_time_factor"});
  EXPECT_EQ(a, b) << nlohmann::json::diff(a, b).dump(1);
}

TEST(MpiDerivatives, ThreeRanksGiveTheThreadRunsCheckToTheBit) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  ExpectSameJsonOnThreeRanks("--parameters c_sc,T_p", "derivatives",
                             "/parameters/1/steps/0/rms_deg");
}

TEST(MpiDerivatives, ThreeRanksGiveTheThreadRunsSweepToTheBit) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  ExpectSameJsonOnThreeRanks("--sweep T_d0 --points 5 --span 0.02", "sweep", "/variation_rms_deg");
}

// Rank 2 dies on its first runs: one line, status 7, no JSON.
TEST(MpiDerivatives, ARankThatDiesEndsTheJobWithOneLine) {
  std::string why;
  if (MpiMissing(&why)) GTEST_SKIP() << why;
  const fs::path dir = ScratchDirectory("mpi_derivatives_lost_" + std::to_string(getpid()));
  const std::string json = (dir / "d.json").string();
  ExpectLostRankEndsTheJob(Derivatives() + "--parameters c_sc,T_p --threads 1", 0, "exit",
                           "--json " + json);
  EXPECT_FALSE(fs::exists(json)) << "no result from a job that lost a rank";
}

}  // namespace
