#pragma once
// Text identify/ prints, writes and digests: one printf into a string, one
// table cell, one list joiner.
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace ccsrm::identify {

// printf into a string.
inline std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
inline std::string Format(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

// A table cell: the number as `format` prints it, "-" when it is not finite
// (a value that was not computed).
inline std::string Cell(const char* format, double value) {
  return std::isfinite(value) ? Format(format, value) : std::string("-");
}

// "a, b, c": names for a line of text.
inline std::string Join(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
  return text;
}

// "s" when `n` is not 1: "thread" + Plural(n).
inline const char* Plural(std::size_t n) { return n == 1 ? "" : "s"; }

// A list as the checkpoint digest reads it: "a,b," or `unset` when absent.
inline std::string DigestText(const std::vector<std::string>* names, const char* unset) {
  if (names == nullptr) return unset;
  std::string text;
  for (const std::string& n : *names) text += n + ",";
  return text;
}

// Values as the checkpoint digest reads them, to the last bit.
inline std::string DigestText(const std::vector<std::pair<std::string, double>>& values) {
  std::string text;
  for (const auto& [name, value] : values) text += Format("%s=%.17g,", name.c_str(), value);
  return text;
}

}  // namespace ccsrm::identify
