#include "hole_friction.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace ccsrm::sim::internal {

double WrapAngle(const Eigen::Vector3d& r_prev, const Eigen::Vector3d& r_i,
                 const Eigen::Vector3d& r_next) {
  const Eigen::Vector3d a = r_prev - r_i;
  const Eigen::Vector3d b = r_next - r_i;
  // pi - arccos(cos(a, b)) = angle between a and -b (eq. 12). atan2 of the
  // sine and cosine parts (both scaled by |a||b|) avoids the ill-conditioned
  // arccos near a straight cable; atan2(0, 0) = 0 for a degenerate side.
  return std::atan2(a.cross(b).norm(), -a.dot(b));
}

double LimitingStaticFriction(double tension_1, double tension_2, double mu_static,
                              double wrap_angle) {
  const double t_min = std::max(0.0, std::min(tension_1, tension_2));
  // expm1 keeps f_max accurate for the small wrap angles of a nearly straight cable.
  return t_min * std::expm1(mu_static * wrap_angle);
}

double HoleSlipFriction(double tension_before, double mu, double wrap_angle, double s_dot) {
  if (s_dot == 0.0) return 0.0;
  const double sigma = s_dot > 0.0 ? 1.0 : -1.0;
  const double t_b = std::max(0.0, tension_before);
  // eq. 9 with sgn(v_tau) = -sigma: f_t = T_b (1 - e^{-mu theta sigma});
  // F = -f_t = T_b expm1(-mu theta sigma), which has the sign of -sigma.
  return t_b * std::expm1(-mu * wrap_angle * sigma);
}

double HoleMemoryTarget(const HoleFrictionLaw& law, double speed, double* slope) {
  if (slope != nullptr) *slope = 0.0;
  const double beyond = std::abs(speed) - law.stick_velocity_mps;
  if (beyond <= 0.0) return 1.0;
  if (!(law.stribeck_velocity_mps > 0.0)) return 0.0;
  const double x = beyond / law.stribeck_velocity_mps;
  const double decay = std::exp(-x * x);
  if (slope != nullptr) *slope = -2.0 * x * decay / law.stribeck_velocity_mps;
  return decay;
}

double HoleFrictionCoefficient(const HoleFrictionLaw& law, double speed, double* slope) {
  const double excess = law.mu_static - law.mu_kinetic;
  double target_slope = 0.0;
  const double target = HoleMemoryTarget(law, speed, &target_slope);
  if (slope != nullptr) *slope = excess * target_slope;
  // The ends exactly: mu' in the stick band, mu once the fall is over.
  if (target == 1.0) return law.mu_static;
  if (target == 0.0 || excess == 0.0) return law.mu_kinetic;
  return law.mu_kinetic + excess * target;
}

HoleFrictionForce SmoothedHoleFriction(const HoleFrictionLaw& law, double tension_before,
                                       double wrap_angle, double s_dot, double memory) {
  HoleFrictionForce out;
  const double t_b = std::max(0.0, tension_before);
  if (t_b == 0.0 || wrap_angle == 0.0) return out;
  const double u = s_dot / law.stick_velocity_mps;
  double r = u > 0.0 ? 1.0 : -1.0, dr_dv = 0.0;
  if (std::abs(u) < 1.0) {
    r = 1.5 * u - 0.5 * u * u * u;
    dr_dv = 1.5 * (1.0 - u * u) / law.stick_velocity_mps;
  }
  const double mu = law.mu_kinetic + (law.mu_static - law.mu_kinetic) * memory;
  const double exponent = -mu * wrap_angle * r;
  out.force = t_b * std::expm1(exponent);
  out.slope = -t_b * std::exp(exponent) * wrap_angle * mu * dr_dv;
  return out;
}

namespace {

// 3u^2 - 2u^3 on [0, 1], 0 below, 1 above: a C1 step.
double SmoothStep(double u) {
  if (u <= 0.0) return 0.0;
  if (u >= 1.0) return 1.0;
  return u * u * (3.0 - 2.0 * u);
}

}  // namespace

ElastoplasticYield ElastoplasticSlide(double load_ratio, double sigma, double v, double band,
                                      double relaxation_scale) {
  ElastoplasticYield out;
  const double alpha =
      SmoothStep((load_ratio - kPreslidingBreakaway) / (1.0 - kPreslidingBreakaway));
  const double loading = v * sigma;
  double ramp = 0.0, ramp_slope = 0.0;
  if (loading >= band) {
    ramp = loading;
    ramp_slope = 1.0;
  } else if (loading > 0.0) {
    const double u = loading / band;
    ramp = loading * SmoothStep(u);
    ramp_slope = u * u * (9.0 - 8.0 * u);
  }
  // The relaxation to the limit, rate ramp / displacement_ss at rho = 1, at
  // most about 1/h: x = ramp h / displacement_ss, c = (1 + x^4)^(-1/4).
  const double x = ramp * relaxation_scale;
  const double x4 = x * x * x * x;
  const double c = 1.0 / std::sqrt(std::sqrt(1.0 + x4));
  const double dc_dx = x4 > 0.0 ? -c * x4 / (x * (1.0 + x4)) : 0.0;
  const double yield_share = alpha * (1.0 + c * (load_ratio - 1.0));
  // d(ramp yield_share)/d(loading), c depending on the loading through x.
  const double slope = ramp_slope * (yield_share + alpha * (load_ratio - 1.0) * dc_dx * x);
  // The clamp acts only sliding near the band at the limit, where the slope
  // of ramp exceeds 1 (it must catch up with x); a negative mass would be
  // unphysical.
  out.engaged_fraction = std::max(0.0, 1.0 - slope);
  out.sliding = yield_share * sigma * ramp;
  return out;
}

PreslidingFriction PreslidingHoleFriction(const PreslidingLaw& law, double tension_before,
                                          double wrap_angle, double s_dot, double memory,
                                          double displacement) {
  PreslidingFriction out;
  const HoleFrictionLaw& f = law.friction;
  const double xi_max = law.presliding_displacement_m;
  const double t_b = std::max(0.0, tension_before);
  const double sigma = displacement < 0.0 ? -1.0 : 1.0;
  const double mu_z = f.mu_kinetic + (f.mu_static - f.mu_kinetic) * memory;
  const double b = f.mu_static * wrap_angle;
  // q = k xi_ss / (T_b sinh(mu' theta)) = xi_ss / xi_max. At b = 0 (a
  // straight cable or no static friction) k is 0 and F too; xi_ss keeps its
  // limit mu_z / mu' (or xi_max without friction) so that xi stays bounded.
  double q = 1.0;
  if (b > 0.0) {
    q = std::abs(std::expm1(-mu_z * wrap_angle * sigma)) / std::sinh(b);
  } else if (f.mu_static > 0.0) {
    q = mu_z / f.mu_static;
  }
  // A limit of nothing (mu_z = 0 under mu' > 0) would make rho infinite.
  q = std::max(q, 1e-3);
  const double xi_ss = xi_max * q;
  out.stiffness = t_b * std::sinh(b) / xi_max;
  out.force = -out.stiffness * displacement;
  out.load_ratio = std::abs(displacement) / xi_ss;
  const ElastoplasticYield yield = ElastoplasticSlide(
      out.load_ratio, sigma, s_dot, f.stick_velocity_mps, law.relaxation_resolution_s / xi_ss);
  out.engaged_fraction = yield.engaged_fraction;
  out.rate = s_dot - yield.sliding;
  out.sliding_speed = yield.sliding;
  out.plastic_power = out.stiffness * displacement * yield.sliding;
  return out;
}

}  // namespace ccsrm::sim::internal
