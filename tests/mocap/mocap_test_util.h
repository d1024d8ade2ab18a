#pragma once
// Helpers shared by the mocap tests: bytes of files, scratch directories and
// InputError messages. The vendor files of ../shared/data/mocap are used in
// place, never copied, through CCSRM_SHARED_FILE_OR_SKIP (shared_data.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "shared_data.h"

namespace ccsrm::mocap::testing {

inline std::vector<std::uint8_t> ReadBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  EXPECT_TRUE(stream.good()) << "cannot open " << path;
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(stream)),
                                   std::istreambuf_iterator<char>());
}

// True when `part` equals the start of `whole`, NaN equal to NaN (a sample
// not seen in both).
inline bool SameStart(const std::vector<double>& part, const std::vector<double>& whole) {
  return part.size() <= whole.size() &&
         std::equal(part.begin(), part.end(), whole.begin(),
                    [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); });
}

inline std::filesystem::path FreshTempDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("ccsrm_mocap_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream stream(path, std::ios::binary);
  stream << text;
}

// Runs `read` and returns the InputError message ("" and a test failure when
// nothing or something else is thrown).
template <typename Read>
std::string InputErrorOf(Read read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

}  // namespace ccsrm::mocap::testing
