#include "ccsrm/common/output_policy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"

namespace ccsrm {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ccsrm_output_policy_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Touch(const fs::path& path, const std::string& text = "x") { std::ofstream(path) << text; }

std::size_t Entries(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// Earlier outputs of this test kind hold a file "mine" with "ours" in it.
OutputKind TestFolderKind() {
  return {"test output folder", true, [](const std::string& path) {
            std::ifstream in(fs::path(path) / "mine");
            std::string text;
            return static_cast<bool>(in >> text) && text == "ours";
          }};
}

std::string Refusal(const std::string& path, const OutputKind& kind,
                    const std::vector<std::string>& inputs) {
  try {
    CheckOutputPath(path, "--out", kind, inputs);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputPolicy, AFolderOfTheUsersFilesIsRefusedAndKept) {
  const fs::path dir = FreshDir("foreign");
  Touch(dir / "precious.txt");
  const std::string message = Refusal(dir.string(), TestFolderKind(), {});
  EXPECT_THAT(message, HasSubstr("--out: exists and is not a test output folder"));
  EXPECT_THAT(message, HasSubstr("refusing to replace it"));
  EXPECT_TRUE(fs::exists(dir / "precious.txt"));
}

// An earlier output as ccsrm writes it: through AtomicOutputDirectory, which
// leaves its manifest.
void WriteEarlierOutput(const fs::path& dir) {
  AtomicOutputDirectory out(dir.string());
  Touch(fs::path(out.temp_path()) / "mine", "ours");
  fs::create_directory(fs::path(out.temp_path()) / "plots");
  Touch(fs::path(out.temp_path()) / "plots" / "a.svg", "<svg/>");
  out.Commit();
}

TEST(OutputPolicy, AnEmptyFolderOrAnEarlierOutputIsReplaced) {
  const fs::path dir = FreshDir("own");
  EXPECT_EQ(Refusal(dir.string(), TestFolderKind(), {}), "");
  WriteEarlierOutput(dir);
  EXPECT_TRUE(fs::exists(dir / kOutputManifestName));
  EXPECT_EQ(Refusal(dir.string(), TestFolderKind(), {}), "");
  EXPECT_EQ(Refusal((dir / "new").string(), TestFolderKind(), {}), "");  // does not exist yet
}

TEST(OutputPolicy, AUsersFileInsideAnEarlierOutputIsRefusedAndKept) {
  const fs::path dir = FreshDir("own_plus_notes");
  WriteEarlierOutput(dir);
  Touch(dir / "plots" / "notes.txt", "my notes");
  const std::string message = Refusal(dir.string(), TestFolderKind(), {});
  EXPECT_THAT(message, HasSubstr("--out: holds 'plots/notes.txt', which ccsrm did not write"));
  EXPECT_TRUE(fs::exists(dir / "plots" / "notes.txt"));
  // A file ccsrm wrote but the user changed since is the user's now.
  fs::remove(dir / "plots" / "notes.txt");
  Touch(dir / "mine", "ours\nannotated by the user");
  EXPECT_THAT(Refusal(dir.string(), TestFolderKind(), {}), HasSubstr("holds 'mine'"));
}

TEST(OutputPolicy, AStubThatLooksLikeAnEarlierOutputIsRefused) {
  // The kind's own file, as a user (or a stub) put it, without a manifest.
  const fs::path dir = FreshDir("stub");
  Touch(dir / "mine", "ours");
  Touch(dir / "thesis.tex", "\\documentclass{article}");
  EXPECT_THAT(Refusal(dir.string(), TestFolderKind(), {}),
              HasSubstr("holds 'mine', 'thesis.tex', which ccsrm did not write"));
  EXPECT_TRUE(fs::exists(dir / "thesis.tex"));
  // A link inside is never ccsrm's, even on a manifest's folder.
  const fs::path linked = FreshDir("linked");
  WriteEarlierOutput(linked);
  fs::create_symlink(dir / "thesis.tex", linked / "thesis.tex");
  EXPECT_THAT(Refusal(linked.string(), TestFolderKind(), {}), HasSubstr("holds 'thesis.tex'"));
}

TEST(OutputPolicy, AStoppedJobsOwnFilesBesideTheManifestAreItsOwn) {
  const fs::path dir = FreshDir("checkpointed");
  WriteEarlierOutput(dir);
  Touch(dir / "checkpoint.json", "{}");
  Touch(dir / "checkpoint.json.tmp-12345-0", "{");
  OutputKind kind = TestFolderKind();
  EXPECT_THAT(Refusal(dir.string(), kind, {}), HasSubstr("holds 'checkpoint.json"));
  kind.own_files = {"checkpoint.json"};
  EXPECT_EQ(Refusal(dir.string(), kind, {}), "");
}

TEST(OutputPolicy, ReplaceAnyExistingLiftsOnlyTheKindRule) {
  const fs::path dir = FreshDir("overwrite");
  Touch(dir / "mycfg.yaml", "schema: something else");
  OutputKind file_kind{"test file", false, [](const std::string&) { return false; }};
  EXPECT_THAT(Refusal((dir / "mycfg.yaml").string(), file_kind, {}),
              HasSubstr("exists and is not a test file"));
  file_kind.replace_any_existing = true;
  EXPECT_EQ(Refusal((dir / "mycfg.yaml").string(), file_kind, {}), "");
  // An input stays an input.
  EXPECT_THAT(Refusal((dir / "mycfg.yaml").string(), file_kind, {(dir / "mycfg.yaml").string()}),
              HasSubstr("is an input file"));
}

TEST(OutputPolicy, AnInputIsNeverAnOutput) {
  const fs::path dir = FreshDir("inputs");
  Touch(dir / "c.yaml");
  const OutputKind file_kind{"test file", false, [](const std::string&) { return true; }};
  // The same file, by another spelling or through a link.
  EXPECT_THAT(Refusal((dir / "c.yaml").string(), file_kind, {(dir / "c.yaml").string()}),
              HasSubstr("is an input file; inputs are never modified"));
  EXPECT_THAT(Refusal((dir / "." / "c.yaml").string(), file_kind, {(dir / "c.yaml").string()}),
              HasSubstr("is an input file"));
  fs::create_symlink(dir / "c.yaml", dir / "link.yaml");
  EXPECT_THAT(Refusal((dir / "link.yaml").string(), file_kind, {(dir / "c.yaml").string()}),
              HasSubstr("is an input file"));
  // Inside an input folder.
  fs::create_directory(dir / "fit");
  EXPECT_THAT(
      Refusal((dir / "fit" / "report").string(), TestFolderKind(), {(dir / "fit").string()}),
      HasSubstr("lies inside the input folder"));
  // A folder output that holds an input: replacing it would delete the input.
  Touch(dir / "fit" / "mine", "ours");
  Touch(dir / "fit" / "exp.h5");
  EXPECT_THAT(
      Refusal((dir / "fit").string(), TestFolderKind(), {(dir / "fit" / "exp.h5").string()}),
      HasSubstr("holds the input"));
  // Options not given are empty strings, skipped.
  EXPECT_EQ(Refusal((dir / "out.h5").string(), file_kind, {"", ""}), "");
}

TEST(OutputPolicy, MissingParentsAndFileFolderMismatchesAreRefused) {
  const fs::path dir = FreshDir("shape");
  const OutputKind file_kind{"test file", false, nullptr};
  EXPECT_THAT(Refusal((dir / "no" / "out.h5").string(), file_kind, {}), HasSubstr("output folder"));
  fs::create_directory(dir / "folder");
  Touch(dir / "folder" / "x");
  EXPECT_THAT(Refusal((dir / "folder").string(), file_kind, {}), HasSubstr("is a folder"));
  Touch(dir / "file");
  EXPECT_THAT(Refusal((dir / "file").string(), TestFolderKind(), {}),
              HasSubstr("exists and is not a folder"));
  // Without a recogniser only an empty file is replaced.
  EXPECT_THAT(Refusal((dir / "file").string(), file_kind, {}), HasSubstr("is not a test file"));
  Touch(dir / "empty", "");
  EXPECT_EQ(Refusal((dir / "empty").string(), file_kind, {}), "");
  EXPECT_THAT(Refusal("", file_kind, {}), HasSubstr("empty"));
}

// A pid no process has: above Linux's largest pid_max (2^22).
constexpr const char* kDeadPid = "2147483646";

TEST(OutputPolicy, AKilledRunsTemporariesAreRemovedByTheNextRunAndALiveRunsKept) {
  const fs::path dir = FreshDir("stale");
  const std::string target = (dir / "run.h5").string();
  Touch(target + ".tmp-" + kDeadPid + "-0");
  fs::create_directory(target + ".tmp-" + kDeadPid + "-1");
  Touch(fs::path(target + ".tmp-" + kDeadPid + "-1") / "fit.json");
  const std::string live = target + ".tmp-" + std::to_string(::getppid()) + "-0";
  Touch(live);
  Touch(dir / "run.h5.tmp-notes");           // not a temporary's name
  Touch(dir / "other.h5.tmp-2147483646-0");  // another target's
  EXPECT_EQ(RemoveStaleTemporaries(target), 2);
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(dir / "run.h5.tmp-notes"));
  EXPECT_TRUE(fs::exists(dir / "other.h5.tmp-2147483646-0"));
  EXPECT_EQ(Entries(dir), 3u);
  // CheckOutputPath does the same before a command works.
  Touch(target + ".tmp-" + kDeadPid + "-2");
  CheckOutputPath(target, "--out", {"test file", false, nullptr}, {});
  EXPECT_FALSE(fs::exists(target + ".tmp-" + kDeadPid + "-2"));
}

// In a child process: unfinished outputs of both kinds, then SIGINT (or
// SIGTERM). The child must die by that signal and leave nothing behind.
void ExpectInterruptRemovesTemporaries(int signal_number) {
  const fs::path dir = FreshDir("interrupt" + std::to_string(signal_number));
  const std::string file = (dir / "run.h5").string();
  const std::string folder = (dir / "fit").string();
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    RemoveTemporariesOnInterrupt();
    AtomicOutputFile out(file);
    std::ofstream(out.temp_path()) << "half written";
    AtomicOutputDirectory out_folder(folder);
    std::ofstream(fs::path(out_folder.temp_path()) / "fit.json") << "{";
    ::kill(::getpid(), signal_number);
    ::sleep(30);  // the watcher ends the process before this returns
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << "child exited with " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), signal_number);
  EXPECT_EQ(Entries(dir), 0u);
}

TEST(OutputPolicy, InterruptRemovesUnfinishedOutputsAndEndsBySigint) {
  ExpectInterruptRemovesTemporaries(SIGINT);
}

TEST(OutputPolicy, TerminateRemovesUnfinishedOutputsAndEndsBySigterm) {
  ExpectInterruptRemovesTemporaries(SIGTERM);
}

}  // namespace
}  // namespace ccsrm
