#include "supernodal_ldlt.h"

#include <algorithm>
#include <cmath>

#include "ccsrm/common/error.h"

namespace ccsrm::sim::internal {
namespace {

// Position of `row` in the sorted list [begin, end) (which holds it).
int PositionOf(const int* begin, const int* end, int row) {
  const int* at = std::lower_bound(begin, end, row);
  CCSRM_CHECK(at != end && *at == row);
  return static_cast<int>(at - begin);
}

// y[i] = sum_k a[k * stride + i] w[k] for i < length: the kernel of both
// the panel factorisation and the updates. The count % 4 leading columns in
// one pass that also sets y, then four columns at a time, so that each pass
// over y does up to four multiply-adds per load and store; the i loops are
// contiguous and vectorise. Built twice, the AVX2 clone chosen at load
// time where the processor has it: 4-wide instead of SSE2's 2-wide, 3 %
// of a fast-reversals run. AVX2 without FMA keeps every rounding the
// default clone's (the angles bit-identical on either path).
__attribute__((target_clones("avx2", "default"))) void Combination(const double* a, int stride,
                                                                   const double* w, int count,
                                                                   int length, double* y) {
  auto column = [&](int k) { return a + static_cast<std::size_t>(k) * stride; };
  int k = count % 4;
  switch (k) {
    case 0:
      for (int i = 0; i < length; ++i) y[i] = 0.0;
      break;
    case 1: {
      const double* a0 = column(0);
      for (int i = 0; i < length; ++i) y[i] = a0[i] * w[0];
      break;
    }
    case 2: {
      const double *a0 = column(0), *a1 = column(1);
      for (int i = 0; i < length; ++i) y[i] = a0[i] * w[0] + a1[i] * w[1];
      break;
    }
    default: {
      const double *a0 = column(0), *a1 = column(1), *a2 = column(2);
      for (int i = 0; i < length; ++i) y[i] = a0[i] * w[0] + a1[i] * w[1] + a2[i] * w[2];
      break;
    }
  }
  for (; k + 4 <= count; k += 4) {
    const double *a0 = column(k), *a1 = column(k + 1), *a2 = column(k + 2), *a3 = column(k + 3);
    const double w0 = w[k], w1 = w[k + 1], w2 = w[k + 2], w3 = w[k + 3];
    for (int i = 0; i < length; ++i) y[i] += a0[i] * w0 + a1[i] * w1 + a2[i] * w2 + a3[i] * w3;
  }
}

// sum_i a[i] b[i] over four partial sums: a single sum is one chain of
// dependent additions, which the compiler may not reorder.
double Dot(const double* a, const double* b, int n) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += a[i] * b[i];
    s1 += a[i + 1] * b[i + 1];
    s2 += a[i + 2] * b[i + 2];
    s3 += a[i + 3] * b[i + 3];
  }
  for (; i < n; ++i) s0 += a[i] * b[i];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace

SupernodalStructure::SupernodalStructure(const Eigen::SparseMatrix<double>& pattern)
    : size_(static_cast<int>(pattern.rows())) {
  CCSRM_CHECK(pattern.rows() == pattern.cols() && pattern.isCompressed());
  const int n = size_;

  // Row structure of each column of L below the diagonal: the column's own
  // lower pattern merged with those of its children in the elimination tree.
  std::vector<std::vector<int>> below(n);
  std::vector<std::vector<int>> children(n);
  std::vector<int> parent(n, -1);
  std::vector<int> mark(n, -1);
  for (int j = 0; j < n; ++j) {
    std::vector<int>& rows = below[j];
    auto add = [&](int i) {
      if (i > j && mark[i] != j) {
        mark[i] = j;
        rows.push_back(i);
      }
    };
    for (Eigen::SparseMatrix<double>::InnerIterator it(pattern, j); it; ++it) add(it.index());
    for (int child : children[j])
      for (int i : below[child]) add(i);
    std::sort(rows.begin(), rows.end());
    if (!rows.empty()) {
      parent[j] = rows.front();
      children[rows.front()].push_back(j);
    }
  }

  // Supernodes: column j joins column j - 1's supernode when j is j - 1's
  // parent in the elimination tree (so the structure of every column of the
  // supernode below it lies in that of its last column) and the explicit
  // zeros this stores stay under a fifth of the panel (a tenth or a third
  // measured slower on the paper's arm: more, narrower panels or more
  // wasted work). Fundamental supernodes alone would split every block of
  // the augmented system, whose coordinates each bring a row of their own.
  std::vector<int> owner(n);
  std::size_t nonzeros = 0;  // true nonzeros of the open supernode's lower trapezoid
  for (int j = 0; j < n; ++j) {
    bool extends = j > 0 && parent[j - 1] == j;
    if (extends) {
      const Supernode& open = supernodes_.back();
      const std::size_t cols = open.num_cols + 1;
      const std::size_t rows = cols + below[j].size();
      const std::size_t merged_stored = rows * cols - cols * (cols - 1) / 2;
      const std::size_t merged_nonzeros = nonzeros + 1 + below[j].size();
      extends = 5 * (merged_stored - merged_nonzeros) <= merged_stored;
      if (extends) nonzeros = merged_nonzeros;
    }
    if (!extends) {
      Supernode s;
      s.first_col = j;
      supernodes_.push_back(s);
      nonzeros = 1 + below[j].size();
    }
    ++supernodes_.back().num_cols;
    owner[j] = static_cast<int>(supernodes_.size()) - 1;
  }
  for (Supernode& s : supernodes_) {
    const int last = s.first_col + s.num_cols - 1;
    s.rows_begin = static_cast<int>(row_index_.size());
    for (int j = s.first_col; j <= last; ++j) row_index_.push_back(j);
    row_index_.insert(row_index_.end(), below[last].begin(), below[last].end());
    s.num_rows = s.num_cols + static_cast<int>(below[last].size());
    s.storage_offset = storage_size_;
    storage_size_ += static_cast<std::size_t>(s.num_rows) * s.num_cols;
    max_below_ = std::max(max_below_, s.num_rows - s.num_cols);
  }

  // Where each supernode's update lands: its below-diagonal rows grouped by
  // the supernode whose columns they are, with every row's position in
  // that supernode's structure.
  for (Supernode& s : supernodes_) {
    s.updates_begin = static_cast<int>(updates_.size());
    const int* rows = &row_index_[s.rows_begin + s.num_cols];
    const int num_below = s.num_rows - s.num_cols;
    for (int k = 0; k < num_below;) {
      Update u;
      u.target = owner[rows[k]];
      u.row_begin = k;
      while (k < num_below && owner[rows[k]] == u.target) ++k;
      u.row_end = k;
      u.relative_begin = static_cast<int>(relative_index_.size());
      const Supernode& t = supernodes_[u.target];
      const int* t_rows = &row_index_[t.rows_begin];
      for (int i = u.row_begin; i < num_below; ++i)
        relative_index_.push_back(PositionOf(t_rows, t_rows + t.num_rows, rows[i]));
      updates_.push_back(u);
    }
    s.updates_end = static_cast<int>(updates_.size());
  }

  // Where each lower-triangle value of the matrix goes in the panels.
  storage_of_value_.assign(static_cast<std::size_t>(pattern.nonZeros()), -1);
  for (int j = 0; j < n; ++j) {
    const Supernode& s = supernodes_[owner[j]];
    const int* rows = &row_index_[s.rows_begin];
    for (int k = pattern.outerIndexPtr()[j]; k < pattern.outerIndexPtr()[j + 1]; ++k) {
      const int i = pattern.innerIndexPtr()[k];
      if (i < j) continue;
      storage_of_value_[k] = static_cast<int>(
          s.storage_offset + static_cast<std::size_t>(j - s.first_col) * s.num_rows +
          PositionOf(rows, rows + s.num_rows, i));
    }
  }
}

std::size_t SupernodalStructure::factor_nonzeros() const {
  std::size_t count = 0;
  for (const Supernode& s : supernodes_) {
    // The lower trapezoid of the panel.
    count += static_cast<std::size_t>(s.num_rows) * s.num_cols -
             static_cast<std::size_t>(s.num_cols) * (s.num_cols - 1) / 2;
  }
  return count;
}

double SupernodalStructure::factor_flops() const {
  double flops = 0.0;
  for (const Supernode& s : supernodes_) {
    for (int k = 0; k < s.num_cols; ++k) {
      const double below = s.num_rows - k - 1;
      flops += below * (below + 3) / 2;
    }
  }
  return flops;
}

int SupernodalStructure::largest_supernode() const {
  int largest = 0;
  for (const Supernode& s : supernodes_) largest = std::max(largest, s.num_cols);
  return largest;
}

SupernodalLdlt::SupernodalLdlt(const SupernodalStructure& structure)
    : structure_(structure),
      storage_(structure.storage_size_, 0.0),
      pivots_(Eigen::VectorXd::Ones(structure.size_)) {
  int widest = 1, tallest = 1;
  for (const auto& s : structure.supernodes_) {
    widest = std::max(widest, s.num_cols);
    tallest = std::max(tallest, s.num_rows);
  }
  update_.setZero(tallest);
  weights_.setZero(widest);
  gathered_.setZero(std::max(1, structure.max_below_));
}

void SupernodalLdlt::Zero() { std::fill(storage_.begin(), storage_.end(), 0.0); }

bool SupernodalLdlt::Factorize(const double* values) {
  const SupernodalStructure& st = structure_;
  Zero();
  for (std::size_t k = 0; k < st.storage_of_value_.size(); ++k)
    if (st.storage_of_value_[k] >= 0) storage_[st.storage_of_value_[k]] = values[k];
  return FactorizeAssembled();
}

bool SupernodalLdlt::FactorizeAssembled() {
  const SupernodalStructure& st = structure_;

  // Right-looking over supernodes: factor a panel, then subtract its
  // contribution from the panels of the later supernodes it touches. Within
  // a panel, left-looking: column j less the combination of the columns
  // before it, weighted by l_jk d_k.
  double* u = update_.data();
  double* w = weights_.data();
  for (const SupernodalStructure::Supernode& s : st.supernodes_) {
    double* panel = storage_.data() + s.storage_offset;
    const double* pivots = pivots_.data() + s.first_col;
    const int rows = s.num_rows, cols = s.num_cols, num_below = rows - cols;
    for (int j = 0; j < cols; ++j) {
      double* col = panel + static_cast<std::size_t>(j) * rows;
      if (j > 0) {
        for (int k = 0; k < j; ++k)
          w[k] = panel[static_cast<std::size_t>(k) * rows + j] * pivots[k];
        Combination(panel + j, rows, w, j, rows - j, u);
        for (int i = j; i < rows; ++i) col[i] -= u[i - j];
      }
      const double pivot = col[j];
      if (!(pivot != 0.0 && std::isfinite(pivot))) return false;
      pivots_[s.first_col + j] = pivot;
      const double inverse = 1.0 / pivot;
      for (int i = j + 1; i < rows; ++i) col[i] *= inverse;
    }
    if (num_below == 0) continue;

    // Column by column of each update block: u = L_below D l_c^T over the
    // rows from the column's own row on, subtracted into the target
    // through the precomputed positions.
    const double* below = panel + cols;
    const int* below_rows = &st.row_index_[s.rows_begin + cols];
    for (int up = s.updates_begin; up < s.updates_end; ++up) {
      const SupernodalStructure::Update& update = st.updates_[up];
      const SupernodalStructure::Supernode& t = st.supernodes_[update.target];
      const int* relative = &st.relative_index_[update.relative_begin] - update.row_begin;
      double* t_panel = storage_.data() + t.storage_offset;
      for (int first = update.row_begin; first < update.row_end; ++first) {
        const int length = num_below - first;
        for (int k = 0; k < cols; ++k)
          w[k] = below[static_cast<std::size_t>(k) * rows + first] * pivots[k];
        Combination(below + first, rows, w, cols, length, u);
        double* t_col =
            t_panel + static_cast<std::size_t>(below_rows[first] - t.first_col) * t.num_rows;
        const int* position = relative + first;
        for (int i = 0; i < length; ++i) t_col[position[i]] -= u[i];
      }
    }
  }
  return true;
}

// Plain loops rather than Eigen's triangular solves and products: the
// panels are small (most a few columns), where the calls' set-up cost more
// than the arithmetic.
void SupernodalLdlt::Solve(Eigen::VectorXd& x_vector) {
  const SupernodalStructure& st = structure_;
  double* x = x_vector.data();
  double* gathered = gathered_.data();
  for (const SupernodalStructure::Supernode& s : st.supernodes_) {
    const double* panel = storage_.data() + s.storage_offset;
    const int rows = s.num_rows, cols = s.num_cols, num_below = rows - cols;
    double* head = x + s.first_col;
    // L_head y = b over the supernode's own columns (unit lower).
    for (int j = 0; j < cols; ++j) {
      const double* col = panel + static_cast<std::size_t>(j) * rows;
      const double xj = head[j];
      for (int i = j + 1; i < cols; ++i) head[i] -= col[i] * xj;
    }
    if (num_below == 0) continue;
    Combination(panel + cols, rows, head, cols, num_below, gathered);
    const int* below_rows = &st.row_index_[s.rows_begin + cols];
    for (int i = 0; i < num_below; ++i) x[below_rows[i]] -= gathered[i];
  }
  for (int k = 0; k < st.size_; ++k) x[k] /= pivots_[k];
  for (auto s = st.supernodes_.rbegin(); s != st.supernodes_.rend(); ++s) {
    const double* panel = storage_.data() + s->storage_offset;
    const int rows = s->num_rows, cols = s->num_cols, num_below = rows - cols;
    double* head = x + s->first_col;
    if (num_below > 0) {
      const int* below_rows = &st.row_index_[s->rows_begin + cols];
      for (int i = 0; i < num_below; ++i) gathered[i] = x[below_rows[i]];
      for (int j = 0; j < cols; ++j)
        head[j] -= Dot(panel + static_cast<std::size_t>(j) * rows + cols, gathered, num_below);
    }
    // L_head^T x = y (unit upper).
    for (int j = cols - 1; j >= 0; --j) {
      const double* col = panel + static_cast<std::size_t>(j) * rows;
      head[j] -= Dot(col + j + 1, head + j + 1, cols - j - 1);
    }
  }
}

}  // namespace ccsrm::sim::internal
