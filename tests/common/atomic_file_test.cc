#include "ccsrm/common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "ccsrm/common/error.h"

namespace ccsrm {
namespace {
namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ccsrm_common_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicOutputFile, CommitMovesTemporaryOntoTarget) {
  const fs::path dir = FreshDir("commit");
  const std::string target = (dir / "out.txt").string();
  WriteTextFileAtomically(target, "hello");
  EXPECT_EQ(ReadTextFile(target), "hello");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicOutputFile, FailedWriteLeavesNoFileAtTarget) {
  const fs::path dir = FreshDir("abort");
  const std::string target = (dir / "out.txt").string();
  try {
    AtomicOutputFile out(target);
    std::ofstream(out.temp_path()) << "partial";
    throw std::runtime_error("writer failed half way");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(AtomicOutputFile, FailedWriteKeepsPreviousTarget) {
  const fs::path dir = FreshDir("keep");
  const std::string target = (dir / "out.txt").string();
  WriteTextFileAtomically(target, "good");
  {
    AtomicOutputFile out(target);
    std::ofstream(out.temp_path()) << "half";
  }  // never committed
  EXPECT_EQ(ReadTextFile(target), "good");
}

TEST(AtomicOutputFile, MissingDirectoryIsInputError) {
  EXPECT_THROW(AtomicOutputFile("/nonexistent-dir-ccsrm/out.h5"), InputError);
}

std::size_t Entries(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST(AtomicOutputDirectory, CommitCreatesTheFolder) {
  const fs::path dir = FreshDir("dir_new");
  const std::string target = (dir / "report").string();
  {
    AtomicOutputDirectory out(target + "/");  // a trailing separator names the same folder
    EXPECT_EQ(fs::path(out.temp_path()).parent_path(), dir);
    WriteTextFileAtomically(out.temp_path() + "/index.html", "new");
    EXPECT_FALSE(fs::exists(target));
    out.Commit();
  }
  EXPECT_EQ(ReadTextFile(target + "/index.html"), "new");
  EXPECT_EQ(Entries(dir), 1u);  // no temporary left beside it
}

TEST(AtomicOutputDirectory, CommitReplacesAnExistingFolderAsAWhole) {
  const fs::path dir = FreshDir("dir_replace");
  const fs::path target = dir / "report";
  fs::create_directories(target / "figures");
  WriteTextFileAtomically((target / "stale.txt").string(), "old");
  WriteTextFileAtomically((target / "index.html").string(), "old");
  {
    AtomicOutputDirectory out(target.string());
    WriteTextFileAtomically(out.temp_path() + "/index.html", "new");
    out.Commit();
  }
  EXPECT_EQ(ReadTextFile((target / "index.html").string()), "new");
  EXPECT_FALSE(fs::exists(target / "stale.txt"));
  EXPECT_FALSE(fs::exists(target / "figures"));
  EXPECT_EQ(Entries(dir), 1u);
}

TEST(AtomicOutputDirectory, WithoutCommitTheOldFolderStaysAndTheTemporaryGoes) {
  const fs::path dir = FreshDir("dir_abort");
  const fs::path target = dir / "report";
  fs::create_directories(target);
  WriteTextFileAtomically((target / "index.html").string(), "old");
  try {
    AtomicOutputDirectory out(target.string());
    WriteTextFileAtomically(out.temp_path() + "/index.html", "half");
    throw std::runtime_error("writer failed half way");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(ReadTextFile((target / "index.html").string()), "old");
  EXPECT_EQ(Entries(dir), 1u);
}

TEST(AtomicOutputDirectory, RejectsAFileTargetAndAMissingParent) {
  const fs::path dir = FreshDir("dir_bad");
  WriteTextFileAtomically((dir / "file").string(), "x");
  EXPECT_THROW(AtomicOutputDirectory((dir / "file").string()), InputError);
  EXPECT_THROW(AtomicOutputDirectory((dir / "missing" / "report").string()), InputError);
  EXPECT_THROW(AtomicOutputDirectory("."), InputError);
  EXPECT_EQ(Entries(dir), 1u);
}

TEST(InputErrorFormat, IsOneLineNamingFileAndField) {
  EXPECT_EQ(FormatInputError("a.yaml", "line 3, key 'x'", "must be\npositive"),
            "a.yaml: line 3, key 'x': must be positive");
}

}  // namespace
}  // namespace ccsrm
