#include "ccsrm/datasets/array.h"

namespace ccsrm::datasets {

std::size_t Array::ElementCount(const std::vector<std::size_t>& shape) {
  std::size_t count = 1;
  for (std::size_t extent : shape) count *= extent;
  return count;
}

std::string ShapeToString(const std::vector<std::size_t>& shape) {
  if (shape.empty()) return "scalar";
  std::string text;
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) text += "×";
    text += std::to_string(shape[i]);
  }
  return text;
}

}  // namespace ccsrm::datasets
