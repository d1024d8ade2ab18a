#pragma once
// Error policy (docs/conventions.md):
//  - bad user input or a bad file throws InputError whose one-line message
//    names the file, the field (key, path, line or byte offset) and what was
//    expected;
//  - broken internal invariants abort through CCSRM_CHECK;
//  - numerical outcomes (a diverging run, a fit that did not converge) are
//    reported in a Summary, never thrown.
#include <stdexcept>
#include <string>

namespace ccsrm {

// Thrown for bad input: configuration, data files, command-line values.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// Builds "<file>: <where>: <what>" (or "<file>: <what>" when where is empty).
std::string FormatInputError(const std::string& file, const std::string& where,
                             const std::string& what);

// Throws InputError(FormatInputError(file, where, what)).
[[noreturn]] void ThrowInputError(const std::string& file, const std::string& where,
                                  const std::string& what);

namespace internal {
[[noreturn]] void CheckFailed(const char* condition, const char* file, int line);
}  // namespace internal

}  // namespace ccsrm

// Aborts with the failed condition when an internal invariant is broken.
// Active in every build type: a broken invariant must never run on silently.
#define CCSRM_CHECK(condition)                                        \
  do {                                                                \
    if (!(condition)) {                                               \
      ::ccsrm::internal::CheckFailed(#condition, __FILE__, __LINE__); \
    }                                                                 \
  } while (false)
