#pragma once
// Reading a number written in a file or on the command line.
#include <string>

namespace ccsrm {

// Reads the whole of `text` as a finite double (strtod's syntax: decimal or
// hexadecimal, optional sign and exponent). Returns "" and sets *value, or
// leaves *value alone and returns what is wrong, a phrase to follow the
// value in a message ("'1e400' is outside the range of a double ..."):
//   "is not a number"
//   "is not a finite number" (inf, nan and YAML's .inf, .nan)
//   "is outside the range of a double (magnitude above 1.8e+308)"
//   "underflows: it is nearer 0 than a double can hold (2.2e-308); write 0 if 0 is meant"
std::string ParseNumberText(const std::string& text, double* value);

// ParseNumberText's answer for text that is no number at all.
inline constexpr const char* kNotANumber = "is not a number";

}  // namespace ccsrm
