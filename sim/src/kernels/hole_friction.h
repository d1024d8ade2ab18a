#pragma once
// Capstan friction between a driving cable and a hole (paper eqs. 8-12).
//
// A hole node i is Eulerian (eq. 7): its position is fixed to a disk and only
// its material coordinate s_i moves. Friction acts on s_i only (eq. 11).
// Notation for node i: the element "before" is the one that ends at node i
// (lower s, towards the input), the element "after" starts at node i. Their
// tensions (eq. 13) are T_b and T_a [N].
//
// Sign convention: forces are generalized forces on s_i [N], right-hand-side
// signed (M q'' = F + ...), i.e. F = -f_t of eq. 9 (the paper's Q_f sits on
// the left of eq. 5). The cable slides through the hole with tangential
// velocity v_tau = -s_i_dot (section 2.3), so the slip direction used below is
// sigma = sgn(s_i_dot) = -sgn(v_tau).
#include <Eigen/Core>

namespace ccsrm::sim::internal {

// Wrap angle of the cable at node i (eq. 12) [rad], in [0, pi]: 0 for a
// straight cable, pi for a cable folded back on itself.
// Evaluated as atan2(|a x b|, -a.b) with a = r_prev - r_i, b = r_next - r_i,
// which equals pi - arccos(a.b / (|a| |b|)) of eq. 12 but needs no clamping of
// the cosine and keeps full precision near 0 and pi.
// Precondition: r_prev != r_i and r_next != r_i (not checked; a zero-length
// side gives 0).
double WrapAngle(const Eigen::Vector3d& r_prev, const Eigen::Vector3d& r_i,
                 const Eigen::Vector3d& r_next);

// Limiting static friction (eq. 10) [N]:
//   f_max = min(T1, T2) (exp(mu_static * theta) - 1),
// with both tensions clamped at >= 0 (a slack side holds nothing).
// Symmetric in T1, T2. Preconditions: mu_static >= 0, theta >= 0.
double LimitingStaticFriction(double tension_1, double tension_2, double mu_static,
                              double wrap_angle);

// Kinetic (slipping) friction on s_i (eq. 9, v_tau != 0), right-hand-side
// signed:
//   F = -T_b (1 - exp(-mu theta sigma)),  sigma = sgn(s_i_dot),  T_b >= 0 clamped.
// sigma = +1: cable drawn towards the "before" side, |F| = T_b (1 - e^{-mu theta})
//   (= T_b - T_a when T_b = T_a e^{mu theta}, the capstan relation);
// sigma = -1: F = T_b (e^{mu theta} - 1), the capstan value.
// F * s_i_dot <= 0 always (friction dissipates); F = 0 when s_i_dot == 0.
// The caller decides stick or slip (velocity tolerance v_eps, trial and
// error); this function does not look at the magnitude of s_i_dot. The
// static branch of eq. 9 has no kernel: a stuck node is held by the
// constraint s = s* whose reaction is checked against f_max
// (docs/model-notes.md, row 3).
// Preconditions: mu >= 0, theta >= 0.
double HoleSlipFriction(double tension_before, double mu, double wrap_angle, double s_dot);

// The friction law of a hole beyond eq. 9's two coefficients: real friction
// does not drop from static to kinetic in zero time (docs/model-notes.md,
// "Stribeck transition"). Within the stick band |v| <= v_eps the
// coefficient is mu'; beyond it, it falls to mu over the Stribeck velocity:
//   mu(|v|) = mu + (mu' - mu) exp(-((|v| - v_eps) / v_s)^2).
// With mu = mu' it is the paper's law whatever v_s is; with v_s = 0 it drops
// to mu at once beyond v_eps (the paper's force form of eq. 9).
struct HoleFrictionLaw {
  double mu_kinetic = 0.0;             // mu
  double mu_static = 0.0;              // mu'
  double stribeck_velocity_mps = 0.0;  // v_s >= 0
  double stick_velocity_mps = 0.0;     // v_eps > 0
};

// mu(|v|) of the law above [1]; *slope (may be null) is d mu / d|v| [s/m].
double HoleFrictionCoefficient(const HoleFrictionLaw& law, double speed, double* slope);

// The same law split in two (docs/model-notes.md, "frictional memory"): a
// memory z in [0, 1] of how static the contact is, with the coefficient
// mu + (mu' - mu) z. Its steady value at slip speed |v| is this target: 1
// inside the stick band, exp(-((|v| - v_eps) / v_s)^2) beyond it (0 when
// v_s = 0), so that at the target the coefficient is HoleFrictionCoefficient.
// *slope (may be null) is d target / d|v| [s/m], <= 0.
double HoleMemoryTarget(const HoleFrictionLaw& law, double speed, double* slope);

// Friction on s_i as one smooth function of the slip speed v = s_i_dot and
// the memory z, for the smoothed treatment of stick-slip
// (docs/model-notes.md): the capstan force of eq. 9 with the coefficient
// mu + (mu' - mu) z and the direction sgn(v) replaced by r(v), which rises
// from 0 to +-1 across the stick band, r = 1.5 u - 0.5 u^3 for u = v / v_eps
// in [-1, 1] (C1 at the band's edges):
//   F = T_b expm1(-(mu + (mu' - mu) z) theta r(v)).
// A node loaded below its static limit so creeps at |v| < v_eps, the SPEC's
// definition of stuck; beyond the band, at the memory's target, it is eq. 9
// with the Stribeck coefficient. `slope` is dF/dv at fixed z [N s/m], <= 0,
// for model smoothing.
// Preconditions: law.stick_velocity_mps > 0, theta >= 0, z in [0, 1].
struct HoleFrictionForce {
  double force = 0.0;  // F [N], right-hand-side signed, F v <= 0
  double slope = 0.0;  // dF/dv [N s/m]
};
HoleFrictionForce SmoothedHoleFriction(const HoleFrictionLaw& law, double tension_before,
                                       double wrap_angle, double s_dot, double memory);

// Presliding (elastoplastic) friction on s_i, for solver.hole_friction:
// presliding (docs/model-notes.md), after the single-state elastoplastic
// models of Dupont, Hayward, Armstrong and Altpeter (IEEE TAC 47(5), 2002).
// The node carries a presliding displacement xi [m], the elastic strain of
// the contact, and the friction is a spring on it:
//   F = -k xi,  k = T_b sinh(mu' theta) / xi_max,
// a stiffness proportional to the load, so that the steady capstan force of
// eq. 9 in either direction is reached at about xi_max whatever the
// tensions. xi follows
//   xi_dot = s_dot - alpha(rho) rho sgn(xi) ramp(s_dot sgn(xi)),
//   rho = |xi| / xi_ss,  xi_ss = T_b |expm1(-mu_z theta sgn(xi))| / k,
// where mu_z = mu + (mu' - mu) z is the coefficient of the memory z (as in
// SmoothedHoleFriction), so that k xi_ss is eq. 9's force with the current
// coefficient. alpha is 0 below the breakaway rho_ba (pure elastic
// presliding: a node loaded below it does not move at all) and rises as a
// C1 smooth step to 1 at rho = 1; ramp(x) is 0 for x <= 0 (unloading and a
// node at rest are elastic) and x beyond v_eps, joined C1 by x (3u^2 - 2u^3),
// u = x / v_eps, so that xi_dot is C1 in s_dot. At steady sliding rho -> 1
// and F is eq. 9's force; where the limit falls below k |xi| (the memory
// drops) rho > 1 and xi relaxes to the limit as the node slides, rather than
// storing force.
// Preconditions: presliding_displacement_m > 0, stick_velocity_mps > 0,
// theta >= 0, z in [0, 1].
struct PreslidingLaw {
  HoleFrictionLaw friction;
  double presliding_displacement_m = 0.0;  // xi_max
  // h of model smoothing applied to the relaxation to the limit
  // (ElastoplasticSlide's relaxation_scale = h / xi_ss); 0: none.
  double relaxation_resolution_s = 0.0;
};
// rho below which presliding is purely elastic (Dupont et al.'s z_ba / z_ss).
inline constexpr double kPreslidingBreakaway = 0.5;

// The yield of the elastoplastic law, shared by the holes and the large-S
// conduits: of a contact's slip speed v, the part that slides when its
// presliding displacement has sign sigma (+-1) and load ratio rho,
//   sliding = alpha(rho) (1 + c (rho - 1)) sigma ramp(v sigma),
// with alpha and ramp (joined over `band`) as above; the displacement's
// rate is v - sliding. With c = 1 this is Dupont et al.'s alpha rho.
// Sliding at the limit, the displacement relaxes to rho = 1 at the rate
// lambda = c ramp / displacement_ss, which grows with the slip speed (1e3/s
// at 10 mm/s and 10 um) and held explicit steps of fast motions near 1 ms
// (docs/model-notes.md row 28). Model smoothing of that relaxation:
// c = (1 + x^4)^(-1/4), x = ramp h / displacement_ss, so lambda <= ~1/h,
// the model's time resolution, while c = 1 - x^4/4 + .. leaves slow sliding
// as it was. rho = 1 stays the only fixed point (steady sliding at eq. 9's
// force), the elastic range and unloading are untouched, and the plastic
// power stays >= 0 (1 + c (rho - 1) > 0 wherever alpha > 0).
// `relaxation_scale` = h / displacement_ss [s/m]; 0 gives c = 1.
struct ElastoplasticYield {
  double sliding = 0.0;  // [m/s]
  // d(v - sliding)/dv clamped at >= 0 (PreslidingFriction::engaged_fraction).
  double engaged_fraction = 1.0;
};
ElastoplasticYield ElastoplasticSlide(double load_ratio, double sigma, double v, double band,
                                      double relaxation_scale = 0.0);
struct PreslidingFriction {
  double force = 0.0;      // F = -k xi [N], right-hand-side signed
  double stiffness = 0.0;  // k [N/m]
  double rate = 0.0;       // xi_dot [m/s]
  // d xi_dot / d s_dot, clamped at >= 0: the share of k that the node feels
  // (1 in the elastic range and on unloading, 0 sliding at the limit), for
  // model smoothing. A node held just over its limit slides at a fraction
  // of v_eps and still feels most of k.
  double engaged_fraction = 1.0;
  double plastic_power = 0.0;  // k xi (s_dot - xi_dot) >= 0 [W]
  double sliding_speed = 0.0;  // s_dot - xi_dot [m/s]: the part of s_dot that slides
  double load_ratio = 0.0;     // rho
};
PreslidingFriction PreslidingHoleFriction(const PreslidingLaw& law, double tension_before,
                                          double wrap_angle, double s_dot, double memory,
                                          double displacement);

// The presliding displacement at which PreslidingHoleFriction's spring
// holds eq. 9's force of the memory's coefficient in the direction `sigma`
// (+-1) of the displacement, xi_ss [m] (its load ratio's unit).
double PreslidingSteadyDisplacement(const PreslidingLaw& law, double wrap_angle, double memory,
                                    double sigma);

// The elastoplastic law's displacement after a finite slip at rest, for the
// quasi-static replay (sim/src/quasi_static.h): ElastoplasticSlide's
// displacement rate integrated over the contact's slip `slip` [m] in the
// limit of slow slip, where the yield's ramp is the slip speed itself and
// the relaxation is not smoothed (rate independence):
//   d xi / d s = 1 - alpha(rho) rho  loading (slip along xi),
//   d xi / d s = 1                   unloading,
// rho = |xi| / xi_ss, xi_ss being `steady_positive` for xi > 0 and
// `steady_negative` for xi < 0 [m, > 0]. Unloading is elastic until xi
// passes zero; loading is elastic below the breakaway, and beyond it
// rho = 1 - e^u solves du/ds = -p(rho)/xi_ss exactly, p = g / (1 - rho) the
// cubic that the law's g = 1 - alpha rho leaves (model notes, "quasi-static
// replay"), by Newton's method on u with the quadrature of the cubic's
// smooth remainder; a displacement beyond its limit (one that fell) relaxes
// as 1 + (rho - 1) e^(-slip / xi_ss). Smooth in the slip on each side of
// zero, as the time integration of the law is.
double ElastoplasticDisplacementAfterSlip(double displacement, double slip, double steady_positive,
                                          double steady_negative);

// The same on one branch of the law, for a Newton solve that must not see
// its kink at zero slip (the quasi-static replay's active set): `along`
// true is the contact slipping along its displacement (loading, sgn(slip)
// = sgn(displacement), +1 at zero), false against it (unloading, on
// through zero). Where the slip has the branch's sign this is
// ElastoplasticDisplacementAfterSlip; past zero slip each branch goes on
// smoothly: unloading elastically, loading along its tangent at zero slip
// (1 - alpha(rho) rho).
double ElastoplasticDisplacementOnBranch(double displacement, double slip, double steady_positive,
                                         double steady_negative, bool along);

}  // namespace ccsrm::sim::internal
