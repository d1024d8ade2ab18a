#include "sparse_system.h"

#include <algorithm>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::sim::internal {
namespace {

// The 8 coordinates of element e of cable c: (r1, r2, s1, s2).
void ElementColumns(const ArmModel& model, int c, int e, int cols[8]) {
  const int o1 = model.node_offset(c, e), o2 = model.node_offset(c, e + 1);
  const int list[8] = {o1, o1 + 1, o1 + 2, o2, o2 + 1, o2 + 2, o1 + 3, o2 + 3};
  std::copy(list, list + 8, cols);
}

}  // namespace

SparseLayout::SparseLayout(const ArmModel& model) : n_(model.num_coordinates()) {
  for (int c = 0; c < model.num_cables(); ++c) {
    const auto& cable = model.cables()[c];
    for (int k = 1; k + 1 < static_cast<int>(cable.nodes.size()); ++k) holes_.push_back({c, k});
  }

  // Constraint rows.
  auto add_row = [&](const std::vector<int>& cols, int hole) {
    ConstraintRowLayout row;
    CCSRM_CHECK(static_cast<int>(cols.size()) <= ConstraintRowLayout::kMaxColumns);
    for (int col : cols) row.cols[row.count++] = col;
    row.hole = hole;
    rows_.push_back(row);
  };
  // A position axis and the quaternion of a link.
  auto link_cols = [&](int link, int axis, std::vector<int>* cols) {
    const int o = model.link_offset(link);
    cols->push_back(o + axis);
    for (int k = 3; k < 7; ++k) cols->push_back(o + k);
  };
  int hole = 0;
  for (int c = 0; c < model.num_cables(); ++c) {
    const auto& cable = model.cables()[c];
    for (int k = 0; k < static_cast<int>(cable.nodes.size()); ++k) {
      const int o = model.node_offset(c, k);
      for (int a = 0; a < 3; ++a) {
        std::vector<int> cols{o + a};
        if (cable.nodes[k].link > 0) link_cols(cable.nodes[k].link, a, &cols);
        add_row(cols, -1);
      }
      const bool is_hole = cable.nodes[k].kind == CableNodeModel::Kind::kHole;
      add_row({o + 3}, is_hole ? hole++ : -1);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    add_row({o + 3, o + 4, o + 5, o + 6}, -1);
  }
  for (int j = 1; j <= model.num_joints(); ++j) {
    for (int a = 0; a < 3; ++a) {
      std::vector<int> cols;
      if (j > 1) link_cols(j - 1, a, &cols);
      link_cols(j, a, &cols);
      add_row(cols, -1);
    }
    std::vector<int> cols;
    for (int link : {j - 1, j}) {
      if (link < 1) continue;
      for (int k = 3; k < 7; ++k) cols.push_back(model.link_offset(link) + k);
    }
    add_row(cols, -1);
  }
  m_ = static_cast<int>(rows_.size());

  for (const ConnectingPairModel& pair : model.connecting_pairs()) {
    std::vector<int> links;
    for (int link = pair.joint_i - 1; link <= pair.joint_i + 1; ++link) {
      if (link >= 1) links.push_back(link);
    }
    pair_links_.push_back(links);
  }
  auto pair_cols = [&](const std::vector<int>& links) {
    std::vector<int> cols;
    for (int link : links)
      for (int a = 3; a < 7; ++a) cols.push_back(model.link_offset(link) + a);
    return cols;
  };

  // Sparsity pattern (D = 1 on the rows of slipping hole nodes, whose stick
  // constraint is switched off, so their lambda is 0).
  std::vector<Eigen::Triplet<double>> pattern;
  int cols[8];
  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e) {
      ElementColumns(model, c, e, cols);
      for (int a : cols)
        for (int b : cols) pattern.emplace_back(a, b, 0.0);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    for (int a = 0; a < 3; ++a) pattern.emplace_back(o + a, o + a, 0.0);
    for (int a = 3; a < 7; ++a)
      for (int b = 3; b < 7; ++b) pattern.emplace_back(o + a, o + b, 0.0);
  }
  for (const std::vector<int>& links : pair_links_) {
    for (int a : pair_cols(links))
      for (int b : pair_cols(links)) pattern.emplace_back(a, b, 0.0);
  }
  for (int r = 0; r < m_; ++r) {
    const ConstraintRowLayout& row = rows_[r];
    for (int a = 0; a < row.count; ++a) {
      pattern.emplace_back(n_ + r, row.cols[a], 0.0);
      pattern.emplace_back(row.cols[a], n_ + r, 0.0);
      for (int b = 0; b < row.count; ++b) pattern.emplace_back(row.cols[a], row.cols[b], 0.0);
    }
    pattern.emplace_back(n_ + r, n_ + r, 0.0);
  }
  {
    // AMD on the pattern, in the convention of Eigen's own ordering step:
    // the ordering yields the inverse permutation.
    Eigen::SparseMatrix<double> model_order(n_ + m_, n_ + m_);
    model_order.setFromTriplets(pattern.begin(), pattern.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;
    Eigen::AMDOrdering<int>()(model_order, inverse);
    const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order = inverse.inverse();
    order_.assign(order.indices().data(), order.indices().data() + n_ + m_);
    for (auto& entry : pattern) {
      entry = Eigen::Triplet<double>(order_[entry.row()], order_[entry.col()], 0.0);
    }
  }
  pattern_.resize(n_ + m_, n_ + m_);
  pattern_.setFromTriplets(pattern.begin(), pattern.end());
  pattern_.makeCompressed();

  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e) {
      ElementColumns(model, c, e, cols);
      for (int a : cols)
        for (int b : cols) element_index_.push_back(Index(a, b));
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    for (int a = 0; a < 3; ++a) link_index_.push_back(Index(o + a, o + a));
    for (int a = 3; a < 7; ++a)
      for (int b = 3; b < 7; ++b) link_index_.push_back(Index(o + a, o + b));
  }
  for (const std::vector<int>& links : pair_links_) {
    std::vector<int> index;
    for (int a : pair_cols(links))
      for (int b : pair_cols(links)) index.push_back(Index(a, b));
    pair_index_.push_back(index);
  }
  for (int r = 0; r < m_; ++r) {
    const ConstraintRowLayout& row = rows_[r];
    row_kkt_offset_.push_back(static_cast<int>(row_kkt_index_.size()));
    for (int a = 0; a < row.count; ++a) {
      row_kkt_index_.push_back(Index(n_ + r, row.cols[a]));
      row_kkt_index_.push_back(Index(row.cols[a], n_ + r));
    }
    row_pair_offset_.push_back(static_cast<int>(row_pair_index_.size()));
    for (int a = 0; a < row.count; ++a)
      for (int b = 0; b < row.count; ++b)
        row_pair_index_.push_back(Index(row.cols[a], row.cols[b]));
    row_diag_index_.push_back(Index(n_ + r, n_ + r));
  }
  for (const HoleNodeRef& h : holes_) {
    const int s = model.node_offset(h.cable, h.node) + 3;
    hole_index_.push_back(Index(s, s));
  }
}

int SparseLayout::Index(int model_row, int model_col) const {
  const int row = order_[model_row], col = order_[model_col];
  const int* inner = pattern_.innerIndexPtr();
  const int begin = pattern_.outerIndexPtr()[col];
  const int end = pattern_.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(inner + begin, inner + end, row);
  CCSRM_CHECK(at != inner + end && *at == row);
  return static_cast<int>(at - inner);
}

AugmentedSystem::AugmentedSystem(const SparseLayout& layout)
    : layout_(layout), matrix_(layout.pattern()) {
  const int size = layout.num_coordinates() + layout.num_constraints();
  // The symbolic analysis of the fixed pattern, once per run.
  ldlt_.analyzePattern(matrix_);
  rhs_.setZero(size);
  solution_.setZero(size);
  ordered_rhs_.setZero(size);
  ordered_solution_.setZero(size);
}

void AugmentedSystem::Clear() {
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  rhs_.setZero();
}

bool AugmentedSystem::Solve() {
  ldlt_.factorize(matrix_);
  if (ldlt_.info() != Eigen::Success) return false;
  const std::vector<int>& order = layout_.order();
  const int size = static_cast<int>(order.size());
  for (int k = 0; k < size; ++k) ordered_rhs_[order[k]] = rhs_[k];
  ordered_solution_ = ldlt_.solve(ordered_rhs_);
  for (int k = 0; k < size; ++k) solution_[k] = ordered_solution_[order[k]];
  return true;
}

}  // namespace ccsrm::sim::internal
