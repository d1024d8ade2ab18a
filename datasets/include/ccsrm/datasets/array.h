#pragma once
// A small N-dimensional array of doubles, stored row-major (C order, the last
// index varies fastest) exactly as the datasets of datasets/README.md are laid
// out on disk and as h5py/NumPy present them.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/error.h"

namespace ccsrm::datasets {

struct Array {
  // Extent of each dimension; shape[0] is the number of rows (frames).
  std::vector<std::size_t> shape;
  // Row-major values; values.size() == ElementCount(shape) for a consistent
  // array (IsConsistent()).
  std::vector<double> values;

  Array() = default;
  // An array of the given shape with every element set to fill.
  explicit Array(std::vector<std::size_t> shape_in, double fill = 0.0)
      : shape(std::move(shape_in)), values(ElementCount(shape), fill) {}

  // Product of the extents (1 for an empty shape, i.e. a scalar).
  static std::size_t ElementCount(const std::vector<std::size_t>& shape);

  std::size_t rank() const { return shape.size(); }
  // Extent of the first dimension; 0 for a rank-0 array.
  std::size_t rows() const { return shape.empty() ? 0 : shape[0]; }
  std::size_t size() const { return values.size(); }
  bool IsConsistent() const { return values.size() == ElementCount(shape); }

  // Element access by index. Requires the matching rank and indices in range;
  // a violation is a programming error and aborts through CCSRM_CHECK (two
  // comparisons per index, cheap enough to keep in every build type).
  double& at(std::size_t i) { return values[Offset1(i)]; }
  double at(std::size_t i) const { return values[Offset1(i)]; }
  double& at(std::size_t i, std::size_t j) { return values[Offset2(i, j)]; }
  double at(std::size_t i, std::size_t j) const { return values[Offset2(i, j)]; }
  double& at(std::size_t i, std::size_t j, std::size_t k) { return values[Offset3(i, j, k)]; }
  double at(std::size_t i, std::size_t j, std::size_t k) const { return values[Offset3(i, j, k)]; }

 private:
  std::size_t Offset1(std::size_t i) const {
    CCSRM_CHECK(shape.size() == 1 && i < shape[0]);
    return i;
  }
  std::size_t Offset2(std::size_t i, std::size_t j) const {
    CCSRM_CHECK(shape.size() == 2 && i < shape[0] && j < shape[1]);
    return i * shape[1] + j;
  }
  std::size_t Offset3(std::size_t i, std::size_t j, std::size_t k) const {
    CCSRM_CHECK(shape.size() == 3 && i < shape[0] && j < shape[1] && k < shape[2]);
    return (i * shape[1] + j) * shape[2] + k;
  }
};

// "4801×12×2" ("scalar" for an empty shape): the notation of error messages,
// inspect listings and datasets/README.md.
std::string ShapeToString(const std::vector<std::size_t>& shape);

}  // namespace ccsrm::datasets
