#include "ccsrm/common/error.h"

#include <cstdio>
#include <cstdlib>

namespace ccsrm {

std::string FormatInputError(const std::string& file, const std::string& where,
                             const std::string& what) {
  std::string message = file;
  if (!where.empty()) message += ": " + where;
  message += ": " + what;
  // One line: the error is printed as a single line on stderr.
  for (char& c : message) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return message;
}

void ThrowInputError(const std::string& file, const std::string& where, const std::string& what) {
  throw InputError(FormatInputError(file, where, what));
}

namespace internal {
void CheckFailed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "ccsrm: internal invariant violated: %s (%s:%d)\n", condition, file, line);
  std::abort();
}
}  // namespace internal

}  // namespace ccsrm
