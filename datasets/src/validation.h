#pragma once
// Private consistency checks shared by the writers (before anything is
// created) and the readers (after the arrays are read), so that one set of
// rules and one wording of messages covers both directions.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/datasets/array.h"

namespace ccsrm::datasets::internal {

// One dimension of an expected shape.
struct Dim {
  std::string symbol;      // "T", "J", ... or the extent itself for fixed dims
  std::size_t extent = 0;  // required extent when bound
  bool bound = true;       // false: any extent, which binds the symbol
  std::string source;      // path a bound symbol was read from, e.g. "/time"
};

inline Dim Fixed(std::size_t extent) { return {std::to_string(extent), extent, true, ""}; }
inline Dim Bound(std::string symbol, std::size_t extent, std::string source) {
  return {std::move(symbol), extent, true, std::move(source)};
}
inline Dim Free(std::string symbol) { return {std::move(symbol), 0, false, ""}; }

// Requires `array` to be consistent and of the shape `dims`; returns its
// shape. Throws InputError "<file>: <path>: expected shape T×J×2 with T=4801
// (from /time), found 4801×12×3".
std::vector<std::size_t> ExpectShape(const std::string& file, const std::string& path,
                                     const Array& array, const std::vector<Dim>& dims);

// A time base: rank 1 (symbol `symbol`), at least one value, every value
// finite and strictly greater than the one before. Returns its length.
std::size_t ExpectTimeBase(const std::string& file, const std::string& path, const Array& array,
                           const std::string& symbol);

// Every value finite.
void ExpectFinite(const std::string& file, const std::string& path, const Array& array);

// Names non-empty and unique.
void ExpectUniqueNames(const std::string& file, const std::string& path,
                       const std::vector<std::string>& names);

// A valid single HDF5 link name for a member we create: non-empty, no '/',
// not "." or "..".
bool IsValidLinkName(const std::string& name);

// Shortest text that reads back to the same double ("0.1", "4801", "nan").
std::string FormatNumber(double value);

}  // namespace ccsrm::datasets::internal
