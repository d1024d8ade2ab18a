#pragma once
// The index bookkeeping of the arm's sparse augmented system (eqs. 62-64),
//   [ M + Phi_q^T Phi_q   Phi_q^T ] [ q_dd   ]   [ F - Phi_q^T b ]
//   [ Phi_q               D       ] [ lambda ] = [ -b            ],
// kept apart from the physics: SparseLayout is the topology (which
// coordinates each constraint row, element, link and connecting pair
// touches), the sparsity pattern, its elimination order and the symbolic
// supernodal factorisation, built once per ArmModel and shared read-only by
// every run; AugmentedSystem is one run's matrix values, right-hand side
// and numeric factorisation over it.
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "supernodal_ldlt.h"

namespace ccsrm::sim {
class ArmModel;
}

namespace ccsrm::sim::internal {

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

  // Positions in the matrix's value array (model order in, storage out):
  // per element its 8 x 8 block over (r1, r2, s1, s2); per link 3 diagonal
  // translational entries then its 4 x 4 quaternion block; per connecting
  // pair the square block over its links' quaternions; per row r its
  // (n + r, col) and (col, n + r) entries, its count x count block of
  // Phi_q^T Phi_q, and its (n + r, n + r) diagonal.
  const int* element_block(int element) const { return &element_index_[64 * element]; }
  const int* link_block(int link) const { return &link_index_[19 * (link - 1)]; }
  const int* pair_block(int p) const { return pair_index_[p].data(); }
  const int* row_coupling(int r) const { return &row_kkt_index_[row_kkt_offset_[r]]; }
  const int* row_block(int r) const { return &row_pair_index_[row_pair_offset_[r]]; }
  int row_diagonal(int r) const { return row_diag_index_[r]; }
  // The (s, s) entry of hole node h (its material coordinate).
  int hole_material_diagonal(int h) const { return hole_index_[h]; }

  // The pattern with zero values, stored in the elimination order (see
  // InterleavedBlockOrder), and the position of model unknown k in it.
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  const std::vector<int>& order() const { return order_; }
  // The symbolic factorisation of the pattern in that order.
  const SupernodalStructure& factorisation() const { return *factorisation_; }

 private:
  int Index(int model_row, int model_col) const;
  std::vector<int> InterleavedBlockOrder(const ArmModel& model,
                                         const std::vector<Eigen::Triplet<double>>& pattern) const;

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
};

// One run's augmented system over a shared layout. The matrix is stored
// (both triangles) in the layout's elimination order, so that each
// factorisation reads it in place instead of permuting a copy; the
// right-hand side and the solution are in the model's order.
class AugmentedSystem {
 public:
  explicit AugmentedSystem(const SparseLayout& layout);

  // Zeroes the matrix values and the right-hand side.
  void Clear();
  double* values() { return matrix_.valuePtr(); }
  Eigen::VectorXd& rhs() { return rhs_; }

  // Factorises and solves; false when the matrix is singular. The solution
  // (q_dd, then lambda) is in the model's order.
  bool Solve();
  const Eigen::VectorXd& solution() const { return solution_; }

 private:
  const SparseLayout& layout_;
  Eigen::SparseMatrix<double> matrix_;
  SupernodalLdlt ldlt_;
  Eigen::VectorXd rhs_, solution_;
  Eigen::VectorXd ordered_;  // right-hand side, then solution, in elimination order
};

}  // namespace ccsrm::sim::internal
