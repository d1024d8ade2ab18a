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
  // The toe of the unilateral law (UnilateralElasticStrain): the strain
  // over which a tightening element takes up its stiffness and damping.
  // 1e-4 is 3.5 N on the paper's cable (E A = 34.5 kN), far below its
  // 100 N pre-tension: an element not close to slack evaluates exactly
  // eqs. 13 and 20.
  double slack_toe_strain = 1e-4;
};

// Everything the assembly needs from one element at one state.
struct AleElementTerms {
  Matrix8d mass;                       // M_ele of eq. 6 [kg] (r' is dimensionless)
  Matrix8d elastic_mass;               // M_elastic of eq. 20 (zero when h = 0)
  Vector8d ale_inertia_force;          // -Q_p of eq. 6 [N]
  Vector8d elastic_force;              // -Q'_e of eq. 20 (= -Q_e of eq. 6 when h = 0) [N]
  RowVector8d strain_jacobian;         // eps_q = d eps / d q [1/m]
  double strain = 0.0;                 // eps (eq. 6) [1]
  double strain_rate = 0.0;            // eps_dot = eps_q q_dot [1/s]
  double strain_accel_bias = 0.0;      // eps_dot_q q_dot = q_dot^T eps_qq q_dot [1/s^2]
  double tension = 0.0;                // T = EA (phi + phi' beta eps_dot) (eq. 13), >= 0 [N]
  double strain_energy_density = 0.0;  // ∫ phi d eps: EA Δs times it is the elastic energy
  double kinetic_energy = 0.0;         // q_dot^T M_ele q_dot / 2 [J]
  // beta' and gamma of eq. 20 as applied (with phi' for k; 0 when the
  // element carries nothing): the smoothed stress is EA (phi + beta' eps_dot
  // + gamma eps_dd).
  double smoothed_damping_s = 0.0;
  double smoothed_inertia_s2 = 0.0;
  bool taut = false;     // k of eq. 6: eps > 0
  bool pushing = false;  // stretched, but eq. 20's explicit stress would push: held at 0
};

// The elastic term of eq. 13 made unilateral: phi(eps) = 0 when slack
// (eps <= 0), eps beyond the toe (eps >= e_t), and e_t x^2 (2 - x) in
// between (x = eps / e_t), which joins them with phi and its slope
// continuous: the tangent stiffness EA phi' rises from 0 to EA without a
// jump (it peaks at 4/3 EA inside the toe). `energy` is the potential
// ∫ phi d eps, eps^2/2 - e_t^2/12 beyond the toe.
struct UnilateralStrain {
  double value = 0.0;   // phi [1]
  double slope = 0.0;   // phi' [1]
  double energy = 0.0;  // ∫_0^eps phi [1]
};
UnilateralStrain UnilateralElasticStrain(double strain, double toe_strain);

// Evaluates the element (eqs. 4, 6, 13, 17-20) in closed form.
//
// Precondition (checked, aborts): s2 - s1 > 0. A caller that can meet a
// collapsed element during a diverging run must test Δs itself first and
// report the divergence.
//
// Notes:
//  - A cable cannot push (docs/model-notes.md row 27). Eqs. 6 and 13 as
//    printed let the Rayleigh term beta eps_dot act on a slack element, which
//    then pushes when compressed quickly. Here the elastic term k eps is
//    phi(eps) (UnilateralElasticStrain), the Rayleigh and smoothing terms
//    take its slope phi' for k. A stretched element whose smoothed stress
//    (eq. 20, without its q'' part) would be negative has it held at 0 and
//    keeps only the smoothing's added mass; `tension` (eq. 13) is never
//    below 0. Beyond the toe: eqs. 13 and 20 as printed, bit for bit.
//  - eq. 20 of the paper prints eps_dot_q^T in front of Q'_e; substituting
//    eq. 18 into eq. 17 gives eps_q^T, which is what is used here.
AleElementTerms EvaluateAleElement(const AleElementParams& params, const Vector8d& q,
                                   const Vector8d& q_dot);

// Elastic strain energy U = EA Δs ∫ phi d eps [J] (the potential of the
// elastic part of eq. 13 over the unstretched length Δs; EA eps^2 Δs / 2 less
// a constant EA e_t^2 Δs / 12 beyond the toe). Precondition: Δs > 0.
double AleStrainEnergy(const AleElementParams& params, const Vector8d& q);

// Kinetic energy T = q_dot^T M_ele q_dot / 2 = (rho A / 2) ∫ |r_dot|^2 ds [J].
// Precondition: Δs > 0.
double AleKineticEnergy(const AleElementParams& params, const Vector8d& q, const Vector8d& q_dot);

// The shape matrix N(zeta) of eq. 4 (3 x 8), exposed for quadrature checks and
// for mapping a point force into element coordinates. Precondition: Δs > 0.
Eigen::Matrix<double, 3, 8> AleShapeMatrix(const Vector8d& q, double zeta);

}  // namespace ccsrm::sim::internal
