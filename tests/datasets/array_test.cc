#include "ccsrm/datasets/array.h"

#include <gtest/gtest.h>

namespace ccsrm::datasets {
namespace {

TEST(Array, ConstructorFillsShapeWithValue) {
  const Array array({2, 3, 4}, 1.5);
  EXPECT_EQ(array.rank(), 3u);
  EXPECT_EQ(array.rows(), 2u);
  EXPECT_EQ(array.size(), 24u);
  EXPECT_TRUE(array.IsConsistent());
  for (double value : array.values) EXPECT_EQ(value, 1.5);
}

TEST(Array, AtIndexesRowMajor) {
  Array matrix({2, 3});
  matrix.at(1, 2) = 7.0;
  EXPECT_EQ(matrix.values[1 * 3 + 2], 7.0);
  Array cube({2, 3, 4});
  cube.at(1, 2, 3) = 9.0;
  EXPECT_EQ(cube.values[(1 * 3 + 2) * 4 + 3], 9.0);
  Array vector({5});
  vector.at(4) = 2.0;
  EXPECT_EQ(vector.values[4], 2.0);
}

TEST(Array, ConsistencyComparesValuesWithShape) {
  Array array({4, 2});
  array.values.pop_back();
  EXPECT_FALSE(array.IsConsistent());
  EXPECT_EQ(Array().rows(), 0u);
}

TEST(Array, ShapeToStringUsesMultiplicationSign) {
  EXPECT_EQ(ShapeToString({4801, 12, 2}), "4801×12×2");
  EXPECT_EQ(ShapeToString({7}), "7");
  EXPECT_EQ(ShapeToString({}), "scalar");
}

TEST(ArrayDeathTest, OutOfRangeIndexAborts) {
  Array array({2, 3});
  EXPECT_DEATH(array.at(2, 0), "internal invariant violated");
  EXPECT_DEATH(array.at(0), "internal invariant violated");  // wrong rank
}

}  // namespace
}  // namespace ccsrm::datasets
