#pragma once
// The index bookkeeping of the arm's sparse augmented system (eqs. 62-64),
//   [ M + Phi_q^T Phi_q   Phi_q^T ] [ q_dd   ]   [ F - Phi_q^T b ]
//   [ Phi_q               D       ] [ lambda ] = [ -b            ],
// kept apart from the physics: SparseLayout is the topology (which
// coordinates each constraint row, element, link and connecting pair
// touches), the sparsity pattern, its elimination order and the symbolic
// supernodal factorisation, built once per ArmModel and shared read-only by
// every run; AugmentedSystem is one run's matrix values, right-hand side
// and numeric factorisation over it. EmbeddedNodeLayout is the same system
// with the cable nodes' positions substituted (solver.embed_cable_nodes).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <utility>
#include <vector>

#include "supernodal_ldlt.h"

namespace ccsrm::sim {
class ArmModel;
}

namespace ccsrm::sim::internal {

class SparseLayout;

// Adds the lower triangle (b <= a) of the symmetric matrix `block` at the
// packed positions `index` of one of SparseLayout's block tables: each
// symmetric pair is stored once.
template <typename Derived>
void AddSymmetricBlock(const Eigen::MatrixBase<Derived>& block, const int* index, double* values) {
  int k = 0;
  for (int a = 0; a < block.rows(); ++a)
    for (int b = 0; b <= a; ++b) values[index[k++]] += block(a, b);
}

// A hole node of a driving cable: Eulerian, free material coordinate.
struct HoleNodeRef {
  int cable = 0;
  int node = 0;  // index within the cable (1 .. nodes-2)
};

// Columns of one constraint row (at most 14: a joint orientation row
// touches two quaternions and nothing else; a joint position row a position
// axis and a quaternion of each link).
struct ConstraintRowLayout {
  static constexpr int kMaxColumns = 14;
  int count = 0;
  int cols[kMaxColumns];
  int hole = -1;  // the material row of hole node `hole` (its stick constraint), else -1
  int node = -1;  // a position row of cable node `node` (numbered over all cables), else -1
};

// A cable node's position rows (eq. 7) say r = r_link + A(e) p_LN (or a
// fixed point for a node on the ground), so its acceleration is an affine
// function of its link's: r_dd = T q_dd(link) + c with T = [I | jac] over
// the link's (position, quaternion) and c = -b, b the rows' Baumgarte
// right-hand side. Filled per evaluation for every cable node.
struct NodeEmbedding {
  Eigen::Matrix<double, 3, 4> jac = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
};

// Whether a system keeps the hole nodes' stick constraints. Only the events
// treatment of hole friction ever switches one on; under the smoothed
// treatment they are always off (lambda = 0), and leaving them out takes a
// quarter off the embedded system's factorisation.
enum class HoleStickRows { kKept, kLeftOut };

// The augmented system with every cable node's position (and its 3 rows)
// eliminated by NodeEmbedding: unknowns the material coordinates, the links'
// coordinates and the other rows (docs/model-notes.md, row 23), the hole
// nodes' stick rows only with HoleStickRows::kKept. Built from a
// SparseLayout; the reduced matrix is assembled from the full one's values.
class EmbeddedNodeLayout {
 public:
  EmbeddedNodeLayout(const ArmModel& model, const SparseLayout& full, HoleStickRows hole_rows);

  int size() const { return size_; }
  const SupernodalStructure& factorisation() const { return *factorisation_; }

 private:
  friend class AugmentedSystem;
  struct NodeInfo {
    int r = 0;     // model index of its x coordinate
    int link = 0;  // 0: on the ground
    int link_offset = 0;
  };
  // Full entries A[r_n a, k] (a = 0..2, -1 where not stored) of a node and a
  // kept unknown k; where T_n^T A[r_n, k] lands in the factor's storage
  // (-1 for a node on the ground, which only moves the right-hand side).
  struct NodeKept {
    int node = 0;
    int kept = 0;  // full model index
    int full[3];
    int target[7];
  };
  // Full entries A[r_n a, r_m b] of two nodes n <= m (row-major 3 x 3).
  // With both nodes on links, X = T_n^T B T_m (7 x 7) is summed into the
  // block of their two links (LinkBlock `block`): as X, as X^T (the block's
  // rows are the other node's link), or as X + X^T (two nodes of one link:
  // the pair and its mirror).
  struct NodePair {
    enum class Into : char { kAsIs, kTransposed, kWithMirror };
    int n = 0, m = 0;
    int block = -1;  // -1: a node on the ground (only the right-hand side)
    Into into = Into::kAsIs;
    int full[9];
  };
  // The 7 x 7 block of the reduced matrix over links (lo, hi), lo <= hi,
  // summed over node pairs first and then added once: entry (p, q),
  // column-major, goes to storage()[target[p + 7q]] of the factor (-1:
  // the upper triangle of a diagonal block).
  struct LinkBlock {
    int target[49];
  };

  int size_ = 0;
  int full_size_ = 0;
  std::vector<NodeInfo> nodes_;
  std::vector<int> reduced_of_;            // full unknown -> reduced unknown, -1 if eliminated
  std::vector<int> full_of_;               // reduced unknown -> full unknown
  std::vector<int> order_;                 // reduced unknown -> position in elimination order
  std::vector<std::pair<int, int>> copy_;  // (full value index, factor storage index)
  std::vector<NodeKept> node_kept_;
  std::vector<NodePair> node_pairs_;
  std::vector<LinkBlock> link_blocks_;
  std::unique_ptr<const SupernodalStructure> factorisation_;
};

class SparseLayout {
 public:
  // Rows, in the order AddConstraints fills them: per cable node 3 position
  // rows and 1 material row (eqs. 7 and the stick constraint), per link the
  // unit quaternion (eq. 35), per joint 3 position rows and 1 orientation row
  // (eqs. 36-37).
  explicit SparseLayout(const ArmModel& model);

  int num_coordinates() const { return n_; }
  int num_constraints() const { return m_; }
  const std::vector<HoleNodeRef>& holes() const { return holes_; }
  const std::vector<ConstraintRowLayout>& rows() const { return rows_; }
  // Links whose quaternion rates connecting pair p's joint rates involve
  // (joint_i - 1, joint_i, joint_i + 1, those >= 1).
  const std::vector<int>& pair_links(int p) const { return pair_links_[p]; }

  // Positions in the matrix's value array (model order in, storage out),
  // which holds each symmetric pair of entries once. A block over a list of
  // coordinates is its packed lower triangle, (a, b) for b <= a row by row
  // (AddSymmetricBlock): per element the block over (r1, r2, s1, s2) (36);
  // per link its 3 diagonal translational entries, then its quaternion block
  // (10); per connecting pair the block over its links' quaternions; per row
  // r its (n + r, col) entries, the block of Phi_q^T Phi_q over its columns,
  // and its (n + r, n + r) diagonal.
  const int* element_block(int element) const { return &element_index_[36 * element]; }
  const int* link_block(int link) const { return &link_index_[13 * (link - 1)]; }
  const int* pair_block(int p) const { return pair_index_[p].data(); }
  const int* row_coupling(int r) const { return &row_kkt_index_[row_kkt_offset_[r]]; }
  const int* row_block(int r) const { return &row_pair_index_[row_pair_offset_[r]]; }
  int row_diagonal(int r) const { return row_diag_index_[r]; }
  // The (s, s) entry of hole node h (its material coordinate).
  int hole_material_diagonal(int h) const { return hole_index_[h]; }

  // The pattern with zero values, its lower triangle stored in the
  // elimination order (see InterleavedBlockOrder), and the position of model
  // unknown k in it.
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  const std::vector<int>& order() const { return order_; }
  // The symbolic factorisation of the pattern in that order.
  const SupernodalStructure& factorisation() const { return *factorisation_; }
  // The same system with the cable nodes' positions eliminated.
  const EmbeddedNodeLayout& embedded(HoleStickRows hole_rows) const {
    return hole_rows == HoleStickRows::kKept ? *embedded_ : *embedded_without_holes_;
  }
  int num_cable_nodes() const { return num_cable_nodes_; }

  // Elimination order for the unknowns of `members` (blocks, each listing
  // coordinates first, then rows; every unknown in exactly one block):
  // blocks ordered by AMD on the block graph of `pattern`, each laid out
  // whole. Returns, per unknown, its position.
  static std::vector<int> BlockOrder(int size, const std::vector<std::vector<int>>& members,
                                     const std::vector<Eigen::Triplet<double>>& pattern);

 private:
  friend class EmbeddedNodeLayout;
  // The stored entry of (model_row, model_col), either way round.
  int Index(int model_row, int model_col) const;
  // Appends the positions of the packed lower triangle over `cols`.
  void PackedLowerIndex(const int* cols, int count, std::vector<int>* index) const;
  std::vector<std::vector<int>> InterleavedBlocks(const ArmModel& model) const;

  int n_ = 0;
  int m_ = 0;
  std::vector<HoleNodeRef> holes_;
  std::vector<ConstraintRowLayout> rows_;
  std::vector<int> row_owner_;  // per row, a coordinate of the block it is eliminated with
  std::vector<std::vector<int>> pair_links_;
  Eigen::SparseMatrix<double> pattern_;
  std::vector<int> order_;
  std::vector<int> element_index_;
  std::vector<int> link_index_;
  std::vector<std::vector<int>> pair_index_;
  std::vector<int> row_kkt_index_, row_kkt_offset_;
  std::vector<int> row_pair_index_, row_pair_offset_;
  std::vector<int> row_diag_index_;
  std::vector<int> hole_index_;
  std::unique_ptr<const SupernodalStructure> factorisation_;
  std::unique_ptr<const EmbeddedNodeLayout> embedded_;
  std::unique_ptr<const EmbeddedNodeLayout> embedded_without_holes_;
  int num_cable_nodes_ = 0;
};

// One run's augmented system over a shared layout. The matrix is stored
// (its lower triangle) in the layout's elimination order, so that each
// factorisation reads it in place instead of permuting a copy; the
// right-hand side and the solution are in the model's order.
class AugmentedSystem {
 public:
  // `hole_rows`: which embedded system SolveEmbedded uses; kLeftOut only
  // where no hole node's stick row is ever on.
  explicit AugmentedSystem(const SparseLayout& layout,
                           HoleStickRows hole_rows = HoleStickRows::kKept);

  // Zeroes the matrix values and the right-hand side.
  void Clear();
  // The matrix values, each symmetric pair once, at the positions of the
  // layout's tables.
  double* values() { return matrix_.valuePtr(); }
  Eigen::VectorXd& rhs() { return rhs_; }

  // Factorises and solves; false when the matrix is singular. The solution
  // (q_dd, then lambda) is in the model's order.
  bool Solve();
  // The same solution through the system with every cable node's position
  // eliminated (`nodes`, one per cable node): the matrix and right-hand
  // side must have been assembled without the nodes' position rows. Their
  // multipliers are not computed (set to 0), nor, with
  // HoleStickRows::kLeftOut, the hole nodes' (0, as they are off).
  bool SolveEmbedded(const std::vector<NodeEmbedding>& nodes);
  const Eigen::VectorXd& solution() const { return solution_; }

 private:
  const SparseLayout& layout_;
  const EmbeddedNodeLayout& embedded_;
  Eigen::SparseMatrix<double> matrix_;
  SupernodalLdlt ldlt_;
  Eigen::VectorXd rhs_, solution_;
  Eigen::VectorXd ordered_;  // right-hand side, then solution, in elimination order
  // The embedded system's factorisation (its matrix assembled in the
  // factor's storage) and vectors.
  SupernodalLdlt embedded_ldlt_;
  Eigen::VectorXd reduced_rhs_;  // g = rhs - A[:, r] c, over the full unknowns
  std::vector<Eigen::Matrix<double, 7, 7>> link_block_sums_;  // per LinkBlock
  Eigen::VectorXd embedded_ordered_;
};

}  // namespace ccsrm::sim::internal
