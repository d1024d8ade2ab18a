// The runs journal of a stopped job (--resume): a tail that is not a record
// (torn by a kill, or garbage a user appended) is dropped, never trusted,
// and never read as a size to allocate (issue 47, 5: std::bad_alloc).
#include "ccsrm/identify/run_journal.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace ccsrm::identify {
namespace {
namespace fs = std::filesystem;

fs::path Journal(const std::string& name, const std::string& bytes) {
  const fs::path path = fs::temp_directory_path() / ("ccsrm_run_journal_" + name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(RunJournal, GarbageIsATornTailNotARecord) {
  // "\0garbage\n{{{": its first eight bytes read as a size of 7e17 bytes.
  const fs::path garbage = Journal("garbage", std::string("\0garbage\n{{{", 12));
  RunJournal journal(garbage.string(), /*resume=*/true);
  EXPECT_EQ(journal.recorded(), 0);
  EXPECT_EQ(journal.simulated(), 0);
}

TEST(RunJournal, ASizeBeyondTheFileIsRefusedBeforeItIsAllocated) {
  std::string bytes(16, '\0');
  const std::uint64_t huge = ~std::uint64_t{0} / 2;  // no memory holds it
  std::memcpy(bytes.data(), &huge, sizeof(huge));
  const fs::path path = Journal("huge", bytes + "a few bytes");
  RunJournal journal(path.string(), /*resume=*/true);
  EXPECT_EQ(journal.recorded(), 0);
}

}  // namespace
}  // namespace ccsrm::identify
