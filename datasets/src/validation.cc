#include "validation.h"

#include <charconv>
#include <cmath>
#include <set>

#include "ccsrm/common/error.h"

namespace ccsrm::datasets::internal {

std::vector<std::size_t> ExpectShape(const std::string& file, const std::string& path,
                                     const Array& array, const std::vector<Dim>& dims) {
  if (!array.IsConsistent()) {
    ThrowInputError(file, path,
                    "array holds " + std::to_string(array.values.size()) +
                        " values but its shape " + ShapeToString(array.shape) + " needs " +
                        std::to_string(Array::ElementCount(array.shape)));
  }
  bool matches = array.rank() == dims.size();
  for (std::size_t i = 0; matches && i < dims.size(); ++i) {
    if (dims[i].bound && array.shape[i] != dims[i].extent) matches = false;
  }
  if (matches) return array.shape;

  std::string expected;
  std::string bindings;
  for (const Dim& dim : dims) {
    if (!expected.empty()) expected += "×";
    expected += dim.symbol;
    if (dim.bound && !dim.source.empty()) {
      if (!bindings.empty()) bindings += ", ";
      bindings += dim.symbol + "=" + std::to_string(dim.extent) + " (from " + dim.source + ")";
    }
  }
  std::string what = "expected shape " + expected;
  if (!bindings.empty()) what += " with " + bindings;
  what += ", found " + ShapeToString(array.shape);
  ThrowInputError(file, path, what);
}

std::size_t ExpectTimeBase(const std::string& file, const std::string& path, const Array& array,
                           const std::string& symbol) {
  ExpectShape(file, path, array, {Free(symbol)});
  const std::vector<double>& t = array.values;
  if (t.empty()) ThrowInputError(file, path, "expected at least one sample, found none");
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) {
      ThrowInputError(file, path,
                      "value at index " + std::to_string(i) + " is " + FormatNumber(t[i]) +
                          ": times must be finite");
    }
    if (i > 0 && !(t[i] > t[i - 1])) {
      ThrowInputError(file, path,
                      "not strictly increasing: index " + std::to_string(i) + " holds " +
                          FormatNumber(t[i]) + " after " + FormatNumber(t[i - 1]));
    }
  }
  return t.size();
}

void ExpectFinite(const std::string& file, const std::string& path, const Array& array) {
  for (std::size_t i = 0; i < array.values.size(); ++i) {
    if (!std::isfinite(array.values[i])) {
      ThrowInputError(file, path,
                      "value at flat index " + std::to_string(i) + " is " +
                          FormatNumber(array.values[i]) + ", expected a finite number");
    }
  }
}

void ExpectUniqueNames(const std::string& file, const std::string& path,
                       const std::vector<std::string>& names) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty()) {
      ThrowInputError(file, path, "name at index " + std::to_string(i) + " is empty");
    }
    if (!seen.insert(names[i]).second) {
      ThrowInputError(file, path, "name '" + names[i] + "' appears more than once");
    }
  }
}

bool IsValidLinkName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos;
}

std::string FormatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

}  // namespace ccsrm::datasets::internal
