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

TEST(InputErrorFormat, IsOneLineNamingFileAndField) {
  EXPECT_EQ(FormatInputError("a.yaml", "line 3, key 'x'", "must be\npositive"),
            "a.yaml: line 3, key 'x': must be positive");
}

}  // namespace
}  // namespace ccsrm
