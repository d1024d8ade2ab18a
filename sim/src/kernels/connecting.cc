#include "connecting.h"

#include <algorithm>
#include <cmath>

#include "hole_friction.h"

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

namespace {

// Eqs. 46-53 from the friction exponents a1 = mu_m(v_tau1) Theta and
// a2 = mu_m(v_tau2) Theta; slope is d mu_m / d v_tau1.
LargeSResult MomentsFromExponents(const LargeSParams& params, double theta_i, double theta_j,
                                  double theta_i_dot, double theta_j_dot, double v1, double a1,
                                  double a2, double slope) {
  LargeSResult out;
  out.slip_velocity_1 = v1;
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

}  // namespace

LargeSResult LargeSMoments(const LargeSParams& params, double theta_i, double theta_j,
                           double theta_i_dot, double theta_j_dot, double memory) {
  const double v1 = ConduitSlipVelocity(params, theta_i_dot, theta_j_dot);
  double slope = 0.0;
  // Both speeds through the law: inside the stick band mu_m(-v) equals
  // -mu_m(v) only to rounding.
  const double a1 =
      ModifiedCoulombWithMemory(params.friction, v1, memory, &slope) * params.wrap_angle_rad;
  const double a2 =
      ModifiedCoulombWithMemory(params.friction, -v1, memory, nullptr) * params.wrap_angle_rad;
  return MomentsFromExponents(params, theta_i, theta_j, theta_i_dot, theta_j_dot, v1, a1, a2,
                              slope);
}

LargeSResult LargeSMomentsWithCoefficient(const LargeSParams& params, double theta_i,
                                          double theta_j, double theta_i_dot, double theta_j_dot,
                                          double coefficient, double coefficient_slope) {
  const double a1 = coefficient * params.wrap_angle_rad;
  return MomentsFromExponents(params, theta_i, theta_j, theta_i_dot, theta_j_dot,
                              ConduitSlipVelocity(params, theta_i_dot, theta_j_dot), a1, -a1,
                              coefficient_slope);
}

ConduitPresliding PreslidingConduitFriction(const ConduitPreslidingLaw& law, double v,
                                            double memory, double displacement) {
  ConduitPresliding out;
  const double eta_max = law.presliding_displacement_m;
  const double sigma = displacement < 0.0 ? -1.0 : 1.0;
  const double mu_z = law.mu_kinetic + (law.mu_static - law.mu_kinetic) * memory;
  // eta_ss / eta_max = mu_z / mu'_c; without static friction there is no
  // spring, and eta_ss = eta_max keeps eta bounded. A limit of nothing
  // (mu_z = 0 under mu'_c > 0) would make rho infinite.
  const double q = law.mu_static > 0.0 ? std::max(mu_z / law.mu_static, 1e-3) : 1.0;
  out.coefficient_per_displacement = -law.mu_static / eta_max;
  out.coefficient = out.coefficient_per_displacement * displacement;
  const double eta_ss = eta_max * q;
  out.load_ratio = std::abs(displacement) / eta_ss;
  const ElastoplasticYield yield = ElastoplasticSlide(out.load_ratio, sigma, v, law.band_mps,
                                                      law.relaxation_resolution_s / eta_ss);
  out.engaged_fraction = yield.engaged_fraction;
  out.sliding_speed = yield.sliding;
  out.rate = v - yield.sliding;
  return out;
}

}  // namespace ccsrm::sim::internal
