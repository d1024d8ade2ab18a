#include "hole_friction.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include <gsl/gsl_integration.h>

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

double PreslidingSteadyDisplacement(const PreslidingLaw& law, double wrap_angle, double memory,
                                    double sigma) {
  const HoleFrictionLaw& f = law.friction;
  const double xi_max = law.presliding_displacement_m;
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
  return xi_max * q;
}

PreslidingFriction PreslidingHoleFriction(const PreslidingLaw& law, double tension_before,
                                          double wrap_angle, double s_dot, double memory,
                                          double displacement) {
  PreslidingFriction out;
  const HoleFrictionLaw& f = law.friction;
  const double xi_max = law.presliding_displacement_m;
  const double t_b = std::max(0.0, tension_before);
  const double sigma = displacement < 0.0 ? -1.0 : 1.0;
  const double b = f.mu_static * wrap_angle;
  const double xi_ss = PreslidingSteadyDisplacement(law, wrap_angle, memory, sigma);
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

namespace {

// Beyond the breakaway the loading law d rho / d delta = g(rho) = 1 - alpha
// rho (delta = slip / xi_ss, alpha the C1 step from rho = 1/2 to 1) factors
// as g = (1 - rho) p(rho) with the cubic p = -16 rho^3 + 20 rho^2 - 4 rho +
// 1, which lies in [1, 2.52] there (p(1/2) = 2, p(1) = 1). So 1 / g =
// 1 / (1 - rho) - 4 rho (4 rho - 1) / p(rho): the log of the exponential
// approach to the limit plus a smooth remainder, integrated below.
static_assert(kPreslidingBreakaway == 0.5, "the cubic p belongs to a breakaway at rho = 1/2");

double YieldCubic(double rho) { return ((-16.0 * rho + 20.0) * rho - 4.0) * rho + 1.0; }

double YieldRemainder(double rho, void* /*unused*/) {
  return 4.0 * rho * (4.0 * rho - 1.0) / YieldCubic(rho);
}

// The remainder's integral over [from, to] in [1/2, 1]: 16-point
// Gauss-Legendre (the nearest pole, p's real root at 1.07, keeps the error
// near 1e-10 of the integral over the whole range).
double YieldRemainderIntegral(double from, double to) {
  static const gsl_integration_glfixed_table* const table = gsl_integration_glfixed_table_alloc(16);
  gsl_function f;
  f.function = &YieldRemainder;
  f.params = nullptr;
  return gsl_integration_glfixed(&f, from, to, table);
}

// rho after loading over delta = slip / xi_ss from rho0 >= 0.
double LoadRatioAfterLoading(double rho0, double delta) {
  // A displacement beyond a limit that fell: alpha = 1, g = 1 - rho.
  if (rho0 >= 1.0) return 1.0 + (rho0 - 1.0) * std::exp(-delta);
  const double elastic = std::max(0.0, kPreslidingBreakaway - rho0);
  if (delta <= elastic) return rho0 + delta;
  delta -= elastic;
  rho0 = std::max(rho0, kPreslidingBreakaway);
  // rho = 1 - e^u: G(u) = u - u0 + delta + I(rho0, rho) = 0 with
  // G' = 1 / p(rho) in [1/2.52, 1], so u lies in [u0 - 2.52 delta,
  // u0 - delta]; safeguarded Newton inside that bracket.
  const double u0 = std::log1p(-rho0);
  double lo = u0 - 2.52 * delta, hi = u0 - delta;
  double u = hi;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double rho = -std::expm1(u);
    const double g = u - u0 + delta + YieldRemainderIntegral(rho0, rho);
    if (g > 0.0) {
      hi = u;
    } else {
      lo = u;
    }
    double next = u - g * YieldCubic(rho);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool converged = std::abs(next - u) <= 1e-14 * std::max(1.0, std::abs(u));
    u = next;
    if (converged || hi - lo <= 1e-14 * std::max(1.0, std::abs(u))) break;
  }
  return -std::expm1(u);
}

}  // namespace

double ElastoplasticDisplacementAfterSlip(double displacement, double slip, double steady_positive,
                                          double steady_negative) {
  if (slip == 0.0) return displacement;
  const double direction = slip > 0.0 ? 1.0 : -1.0;
  double loading = std::abs(slip);
  if (displacement * direction < 0.0) {
    // Unloading is elastic until the displacement passes zero.
    if (loading <= std::abs(displacement)) return displacement + slip;
    loading -= std::abs(displacement);
    displacement = 0.0;
  }
  const double steady = direction > 0.0 ? steady_positive : steady_negative;
  return direction * steady *
         LoadRatioAfterLoading(std::abs(displacement) / steady, loading / steady);
}

double ElastoplasticDisplacementOnBranch(double displacement, double slip, double steady_positive,
                                         double steady_negative, bool along) {
  const double sigma = displacement < 0.0 ? -1.0 : 1.0;
  const bool slips_along = slip * sigma > 0.0;
  if (slip == 0.0 || slips_along == along) {
    return ElastoplasticDisplacementAfterSlip(displacement, slip, steady_positive, steady_negative);
  }
  if (!along) return displacement + slip;
  // d xi / d s at zero slip, loading: 1 - alpha(rho) rho (1 - rho beyond a
  // limit that fell).
  const double rho = std::abs(displacement) / (sigma > 0.0 ? steady_positive : steady_negative);
  const double alpha = SmoothStep((rho - kPreslidingBreakaway) / (1.0 - kPreslidingBreakaway));
  return displacement + slip * (1.0 - alpha * rho);
}

}  // namespace ccsrm::sim::internal
