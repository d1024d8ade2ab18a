#pragma once
// Connecting cables between two adjacent joints i and j = i + 1 of a segment
// (paper eqs. 38-53). Every function works on one bending axis: theta_i,
// theta_j are that axis's joint angles [rad] and the caller applies the
// function to x and to y. Moments are joint-space moments [N m] acting on the
// joint's own angle, right-hand-side signed (they enter M_joint of eq. 54).
#include <Eigen/Core>

namespace ccsrm::sim::internal {

// Moments of one connecting mechanism on its two joints.
struct ConnectingMoments {
  double on_i = 0.0;  // M_ci [N m]
  double on_j = 0.0;  // M_cj [N m]
};

// Small "S" mechanism (eqs. 38-43): a linear torsional spring-damper.
struct SmallSParams {
  double axial_stiffness_n = 0.0;  // E_c A_c [N]
  double pulley_radius_m = 0.0;    // r_sc
  double cable_length_m = 0.0;     // l_sc
  double damping_nmsprad = 0.0;    // c_sc [N m s/rad]
};

// k_sc = 2 E_c A_c r_sc^2 / l_sc (eq. 41) [N m/rad]. Precondition: l_sc > 0.
double SmallSStiffness(const SmallSParams& params);

// M_i = k_sc (theta_j - theta_i) + c_sc (theta_j_dot - theta_i_dot) (eq. 42),
// M_j = k_sc (theta_i - theta_j) + c_sc (theta_i_dot - theta_j_dot) (eq. 43).
ConnectingMoments SmallSMoments(const SmallSParams& params, double theta_i, double theta_j,
                                double theta_i_dot, double theta_j_dot);

// Modified Coulomb friction law of eq. 45 with SPEC §3 correction (a).
struct ModifiedCoulombParams {
  double mu_kinetic = 0.0;    // mu_c
  double mu_static = 0.0;     // mu'_c
  double v_static_mps = 0.0;  // v_s > 0: the stick band
  // v_c_s >= 0: mu'_c falls to mu_c between v_s and v_s + v_c_s (the
  // paper's v_d - v_s, a numerical tolerance there; a physical Stribeck
  // velocity here, docs/model-notes.md). 0: at once.
  double stribeck_velocity_mps = 0.0;
};

// mu_m(v) [1], an odd function of v with mu_m(v) v <= 0 (when mu_c, mu'_c >= 0):
//   |v| > v_d:        -mu_c sgn v
//   v_s <= |v| <= v_d: -[mu'_c + (mu_c - mu'_c) x^2 (3 - 2x)] sgn v,
//                      x = (|v| - v_s) / (v_d - v_s)     (corrected, continuous)
//   |v| < v_s:        mu'_c - 2 mu'_c u^2 (3 - 2u), u = (v + v_s) / (2 v_s)
//                      (the paper's lower branch: +mu'_c at -v_s, 0 at 0, -mu'_c at v_s),
// with v_d = v_s + v_c_s.
// Continuous and C1 at |v| = v_s and |v| = v_d (v_c_s > 0). Preconditions: v_s > 0,
// v_c_s >= 0.
// It is ModifiedCoulombWithMemory at the memory's steady value.
double ModifiedCoulomb(const ModifiedCoulombParams& params, double v);

// The same law split in two (docs/model-notes.md, "frictional memory"): a
// band shape rho(v) that takes the sign of v across the stick band (the
// paper's lower branch divided by -mu'_c, +-1 beyond v_s), and a memory
// z in [0, 1] of how static the contact is:
//   mu_m(v, z) = -[mu_c + (mu'_c - mu_c) z] rho(v).
// z's steady value at slip speed |v| is ConduitMemoryTarget: 1 up to v_s,
// falling as 1 - x^2 (3 - 2x) to 0 at v_d, so that mu_m(v, target(|v|)) is
// eq. 45 exactly. With mu_c = mu'_c the memory has no effect.
// *slope (may be null) is d mu_m / dv at fixed z [s/m], <= 0.
double ModifiedCoulombWithMemory(const ModifiedCoulombParams& params, double v, double memory,
                                 double* slope);
// *slope (may be null) is d target / d|v| [s/m], <= 0.
double ConduitMemoryTarget(const ModifiedCoulombParams& params, double speed, double* slope);

// phi(x) = x / (1 - e^{-x}) [1], evaluated as -x / expm1(-x) so it is accurate
// for small |x|; phi(0) = 1 exactly (the frictionless limit of eqs. 46-53).
// phi(x) e^{-x} = phi(-x) and phi(x) - phi(-x) = x.
double CapstanFactor(double x);

// Large "S" mechanism (eqs. 44-53).
struct LargeSParams {
  double axial_stiffness_n = 0.0;  // E_c A_c [N]
  double pulley_radius_m = 0.0;    // r_lc
  double cable_length_m = 0.0;     // l_lc
  double wrap_angle_rad = 0.0;     // Theta_lc
  double pretension_n = 0.0;       // T_p
  double damping_nmsprad = 0.0;    // c_lc [N m s/rad]
  ModifiedCoulombParams friction;  // mu_c, mu'_c, v_s, v_c_s
};

// Moments and the intermediate quantities of eqs. 49-53.
struct LargeSResult {
  ConnectingMoments moments;     // M_ci (eq. 51), M_cj (eq. 52)
  double friction_i = 0.0;       // M_pi (eq. 50) [N m]
  double friction_j = 0.0;       // M_pj (eq. 53) [N m]
  double stiffness_i = 0.0;      // k_lci (eq. 50) [N m/rad]
  double stiffness_j = 0.0;      // k_lcj (eq. 53) [N m/rad]
  double slip_velocity_1 = 0.0;  // v_tau1 [m/s] (v_tau2 = -v_tau1)
  // -dM_pi/d(theta_dot_i) at fixed memory, equal for both joints' rates and
  // both moments (M_pi = M_pj depends on theta_dot_i + theta_dot_j only):
  // T_p r_lc^2 Theta |d mu_m/dv| / 2 >= 0 [N m s/rad], the conduit's
  // damping across the stick band.
  double conduit_damping = 0.0;
};

// v_tau1 [m/s], the sliding speed of the couple in the conduit (below).
double ConduitSlipVelocity(const LargeSParams& params, double theta_i_dot, double theta_j_dot);

// Evaluates eqs. 45-53 with the sliding speeds
//   v_tau1 = -r_lc (theta_i_dot + theta_j_dot) / 2,  v_tau2 = -v_tau1,
// and mu_m = ModifiedCoulombWithMemory(v, memory) (the memory is a property
// of the contact, so the same for both speeds; eq. 45 as printed is memory
// = ConduitMemoryTarget(|v_tau1|)).
// The minus sign (SPEC §3 correction (b) prints +) is the one that makes the
// friction moments dissipate with eqs. 50 and 53 as written: since
// phi(x) - phi(-x) = x and mu_m is odd, M_pi = M_pj = -T_p r_lc Theta mu_m(v_tau1),
// and with v_tau1 = -r (theta_i_dot + theta_j_dot)/2 their power is
// 2 T_p Theta mu_m(v_tau1) v_tau1 <= 0. With mu_c = mu'_c = 0 the result is
// the small-S law with k = 2 E_c A_c r_lc^2 / l_lc bitwise.
// Preconditions: l_lc > 0, v_s > 0, v_c_s >= 0, memory in [0, 1].
LargeSResult LargeSMoments(const LargeSParams& params, double theta_i, double theta_j,
                           double theta_i_dot, double theta_j_dot, double memory);

// Eqs. 46-53 with a given friction coefficient mu_m of the speed v_tau1
// (mu_m(v_tau2) = -mu_m, as for eq. 45's odd law) and its slope
// d mu_m / d v_tau1 [s/m] (for conduit_damping); LargeSMoments is this at
// ModifiedCoulombWithMemory. params.friction is not read.
LargeSResult LargeSMomentsWithCoefficient(const LargeSParams& params, double theta_i,
                                          double theta_j, double theta_i_dot, double theta_j_dot,
                                          double coefficient, double coefficient_slope);

// Presliding (elastoplastic) conduit friction, for solver.conduit_friction:
// presliding (docs/model-notes.md): the law of PreslidingHoleFriction for
// the couple sliding in its conduit. Each conduit axis carries a presliding
// displacement eta [m] of the couple, and eq. 45's coefficient becomes a
// spring on it,
//   mu_m = -mu'_c eta / eta_max,
// which reaches the current limit mu_z = mu_c + (mu'_c - mu_c) z (memory z)
// at eta_ss = eta_max mu_z / mu'_c. eta follows
//   eta_dot = v - ElastoplasticSlide(|eta| / eta_ss, sgn eta, v, band, h / eta_ss).sliding
// with v = v_tau1: a conduit loaded below its limit does not slide at all
// (eq. 45's stick band lets it creep at up to v_s), at steady sliding mu_m
// is -mu_z sgn v, eq. 45 beyond its bands. Moments then follow
// LargeSMomentsWithCoefficient: M_pi = M_pj = T_p r_lc Theta mu'_c eta / eta_max.
// Preconditions: presliding_displacement_m > 0, band_mps > 0, z in [0, 1].
struct ConduitPreslidingLaw {
  double mu_kinetic = 0.0;                 // mu_c
  double mu_static = 0.0;                  // mu'_c
  double presliding_displacement_m = 0.0;  // eta_max
  double band_mps = 0.0;                   // the yield's ramp (v_eps)
  // h of model smoothing of the relaxation to the limit (ElastoplasticSlide).
  double relaxation_resolution_s = 0.0;
};
struct ConduitPresliding {
  double coefficient = 0.0;  // mu_m [1]
  // d mu_m / d eta = -mu'_c / eta_max [1/m].
  double coefficient_per_displacement = 0.0;
  double rate = 0.0;              // eta_dot [m/s]
  double engaged_fraction = 1.0;  // d eta_dot / dv clamped at >= 0
  double sliding_speed = 0.0;     // v - eta_dot [m/s]
  double load_ratio = 0.0;        // |eta| / eta_ss
};
ConduitPresliding PreslidingConduitFriction(const ConduitPreslidingLaw& law, double v,
                                            double memory, double displacement);

}  // namespace ccsrm::sim::internal
