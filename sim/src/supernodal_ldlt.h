#pragma once
// A supernodal LDL^T with static pivots for a symmetric matrix whose
// elimination order is fixed beforehand (the rows and columns of the pattern
// are already in that order). No pivot is ever exchanged: the caller's
// order must make every pivot safe, as SparseLayout's interleaved block order
// does for the augmented system. The symbolic part (SupernodalStructure) is
// built once per pattern; the numeric part (SupernodalLdlt) owns all of its
// workspace, so Factorize and Solve never allocate.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstddef>
#include <vector>

namespace ccsrm::sim::internal {

class SupernodalStructure {
 public:
  // `pattern`: square, column-compressed, in elimination order; entries
  // with row >= column (the lower triangle) are what gets factorised.
  explicit SupernodalStructure(const Eigen::SparseMatrix<double>& pattern);

  int size() const { return size_; }
  int num_supernodes() const { return static_cast<int>(supernodes_.size()); }
  std::size_t storage_size() const { return storage_size_; }
  // Nonzeros of L (its unit diagonal included) and the multiply-adds of
  // one factorisation: figures for comparing orderings.
  std::size_t factor_nonzeros() const;
  double factor_flops() const;
  int largest_supernode() const;
  // Where value k of the pattern's lower triangle sits in the factor's
  // storage (SupernodalLdlt::storage), for assembling in place.
  int StorageIndex(int value) const { return storage_of_value_[value]; }

 private:
  friend class SupernodalLdlt;

  // Columns first_col .. first_col + num_cols - 1 share one row structure
  // (rows_begin .. rows_begin + num_rows in row_index_, the supernode's own
  // columns first), stored as a dense num_rows x num_cols column-major
  // panel at storage_offset.
  struct Supernode {
    int first_col = 0;
    int num_cols = 0;
    int num_rows = 0;
    int rows_begin = 0;
    std::size_t storage_offset = 0;
    int updates_begin = 0;  // into updates_
    int updates_end = 0;
  };
  // The part of supernode s's below-diagonal rows that falls in the columns
  // of a later supernode `target`: rows [row_begin, row_end) of s's
  // below-diagonal block (0-based past s's own columns) are target columns;
  // rows [row_begin, num_below) land in target at
  // relative_index_[relative_begin + k - row_begin].
  struct Update {
    int target = 0;
    int row_begin = 0;
    int row_end = 0;
    int relative_begin = 0;
  };

  int size_ = 0;
  std::vector<Supernode> supernodes_;
  std::vector<int> row_index_;
  std::vector<Update> updates_;
  std::vector<int> relative_index_;
  // Pattern value k goes to storage[storage_of_value_[k]] (-1 above the
  // diagonal, which is not factorised).
  std::vector<int> storage_of_value_;
  std::size_t storage_size_ = 0;
  int max_below_ = 0;  // largest below-diagonal row count
};

class SupernodalLdlt {
 public:
  explicit SupernodalLdlt(const SupernodalStructure& structure);

  // Factorises the matrix whose values (in the pattern's storage order) are
  // `values`; false when a pivot is zero or not finite.
  bool Factorize(const double* values);
  // The same with the matrix assembled in place: Zero(), add each value at
  // storage()[structure.StorageIndex(k)], then FactorizeAssembled().
  void Zero();
  double* storage() { return storage_.data(); }
  bool FactorizeAssembled();
  // Solves L D L^T x = b in place, b and x in elimination order.
  void Solve(Eigen::VectorXd& x);

 private:
  const SupernodalStructure& structure_;
  std::vector<double> storage_;
  Eigen::VectorXd pivots_;
  Eigen::VectorXd update_;   // one column of an update (or of a panel's own update)
  Eigen::VectorXd weights_;  // l_jk d_k of that column
  Eigen::VectorXd gathered_;
};

}  // namespace ccsrm::sim::internal
