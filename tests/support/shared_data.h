#pragma once
// Files of the shared folder beside the repository (../shared, or
// -DCCSRM_SHARED_DIR=...): the real motion-capture recordings that tests read
// in place. A clone without that folder skips the tests that need it, each
// naming the path it looked for; a normal checkout runs them all.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace ccsrm::testing {

// Path of `relative` (e.g. "data/mocap/c3d/Eb015pi.c3d") in the shared folder.
inline std::string SharedPath(const std::string& relative) {
  return std::string(CCSRM_SHARED_DIR) + "/" + relative;
}

}  // namespace ccsrm::testing

// In a test body, or in a helper returning void that a test calls last:
// declares `const std::string variable`, the path of `relative` in the shared
// folder, and skips the test (GTEST_SKIP, which returns) when that file is
// missing, so nothing reads an empty file.
#define CCSRM_SHARED_FILE_OR_SKIP(variable, relative)                                \
  const std::string variable = ::ccsrm::testing::SharedPath(relative);               \
  if (!std::filesystem::is_regular_file(variable))                                   \
  GTEST_SKIP() << "needs the shared file " << variable                               \
               << ", which is missing (the shared folder beside the repository, or " \
                  "-DCCSRM_SHARED_DIR=...)"
