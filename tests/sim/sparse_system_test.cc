// The sparse solve of the augmented system (sparse_system.h) on the paper's
// arm: the paper model's layout, matrix values assembled the way
// ArmDynamics assembles them (element and link masses from the kernels,
// constraint Jacobians as in FillConstraints) at a bent state, solved and
// compared with a dense LU of the same 1104 x 1104 matrix.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <random>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "kernels/ale_element.h"
#include "kernels/rigid_body.h"
#include "sparse_system.h"

namespace ccsrm::sim::internal {
namespace {

const std::string kPaper = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
// The multiplier diagonal of an active row (kRegularization in dynamics.cc).
constexpr double kDelta = 1e-10;

// The state: joints bent by up to ~9 degrees about both axes, links and
// cable nodes where the kinematics puts them, material coordinates as in
// ArmDynamics::InitialState, a little velocity everywhere.
struct BentState {
  Eigen::VectorXd q, qd;
};

BentState MakeBentState(const ArmModel& model, const Config& config) {
  JointAngles angles(model.num_joints());
  for (int j = 0; j < model.num_joints(); ++j)
    angles[j] = Eigen::Vector2d(0.15 * std::sin(0.7 * j + 0.3), 0.1 * std::cos(1.1 * j));
  const std::vector<LinkPose> poses = ForwardKinematics(model, angles);
  BentState state;
  state.q.setZero(model.num_coordinates());
  state.qd.setZero(model.num_coordinates());
  for (int i = 1; i <= model.num_links(); ++i) {
    const int o = model.link_offset(i);
    const Eigen::Quaterniond e(poses[i - 1].R_WB);
    state.q.segment<3>(o) = poses[i - 1].p_WB;
    state.q.segment<4>(o + 3) << e.w(), e.x(), e.y(), e.z();
  }
  const double eps0 = config.parameters.T_d0 /
                      (config.arm.driving.youngs_modulus_pa * config.arm.driving.cross_section_m2);
  for (int c = 0; c < model.num_cables(); ++c) {
    double s = 0.0;
    Eigen::Vector3d previous;
    for (int k = 0; k < static_cast<int>(model.cables()[c].nodes.size()); ++k) {
      const Eigen::Vector3d p = CableNodePosition(model, c, k, poses);
      if (k > 0) s += (p - previous).norm() / std::sqrt(1.0 + 2.0 * eps0);
      state.q.segment<3>(model.node_offset(c, k)) = p;
      state.q[model.node_offset(c, k) + 3] = s;
      previous = p;
    }
  }
  for (int k = 0; k < model.num_coordinates(); ++k) state.qd[k] = 1e-3 * ((k % 7) - 3);
  return state;
}

// The Jacobian row values of every constraint, in the order of
// SparseLayout::rows() and of each row's columns (as FillConstraints).
std::vector<std::vector<double>> ConstraintJacobian(const ArmModel& model,
                                                    const Eigen::VectorXd& q) {
  auto quaternion = [&](int link) {
    return Eigen::Vector4d(q.segment<4>(model.link_offset(link) + 3));
  };
  std::vector<std::vector<double>> rows;
  for (int c = 0; c < model.num_cables(); ++c) {
    for (const CableNodeModel& node : model.cables()[c].nodes) {
      Eigen::Matrix<double, 3, 4> jac = Eigen::Matrix<double, 3, 4>::Zero();
      if (node.link > 0) jac = PointJacobian(quaternion(node.link), node.p_LN);
      for (int a = 0; a < 3; ++a) {
        std::vector<double> row{1.0};
        if (node.link > 0) {
          row.push_back(-1.0);
          for (int k = 0; k < 4; ++k) row.push_back(-jac(a, k));
        }
        rows.push_back(row);
      }
      rows.push_back({1.0});
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const Eigen::Vector4d e = quaternion(i);
    rows.push_back({2 * e[0], 2 * e[1], 2 * e[2], 2 * e[3]});
  }
  for (int j = 1; j <= model.num_joints(); ++j) {
    const Eigen::Matrix<double, 3, 4> jc = PointJacobian(quaternion(j), model.p_child_joint(j));
    for (int a = 0; a < 3; ++a) {
      std::vector<double> row;
      if (j > 1) {
        const Eigen::Matrix<double, 3, 4> jp =
            PointJacobian(quaternion(j - 1), model.p_parent_joint(j));
        row.push_back(1.0);
        for (int k = 0; k < 4; ++k) row.push_back(jp(a, k));
      }
      row.push_back(-1.0);
      for (int k = 0; k < 4; ++k) row.push_back(-jc(a, k));
      rows.push_back(row);
    }
    const Eigen::Vector3d x_parent =
        j > 1
            ? Eigen::Vector3d(RotationFromQuaternion(quaternion(j - 1)) * Eigen::Vector3d::UnitX())
            : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d y_child =
        RotationFromQuaternion(quaternion(j)) * Eigen::Vector3d::UnitY();
    std::vector<double> row;
    if (j > 1) {
      const Eigen::Matrix<double, 1, 4> g =
          y_child.transpose() * PointJacobian(quaternion(j - 1), Eigen::Vector3d::UnitX());
      for (int k = 0; k < 4; ++k) row.push_back(g[k]);
    }
    const Eigen::Matrix<double, 1, 4> g =
        x_parent.transpose() * PointJacobian(quaternion(j), Eigen::Vector3d::UnitY());
    for (int k = 0; k < 4; ++k) row.push_back(g[k]);
    rows.push_back(row);
  }
  return rows;
}

// Fills `system` as ArmDynamics::Evaluate does (element and link masses,
// connecting-pair terms, Phi_q^T Phi_q, the coupling and the multiplier
// diagonal: -delta, or -1 on the stick rows switched off), with a random
// right-hand side. Every other hole node slips, or with `every_hole_slips`
// all of them (as under the smoothed treatment).
// With `skip_node_rows`, the cable nodes' position rows are left out, as
// ArmDynamics leaves them out for the embedded system.
bool SwitchedOff(const ConstraintRowLayout& row, bool every_hole_slips) {
  return row.hole >= 0 && (every_hole_slips || row.hole % 2 == 1);
}

void Assemble(const ArmModel& model, const Config& config, const BentState& state,
              AugmentedSystem* system, bool skip_node_rows = false, bool every_hole_slips = false) {
  const SparseLayout& layout = model.sparse_layout();
  const int n = layout.num_coordinates();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  system->Clear();
  double* values = system->values();

  AleElementParams ale;
  ale.linear_density_kgpm = config.arm.driving.density_kgpm3 * config.arm.driving.cross_section_m2;
  ale.axial_stiffness_n =
      config.arm.driving.youngs_modulus_pa * config.arm.driving.cross_section_m2;
  ale.rayleigh_beta_s = config.parameters.beta;
  ale.smoothing_step_s = config.solver.smoothing_step_s;
  int element = 0;
  for (int c = 0; c < model.num_cables(); ++c) {
    for (int e = 0; e < model.cables()[c].num_elements(); ++e, ++element) {
      const int o1 = model.node_offset(c, e), o2 = model.node_offset(c, e + 1);
      const int cols[8] = {o1, o1 + 1, o1 + 2, o2, o2 + 1, o2 + 2, o1 + 3, o2 + 3};
      Vector8d qe, qde;
      for (int k = 0; k < 8; ++k) {
        qe[k] = state.q[cols[k]];
        qde[k] = state.qd[cols[k]];
      }
      const AleElementTerms terms = EvaluateAleElement(ale, qe, qde);
      AddSymmetricBlock(terms.mass + terms.elastic_mass, layout.element_block(element), values);
    }
  }
  for (int i = 1; i <= model.num_links(); ++i) {
    const LinkModel& link = model.link(i);
    const Eigen::Matrix4d me = QuaternionMass(state.q.segment<4>(model.link_offset(i) + 3),
                                              link.inertia_kgm2.asDiagonal().toDenseMatrix());
    const int* index = layout.link_block(i);
    for (int a = 0; a < 3; ++a) values[index[a]] += link.mass_kg;
    AddSymmetricBlock(me, index + 3, values);
  }
  // The connecting pairs' smoothed stiffness on their links' quaternions:
  // a small symmetric positive semi-definite block (rank 2, as a spring
  // between joint angles would add).
  for (std::size_t p = 0; p < model.connecting_pairs().size(); ++p) {
    const int size = 4 * static_cast<int>(layout.pair_links(static_cast<int>(p)).size());
    Eigen::MatrixXd g(2, size);
    for (int k = 0; k < g.size(); ++k) g(k) = uniform(random);
    const Eigen::MatrixXd block = 1e-4 * g.transpose() * g;
    AddSymmetricBlock(block, layout.pair_block(static_cast<int>(p)), values);
  }

  Eigen::VectorXd& rhs = system->rhs();
  for (int k = 0; k < rhs.size(); ++k) rhs[k] = uniform(random);
  const std::vector<std::vector<double>> jacobian = ConstraintJacobian(model, state.q);
  ASSERT_EQ(jacobian.size(), layout.rows().size());
  for (int r = 0; r < layout.num_constraints(); ++r) {
    const ConstraintRowLayout& row = layout.rows()[r];
    ASSERT_EQ(static_cast<int>(jacobian[r].size()), row.count);
    if (skip_node_rows && row.node >= 0) continue;
    if (SwitchedOff(row, every_hole_slips)) {
      values[layout.row_diagonal(r)] = -1.0;
      rhs[n + r] = 0.0;
      continue;
    }
    values[layout.row_diagonal(r)] = -kDelta;
    const int* block = layout.row_block(r);
    const int* coupling = layout.row_coupling(r);
    for (int a = 0, k = 0; a < row.count; ++a) {
      values[coupling[a]] += jacobian[r][a];
      for (int b = 0; b <= a; ++b) values[block[k++]] += jacobian[r][a] * jacobian[r][b];
    }
  }
}

// The assembled matrix in the model's order (both triangles; the layout
// stores each symmetric pair once).
Eigen::SparseMatrix<double> ModelOrderMatrix(const SparseLayout& layout,
                                             const AugmentedSystem& system) {
  const Eigen::SparseMatrix<double>& pattern = layout.pattern();
  std::vector<int> model_of(layout.order().size());
  for (std::size_t k = 0; k < model_of.size(); ++k)
    model_of[layout.order()[k]] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> entries;
  const double* values = const_cast<AugmentedSystem&>(system).values();
  for (int j = 0; j < pattern.outerSize(); ++j) {
    for (int k = pattern.outerIndexPtr()[j]; k < pattern.outerIndexPtr()[j + 1]; ++k) {
      const int i = pattern.innerIndexPtr()[k];
      entries.emplace_back(model_of[i], model_of[j], values[k]);
      if (i != j) entries.emplace_back(model_of[j], model_of[i], values[k]);
    }
  }
  Eigen::SparseMatrix<double> a(pattern.rows(), pattern.cols());
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

double RelativeError(const Eigen::VectorXd& x, const Eigen::VectorXd& reference) {
  return (x - reference).norm() / reference.norm();
}

class SparseSystemTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = LoadConfig(kPaper);
    model_ = std::make_unique<ArmModel>(config_.arm);
    system_ = std::make_unique<AugmentedSystem>(model_->sparse_layout());
    Assemble(*model_, config_, MakeBentState(*model_, config_), system_.get());
    a_ = ModelOrderMatrix(model_->sparse_layout(), *system_);
    b_ = system_->rhs();
    dense_ = Eigen::MatrixXd(a_).partialPivLu().solve(b_);
  }

  Config config_;
  std::unique_ptr<ArmModel> model_;
  std::unique_ptr<AugmentedSystem> system_;
  Eigen::SparseMatrix<double> a_;
  Eigen::VectorXd b_, dense_;
};

TEST_F(SparseSystemTest, SolvesThePaperArmToDenseAccuracy) {
  const SparseLayout& layout = model_->sparse_layout();
  const int n = layout.num_coordinates();
  ASSERT_EQ(n, 564);
  ASSERT_EQ(layout.num_constraints(), 540);
  const SupernodalStructure& f = layout.factorisation();
  std::printf("factor: %d supernodes (widest %d), nnz(L) %zu, %.3g multiply-adds\n",
              f.num_supernodes(), f.largest_supernode(), f.factor_nonzeros(), f.factor_flops());

  ASSERT_TRUE(system_->Solve());
  const Eigen::VectorXd& x = system_->solution();
  // Backward error (normwise, infinity norms): a backward-stable solve
  // gives a small multiple of the unit roundoff 1.1e-16; 1e-14 leaves room
  // for the growth of a static-pivot factorisation and nothing more.
  const double backward =
      (a_ * x - b_).lpNorm<Eigen::Infinity>() /
      (Eigen::MatrixXd(a_).cwiseAbs().rowwise().sum().maxCoeff() * x.lpNorm<Eigen::Infinity>() +
       b_.lpNorm<Eigen::Infinity>());
  // Forward error against the dense partial-pivoting LU. The dense solve's
  // own error at this conditioning is ~1e-14; the old scalar-AMD
  // SimplicialLDLT, pivoting on -1e-10, was off by ~3e-5 on q_dd (checked
  // below), so 1e-10 separates the two by orders of magnitude either way.
  const double forward_q = RelativeError(x.head(n), dense_.head(n));
  const double forward_lambda = RelativeError(x.tail(x.size() - n), dense_.tail(x.size() - n));
  std::printf("supernodal: backward error %.2e, forward error q_dd %.2e, lambda %.2e\n", backward,
              forward_q, forward_lambda);
  EXPECT_LT(backward, 1e-14);
  EXPECT_LT(forward_q, 1e-10);
  EXPECT_LT(forward_lambda, 1e-10);
}

// The bound above must be one that the previous solver (Eigen's
// SimplicialLDLT on a scalar AMD order of the same matrix) fails, or the
// test would not tell the two apart.
TEST_F(SparseSystemTest, ScalarAmdSimplicialLdltFailsTheForwardBound) {
  const int n = model_->sparse_layout().num_coordinates();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> old(a_);
  ASSERT_EQ(old.info(), Eigen::Success);
  const Eigen::VectorXd x = old.solve(b_);
  const double forward_q = RelativeError(x.head(n), dense_.head(n));
  std::printf("scalar-AMD SimplicialLDLT: forward error q_dd %.2e\n", forward_q);
  const Eigen::SparseMatrix<double> l = old.matrixL();
  std::printf("scalar-AMD SimplicialLDLT: nnz(L) %ld\n", static_cast<long>(l.nonZeros()));
  EXPECT_GT(forward_q, 1e-10);
}

// Writing every cable node's position as a function of its link's pose
// (EmbeddedNodeLayout) solves the same equations: the right-hand side is
// made consistent (F - Phi_q^T b over the coordinates, -b on the rows, as
// AddConstraints builds it), and the embedded system, assembled without
// the node rows, gets their b through NodeEmbedding's c = -b. With the hole
// nodes' stick rows left out, every hole node slips (their lambda is 0).
void ExpectEmbeddedSolvesTheSameEquations(const ArmModel& model, const Config& config,
                                          HoleStickRows hole_rows) {
  const SparseLayout& layout = model.sparse_layout();
  const int n = layout.num_coordinates(), m = layout.num_constraints();
  const bool every_hole_slips = hole_rows == HoleStickRows::kLeftOut;
  const BentState state = MakeBentState(model, config);
  AugmentedSystem full(layout);
  Assemble(model, config, state, &full, /*skip_node_rows=*/false, every_hole_slips);
  AugmentedSystem embedded(layout, hole_rows);
  Assemble(model, config, state, &embedded, /*skip_node_rows=*/true, every_hole_slips);
  const EmbeddedNodeLayout& em = layout.embedded(hole_rows);
  std::printf("embedded (hole rows %s): %d unknowns (full %d), nnz(L) %zu, %.3g multiply-adds\n",
              every_hole_slips ? "left out" : "kept", em.size(), n + m,
              em.factorisation().factor_nonzeros(), em.factorisation().factor_flops());
  // 120 nodes' 3 coordinates and 3 rows; left out, the 108 hole nodes' rows.
  EXPECT_EQ(em.size(), n + m - 720 - (every_hole_slips ? 108 : 0));

  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd force(n), b(m);
  for (int k = 0; k < n; ++k) force[k] = uniform(random);
  for (int r = 0; r < m; ++r) b[r] = uniform(random);
  const std::vector<std::vector<double>> jacobian = ConstraintJacobian(model, state.q);
  std::vector<NodeEmbedding> nodes(layout.num_cable_nodes());
  Eigen::VectorXd full_rhs = Eigen::VectorXd::Zero(n + m);
  full_rhs.head(n) = force;
  Eigen::VectorXd& embedded_rhs = embedded.rhs();
  embedded_rhs = full_rhs;
  for (int r = 0; r < m; ++r) {
    const ConstraintRowLayout& row = layout.rows()[r];
    if (SwitchedOff(row, every_hole_slips)) continue;  // lambda = 0
    if (row.node >= 0) {
      // Rows of a node come in axis order; their Jacobian is [1, -1, -jac].
      NodeEmbedding& node = nodes[row.node];
      const int axis = (r > 0 && layout.rows()[r - 1].node == row.node)
                           ? ((r > 1 && layout.rows()[r - 2].node == row.node) ? 2 : 1)
                           : 0;
      node.c[axis] = -b[r];
      if (row.count > 1)
        for (int k = 0; k < 4; ++k) node.jac(axis, k) = -jacobian[r][2 + k];
    }
    full_rhs[n + r] = -b[r];
    for (int a = 0; a < row.count; ++a) full_rhs[row.cols[a]] -= jacobian[r][a] * b[r];
    if (row.node >= 0) continue;
    embedded_rhs[n + r] = -b[r];
    for (int a = 0; a < row.count; ++a) embedded_rhs[row.cols[a]] -= jacobian[r][a] * b[r];
  }
  // The reference: the full system with the node rows exact (no -delta on
  // their diagonal, which the embedding does not have), by dense LU.
  Eigen::MatrixXd exact(ModelOrderMatrix(layout, full));
  for (int r = 0; r < m; ++r)
    if (layout.rows()[r].node >= 0) exact(n + r, n + r) = 0.0;
  const Eigen::VectorXd reference = exact.partialPivLu().solve(full_rhs);
  ASSERT_TRUE(embedded.SolveEmbedded(nodes));
  const Eigen::VectorXd& x = embedded.solution();
  // The same equations, so the same answer to the dense solve's own error
  // (~1e-14 at this conditioning): 1e-12. With -delta on the node rows the
  // difference is O(delta lambda), ~1e-9 here.
  const double forward_q = RelativeError(x.head(n), reference.head(n));
  double forward_lambda = 0.0, reference_lambda = 0.0;
  for (int r = 0; r < m; ++r) {
    if (layout.rows()[r].node >= 0) continue;
    forward_lambda += std::pow(x[n + r] - reference[n + r], 2);
    reference_lambda += std::pow(reference[n + r], 2);
  }
  forward_lambda = std::sqrt(forward_lambda / reference_lambda);
  std::printf("embedded against the full dense solve: q_dd %.2e, lambda %.2e\n", forward_q,
              forward_lambda);
  EXPECT_LT(forward_q, 1e-12);
  EXPECT_LT(forward_lambda, 1e-12);
  // Each is the cheaper factorisation, or it has no reason to exist.
  const double cheaper_than =
      every_hole_slips ? layout.embedded(HoleStickRows::kKept).factorisation().factor_flops()
                       : layout.factorisation().factor_flops();
  EXPECT_LT(em.factorisation().factor_flops(), cheaper_than);
}

TEST_F(SparseSystemTest, EmbeddedNodesSolveTheSameEquations) {
  ExpectEmbeddedSolvesTheSameEquations(*model_, config_, HoleStickRows::kKept);
}

TEST_F(SparseSystemTest, EmbeddedNodesWithoutHoleStickRowsSolveTheSameEquationsWhenEveryHoleSlips) {
  ExpectEmbeddedSolvesTheSameEquations(*model_, config_, HoleStickRows::kLeftOut);
}

}  // namespace
}  // namespace ccsrm::sim::internal
