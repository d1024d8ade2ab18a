#include "ccsrm/common/number_text.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace ccsrm {
namespace {

std::string Format(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2g", value);
  return text;
}

// YAML's spellings of the non-finite values, which strtod does not read.
bool IsYamlNonFinite(const std::string& text) {
  for (const char* word : {".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "+.inf", "+.Inf",
                           "+.INF", "-.inf", "-.Inf", "-.INF"}) {
    if (text == word) return true;
  }
  return false;
}

}  // namespace

std::string ParseNumberText(const std::string& text, double* value) {
  if (IsYamlNonFinite(text)) return "is not a finite number";
  // strtod skips leading white space; a number in a file or an option has none.
  if (text.empty() || std::isspace(static_cast<unsigned char>(text.front()))) {
    return kNotANumber;
  }
  errno = 0;
  char* end = nullptr;
  const double parsed = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return kNotANumber;
  if (!std::isfinite(parsed)) {
    // strtod gives +-HUGE_VAL with ERANGE for a number too large; "inf" and
    // "nan" written out come without.
    if (errno == ERANGE) {
      return "is outside the range of a double (magnitude above " +
             Format(std::numeric_limits<double>::max()) + ")";
    }
    return "is not a finite number";
  }
  if (errno == ERANGE) {
    // Underflow: the result is 0 or subnormal, the digits are lost.
    return "underflows: it is nearer 0 than a double can hold (" +
           Format(std::numeric_limits<double>::min()) + "); write 0 if 0 is meant";
  }
  *value = parsed;
  return "";
}

}  // namespace ccsrm
