#include "connecting.h"

#include <cmath>

namespace ccsrm::sim::internal {
namespace {

// E_c A_c r^2 / l, the stiffness of one cable of the couple seen from a joint.
// Shared by both mechanisms so the frictionless large S equals the small S
// bitwise (multiplying by 2 is exact in floating point).
double HalfCoupleStiffness(double axial_stiffness, double radius, double length) {
  return axial_stiffness * radius * radius / length;
}

}  // namespace

double SmallSStiffness(const SmallSParams& params) {
  return 2.0 * HalfCoupleStiffness(params.axial_stiffness_n, params.pulley_radius_m,
                                   params.cable_length_m);
}

ConnectingMoments SmallSMoments(const SmallSParams& params, double theta_i, double theta_j,
                                double theta_i_dot, double theta_j_dot) {
  const double k = SmallSStiffness(params);
  const double c = params.damping_nmsprad;
  ConnectingMoments m;
  m.on_i = k * (theta_j - theta_i) + c * (theta_j_dot - theta_i_dot);
  m.on_j = k * (theta_i - theta_j) + c * (theta_i_dot - theta_j_dot);
  return m;
}

double ConduitMemoryTarget(const ModifiedCoulombParams& params, double speed, double* slope) {
  if (slope != nullptr) *slope = 0.0;
  if (speed <= params.v_static_mps) return 1.0;
  const double width = params.stribeck_velocity_mps;
  if (speed >= params.v_static_mps + width) return 0.0;
  // SPEC §3 (a): a smooth step from mu'_c at v_s to mu_c at v_s + v_c_s
  // (the paper's v_d). The paper's printed branch swaps mu_c and mu'_c,
  // which makes mu_m jump at both ends unless mu_c = mu'_c.
  const double x = (speed - params.v_static_mps) / width;
  if (slope != nullptr) *slope = -6.0 * x * (1.0 - x) / width;
  return 1.0 - x * x * (3.0 - 2.0 * x);
}

double ModifiedCoulombWithMemory(const ModifiedCoulombParams& params, double v, double memory,
                                 double* slope) {
  const double mu = params.mu_kinetic + (params.mu_static - params.mu_kinetic) * memory;
  if (slope != nullptr) *slope = 0.0;
  if (std::abs(v) >= params.v_static_mps) return v > 0.0 ? -mu : mu;
  // Paper's lower branch (eq. 45) over mu'_c: a cubic through +1 at -v_s, 0
  // at 0 and -1 at v_s with zero slope at both ends.
  const double u = (v + params.v_static_mps) / (2.0 * params.v_static_mps);
  if (slope != nullptr) *slope = -mu * 6.0 * u * (1.0 - u) / params.v_static_mps;
  return mu * (1.0 - 2.0 * u * u * (3.0 - 2.0 * u));
}

double ModifiedCoulomb(const ModifiedCoulombParams& params, double v) {
  return ModifiedCoulombWithMemory(params, v, ConduitMemoryTarget(params, std::abs(v), nullptr),
                                   nullptr);
}

double CapstanFactor(double x) {
  // x / (1 - e^{-x}) -> 1 as x -> 0 (eqs. 46-53 without friction). expm1
  // keeps full relative precision for small |x|; only x == 0 needs the limit.
  if (x == 0.0) return 1.0;
  return -x / std::expm1(-x);
}

double ConduitSlipVelocity(const LargeSParams& params, double theta_i_dot, double theta_j_dot) {
  // Sign chosen so that the friction moments dissipate (see the header).
  return -0.5 * params.pulley_radius_m * (theta_i_dot + theta_j_dot);
}

LargeSResult LargeSMoments(const LargeSParams& params, double theta_i, double theta_j,
                           double theta_i_dot, double theta_j_dot, double memory) {
  LargeSResult out;
  out.slip_velocity_1 = ConduitSlipVelocity(params, theta_i_dot, theta_j_dot);
  const double v2 = -out.slip_velocity_1;
  double slope = 0.0;
  const double a1 =
      ModifiedCoulombWithMemory(params.friction, out.slip_velocity_1, memory, &slope) *
      params.wrap_angle_rad;
  const double a2 =
      ModifiedCoulombWithMemory(params.friction, v2, memory, nullptr) * params.wrap_angle_rad;

  // Tension factors at the i ends (eqs. 46-47: T_i = (EA dl / l) phi(a)) and
  // at the j ends (T_j = T_i e^{-a} = (EA dl / l) phi(-a)).
  const double phi_1 = CapstanFactor(a1);
  const double phi_2 = CapstanFactor(a2);
  const double phi_m1 = CapstanFactor(-a1);
  const double phi_m2 = CapstanFactor(-a2);

  const double tp_r = params.pretension_n * params.pulley_radius_m;
  const double k0 =
      HalfCoupleStiffness(params.axial_stiffness_n, params.pulley_radius_m, params.cable_length_m);
  out.friction_i = tp_r * (phi_2 - phi_1);    // eq. 50
  out.stiffness_i = k0 * (phi_2 + phi_1);     // eq. 50
  out.friction_j = tp_r * (phi_m1 - phi_m2);  // eq. 53
  out.stiffness_j = k0 * (phi_m1 + phi_m2);   // eq. 53

  // M_p = -T_p r Theta mu_m(v_tau1), d v_tau1 / d theta_dot = -r / 2.
  out.conduit_damping = -0.5 * tp_r * params.pulley_radius_m * params.wrap_angle_rad * slope;

  const double c = params.damping_nmsprad;
  out.moments.on_i = out.friction_i + out.stiffness_i * (theta_j - theta_i) +
                     c * (theta_j_dot - theta_i_dot);  // eq. 51
  out.moments.on_j = out.friction_j + out.stiffness_j * (theta_i - theta_j) +
                     c * (theta_i_dot - theta_j_dot);  // eq. 52
  return out;
}

}  // namespace ccsrm::sim::internal
