#include "sparse_system.h"

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <map>
#include <memory>

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
  // `owner`: a coordinate of the block the row is eliminated with (see
  // InterleavedBlockOrder).
  auto add_row = [&](const std::vector<int>& cols, int hole, int owner) {
    row_owner_.push_back(owner);
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
        add_row(cols, -1, o + a);
        rows_.back().node = num_cable_nodes_;
      }
      ++num_cable_nodes_;
      const bool is_hole = cable.nodes[k].kind == CableNodeModel::Kind::kHole;
      add_row({o + 3}, is_hole ? hole++ : -1, o + 3);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    add_row({o + 3, o + 4, o + 5, o + 6}, -1, o + 3);
  }
  for (int j = 1; j <= model.num_joints(); ++j) {
    for (int a = 0; a < 3; ++a) {
      std::vector<int> cols;
      if (j > 1) link_cols(j - 1, a, &cols);
      link_cols(j, a, &cols);
      add_row(cols, -1, model.link_offset(j) + a);
    }
    std::vector<int> cols;
    for (int link : {j - 1, j}) {
      if (link < 1) continue;
      for (int k = 3; k < 7; ++k) cols.push_back(model.link_offset(link) + k);
    }
    add_row(cols, -1, model.link_offset(j) + 3);
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
  order_ = BlockOrder(n_ + m_, InterleavedBlocks(model), pattern);
  // Each symmetric pair once, in the lower triangle.
  for (auto& entry : pattern) {
    const int i = order_[entry.row()], j = order_[entry.col()];
    entry = Eigen::Triplet<double>(std::max(i, j), std::min(i, j), 0.0);
  }
  pattern_.resize(n_ + m_, n_ + m_);
  pattern_.setFromTriplets(pattern.begin(), pattern.end());
  pattern_.makeCompressed();
  factorisation_ = std::make_unique<const SupernodalStructure>(pattern_);

  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e) {
      ElementColumns(model, c, e, cols);
      PackedLowerIndex(cols, 8, &element_index_);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    for (int a = 0; a < 3; ++a) link_index_.push_back(Index(o + a, o + a));
    const int quaternion[4] = {o + 3, o + 4, o + 5, o + 6};
    PackedLowerIndex(quaternion, 4, &link_index_);
  }
  for (const std::vector<int>& links : pair_links_) {
    const std::vector<int> quaternions = pair_cols(links);
    std::vector<int> index;
    PackedLowerIndex(quaternions.data(), static_cast<int>(quaternions.size()), &index);
    pair_index_.push_back(index);
  }
  for (int r = 0; r < m_; ++r) {
    const ConstraintRowLayout& row = rows_[r];
    row_kkt_offset_.push_back(static_cast<int>(row_kkt_index_.size()));
    for (int a = 0; a < row.count; ++a) row_kkt_index_.push_back(Index(n_ + r, row.cols[a]));
    row_pair_offset_.push_back(static_cast<int>(row_pair_index_.size()));
    PackedLowerIndex(row.cols, row.count, &row_pair_index_);
    row_diag_index_.push_back(Index(n_ + r, n_ + r));
  }
  for (const HoleNodeRef& h : holes_) {
    const int s = model.node_offset(h.cable, h.node) + 3;
    hole_index_.push_back(Index(s, s));
  }
  embedded_ = std::make_unique<const EmbeddedNodeLayout>(model, *this, HoleStickRows::kKept);
  embedded_without_holes_ =
      std::make_unique<const EmbeddedNodeLayout>(model, *this, HoleStickRows::kLeftOut);
}

// The elimination order. Under a scalar fill-reducing order the multiplier
// rows, having the fewest neighbours, come first and are pivoted on their
// own -delta = -1e-10 diagonal; the resulting growth cost q_dd five digits.
// Here the unknowns are grouped into blocks (a cable node's 4 coordinates, a
// link's 7), each constraint row joins the block of the coordinate it is
// written for (a cable node's rows their node, a link's unit-quaternion row
// and a joint's rows the child link), and every block is eliminated
// coordinates first, rows after. A row's pivot is then -delta minus the
// Schur value of its block's coordinates, O(1) and negative, and the
// coordinates' pivots stay O(1) and positive: static pivots are stable.
// The blocks are ordered by AMD on the block graph, each block expanded to
// all of its unknowns so that AMD weighs blocks by their size. Rows riding
// along in the fronts until their block comes make L about 1.7 times as
// full as under the scalar order (26k against 14k nonzeros on the paper's
// arm); the dense supernodal kernels make up for it. Finer groups
// (a row with one coordinate, a link's quaternion with its two quaternion
// rows) measured no better.
std::vector<std::vector<int>> SparseLayout::InterleavedBlocks(const ArmModel& model) const {
  std::vector<std::vector<int>> members;
  std::vector<int> block_of(n_, -1);
  // Members: coordinates, then rows. The coordinate coupled to all others
  // of its block goes first (a cable node's s, through the element mass; a
  // link's quaternion, through its position rows), so that eliminating it
  // fills the block in and the whole block is one supernode.
  auto add_block = [&](std::initializer_list<int> coordinates) {
    for (int k : coordinates) block_of[k] = static_cast<int>(members.size());
    members.emplace_back(coordinates);
  };
  for (int c = 0; c < model.num_cables(); ++c) {
    for (int k = 0; k < static_cast<int>(model.cables()[c].nodes.size()); ++k) {
      const int o = model.node_offset(c, k);
      add_block({o + 3, o, o + 1, o + 2});
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    add_block({o + 3, o + 4, o + 5, o + 6, o, o + 1, o + 2});
  }
  for (int r = 0; r < m_; ++r) members[block_of[row_owner_[r]]].push_back(n_ + r);
  return members;
}

std::vector<int> SparseLayout::BlockOrder(int size, const std::vector<std::vector<int>>& members,
                                          const std::vector<Eigen::Triplet<double>>& pattern) {
  const int num_blocks = static_cast<int>(members.size());
  std::vector<int> block_of(size, -1);
  for (int b = 0; b < num_blocks; ++b)
    for (int k : members[b]) block_of[k] = b;
  for (int k = 0; k < size; ++k) CCSRM_CHECK(block_of[k] >= 0);

  std::vector<std::vector<int>> neighbours(num_blocks);
  for (const auto& entry : pattern) {
    neighbours[block_of[entry.row()]].push_back(block_of[entry.col()]);
  }
  std::vector<Eigen::Triplet<double>> expanded;
  for (int b = 0; b < num_blocks; ++b) {
    std::vector<int>& adjacent = neighbours[b];
    std::sort(adjacent.begin(), adjacent.end());
    adjacent.erase(std::unique(adjacent.begin(), adjacent.end()), adjacent.end());
    for (int other : adjacent)
      for (int i : members[b])
        for (int j : members[other]) expanded.emplace_back(i, j, 1.0);
  }
  Eigen::SparseMatrix<double> graph(size, size);
  graph.setFromTriplets(expanded.begin(), expanded.end());
  // Eigen's ordering yields the inverse permutation: indices()[k] is the
  // unknown eliminated k-th.
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;
  Eigen::AMDOrdering<int>()(graph, inverse);

  // Blocks in the order their first unknown appears, each laid out whole.
  std::vector<int> order(size, -1);
  std::vector<char> placed(num_blocks, 0);
  int position = 0;
  for (int k = 0; k < size; ++k) {
    const int b = block_of[inverse.indices()[k]];
    if (placed[b]) continue;
    placed[b] = 1;
    for (int unknown : members[b]) order[unknown] = position++;
  }
  CCSRM_CHECK(position == size);
  return order;
}

int SparseLayout::Index(int model_row, int model_col) const {
  const int row = std::max(order_[model_row], order_[model_col]);
  const int col = std::min(order_[model_row], order_[model_col]);
  const int* inner = pattern_.innerIndexPtr();
  const int begin = pattern_.outerIndexPtr()[col];
  const int end = pattern_.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(inner + begin, inner + end, row);
  CCSRM_CHECK(at != inner + end && *at == row);
  return static_cast<int>(at - inner);
}

void SparseLayout::PackedLowerIndex(const int* cols, int count, std::vector<int>* index) const {
  for (int a = 0; a < count; ++a)
    for (int b = 0; b <= a; ++b) index->push_back(Index(cols[a], cols[b]));
}

AugmentedSystem::AugmentedSystem(const SparseLayout& layout, HoleStickRows hole_rows)
    : layout_(layout),
      embedded_(layout.embedded(hole_rows)),
      matrix_(layout.pattern()),
      ldlt_(layout.factorisation()),
      embedded_ldlt_(embedded_.factorisation()) {
  const int size = layout.num_coordinates() + layout.num_constraints();
  rhs_.setZero(size);
  solution_.setZero(size);
  ordered_.setZero(size);
  reduced_rhs_.setZero(size);
  embedded_ordered_.setZero(embedded_.size());
}

void AugmentedSystem::Clear() {
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  rhs_.setZero();
}

bool AugmentedSystem::Solve() {
  if (!ldlt_.Factorize(matrix_.valuePtr())) return false;
  const std::vector<int>& order = layout_.order();
  const int size = static_cast<int>(order.size());
  for (int k = 0; k < size; ++k) ordered_[order[k]] = rhs_[k];
  ldlt_.Solve(ordered_);
  for (int k = 0; k < size; ++k) solution_[k] = ordered_[order[k]];
  return true;
}

EmbeddedNodeLayout::EmbeddedNodeLayout(const ArmModel& model, const SparseLayout& full,
                                       HoleStickRows hole_rows)
    : full_size_(full.n_ + full.m_) {
  const int n = full.n_;
  // Which full unknowns are a node's position coordinate, a link's
  // coordinate, or a node's position row (the eliminated ones).
  std::vector<int> node_of(full_size_, -1), axis_of(full_size_, -1);
  std::vector<char> eliminated(full_size_, 0), is_link(full_size_, 0);
  for (int c = 0; c < model.num_cables(); ++c) {
    const auto& cable = model.cables()[c];
    for (int k = 0; k < static_cast<int>(cable.nodes.size()); ++k) {
      NodeInfo info;
      info.r = model.node_offset(c, k);
      info.link = cable.nodes[k].link;
      info.link_offset = info.link > 0 ? model.link_offset(info.link) : 0;
      for (int a = 0; a < 3; ++a) {
        node_of[info.r + a] = static_cast<int>(nodes_.size());
        axis_of[info.r + a] = a;
        eliminated[info.r + a] = 1;
      }
      nodes_.push_back(info);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i)
    for (int a = 0; a < 7; ++a) is_link[model.link_offset(i) + a] = 1;
  for (int r = 0; r < full.m_; ++r) {
    if (full.rows_[r].node >= 0) eliminated[n + r] = 1;
    // A row left out has no image: its entries are dropped, lambda = 0.
    if (hole_rows == HoleStickRows::kLeftOut && full.rows_[r].hole >= 0) eliminated[n + r] = 1;
  }
  reduced_of_.assign(full_size_, -1);
  for (int u = 0; u < full_size_; ++u) {
    if (eliminated[u]) continue;
    reduced_of_[u] = static_cast<int>(full_of_.size());
    full_of_.push_back(u);
  }
  size_ = static_cast<int>(full_of_.size());

  // Reduced unknown of coordinate p (0..6: position, quaternion) of node
  // i's link.
  auto link_unknown = [&](int node, int p) { return reduced_of_[nodes_[node].link_offset + p]; };
  // The reduced unknowns a full unknown maps to: itself, or its node's
  // link's position axis and quaternion (none on the ground).
  auto image = [&](int u, std::vector<int>* out) {
    out->clear();
    if (reduced_of_[u] >= 0) {
      out->push_back(reduced_of_[u]);
    } else if (node_of[u] >= 0 && nodes_[node_of[u]].link > 0) {
      out->push_back(link_unknown(node_of[u], axis_of[u]));
      for (int j = 0; j < 4; ++j) out->push_back(link_unknown(node_of[u], 3 + j));
    }
  };

  // The full pattern's entries in model indices.
  std::vector<int> unknown_at(full_size_);
  for (int u = 0; u < full_size_; ++u) unknown_at[full.order_[u]] = u;
  struct Entry {
    int row, col, value;
  };
  std::vector<Entry> entries;
  const Eigen::SparseMatrix<double>& fp = full.pattern_;
  for (int col = 0; col < full_size_; ++col) {
    for (int k = fp.outerIndexPtr()[col]; k < fp.outerIndexPtr()[col + 1]; ++k) {
      entries.push_back({unknown_at[fp.innerIndexPtr()[k]], unknown_at[col], k});
    }
  }
  auto is_node_row = [&](int u) { return u >= n && eliminated[u]; };

  // Reduced pattern: T^T A T over every entry that is not a node row's.
  std::vector<Eigen::Triplet<double>> pattern;
  std::vector<int> image_i, image_j;
  for (const Entry& e : entries) {
    if (is_node_row(e.row) || is_node_row(e.col)) continue;
    image(e.row, &image_i);
    image(e.col, &image_j);
    for (int p : image_i) {
      for (int q : image_j) {
        pattern.emplace_back(p, q, 0.0);
        pattern.emplace_back(q, p, 0.0);
      }
    }
  }
  for (int p = 0; p < size_; ++p) pattern.emplace_back(p, p, 0.0);

  std::vector<std::vector<int>> members;
  for (const std::vector<int>& block : full.InterleavedBlocks(model)) {
    std::vector<int> kept;
    for (int u : block)
      if (reduced_of_[u] >= 0) kept.push_back(reduced_of_[u]);
    if (!kept.empty()) members.push_back(kept);
  }
  order_ = SparseLayout::BlockOrder(size_, members, pattern);
  for (auto& entry : pattern) {
    const int i = order_[entry.row()], j = order_[entry.col()];
    entry = Eigen::Triplet<double>(std::max(i, j), std::min(i, j), 0.0);
  }
  Eigen::SparseMatrix<double> reduced_pattern(size_,
                                              size_);  // lower triangle, in elimination order
  reduced_pattern.setFromTriplets(pattern.begin(), pattern.end());
  reduced_pattern.makeCompressed();
  factorisation_ = std::make_unique<const SupernodalStructure>(reduced_pattern);

  // Value index of the lower-triangle entry of reduced unknowns p and q.
  auto lower = [&](int p, int q) {
    const int a = std::max(order_[p], order_[q]), b = std::min(order_[p], order_[q]);
    const int* inner = reduced_pattern.innerIndexPtr();
    const int* begin = inner + reduced_pattern.outerIndexPtr()[b];
    const int* end = inner + reduced_pattern.outerIndexPtr()[b + 1];
    const int* at = std::lower_bound(begin, end, a);
    CCSRM_CHECK(at != end && *at == a);
    return static_cast<int>(at - inner);
  };

  std::vector<std::vector<int>> kept_of_node(nodes_.size());  // node -> index into node_kept_
  std::vector<std::vector<int>> pair_of_node(nodes_.size());  // node n -> index into node_pairs_
  std::map<std::pair<int, int>, int> link_block_of;           // (lo, hi) links -> link_blocks_
  for (const Entry& stored : entries) {
    if (reduced_of_[stored.row] >= 0 && reduced_of_[stored.col] >= 0) {
      copy_.emplace_back(stored.value, lower(reduced_of_[stored.row], reduced_of_[stored.col]));
      continue;
    }
    // The full pattern stores each pair once, either way round: read it
    // with a node's position first (of two nodes, the lower-numbered).
    Entry e = stored;
    if (node_of[e.row] < 0 || (node_of[e.col] >= 0 && node_of[e.col] < node_of[e.row]))
      std::swap(e.row, e.col);
    const int rj = reduced_of_[e.col];
    const int ni = node_of[e.row];
    if (ni < 0) continue;  // a node row's entry, or a row left out
    const int nj = node_of[e.col];
    if (nj < 0) {
      // Only the node's own position rows couple it to a link, and they
      // are not assembled.
      if (rj < 0 || is_link[e.col]) continue;
      int found = -1;
      for (int index : kept_of_node[ni])
        if (node_kept_[index].kept == e.col) found = index;
      if (found < 0) {
        NodeKept nk;
        nk.node = ni;
        nk.kept = e.col;
        std::fill(nk.full, nk.full + 3, -1);
        std::fill(nk.target, nk.target + 7, -1);
        if (nodes_[ni].link > 0) {
          for (int p = 0; p < 7; ++p) nk.target[p] = lower(link_unknown(ni, p), rj);
        }
        found = static_cast<int>(node_kept_.size());
        kept_of_node[ni].push_back(found);
        node_kept_.push_back(nk);
      }
      node_kept_[found].full[axis_of[e.row]] = e.value;
      continue;
    }
    int found = -1;
    for (int index : pair_of_node[ni])
      if (node_pairs_[index].m == nj) found = index;
    if (found < 0) {
      NodePair np;
      np.n = ni;
      np.m = nj;
      std::fill(np.full, np.full + 9, -1);
      const int link_n = nodes_[ni].link, link_m = nodes_[nj].link;
      if (link_n > 0 && link_m > 0) {
        const int lo = std::min(link_n, link_m), hi = std::max(link_n, link_m);
        auto at = link_block_of.find({lo, hi});
        if (at == link_block_of.end()) {
          LinkBlock block;
          const int lo_offset = nodes_[link_n == lo ? ni : nj].link_offset;
          const int hi_offset = nodes_[link_n == hi ? ni : nj].link_offset;
          for (int p = 0; p < 7; ++p) {
            for (int q = 0; q < 7; ++q) {
              const int P = reduced_of_[lo_offset + p], Q = reduced_of_[hi_offset + q];
              const bool in_lower = lo != hi || order_[P] >= order_[Q];
              block.target[p + 7 * q] = in_lower ? lower(P, Q) : -1;
            }
          }
          at = link_block_of.emplace(std::make_pair(lo, hi), static_cast<int>(link_blocks_.size()))
                   .first;
          link_blocks_.push_back(block);
        }
        np.block = at->second;
        if (link_n == link_m) {
          np.into = ni == nj ? NodePair::Into::kAsIs : NodePair::Into::kWithMirror;
        } else {
          np.into = link_n == lo ? NodePair::Into::kAsIs : NodePair::Into::kTransposed;
        }
      }
      found = static_cast<int>(node_pairs_.size());
      pair_of_node[ni].push_back(found);
      node_pairs_.push_back(np);
    }
    node_pairs_[found].full[3 * axis_of[e.row] + axis_of[e.col]] = e.value;
    // A node's own block holds its lower triangle: the mirror is the same.
    if (ni == nj) node_pairs_[found].full[3 * axis_of[e.col] + axis_of[e.row]] = e.value;
  }

  // The reduced matrix is assembled straight into its factor's storage.
  auto to_storage = [&](int& value) {
    if (value >= 0) value = factorisation_->StorageIndex(value);
  };
  for (auto& entry : copy_) to_storage(entry.second);
  for (NodeKept& nk : node_kept_)
    for (int& target : nk.target) to_storage(target);
  for (LinkBlock& block : link_blocks_)
    for (int& target : block.target) to_storage(target);
}

bool AugmentedSystem::SolveEmbedded(const std::vector<NodeEmbedding>& nodes) {
  const EmbeddedNodeLayout& em = embedded_;
  CCSRM_CHECK(nodes.size() == em.nodes_.size());
  const double* full = matrix_.valuePtr();
  auto value = [full](int k) { return k >= 0 ? full[k] : 0.0; };
  embedded_ldlt_.Zero();
  double* reduced = embedded_ldlt_.storage();
  for (const auto& [from, to] : em.copy_) reduced[to] += full[from];

  // g = rhs - A[:, r] c over the full unknowns (only the kept ones and the
  // nodes' positions are read).
  Eigen::VectorXd& g = reduced_rhs_;
  g = rhs_;
  using Vector3 = Eigen::Vector3d;
  for (const EmbeddedNodeLayout::NodeKept& nk : em.node_kept_) {
    const Vector3 a(value(nk.full[0]), value(nk.full[1]), value(nk.full[2]));
    g[nk.kept] -= a.dot(nodes[nk.node].c);
    if (nk.target[0] < 0) continue;
    const Eigen::Matrix<double, 4, 1> t = nodes[nk.node].jac.transpose() * a;
    for (int p = 0; p < 3; ++p) reduced[nk.target[p]] += a[p];
    for (int j = 0; j < 4; ++j) reduced[nk.target[3 + j]] += t[j];
  }
  // Node pairs on links: X = T_n^T B T_m with T = [I | jac], summed per
  // pair of links and added to the reduced matrix once per link block.
  link_block_sums_.resize(em.link_blocks_.size());
  for (Eigen::Matrix<double, 7, 7>& sum : link_block_sums_) sum.setZero();
  using Into = EmbeddedNodeLayout::NodePair::Into;
  for (const EmbeddedNodeLayout::NodePair& np : em.node_pairs_) {
    Eigen::Matrix3d b;
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) b(a, c) = value(np.full[3 * a + c]);
    const int rn = em.nodes_[np.n].r, rm = em.nodes_[np.m].r;
    g.segment<3>(rn) -= b * nodes[np.m].c;
    if (np.n != np.m) g.segment<3>(rm) -= b.transpose() * nodes[np.n].c;
    if (np.block < 0) continue;
    Eigen::Matrix<double, 3, 7> bt;
    bt.leftCols<3>() = b;
    bt.rightCols<4>().noalias() = b * nodes[np.m].jac;
    Eigen::Matrix<double, 7, 7> x;
    x.topRows<3>() = bt;
    x.bottomRows<4>().noalias() = nodes[np.n].jac.transpose() * bt;
    Eigen::Matrix<double, 7, 7>& sum = link_block_sums_[np.block];
    switch (np.into) {
      case Into::kAsIs:
        sum += x;
        break;
      case Into::kTransposed:
        sum += x.transpose();
        break;
      case Into::kWithMirror:
        sum += x + x.transpose();
        break;
    }
  }
  for (std::size_t k = 0; k < em.link_blocks_.size(); ++k) {
    const int* target = em.link_blocks_[k].target;
    const double* sum = link_block_sums_[k].data();
    for (int e = 0; e < 49; ++e)
      if (target[e] >= 0) reduced[target[e]] += sum[e];
  }

  // Reduced right-hand side: the kept unknowns' g, plus T_n^T g(r_n).
  Eigen::VectorXd& x = embedded_ordered_;
  for (int p = 0; p < em.size_; ++p) x[em.order_[p]] = g[em.full_of_[p]];
  for (std::size_t i = 0; i < em.nodes_.size(); ++i) {
    const EmbeddedNodeLayout::NodeInfo& node = em.nodes_[i];
    if (node.link == 0) continue;
    const Vector3 gr = g.segment<3>(node.r);
    const Eigen::Matrix<double, 4, 1> t = nodes[i].jac.transpose() * gr;
    for (int p = 0; p < 3; ++p) x[em.order_[em.reduced_of_[node.link_offset + p]]] += gr[p];
    for (int j = 0; j < 4; ++j) x[em.order_[em.reduced_of_[node.link_offset + 3 + j]]] += t[j];
  }

  if (!embedded_ldlt_.FactorizeAssembled()) return false;
  embedded_ldlt_.Solve(x);

  solution_.setZero();
  for (int p = 0; p < em.size_; ++p) solution_[em.full_of_[p]] = x[em.order_[p]];
  for (std::size_t i = 0; i < em.nodes_.size(); ++i) {
    const EmbeddedNodeLayout::NodeInfo& node = em.nodes_[i];
    Vector3 r_dd = nodes[i].c;
    if (node.link > 0) {
      r_dd += solution_.segment<3>(node.link_offset) +
              nodes[i].jac * solution_.segment<4>(node.link_offset + 3);
    }
    solution_.segment<3>(node.r) = r_dd;
  }
  return true;
}

}  // namespace ccsrm::sim::internal
