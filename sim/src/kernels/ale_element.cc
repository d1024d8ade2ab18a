#include "ale_element.h"

#include <algorithm>

#include "ccsrm/common/error.h"

namespace ccsrm::sim::internal {
namespace {

// ∫ N_a N_b d zeta over [-1, 1], times 1/2 (so Δs * kMab is (Δs/2) ∫ N_a N_b).
constexpr double kM11 = 1.0 / 3.0;
constexpr double kM12 = 1.0 / 6.0;

struct Kinematics {
  Eigen::Vector3d r_s;      // r' = Δr / Δs
  Eigen::Vector3d r_s_dot;  // d r' / dt = (Δr_dot - r' Δs_dot) / Δs
  double ds = 0.0;          // Δs
  double ds_dot = 0.0;      // Δs_dot
};

Kinematics ComputeKinematics(const Vector8d& q, const Vector8d& q_dot) {
  Kinematics k;
  k.ds = q(7) - q(6);
  CCSRM_CHECK(k.ds > 0.0);
  k.ds_dot = q_dot(7) - q_dot(6);
  const double inv_ds = 1.0 / k.ds;
  k.r_s = (q.segment<3>(3) - q.segment<3>(0)) * inv_ds;
  k.r_s_dot = (q_dot.segment<3>(3) - q_dot.segment<3>(0) - k.r_s * k.ds_dot) * inv_ds;
  return k;
}

// M_ele of eq. 6 in closed form: block (a, b) is rho A Δs m_ab times
// [I, -r'; -r'^T, |r'|^2] patterns of N^T N.
void FillMass(double rho_a, const Kinematics& k, Matrix8d* mass) {
  const double m[2][2] = {{kM11, kM12}, {kM12, kM11}};
  const double scale = rho_a * k.ds;
  const double rr = k.r_s.squaredNorm();
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const double mab = scale * m[a][b];
      mass->block<3, 3>(3 * a, 3 * b) = mab * Eigen::Matrix3d::Identity();
      mass->block<3, 1>(3 * a, 6 + b) = -mab * k.r_s;
      mass->block<1, 3>(6 + b, 3 * a) = -mab * k.r_s.transpose();
      (*mass)(6 + a, 6 + b) = mab * rr;
    }
  }
}

// q_dot^T M_ele q_dot / 2 from M_ele's pattern: with u_a = r_a_dot - r' s_a_dot
// (the material velocity at node a), it is rho A Δs sum_ab m_ab u_a.u_b / 2.
double KineticEnergy(double rho_a, const Kinematics& k, const Vector8d& q_dot) {
  const Eigen::Vector3d u1 = q_dot.segment<3>(0) - k.r_s * q_dot(6);
  const Eigen::Vector3d u2 = q_dot.segment<3>(3) - k.r_s * q_dot(7);
  return 0.5 * rho_a * k.ds *
         (kM11 * (u1.squaredNorm() + u2.squaredNorm()) + 2.0 * kM12 * u1.dot(u2));
}

}  // namespace

UnilateralStrain UnilateralElasticStrain(double strain, double toe_strain) {
  if (strain <= 0.0) return {0.0, 0.0, 0.0};
  if (strain >= toe_strain) {
    return {strain, 1.0, 0.5 * strain * strain - toe_strain * toe_strain / 12.0};
  }
  const double x = strain / toe_strain;
  return {toe_strain * x * x * (2.0 - x), x * (4.0 - 3.0 * x),
          toe_strain * toe_strain * x * x * x * (2.0 / 3.0 - 0.25 * x)};
}

Eigen::Matrix<double, 3, 8> AleShapeMatrix(const Vector8d& q, double zeta) {
  const double ds = q(7) - q(6);
  CCSRM_CHECK(ds > 0.0);
  const Eigen::Vector3d r_s = (q.segment<3>(3) - q.segment<3>(0)) / ds;
  const double n1 = 0.5 * (1.0 - zeta);
  const double n2 = 0.5 * (1.0 + zeta);
  Eigen::Matrix<double, 3, 8> n;
  n.block<3, 3>(0, 0) = n1 * Eigen::Matrix3d::Identity();
  n.block<3, 3>(0, 3) = n2 * Eigen::Matrix3d::Identity();
  n.col(6) = -n1 * r_s;  // (∂N_r/∂s1) q_r
  n.col(7) = -n2 * r_s;  // (∂N_r/∂s2) q_r
  return n;
}

AleElementTerms EvaluateAleElement(const AleElementParams& params, const Vector8d& q,
                                   const Vector8d& q_dot) {
  const Kinematics k = ComputeKinematics(q, q_dot);
  const double inv_ds = 1.0 / k.ds;
  const double rr = k.r_s.squaredNorm();
  AleElementTerms out;

  FillMass(params.linear_density_kgpm, k, &out.mass);
  out.kinetic_energy = KineticEnergy(params.linear_density_kgpm, k, q_dot);

  // Strain (eq. 6), its Jacobian and rates (eq. 18).
  out.strain = 0.5 * (rr - 1.0);
  out.strain_jacobian.segment<3>(0) = -inv_ds * k.r_s.transpose();
  out.strain_jacobian.segment<3>(3) = inv_ds * k.r_s.transpose();
  out.strain_jacobian(6) = rr * inv_ds;
  out.strain_jacobian(7) = -rr * inv_ds;
  out.strain_rate = k.r_s.dot(k.r_s_dot);
  // d/dt (r'.r'_dot) with q'' = 0: |r'_dot|^2 + r'.(-2 r'_dot Δs_dot / Δs).
  out.strain_accel_bias = k.r_s_dot.squaredNorm() - 2.0 * out.strain_rate * k.ds_dot * inv_ds;

  // The unilateral law (docs/model-notes.md row 27): eq. 13's elastic term
  // k eps becomes phi(eps), zero when slack and joined to eps by a short
  // toe, and the Rayleigh and smoothing terms take the tangent stiffness
  // phi' in place of k (Rayleigh damping is proportional to it); a cable
  // that would push instead carries nothing. Beyond the toe phi = eps and
  // phi' = 1: eqs. 13 and 20 as printed, to the last bit.
  out.taut = out.strain > 0.0;
  const UnilateralStrain u = UnilateralElasticStrain(out.strain, params.slack_toe_strain);
  const double ea = params.axial_stiffness_n;
  const double beta = u.slope * params.rayleigh_beta_s;
  const double tension = ea * (u.value + beta * out.strain_rate);

  // Model smoothing (eqs. 17-20). With h = 0: beta' = beta, gamma = 0, and
  // Q'_e reduces to eq. 6's Q_e = Δs eps_q^T T.
  const double h = params.smoothing_step_s;
  out.smoothed_damping_s = beta + 0.5 * u.slope * h;
  out.smoothed_inertia_s2 = 0.5 * beta * h + u.slope * h * h / 6.0;
  const double explicit_stress = ea * (u.value + out.smoothed_damping_s * out.strain_rate +
                                       out.smoothed_inertia_s2 * out.strain_accel_bias);
  // A slack element carries nothing. One unloading faster than its damping
  // lets it relax would push: its explicit stress is held at zero, while
  // the smoothing's added mass (eq. 20, a part of the averaged stress that
  // only resists strain acceleration) stays, so that the inertia the
  // integrator sees does not jump when it starts or stops.
  out.pushing = out.taut && explicit_stress < 0.0;
  out.strain_energy_density = u.energy;
  out.tension = out.taut ? std::max(0.0, tension) : 0.0;
  if (!out.taut) {
    out.smoothed_damping_s = 0.0;
    out.smoothed_inertia_s2 = 0.0;
    out.elastic_force.setZero();
    out.elastic_mass.setZero();
  } else {
    // Integrands are constant in zeta, so (Δs/2) ∫ d zeta = Δs.
    out.elastic_force = -(k.ds * std::max(0.0, explicit_stress)) * out.strain_jacobian.transpose();
    out.elastic_mass.noalias() = (k.ds * ea * out.smoothed_inertia_s2) *
                                 out.strain_jacobian.transpose() * out.strain_jacobian;
  }

  // Additional inertia (eqs. 4, 6). Writing out eq. 4 with the derivatives of
  // N_r gives r''_s = -2 w r'_dot, w(zeta) = N1 s1_dot + N2 s2_dot, so
  // Q_p = (Δs/2) ∫ rho A N^T r''_s = -2 rho A [c1 r'_dot; c2 r'_dot;
  // -c1 r'.r'_dot; -c2 r'.r'_dot], c_a = Δs (m_a1 s1_dot + m_a2 s2_dot).
  const double c1 = k.ds * (kM11 * q_dot(6) + kM12 * q_dot(7));
  const double c2 = k.ds * (kM12 * q_dot(6) + kM11 * q_dot(7));
  const double two_rho_a = 2.0 * params.linear_density_kgpm;
  out.ale_inertia_force.segment<3>(0) = (two_rho_a * c1) * k.r_s_dot;
  out.ale_inertia_force.segment<3>(3) = (two_rho_a * c2) * k.r_s_dot;
  out.ale_inertia_force(6) = -two_rho_a * c1 * out.strain_rate;
  out.ale_inertia_force(7) = -two_rho_a * c2 * out.strain_rate;
  return out;
}

double AleStrainEnergy(const AleElementParams& params, const Vector8d& q) {
  const double ds = q(7) - q(6);
  CCSRM_CHECK(ds > 0.0);
  const double strain = 0.5 * ((q.segment<3>(3) - q.segment<3>(0)).squaredNorm() / (ds * ds) - 1.0);
  // A slack element stores no energy.
  return params.axial_stiffness_n *
         UnilateralElasticStrain(strain, params.slack_toe_strain).energy * ds;
}

double AleKineticEnergy(const AleElementParams& params, const Vector8d& q, const Vector8d& q_dot) {
  return KineticEnergy(params.linear_density_kgpm, ComputeKinematics(q, q_dot), q_dot);
}

}  // namespace ccsrm::sim::internal
