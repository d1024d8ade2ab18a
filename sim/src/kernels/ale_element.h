#pragma once
// Two-node ALE cable element (paper eqs. 1-6, 13, 17-20).
//
// Element coordinates q = [r1 (3), r2 (3), s1, s2] (8): world positions of the
// two nodes [m] and their material coordinates [m, unstretched arc length].
// Linear interpolation in the local coordinate zeta in [-1, 1] (eq. 3), so
//   r'  = dr/ds = (r2 - r1) / (s2 - s1)           constant along the element,
//   eps = (|r'|^2 - 1) / 2                        Green strain (eq. 6), constant,
//   N(zeta) = [N1 I3, N2 I3, -N1 r', -N2 r']      eq. 4, N1 = (1 - zeta)/2,
//                                                 N2 = (1 + zeta)/2.
// Because r' and eps are constant, every integral of eq. 6 and eq. 20 has a
// closed form; this file evaluates those closed forms (the tests check them
// against Gauss quadrature of the paper's integrands).
//
// Sign convention: every force returned here is "right-hand side" signed, so
// the element contributes
//   (M + M_elastic) q'' = ale_inertia_force + elastic_force + (external) ,
// i.e. ale_inertia_force = -Q_p and elastic_force = -Q'_e of eq. 19.
#include <Eigen/Core>

namespace ccsrm::sim::internal {

using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix8d = Eigen::Matrix<double, 8, 8>;
using RowVector8d = Eigen::Matrix<double, 1, 8>;

// Material and model-smoothing parameters of one cable element.
struct AleElementParams {
  double linear_density_kgpm = 0.0;  // rho A [kg/m]
  double axial_stiffness_n = 0.0;    // E A [N]
  double rayleigh_beta_s = 0.0;      // beta [s] (eq. 6)
  double smoothing_step_s = 0.0;     // h [s] (eqs. 14-20); 0 switches smoothing off
};

// Everything the assembly needs from one element at one state.
struct AleElementTerms {
  Matrix8d mass;                   // M_ele of eq. 6 [kg] (r' is dimensionless)
  Matrix8d elastic_mass;           // M_elastic of eq. 20 (zero when h = 0)
  Vector8d ale_inertia_force;      // -Q_p of eq. 6 [N]
  Vector8d elastic_force;          // -Q'_e of eq. 20 (= -Q_e of eq. 6 when h = 0) [N]
  RowVector8d strain_jacobian;     // eps_q = d eps / d q [1/m]
  double strain = 0.0;             // eps (eq. 6) [1]
  double strain_rate = 0.0;        // eps_dot = eps_q q_dot [1/s]
  double strain_accel_bias = 0.0;  // eps_dot_q q_dot = q_dot^T eps_qq q_dot [1/s^2]
  double tension = 0.0;            // T = EA (k eps + beta eps_dot) (eq. 13) [N]
  double kinetic_energy = 0.0;     // q_dot^T M_ele q_dot / 2 [J]
  bool taut = false;               // k of eq. 6: eps > 0
};

// Evaluates the element (eqs. 4, 6, 13, 17-20) in closed form.
//
// Precondition (checked, aborts): s2 - s1 > 0. A caller that can meet a
// collapsed element during a diverging run must test Δs itself first and
// report the divergence.
//
// Notes:
//  - k (tension only) multiplies the elastic strain term only; the Rayleigh
//    term beta eps_dot acts on slack elements too, exactly as eqs. 6 and 13
//    are written (so `tension` can be negative for a slack element that is
//    being stretched or compressed quickly).
//  - eq. 20 of the paper prints eps_dot_q^T in front of Q'_e; substituting
//    eq. 18 into eq. 17 gives eps_q^T, which is what is used here.
AleElementTerms EvaluateAleElement(const AleElementParams& params, const Vector8d& q,
                                   const Vector8d& q_dot);

// Elastic strain energy U = EA k eps^2 Δs / 2 [J] (the potential of the k eps
// part of eq. 13 over the unstretched length Δs). Precondition: Δs > 0.
double AleStrainEnergy(const AleElementParams& params, const Vector8d& q);

// Kinetic energy T = q_dot^T M_ele q_dot / 2 = (rho A / 2) ∫ |r_dot|^2 ds [J].
// Precondition: Δs > 0.
double AleKineticEnergy(const AleElementParams& params, const Vector8d& q, const Vector8d& q_dot);

// The shape matrix N(zeta) of eq. 4 (3 x 8), exposed for quadrature checks and
// for mapping a point force into element coordinates. Precondition: Δs > 0.
Eigen::Matrix<double, 3, 8> AleShapeMatrix(const Vector8d& q, double zeta);

}  // namespace ccsrm::sim::internal
