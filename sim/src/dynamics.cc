#include "dynamics.h"

#include <algorithm>
#include <cmath>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/kinematics.h"
#include "kernels/ale_element.h"
#include "kernels/connecting.h"
#include "kernels/hole_friction.h"
#include "kernels/rigid_body.h"

namespace ccsrm::sim::internal {
namespace {

using Vector4 = Eigen::Vector4d;
using Vector3 = Eigen::Vector3d;

Vector4 Quaternion(const double* q, int offset) {
  return Vector4(q[offset + 3], q[offset + 4], q[offset + 5], q[offset + 6]);
}
Vector3 Position(const double* q, int offset) {
  return Vector3(q[offset], q[offset + 1], q[offset + 2]);
}

// The augmented system is made quasi-definite by -kRegularization on the
// multiplier diagonal, so that a sparse LDL^T exists for any fill-reducing
// ordering (Vanderbei 1995). It perturbs the constraint equations by
// kRegularization * lambda, far below the Baumgarte-stabilised drift.
constexpr double kRegularization = 1e-10;

}  // namespace

// The state an effect may read and the loads it may add during one
// evaluation (effects/effect.h).
class ArmDynamics::EffectLoadsView final : public EffectLoads {
 public:
  explicit EffectLoadsView(ArmDynamics* dynamics) : d_(dynamics) {}
  void Bind(double t, const double* qd) {
    t_ = t;
    qd_ = qd;
    bending_rate_valid_ = false;
  }
  double time() const override { return t_; }
  int num_links() const override { return d_->model_.num_links(); }
  int num_joints() const override { return d_->model_.num_joints(); }
  const Eigen::Vector2d& joint_angle(int joint) const override { return d_->theta_[joint - 1]; }
  const Eigen::Vector2d& joint_rate(int joint) const override { return d_->theta_dot_[joint - 1]; }
  // Joint j turns link j on link j - 1: it belongs to link j's segment.
  int joint_segment(int joint) const override { return d_->model_.link(joint).segment + 1; }
  Vector3 link_velocity(int link) const override {
    return Position(qd_, d_->model_.link_offset(link));
  }
  double link_mass(int link) const override { return d_->model_.link(link).mass_kg; }
  double commanded_bending_rate(int segment, int axis) const override {
    if (!bending_rate_valid_) {
      // The map is built on the first request of the run (4 S kinematic
      // evaluations), so a run that never asks pays nothing.
      if (bending_per_pulled_.size() == 0) {
        bending_per_pulled_ = SegmentBendingPerPulledLength(d_->model_);
        input_rate_.resize(d_->model_.num_cables());
      }
      for (int c = 0; c < d_->model_.num_cables(); ++c) {
        double value, accel;
        d_->inputs_.Evaluate(c, t_, &value, &input_rate_[c], &accel);
      }
      bending_rate_ = bending_per_pulled_ * input_rate_;
      bending_rate_valid_ = true;
    }
    return bending_rate_[2 * (segment - 1) + axis];
  }
  void AddLinkForce(int link, const Vector3& f_W) override {
    d_->force_.segment<3>(d_->model_.link_offset(link)) += f_W;
  }
  void AddJointMoment(int joint, int axis, double moment, double damping) override {
    d_->AddEffectJointMoment(joint, axis, moment, damping);
  }
  void AddDissipation(double power_w) override { d_->dissipation_ += power_w; }

 private:
  ArmDynamics* d_;
  double t_ = 0.0;
  const double* qd_ = nullptr;
  // SegmentBendingPerPulledLength; the inputs' rates [m/s] and the bending
  // rates they command [rad/s] at t_, evaluated on the first request after
  // Bind.
  mutable Eigen::MatrixXd bending_per_pulled_;
  mutable Eigen::VectorXd input_rate_, bending_rate_;
  mutable bool bending_rate_valid_ = false;
};

ArmDynamics::~ArmDynamics() = default;

ArmDynamics::ArmDynamics(const ArmModel& model, const ArmParameters& parameters,
                         const CableInputs& inputs, const SolverConfig& solver)
    : model_(model),
      layout_(model.sparse_layout()),
      inputs_(inputs),
      parameters_(parameters),
      solver_(solver),
      n_(model.num_coordinates()),
      m_(model.sparse_layout().num_constraints()),
      system_(model.sparse_layout(),
              has_stick_slip() ? HoleStickRows::kKept : HoleStickRows::kLeftOut) {
  CCSRM_CHECK(inputs.num_cables() == model.num_cables());
  const ArmConfig& arm = model_.arm();
  ale_.linear_density_kgpm = arm.driving.density_kgpm3 * arm.driving.cross_section_m2;
  ale_.axial_stiffness_n = arm.driving.youngs_modulus_pa * arm.driving.cross_section_m2;
  ale_.rayleigh_beta_s = parameters_.beta;
  ale_.smoothing_step_s = solver_.smoothing_step_s;
  const double connecting_ea = arm.connecting.youngs_modulus_pa * arm.connecting.cross_section_m2;
  num_memory_ = static_cast<int>(layout_.holes().size());
  for (const ConnectingPairModel& pair : model_.connecting_pairs()) {
    PairKernel k;
    k.kind = pair.kind;
    k.joint_i = pair.joint_i;
    if (pair.kind == ConnectingKind::kSmallS) {
      k.small = {connecting_ea, pair.pulley_radius_m, pair.cable_length_m, parameters_.c_sc};
    } else {
      k.large.axial_stiffness_n = connecting_ea;
      k.large.pulley_radius_m = pair.pulley_radius_m;
      k.large.cable_length_m = pair.cable_length_m;
      k.large.wrap_angle_rad = pair.wrap_angle_rad;
      k.large.pretension_n = parameters_.T_p;
      k.large.damping_nmsprad = parameters_.c_lc;
      k.large.friction.mu_kinetic = parameters_.mu_c;
      k.large.friction.mu_static = parameters_.mu_c_s;
      k.large.friction.v_static_mps = solver_.large_s_static_velocity_mps;
      k.large.friction.stribeck_velocity_mps = parameters_.v_c_s;
      k.memory = num_memory_;
      num_memory_ += 2;
    }
    pair_kernels_.push_back(k);
  }
  if (solver_.hole_friction == HoleFrictionModel::kPresliding) {
    presliding_ = num_memory_;
    num_memory_ += static_cast<int>(layout_.holes().size());
  }
  if (solver_.conduit_friction == ConduitFrictionModel::kPresliding) {
    for (PairKernel& k : pair_kernels_) {
      if (k.kind != ConnectingKind::kLargeS) continue;
      k.presliding = num_memory_;
      num_memory_ += 2;
    }
  }

  // Effects: only those that act in the right-hand side are kept, each in
  // the list of the hooks it uses; with every effect off the lists are
  // empty and the evaluation is the model's alone.
  effects_ = MakeEffects(parameters_);
  for (const std::unique_ptr<Effect>& effect : effects_) {
    if (effect->scales_pretension()) pretension_effects_.push_back(effect.get());
    if (effect->deflects_couples()) deflection_effects_.push_back(effect.get());
    if (effect->adds_loads()) load_effects_.push_back(effect.get());
  }
  // The couples' energy, k ∫D, is that of one deflection law.
  CCSRM_CHECK(deflection_effects_.size() <= 1);
  effect_loads_ = std::make_unique<EffectLoadsView>(this);

  const std::size_t holes = layout_.holes().size();
  modes_.assign(holes, has_stick_slip() ? HoleMode::kStuck : HoleMode::kSlipUp);
  reports_.assign(holes, HoleReport{});
  memory_rate_.assign(num_memory_, 0.0);
  rows_.resize(m_);
  embedding_.resize(layout_.num_cable_nodes());
  force_.resize(n_);
  tension_.resize(model_.num_cables());
  for (int c = 0; c < model_.num_cables(); ++c)
    tension_[c].assign(model_.cables()[c].num_elements(), 0.0);
  rotation_.resize(model_.num_links());
  rate_matrix_.resize(model_.num_links());
  omega_.resize(model_.num_links());
  point_kinematics_.resize(model_.num_links());
  relative_rotation_.resize(model_.num_joints());
  joint_moment_.resize(model_.num_joints());
  theta_.resize(model_.num_joints());
  theta_dot_.resize(model_.num_joints());

  const Eigen::VectorXd y0 = InitialState();
  for (int c = 0; c < model_.num_cables(); ++c) {
    for (std::size_t k = 0; k < model_.cables()[c].nodes.size(); ++k) {
      initial_s_.push_back(y0[model_.node_offset(c, static_cast<int>(k)) + 3]);
    }
  }
  stuck_s_.resize(holes);
  for (std::size_t h = 0; h < holes; ++h) {
    const HoleNodeRef& hole = layout_.holes()[h];
    stuck_s_[h] = y0[model_.node_offset(hole.cable, hole.node) + 3];
  }
  zero_rates_.assign(n_, 0.0);
  rest_memory_.assign(y0.data() + memory_offset(), y0.data() + state_size());
  settled_now_ = InitialSettledFriction();
  branches_.hole.assign(holes, 0);
  branches_.conduit.assign(2 * pair_kernels_.size(), 0);
}

const char* ArmDynamics::StateEntryKind(int k) const {
  if (k < 2 * n_) {
    const int q = k % n_;
    const bool velocity = k >= n_;
    for (const HoleNodeRef& hole : layout_.holes()) {
      if (velocity && q == model_.node_offset(hole.cable, hole.node) + 3) return "hole slip speed";
    }
    const bool link = q >= model_.link_offset(1);  // nodes first, then links
    if (velocity) return link ? "link velocity" : "node velocity";
    return link ? "link coordinate" : "node coordinate";
  }
  if (k == 2 * n_) return "energy";
  const int memory = k - memory_offset();
  if (memory < static_cast<int>(layout_.holes().size())) return "hole memory";
  if (presliding_ >= 0 && memory >= presliding_ &&
      memory < presliding_ + static_cast<int>(layout_.holes().size())) {
    return "hole presliding";
  }
  for (const PairKernel& pair : pair_kernels_) {
    if (pair.presliding >= 0 && (memory == pair.presliding || memory == pair.presliding + 1)) {
      return "conduit presliding";
    }
  }
  return "conduit memory";
}

std::vector<double> ArmDynamics::ErrorScales() const {
  // Coordinates get absolute_tolerance; velocities that over
  // velocity_tolerance_time_s (an error that moves a position by
  // absolute_tolerance over that time).
  std::vector<double> scale(state_size(), 1.0);
  for (int k = n_; k < 2 * n_; ++k) scale[k] = 1.0 / solver_.velocity_tolerance_time_s;
  // The smoothed hole friction is a function of the slip speed across a stick
  // band of v_eps (1e-6 m/s): the slip speeds are resolved to a tenth of it,
  // or the friction force follows the step sequence rather than the state.
  // The presliding law's force is its displacement's; the slip speed enters
  // only its yield, which slides at the limit on loading (s_dot sgn(xi) > 0,
  // joined over v_eps): slip-speed noise beyond v_eps at a node held at its
  // limit would ratchet it along, so it needs v_eps. (A tenth of it, as
  // before issue 43, left the 60 s hold drift and the paper's case 2 as they
  // were, and held fast motions' steps 1.8x shorter.)
  if (solver_.hole_friction == HoleFrictionModel::kSmoothed ||
      solver_.hole_friction == HoleFrictionModel::kPresliding) {
    const double resolution =
        solver_.hole_friction == HoleFrictionModel::kSmoothed ? 0.1 : 1.0;  // of v_eps
    const double slip_scale =
        resolution * solver_.stick_velocity_tolerance_mps / solver_.absolute_tolerance;
    for (const HoleNodeRef& hole : layout_.holes()) {
      double& s = scale[n_ + model_.node_offset(hole.cable, hole.node) + 3];
      s = std::min(s, slip_scale);
    }
  }
  // A memory z in [0, 1] weighs the static excess mu' - mu (~0.1 or less):
  // an error of 1e3 absolute_tolerance in z moves a friction coefficient by
  // ~1e-5 relative, the relative tolerance of everything else.
  for (int k = memory_offset(); k < state_size(); ++k) scale[k] = 1e3;
  // A presliding displacement (up to ~xi_f) is resolved to a hundredth of
  // xi_f: its force, k xi, then to a hundredth of the capstan force.
  if (presliding_ >= 0) {
    const double xi_scale = 0.01 * parameters_.xi_f / solver_.absolute_tolerance;
    for (std::size_t h = 0; h < layout_.holes().size(); ++h)
      scale[memory_offset() + presliding_ + h] = xi_scale;
  }
  // Likewise a conduit's, to a hundredth of xi_c.
  const double eta_scale = 0.01 * parameters_.xi_c / solver_.absolute_tolerance;
  for (const PairKernel& k : pair_kernels_) {
    if (k.presliding < 0) continue;
    scale[memory_offset() + k.presliding] = scale[memory_offset() + k.presliding + 1] = eta_scale;
  }
  return scale;
}

Eigen::VectorXd ArmDynamics::InitialState() const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(state_size());
  const std::vector<LinkPose> poses =
      ForwardKinematics(model_, JointAngles(model_.num_joints(), Eigen::Vector2d::Zero()));
  for (int i = 1; i <= model_.num_links(); ++i) {
    const int o = model_.link_offset(i);
    y.segment<3>(o) = poses[i - 1].p_WB;
    y[o + 3] = 1.0;  // e = (1, 0, 0, 0): body axes along the world axes
  }
  // Uniform pre-strain: T_d0 = EA eps0 (eq. 13), so each element's
  // unstretched length is its chord / sqrt(1 + 2 eps0) (Green strain); an
  // effect may change a segment's (segment_pretension).
  for (int c = 0; c < model_.num_cables(); ++c) {
    double pretension = parameters_.T_d0;
    for (const std::unique_ptr<Effect>& effect : effects_)
      pretension += effect->DrivingPretensionChange(model_.cables()[c].segment + 1);
    const double eps0 = pretension / ale_.axial_stiffness_n;
    const double stretch = std::sqrt(1.0 + 2.0 * eps0);
    double s = 0.0;
    Vector3 previous;
    for (int k = 0; k < static_cast<int>(model_.cables()[c].nodes.size()); ++k) {
      const Vector3 p = CableNodePosition(model_, c, k, poses);
      if (k > 0) s += (p - previous).norm() / stretch;
      const int o = model_.node_offset(c, k);
      y.segment<3>(o) = p;
      y[o + 3] = s;
      previous = p;
    }
  }
  // At rest every contact has its full static friction.
  y.tail(num_memory_).setOnes();
  // ... and no presliding displacement.
  if (presliding_ >= 0) {
    y.segment(memory_offset() + presliding_, layout_.holes().size()).setZero();
  }
  for (const PairKernel& k : pair_kernels_) {
    if (k.presliding >= 0) y.segment<2>(memory_offset() + k.presliding).setZero();
  }
  return y;
}

bool ArmDynamics::Evaluate(double t, const double* y, double* ydot) {
  ++evaluations_;
  failure_.clear();
  const double* q = y;
  const double* qd = y + n_;
  system_.Clear();
  force_.setZero();
  dissipation_ = kinetic_ = elastic_ = 0.0;

  ComputeLinkKinematics(q, qd);                  // eqs. 21-22, 26
  if (!AddCableElements(q, qd)) return false;    // eqs. 1-6, 13, 17-20
  AddHoleFriction(q, qd, y + memory_offset());   // eqs. 8-12, stick-slip
  ComputeJointAngles();                          // eqs. 23-29
  AddConnectingMoments(t, y + memory_offset());  // eqs. 38-53
  AddBackboneMoments();                          // an elastic backbone (BackboneGeometry)
  AddEffectLoads(t, qd);                         // effects/effect.h
  ApplyJointMoments(q);                          // eqs. 54-58
  AddLinkInertia(q, qd);                         // eqs. 30-34
  AddConstraints(t, q, qd);                      // eqs. 35-37, 61-63
  if (!SolveAugmentedSystem()) return false;     // eqs. 64-68
  return FinishDerivative(qd, ydot);
}

// Rotation A(e), rate matrix G(e) and body angular velocity w' = G e_dot
// of every link.
void ArmDynamics::ComputeLinkKinematics(const double* q, const double* qd) {
  for (int i = 1; i <= model_.num_links(); ++i) {
    const int o = model_.link_offset(i);
    const Vector4 e = Quaternion(q, o), ed = Quaternion(qd, o);
    rotation_[i - 1] = RotationFromQuaternion(e);
    rate_matrix_[i - 1] = QuaternionRateMatrix(e);
    omega_[i - 1] = rate_matrix_[i - 1] * ed;
    point_kinematics_[i - 1] = BodyPointKinematics(e, ed);
  }
}

// Driving-cable ALE elements: mass, the additional inertia term Q_p, the
// smoothed elastic force and mass, tensions; the power that Rayleigh
// damping and smoothing take out is booked once q_dd is known.
bool ArmDynamics::AddCableElements(const double* q, const double* qd) {
  double* values = system_.values();
  element_rates_.clear();
  int element = 0;
  for (int c = 0; c < model_.num_cables(); ++c) {
    const int elements = model_.cables()[c].num_elements();
    for (int e = 0; e < elements; ++e, ++element) {
      const int o1 = model_.node_offset(c, e), o2 = model_.node_offset(c, e + 1);
      const int cols[8] = {o1, o1 + 1, o1 + 2, o2, o2 + 1, o2 + 2, o1 + 3, o2 + 3};
      Vector8d qe, qde;
      for (int k = 0; k < 8; ++k) {
        qe[k] = q[cols[k]];
        qde[k] = qd[cols[k]];
      }
      const double ds = qe[7] - qe[6];
      if (!(ds > 0.0) || !std::isfinite(ds)) {
        failure_ = "cable " + std::to_string(c + 1) + " element " + std::to_string(e + 1) +
                   " collapsed (material length " + std::to_string(ds) + " m)";
        return false;
      }
      const AleElementTerms terms = EvaluateAleElement(ale_, qe, qde);
      const int* index = layout_.element_block(element);
      AddSymmetricBlock(terms.mass + terms.elastic_mass, index, values);
      Vector8d f = terms.ale_inertia_force + terms.elastic_force;
      if (settled_from_ != nullptr) {
        f -= (ds * ale_.axial_stiffness_n * settled_element_stiffness_ * terms.strain) *
             terms.strain_jacobian.transpose();
      }
      for (int a = 0; a < 8; ++a) force_[cols[a]] += f[a];
      tension_[c][e] = terms.tension;
      kinetic_ += terms.kinetic_energy;
      elastic_ += ale_.axial_stiffness_n * terms.strain_energy_density * ds;
      // The power the non-elastic part of the applied stress takes out,
      // Δs eps_dot (sigma - EA phi): the smoothing and Rayleigh terms, or,
      // for a stretched element that would push and carries nothing, the
      // elastic energy it lets go without doing work.
      const double scale = ds * ale_.axial_stiffness_n * terms.strain_rate;
      ElementRate rate;
      rate.coefficient =
          terms.pushing
              ? -scale * UnilateralElasticStrain(terms.strain, ale_.slack_toe_strain).value
              : scale * (terms.smoothed_damping_s * terms.strain_rate +
                         terms.smoothed_inertia_s2 * terms.strain_accel_bias);
      rate.gamma_term = scale * terms.smoothed_inertia_s2;
      rate.jac = terms.strain_jacobian;
      std::copy(cols, cols + 8, rate.cols);
      element_rates_.push_back(rate);
    }
  }
  return true;
}

// Capstan friction on the material coordinate of the hole nodes (eqs. 9,
// 11) with the Stribeck coefficient of HoleFrictionCoefficient, and for
// every node the wrap angle (eq. 12) and limiting static friction (eq. 10).
// kEvents: on every slipping node; a stuck node's friction is its stick
// constraint's reaction, known after the solve. kSmoothed: one smooth law
// of the slip speed and the frictional memory on every node (its memory
// follows the Stribeck target over tau_f; with tau_f = 0 it is the target),
// whose slope is smoothed over h like the elastic forces (eqs. 14-16): the
// force sees the slip speed averaged over the step, v + (h/2) v_dot, which
// adds -(h/2) dF/dv to the node's mass.
void ArmDynamics::AddHoleFriction(const double* q, const double* qd, const double* memory) {
  const std::vector<HoleNodeRef>& holes = layout_.holes();
  const HoleFrictionLaw law{parameters_.mu, parameters_.mu_s, parameters_.v_s,
                            solver_.stick_velocity_tolerance_mps};
  double* values = system_.values();
  hole_smoothing_power_.clear();
  for (std::size_t h = 0; h < holes.size(); ++h) {
    const HoleNodeRef& hole = holes[h];
    const int o = model_.node_offset(hole.cable, hole.node);
    const Vector3 r_prev = Position(q, model_.node_offset(hole.cable, hole.node - 1));
    const Vector3 r_next = Position(q, model_.node_offset(hole.cable, hole.node + 1));
    HoleReport& report = reports_[h];
    report.s_dot = qd[o + 3];
    report.wrap_angle = WrapAngle(r_prev, Position(q, o), r_next);
    const double t_before = tension_[hole.cable][hole.node - 1];
    const double t_after = tension_[hole.cable][hole.node];
    report.friction_limit =
        LimitingStaticFriction(t_before, t_after, parameters_.mu_s, report.wrap_angle);
    report.required_friction = 0.0;
    memory_rate_[h] = 0.0;
    const double v = qd[o + 3];
    if (presliding_ >= 0) {
      const double xi =
          settled_from_ != nullptr
              ? SettledHoleDisplacement(static_cast<int>(h), q[o + 3], report.wrap_angle)
              : memory[presliding_ + h];
      AddPreslidingFriction(static_cast<int>(h), o + 3, t_before, v, memory, xi);
      continue;
    }
    if (solver_.hole_friction == HoleFrictionModel::kSmoothed) {
      double target_slope = 0.0;
      const double target = HoleMemoryTarget(law, v, &target_slope);
      const bool remembers = parameters_.tau_f > 0.0;
      const double z = remembers ? memory[h] : target;
      if (remembers) memory_rate_[h] = (target - z) / parameters_.tau_f;
      const HoleFrictionForce f = SmoothedHoleFriction(law, t_before, report.wrap_angle, v, z);
      report.required_friction = f.force;
      force_[o + 3] += f.force;
      dissipation_ -= f.force * v;
      // dF/dv at fixed memory falls across the stick band (dissipative).
      // Without memory the Stribeck fall adds dF/dz dz/dv, which rises; a
      // negative added mass would be unphysical, so only a falling total is
      // smoothed.
      // The fall lies beyond the band, where r(v) = sgn(v): dF/dz =
      // -(F + T_b) (mu' - mu) theta sgn(v) and dz/dv = target' sgn(v).
      double slope = f.slope;
      if (!remembers) {
        slope -= (f.force + std::max(0.0, t_before)) * (law.mu_static - law.mu_kinetic) *
                 report.wrap_angle * target_slope;
      }
      const double added_mass = -0.5 * solver_.smoothing_step_s * std::min(0.0, slope);
      if (added_mass > 0.0) {
        values[layout_.hole_material_diagonal(static_cast<int>(h))] += added_mass;
        hole_smoothing_power_.push_back({o + 3, added_mass * v});
      }
      continue;
    }
    // Where even the static limit is below the force tolerance (a cable
    // running nearly straight through the hole) friction is negligible and
    // left out, so that its direction need not follow a slip speed that
    // hovers around zero.
    const bool negligible = report.friction_limit < solver_.stick_force_tolerance_n;
    if (!has_stick_slip() || modes_[h] == HoleMode::kStuck || negligible) continue;
    const double sigma = modes_[h] == HoleMode::kSlipUp ? 1.0 : -1.0;
    const double mu = HoleFrictionCoefficient(law, v, nullptr);
    const double f = HoleSlipFriction(t_before, mu, report.wrap_angle, sigma);
    force_[o + 3] += f;
    dissipation_ -= f * v;
  }
}

// Presliding friction on hole h's material coordinate (column s_col, slip
// speed v), an elastoplastic spring on its displacement xi
// (PreslidingHoleFriction), with its memory as for kSmoothed. Model
// smoothing as for the elastic forces (eqs. 14-16): the force sees xi
// averaged over the step, xi + (h/2) xi_dot + (h^2/6) xi_dd, linearised
// with g = d xi_dot / d s_dot >= 0 (the share of s_dot that presliding
// takes up): a damper k g h/2 on s_dot and k (h^2/6) g added to the
// node's mass, which put the spring's mode (k ~ 1e5 N/m against 1e-4 kg)
// near sqrt(6)/h. Linearised rather than k (h/2) xi_dot: inside the band
// v_eps, at the limit, xi_dot falls as s_dot rises (g < 0 before the clamp),
// and that damper would feed energy in. The spring's energy joins the
// elastic energy; the plastic and the smoothing power are dissipated.
void ArmDynamics::AddPreslidingFriction(int h, int s_col, double t_before, double v,
                                        const double* memory, double xi) {
  const PreslidingLaw law = HolePreslidingLaw(PreslidingRelaxationResolution());
  HoleReport& report = reports_[h];
  const bool remembers = parameters_.tau_f > 0.0;
  const double target = HoleMemoryTarget(law.friction, v, nullptr);
  const double z = remembers ? memory[h] : target;
  if (remembers) memory_rate_[h] = (target - z) / parameters_.tau_f;
  const PreslidingFriction f = PreslidingHoleFriction(law, t_before, report.wrap_angle, v, z, xi);
  memory_rate_[presliding_ + h] = f.rate;
  report.required_friction = f.force;
  report.sliding_speed = f.sliding_speed;
  const double step = solver_.smoothing_step_s;
  const double damping_force = -0.5 * step * f.stiffness * f.engaged_fraction * v;
  force_[s_col] += f.force + damping_force;
  elastic_ += 0.5 * f.stiffness * xi * xi;
  dissipation_ += f.plastic_power - damping_force * v;
  const double added_mass = step * step / 6.0 * f.stiffness * f.engaged_fraction;
  if (added_mass > 0.0) {
    system_.values()[layout_.hole_material_diagonal(h)] += added_mass;
    hole_smoothing_power_.push_back({s_col, added_mass * v});
  }
}

// Relative rotations, universal-joint angles and rates of every joint.
void ArmDynamics::ComputeJointAngles() {
  for (int j = 1; j <= model_.num_joints(); ++j) {
    Eigen::Matrix3d& rel = relative_rotation_[j - 1];
    rel = j > 1 ? Eigen::Matrix3d(rotation_[j - 2].transpose() * rotation_[j - 1]) : rotation_[0];
    theta_[j - 1] = UniversalJointAngles(rel);
    const Vector3 w_parent = j > 1 ? omega_[j - 2] : Vector3::Zero();
    theta_dot_[j - 1] = UniversalJointRates(theta_[j - 1][1],
                                            RelativeAngularVelocity(rel, omega_[j - 1], w_parent));
  }
}

Eigen::Matrix<double, 1, 4> ArmDynamics::JointRateRow(int k, int link, int axis) const {
  const Matrix32d b = UniversalJointRateMatrix(theta_[k - 1][1]);
  if (link == k) return (b.transpose() * rate_matrix_[link - 1]).row(axis);
  if (link == k - 1) {
    return -(b.transpose() * relative_rotation_[k - 1].transpose() * rate_matrix_[link - 1])
                .row(axis);
  }
  return Eigen::Matrix<double, 1, 4>::Zero();
}

// Small-S and large-S moments on both joints of every pair and axis and
// their model smoothing (added mass), into the joint moments. Effects may
// relax T_p (PretensionFactor) and put a dead band into the springs
// (Deflect).
void ArmDynamics::AddConnectingMoments(double t, const double* memory) {
  double* values = system_.values();
  const double h = solver_.smoothing_step_s;
  std::fill(joint_moment_.begin(), joint_moment_.end(), Eigen::Vector2d::Zero());
  auto rate_row = [&](int k, int link, int axis) { return JointRateRow(k, link, axis); };
  double pretension_factor = 1.0;
  for (const Effect* effect : pretension_effects_) pretension_factor *= effect->PretensionFactor(t);
  const Effect* deflection = deflection_effects_.empty() ? nullptr : deflection_effects_[0];
  smoothing_power_.clear();
  for (std::size_t p = 0; p < pair_kernels_.size(); ++p) {
    const PairKernel& pair = pair_kernels_[p];
    const std::vector<int>& links = layout_.pair_links(static_cast<int>(p));
    const int i = pair.joint_i - 1, j = pair.joint_i;
    const int width = 4 * static_cast<int>(links.size());
    LargeSParams relaxed;
    const LargeSParams* large_params = &pair.large;
    if (!pretension_effects_.empty() && pair.kind == ConnectingKind::kLargeS) {
      relaxed = pair.large;
      relaxed.pretension_n *= pretension_factor;
      large_params = &relaxed;
    }
    for (int axis = 0; axis < 2; ++axis) {
      const double th_i = theta_[i][axis];
      const double rt_i = theta_dot_[i][axis], rt_j = theta_dot_[j][axis];
      // The spring sees th_j - th_i, or its dead-banded deflection.
      CoupleDeflection bent;
      double th_j = theta_[j][axis];
      if (deflection != nullptr) {
        bent = deflection->Deflect(th_j - th_i);
        th_j = th_i + bent.value;
      }
      ConnectingMoments m;
      // N·m/rad: the frictionless couple (energy bookkeeping), and the
      // stiffness it has right now (smoothing).
      double k_conservative = 0.0, k_now = 0.0;
      double damping = 0.0;  // N·m·s/rad
      // (h/2) C on (theta_dot_i, theta_dot_j): smoothing of the conduit friction.
      Eigen::Matrix2d friction_smoothing = Eigen::Matrix2d::Zero();
      if (pair.kind == ConnectingKind::kSmallS) {
        m = SmallSMoments(pair.small, th_i, th_j, rt_i, rt_j);
        k_conservative = k_now = SmallSStiffness(pair.small);
        if (deflection != nullptr) k_now *= bent.slope;
        damping = pair.small.damping_nmsprad;
      } else {
        // The conduit's frictional memory follows eq. 45's static-to-kinetic
        // target over tau_c_f; with tau_c_f = 0 it is the target (eq. 45).
        const ModifiedCoulombParams& law = large_params->friction;
        const double v_tau1 = ConduitSlipVelocity(*large_params, rt_i, rt_j);
        const double speed = std::abs(v_tau1);
        double target_slope = 0.0;
        const double target = ConduitMemoryTarget(law, speed, &target_slope);
        const bool remembers = parameters_.tau_c_f > 0.0;
        const int z_index = pair.memory + axis;
        const double z = remembers ? memory[z_index] : target;
        memory_rate_[z_index] = remembers ? (target - z) / parameters_.tau_c_f : 0.0;
        LargeSResult large;
        if (pair.presliding < 0) {
          large = LargeSMoments(*large_params, th_i, th_j, rt_i, rt_j, z);
        } else {
          // Presliding (model notes row 25): eq. 45's coefficient is a spring
          // on the couple's presliding displacement eta, M_p = K eta with
          // K = T_p r Theta mu'_c / xi_c [N m/m], on both joints.
          const ConduitPreslidingLaw presliding_law{law.mu_kinetic, law.mu_static, parameters_.xi_c,
                                                    solver_.stick_velocity_tolerance_mps,
                                                    PreslidingRelaxationResolution()};
          const int eta_index = pair.presliding + axis;
          const double eta = settled_from_ != nullptr
                                 ? SettledConduitDisplacement(static_cast<int>(p), axis,
                                                              theta_[i][axis], theta_[j][axis])
                                 : memory[eta_index];
          const ConduitPresliding f = PreslidingConduitFriction(presliding_law, v_tau1, z, eta);
          memory_rate_[eta_index] = f.rate;
          large = LargeSMomentsWithCoefficient(*large_params, th_i, th_j, rt_i, rt_j, f.coefficient,
                                               0.0);
          const double r = pair.large.pulley_radius_m;
          const double spring = -large_params->pretension_n * r * pair.large.wrap_angle_rad *
                                f.coefficient_per_displacement;
          // Model smoothing as for the holes' presliding (row 24): with
          // eta_dot ~ g v and v = -(r/2)(theta_dot_i + theta_dot_j), the
          // spring is k [1 1; 1 1] on (theta_i, theta_j), k = spring g r/2;
          // averaged over h it adds the damper (h/2) k on the pair's common
          // rate and (h^2/6) k [1 1; 1 1] to the mass.
          const double k_common = 0.5 * spring * f.engaged_fraction * r;
          const double common_damping = -0.5 * h * k_common * (rt_i + rt_j);
          large.moments.on_i += common_damping;
          large.moments.on_j += common_damping;
          friction_smoothing.setConstant(h * h / 6.0 * k_common);
          // Its energy K eta^2 / r (the moments' power is -2 K eta v / r) is
          // elastic; what the moments' power leaves over it is the plastic
          // power 2 K eta (v - eta_dot) / r >= 0, dissipated.
          elastic_ += spring * eta * eta / r;
          dissipation_ -= 2.0 * spring * eta * f.rate / r;
        }
        m = large.moments;
        k_conservative = SmallSStiffness({pair.large.axial_stiffness_n, pair.large.pulley_radius_m,
                                          pair.large.cable_length_m, 0.0});
        k_now = large.stiffness_i;
        if (deflection != nullptr) k_now *= bent.slope;
        damping = pair.large.damping_nmsprad;
        if (pair.presliding < 0 && solver_.smooth_connecting_friction && h > 0.0) {
          // Model smoothing of the conduit friction (interpretation beyond
          // the paper, as eqs. 14-16 do for strain): the friction moments
          // M_pi = M_pj see the rates averaged over h, theta_dot + (h/2)
          // theta_dd. Linearised, that adds (h/2) c [1 1; 1 1] to the mass on
          // (theta_dot_i, theta_dot_j), c = -dM_p/d(theta_dot), and takes the
          // microsecond time constant of eq. 45's stick band out of the
          // explicit integration. At fixed memory c >= 0; without memory the
          // static-to-kinetic fall adds a negative part, and only a
          // dissipative total is smoothed (a negative added mass is
          // unphysical). The rate dependence of the capstan stiffness k_lc is
          // not smoothed: its form is not symmetric and vanishes with mu_m.
          double c = large.conduit_damping;
          if (!remembers) {
            const double tp_r_theta =
                large_params->pretension_n * pair.large.pulley_radius_m * pair.large.wrap_angle_rad;
            c += 0.5 * tp_r_theta * pair.large.pulley_radius_m * (law.mu_static - law.mu_kinetic) *
                 target_slope;
          }
          friction_smoothing.setConstant(0.5 * h * std::max(0.0, c));
        }
      }
      // Model smoothing of the connecting spring and damper (interpretation
      // beyond the paper, after eqs. 14-20): the moments see the
      // acceleration part of the average over h, k (h^2/6) d_dd + c (h/2)
      // d_dd (d = theta_j - theta_i), which adds mu J_d^T J_d to the mass and
      // caps the couple's torsional modes near sqrt(6)/h. The (h/2) d_dot
      // part is left out: it would add a damper of k h/2 (0.8 N·m·s/rad, 16x
      // c) and change the arm's slow transients by ~10 %. The bias of d_dd
      // (quadratic in the rates, ~1e-7 N·m here) is left out too.
      const double smoothing_mass =
          solver_.smooth_connecting_elasticity ? k_now * h * h / 6.0 + damping * h / 2.0 : 0.0;
      if (smoothing_mass > 0.0 || !friction_smoothing.isZero(0.0)) {
        Eigen::Matrix<double, 2, 12> jac = Eigen::Matrix<double, 2, 12>::Zero();
        for (std::size_t l = 0; l < links.size(); ++l) {
          jac.block<1, 4>(0, 4 * l) = rate_row(pair.joint_i, links[l], axis);
          jac.block<1, 4>(1, 4 * l) = rate_row(pair.joint_i + 1, links[l], axis);
        }
        // Both smoothings in one 2x2 form on (theta_dot_i, theta_dot_j).
        Eigen::Matrix2d form = friction_smoothing;
        form += smoothing_mass * (Eigen::Matrix2d() << 1.0, -1.0, -1.0, 1.0).finished();
        // jac^T form jac, its packed lower triangle only (a 12 x 12
        // product would go through Eigen's general matrix kernel).
        const Eigen::Matrix<double, 12, 2> jac_form = jac.transpose() * form;
        const int* block = layout_.pair_block(static_cast<int>(p));
        for (int a = 0, k = 0; a < width; ++a)
          for (int b = 0; b <= a; ++b) values[block[k++]] += jac_form.row(a).dot(jac.col(b));
        // The smoothing moments -form * theta_dd do work on the rates; it is
        // booked as dissipation once q_dd is known.
        SmoothingPower power;
        power.weights = (Eigen::RowVector2d(rt_i, rt_j) * form * jac).transpose();
        for (std::size_t l = 0; l < links.size(); ++l)
          for (int a = 0; a < 4; ++a) power.cols[4 * l + a] = model_.link_offset(links[l]) + 3 + a;
        power.count = width;
        smoothing_power_.push_back(power);
      }
      joint_moment_[i][axis] += m.on_i;
      joint_moment_[j][axis] += m.on_j;
      const double d_theta = th_j - th_i, d_rate = rt_j - rt_i;
      // With a dead band the spring's energy is k ∫D and d_theta is D(d).
      elastic_ += deflection == nullptr ? 0.5 * k_conservative * d_theta * d_theta
                                        : k_conservative * bent.energy;
      // Dissipated = -(power of the moments) - d/dt(conservative energy).
      dissipation_ += -(m.on_i * rt_i + m.on_j * rt_j) - k_conservative * d_theta * d_rate;
    }
  }
}

// Forces and moments of the effects that are on (none: nothing to do).
void ArmDynamics::AddEffectLoads(double t, const double* qd) {
  if (load_effects_.empty()) return;
  effect_loads_->Bind(t, qd);
  for (const Effect* effect : load_effects_) effect->AddLoads(effect_loads_.get());
}

// An elastic backbone's bending moments, M = -k theta - c theta_dot on
// every joint and axis of its segments (k = k_b E I / l, c = c_b). Its
// energy k theta^2 / 2 is elastic, c theta_dot^2 dissipated. Model smoothing
// as for the connecting springs (smooth_connecting_elasticity): the moment
// sees the acceleration part of its average over h, (h^2/6) k + (h/2) c on
// the joint's inertia, which caps the joints' bending modes (a stiff rod on
// light disks) near sqrt(6)/h.
void ArmDynamics::AddBackboneMoments() {
  const double h = solver_.smoothing_step_s;
  for (int j = 1; j <= model_.num_joints(); ++j) {
    const double k = parameters_.k_b * model_.backbone_stiffness_nmprad(j);
    if (k == 0.0) continue;
    const double c = parameters_.c_b;
    for (int axis = 0; axis < 2; ++axis) {
      const double angle = theta_[j - 1][axis], rate = theta_dot_[j - 1][axis];
      joint_moment_[j - 1][axis] += -k * angle - c * rate;
      elastic_ += 0.5 * k * angle * angle;
      dissipation_ += c * rate * rate;
      if (solver_.smooth_connecting_elasticity && h > 0.0) {
        AddJointSmoothingMass(j, axis, k * h * h / 6.0 + c * h / 2.0);
      }
    }
  }
}

void ArmDynamics::AddEffectJointMoment(int joint, int axis, double moment, double damping) {
  joint_moment_[joint - 1][axis] += moment;
  const double h = solver_.smoothing_step_s;
  if (!(damping > 0.0) || !(h > 0.0)) return;
  // Model smoothing of the damping (as for the conduit friction, model
  // notes row 6): the moment sees theta_dot + (h/2) theta_dd, which adds
  // (h/2) damping to the joint's inertia.
  AddJointSmoothingMass(joint, axis, 0.5 * h * damping);
}

// mass J^T J into the mass matrix, J the joint rate's row over the
// quaternions of links joint - 1 and joint, and the power of the smoothing
// moment -mass theta_dd booked as dissipation. The joint's orientation row
// (eq. 37) spans exactly those columns, so its block holds the entries.
void ArmDynamics::AddJointSmoothingMass(int joint, int axis, double mass) {
  const int r = m_ - 4 * model_.num_joints() + 4 * (joint - 1) + 3;
  const ConstraintRowLayout& cols = layout_.rows()[r];
  const int first_link = joint > 1 ? joint - 1 : joint;
  const int width = cols.count;
  CCSRM_CHECK(width == 4 * (joint - first_link + 1) &&
              cols.cols[0] == model_.link_offset(first_link) + 3);
  Eigen::Matrix<double, 1, 8> jac = Eigen::Matrix<double, 1, 8>::Zero();
  for (int link = first_link, l = 0; link <= joint; ++link, ++l) {
    jac.segment<4>(4 * l) = JointRateRow(joint, link, axis);
  }
  double* values = system_.values();
  const int* block = layout_.row_block(r);
  for (int a = 0, k = 0; a < width; ++a)
    for (int b = 0; b <= a; ++b) values[block[k++]] += mass * jac[a] * jac[b];
  // The smoothing moment -mass theta_dd does work on the rate; booked once
  // q_dd is known.
  SmoothingPower power;
  power.weights.setZero();
  for (int a = 0; a < width; ++a) {
    power.weights[a] = theta_dot_[joint - 1][axis] * mass * jac[a];
    power.cols[a] = cols.cols[a];
  }
  power.count = width;
  smoothing_power_.push_back(power);
}

// The joint moments mapped onto the two links' quaternions (eqs. 54-58).
void ArmDynamics::ApplyJointMoments(const double* q) {
  const std::vector<Eigen::Matrix3d>& rel = relative_rotation_;
  for (int j = 1; j <= model_.num_joints(); ++j) {
    if (joint_moment_[j - 1].isZero(0.0)) continue;
    const JointBodyMoments body =
        JointMomentsToBodies(rel[j - 1], theta_[j - 1][1], joint_moment_[j - 1]);
    const int oc = model_.link_offset(j);
    force_.segment<4>(oc + 3) += QuaternionMomentForce(Quaternion(q, oc), body.on_child_body);
    if (j > 1) {
      const int op = model_.link_offset(j - 1);
      force_.segment<4>(op + 3) += QuaternionMomentForce(Quaternion(q, op), body.on_parent_body);
    }
  }
}

// Rigid links: translational mass, the quaternion mass and velocity terms,
// gravity.
void ArmDynamics::AddLinkInertia(const double* q, const double* qd) {
  double* values = system_.values();
  for (int i = 1; i <= model_.num_links(); ++i) {
    const LinkModel& link = model_.link(i);
    const int o = model_.link_offset(i);
    const Vector4 e = Quaternion(q, o), ed = Quaternion(qd, o);
    const Eigen::Matrix3d inertia = link.inertia_kgm2.asDiagonal();
    const int* index = layout_.link_block(i);
    for (int a = 0; a < 3; ++a) values[index[a]] += link.mass_kg;
    AddSymmetricBlock(QuaternionMass(e, inertia), index + 3, values);
    force_.segment<3>(o) += link.mass_kg * model_.arm().gravity_mps2;
    force_.segment<4>(o + 3) += QuaternionVelocityForce(e, ed, inertia);
    kinetic_ += 0.5 * link.mass_kg * Position(qd, o).squaredNorm() +
                0.5 * omega_[i - 1].dot(inertia * omega_[i - 1]);
  }
}

// The constraint rows with Baumgarte stabilisation, added to the augmented
// matrix as Phi_q^T Phi_q, the coupling blocks and the regularised
// multiplier diagonal; a stick constraint that is off gets D = 1 instead.
void ArmDynamics::AddConstraints(double t, const double* q, const double* qd) {
  FillConstraints(t, q, qd, true);
  double* values = system_.values();
  Eigen::VectorXd& rhs = system_.rhs();
  rhs.head(n_) = force_;
  const std::vector<ConstraintRowLayout>& layout_rows = layout_.rows();
  for (int r = 0; r < m_; ++r) {
    const ConstraintRowLayout& cols = layout_rows[r];
    const RowValues& row = rows_[r];
    // The embedded system substitutes these rows (embedding_) instead.
    if (solver_.embed_cable_nodes && cols.node >= 0) continue;
    if (!row.active) {
      values[layout_.row_diagonal(r)] = -1.0;
      rhs[n_ + r] = 0.0;
      continue;
    }
    values[layout_.row_diagonal(r)] = -kRegularization;
    rhs[n_ + r] = -row.b;
    const int* block = layout_.row_block(r);
    const int* coupling = layout_.row_coupling(r);
    for (int a = 0, k = 0; a < cols.count; ++a) {
      rhs[cols.cols[a]] -= row.vals[a] * row.b;
      values[coupling[a]] += row.vals[a];
      for (int b = 0; b <= a; ++b) values[block[k++]] += row.vals[a] * row.vals[b];
    }
  }
}

bool ArmDynamics::SolveAugmentedSystem() {
  const bool solved =
      solver_.embed_cable_nodes ? system_.SolveEmbedded(embedding_) : system_.Solve();
  if (!solved) {
    failure_ = "augmented mass matrix is singular";
    return false;
  }
  return true;
}

// ydot = (q_dot, q_dd, dissipated power, memory rates); the stuck nodes' required
// friction from their multipliers.
bool ArmDynamics::FinishDerivative(const double* qd, double* ydot) {
  const Eigen::VectorXd& solution = system_.solution();
  for (int k = 0; k < n_; ++k) {
    ydot[k] = qd[k];
    ydot[n_ + k] = solution[k];
  }
  // Element smoothing and Rayleigh damping dissipate
  // Δs EA eps_dot (beta' eps_dot + gamma eps_dd) with eps_dd = bias + eps_q q_dd.
  for (const ElementRate& rate : element_rates_) {
    double eps_q_qdd = 0.0;
    for (int k = 0; k < 8; ++k) eps_q_qdd += rate.jac[k] * solution[rate.cols[k]];
    dissipation_ += rate.coefficient + rate.gamma_term * eps_q_qdd;
  }
  for (const SmoothingPower& power : smoothing_power_) {
    for (int k = 0; k < power.count; ++k)
      dissipation_ += power.weights[k] * solution[power.cols[k]];
  }
  for (const auto& [col, weight] : hole_smoothing_power_) dissipation_ += weight * solution[col];
  ydot[2 * n_] = dissipation_;
  std::copy(memory_rate_.begin(), memory_rate_.end(), ydot + memory_offset());

  // Friction a stuck node needs: the reaction of its constraint, -lambda.
  const std::vector<ConstraintRowLayout>& layout_rows = layout_.rows();
  for (int r = 0; r < m_; ++r) {
    const int hole = layout_rows[r].hole;
    if (hole >= 0 && rows_[r].active) reports_[hole].required_friction = -solution[n_ + r];
  }
  for (int k = 0; k < state_size(); ++k) {
    if (!std::isfinite(ydot[k])) {
      failure_ = "non-finite acceleration";
      return false;
    }
  }
  return true;
}

void ArmDynamics::FillConstraints(double t, const double* q, const double* qd, bool with_jacobian) {
  const double alpha = solver_.baumgarte_alpha_per_s;
  const double beta = solver_.baumgarte_beta_per_s2;
  const std::vector<ConstraintRowLayout>& layout_rows = layout_.rows();
  int r = 0;
  int node_index = 0;
  // Sets row r's Baumgarte right-hand side b = Phi_dd(q_dd = 0) + alpha Phi_d + beta Phi.
  auto finish = [&](RowValues& row, double phi, double phi_dot, double bias) {
    row.phi = phi;
    row.b = bias + alpha * phi_dot + beta * phi;
  };
  for (int c = 0; c < model_.num_cables(); ++c) {
    const auto& cable = model_.cables()[c];
    for (int k = 0; k < static_cast<int>(cable.nodes.size()); ++k, ++node_index) {
      const CableNodeModel& node = cable.nodes[k];
      const int o = model_.node_offset(c, k);
      const Vector3 r_node = Position(q, o), v_node = Position(qd, o);
      Vector3 phi, phi_dot, bias = Vector3::Zero();
      Eigen::Matrix<double, 3, 4> jac = Eigen::Matrix<double, 3, 4>::Zero();
      if (node.link == 0) {
        phi = r_node - node.p_LN;
        phi_dot = v_node;
      } else {
        const int lo = model_.link_offset(node.link);
        const Vector4 ed = Quaternion(qd, lo);
        const BodyPointKinematics& points = point_kinematics_[node.link - 1];
        jac = points.Jacobian(node.p_LN);
        phi = r_node - Position(q, lo) - rotation_[node.link - 1] * node.p_LN;
        phi_dot = v_node - Position(qd, lo) - jac * ed;
        bias = -points.VelocityProduct(node.p_LN);
      }
      NodeEmbedding& embedding = embedding_[node_index];
      embedding.jac = jac;
      for (int a = 0; a < 3; ++a, ++r) {
        RowValues& row = rows_[r];
        if (with_jacobian) {
          row.vals[0] = 1.0;
          if (node.link > 0) {
            row.vals[1] = -1.0;
            for (int k4 = 0; k4 < 4; ++k4) row.vals[2 + k4] = -jac(a, k4);
          }
        }
        finish(row, phi[a], phi_dot[a], bias[a]);
        embedding.c[a] = -row.b;
      }
      RowValues& srow = rows_[r];
      srow.vals[0] = 1.0;
      const double s = q[o + 3], sd = qd[o + 3];
      srow.active = true;
      if (node.kind == CableNodeModel::Kind::kInput) {
        double pulled, rate, accel;
        inputs_.Evaluate(c, t, &pulled, &rate, &accel);
        finish(srow, s - (initial_s_[node_index] + pulled), sd - rate, -accel);
      } else if (node.kind == CableNodeModel::Kind::kAnchor) {
        finish(srow, s - initial_s_[node_index], sd, 0.0);
      } else {
        const int h = layout_rows[r].hole;
        srow.active = modes_[h] == HoleMode::kStuck;
        finish(srow, srow.active ? s - stuck_s_[h] : 0.0, sd, 0.0);
      }
      ++r;
    }
  }
  for (int i = 1; i <= model_.num_links(); ++i, ++r) {
    const int o = model_.link_offset(i);
    const Vector4 e = Quaternion(q, o), ed = Quaternion(qd, o);
    RowValues& row = rows_[r];
    for (int k = 0; k < 4; ++k) row.vals[k] = 2.0 * e[k];
    finish(row, e.squaredNorm() - 1.0, 2.0 * e.dot(ed), 2.0 * ed.squaredNorm());
  }
  const Vector3 x_axis = Vector3::UnitX(), y_axis = Vector3::UnitY();
  for (int j = 1; j <= model_.num_joints(); ++j) {
    const Vector3 u_p = model_.p_parent_joint(j), u_c = model_.p_child_joint(j);
    const int oc = model_.link_offset(j);
    const Vector4 edc = Quaternion(qd, oc);
    const BodyPointKinematics& child = point_kinematics_[j - 1];
    const Eigen::Matrix<double, 3, 4> jc = child.Jacobian(u_c);
    Vector3 phi = -Position(q, oc) - rotation_[j - 1] * u_c;
    Vector3 phi_dot = -Position(qd, oc) - jc * edc;
    Vector3 bias = -child.VelocityProduct(u_c);
    Eigen::Matrix<double, 3, 4> jp;
    Vector4 edp;
    if (j > 1) {
      const int op = model_.link_offset(j - 1);
      edp = Quaternion(qd, op);
      const BodyPointKinematics& parent = point_kinematics_[j - 2];
      jp = parent.Jacobian(u_p);
      phi += Position(q, op) + rotation_[j - 2] * u_p;
      phi_dot += Position(qd, op) + jp * edp;
      bias += parent.VelocityProduct(u_p);
    } else {
      phi += u_p;
    }
    for (int a = 0; a < 3; ++a, ++r) {
      RowValues& row = rows_[r];
      int v = 0;
      if (j > 1) {
        row.vals[v++] = 1.0;
        for (int k = 0; k < 4; ++k) row.vals[v++] = jp(a, k);
      }
      row.vals[v++] = -1.0;
      for (int k = 0; k < 4; ++k) row.vals[v++] = -jc(a, k);
      finish(row, phi[a], phi_dot[a], bias[a]);
    }
    // Orientation (eq. 37): (A_p x')^T (A_c y') = 0.
    const Vector3 a_vec = j > 1 ? Vector3(rotation_[j - 2] * x_axis) : x_axis;
    const Vector3 c_vec = rotation_[j - 1] * y_axis;
    const Eigen::Matrix<double, 3, 4>& dc = child.axis_jacobian[1];
    const Vector3 c_dot = dc * edc;
    Vector3 a_dot = Vector3::Zero();
    double bias_o = a_vec.dot(child.rate_quadratic.col(1));
    RowValues& row = rows_[r++];
    int v = 0;
    if (j > 1) {
      const BodyPointKinematics& parent = point_kinematics_[j - 2];
      const Eigen::Matrix<double, 3, 4>& dp = parent.axis_jacobian[0];
      a_dot = dp * edp;
      const Eigen::Matrix<double, 1, 4> g = c_vec.transpose() * dp;
      for (int k = 0; k < 4; ++k) row.vals[v++] = g[k];
      bias_o += c_vec.dot(parent.rate_quadratic.col(0)) + 2.0 * a_dot.dot(c_dot);
    }
    const Eigen::Matrix<double, 1, 4> g = a_vec.transpose() * dc;
    for (int k = 0; k < 4; ++k) row.vals[v++] = g[k];
    finish(row, a_vec.dot(c_vec), a_dot.dot(c_vec) + a_vec.dot(c_dot), bias_o);
  }
  CCSRM_CHECK(r == m_);
}

SettledFriction ArmDynamics::InitialSettledFriction() const {
  SettledFriction friction;
  const std::vector<HoleNodeRef>& holes = layout_.holes();
  const Eigen::VectorXd y0 = InitialState();
  for (const HoleNodeRef& hole : holes)
    friction.hole_s.push_back(y0[model_.node_offset(hole.cable, hole.node) + 3]);
  friction.hole_xi.assign(holes.size(), 0.0);
  friction.conduit_slip.assign(2 * pair_kernels_.size(), 0.0);
  friction.conduit_eta.assign(2 * pair_kernels_.size(), 0.0);
  return friction;
}

Eigen::VectorXd ArmDynamics::RestState(const double* q, const SettledFriction& friction) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(state_size());
  y.head(n_) = Eigen::Map<const Eigen::VectorXd>(q, n_);
  y.tail(num_memory_) = Eigen::Map<const Eigen::VectorXd>(rest_memory_.data(), num_memory_);
  if (presliding_ >= 0) {
    for (std::size_t h = 0; h < layout_.holes().size(); ++h)
      y[memory_offset() + presliding_ + h] = friction.hole_xi[h];
  }
  for (std::size_t p = 0; p < pair_kernels_.size(); ++p) {
    if (pair_kernels_[p].presliding < 0) continue;
    for (int axis = 0; axis < 2; ++axis)
      y[memory_offset() + pair_kernels_[p].presliding + axis] = friction.conduit_eta[2 * p + axis];
  }
  return y;
}

namespace {

// The presliding displacement after a slip at rest, on the branch the
// settled residual was told (0: the law itself).
double DisplacementOnBranch(double displacement, double slip, double up, double down,
                            signed char branch) {
  if (branch == 0) return ElastoplasticDisplacementAfterSlip(displacement, slip, up, down);
  return ElastoplasticDisplacementOnBranch(displacement, slip, up, down, branch > 0);
}

}  // namespace

// The presliding laws at rest (memory z = 1), without their relaxation's
// smoothing: slow slip is the limit it leaves unchanged.
double ArmDynamics::SettledHoleDisplacement(int h, double s, double wrap_angle) {
  const PreslidingLaw law = HolePreslidingLaw(0.0);
  const double up = PreslidingSteadyDisplacement(law, wrap_angle, 1.0, 1.0);
  const double down = PreslidingSteadyDisplacement(law, wrap_angle, 1.0, -1.0);
  const double xi = DisplacementOnBranch(settled_from_->hole_xi[h], s - settled_from_->hole_s[h],
                                         up, down, branches_.hole[h]);
  settled_now_.hole_s[h] = s;
  settled_now_.hole_xi[h] = xi;
  return xi;
}

// At rest eta_ss is xi_c in both directions (PreslidingConduitFriction at z
// = 1); the slip coordinate is v_tau1's integral, linear in the angles.
double ArmDynamics::SettledConduitDisplacement(int p, int axis, double theta_i, double theta_j) {
  const int k = 2 * p + axis;
  const double slip = ConduitSlipVelocity(pair_kernels_[p].large, theta_i, theta_j);
  const double eta =
      DisplacementOnBranch(settled_from_->conduit_eta[k], slip - settled_from_->conduit_slip[k],
                           parameters_.xi_c, parameters_.xi_c, branches_.conduit[k]);
  settled_now_.conduit_slip[k] = slip;
  settled_now_.conduit_eta[k] = eta;
  return eta;
}

bool ArmDynamics::SettledResidual(double t, const double* x, const SettledFriction& from,
                                  double* residual) {
  ++evaluations_;
  failure_.clear();
  const double* q = x;
  const double* qd = zero_rates_.data();
  const double* memory = rest_memory_.data();
  system_.Clear();
  force_.setZero();
  dissipation_ = kinetic_ = elastic_ = 0.0;
  // The stages of Evaluate up to the constraints, at rest; the presliding
  // displacements from `from` (settled_from_ is read by the friction stages).
  settled_from_ = &from;
  ComputeLinkKinematics(q, qd);
  const bool elements = AddCableElements(q, qd);
  if (elements) {
    AddHoleFriction(q, qd, memory);
    ComputeJointAngles();
    AddConnectingMoments(t, memory);
    AddBackboneMoments();
    AddEffectLoads(t, qd);
    ApplyJointMoments(q);
    AddLinkInertia(q, qd);
    FillConstraints(t, q, qd, true);
  }
  settled_from_ = nullptr;
  if (!elements) return false;
  const double* lambda = x + n_;
  std::copy(force_.data(), force_.data() + n_, residual);
  const std::vector<ConstraintRowLayout>& layout_rows = layout_.rows();
  for (int r = 0; r < m_; ++r) {
    const RowValues& row = rows_[r];
    if (!row.active) {
      residual[n_ + r] = lambda[r];
      continue;
    }
    residual[n_ + r] = row.phi;
    const ConstraintRowLayout& cols = layout_rows[r];
    for (int a = 0; a < cols.count; ++a) residual[cols.cols[a]] -= row.vals[a] * lambda[r];
  }
  for (int k = 0; k < n_ + m_; ++k) {
    if (!std::isfinite(residual[k])) {
      failure_ = "non-finite force at rest";
      return false;
    }
  }
  return true;
}

double ArmDynamics::ConstraintViolation(double t, const double* y) {
  ComputeLinkKinematics(y, y + n_);
  FillConstraints(t, y, y + n_, false);
  double sum = 0.0;
  for (const RowValues& row : rows_) {
    if (row.active) sum += row.phi * row.phi;
  }
  return std::sqrt(sum);
}

void ArmDynamics::Observe(double t, const double* y, TrajectoryFrame* out, bool evaluate) {
  if (evaluate) {
    std::vector<double> ydot(state_size());
    Evaluate(t, y, ydot.data());
  }
  out->joint_angles = theta_;
  out->joint_rates = theta_dot_;
  out->link_pose.resize(model_.num_links());
  for (int i = 1; i <= model_.num_links(); ++i) {
    const int o = model_.link_offset(i);
    Eigen::Matrix<double, 7, 1> pose;
    pose.head<3>() = Position(y, o);
    pose.tail<4>() = Quaternion(y, o).normalized();
    out->link_pose[i - 1] = pose;
  }
  out->element_tension = tension_;
  out->hole_slip_velocity.assign(model_.num_cables(), {});
  out->hole_stuck.assign(model_.num_cables(), {});
  const std::vector<HoleNodeRef>& holes = layout_.holes();
  for (std::size_t h = 0; h < holes.size(); ++h) {
    const int c = holes[h].cable;
    out->hole_slip_velocity[c].push_back(reports_[h].s_dot);
    // Smoothed: stuck is creeping inside the stick band, the SPEC's
    // definition. Presliding: what slides of the slip speed (beyond the
    // presliding displacement's rate) is inside the band.
    const double v_eps = solver_.stick_velocity_tolerance_mps;
    bool stuck = modes_[h] == HoleMode::kStuck;
    if (solver_.hole_friction == HoleFrictionModel::kSmoothed) {
      stuck = std::abs(reports_[h].s_dot) < v_eps;
    } else if (solver_.hole_friction == HoleFrictionModel::kPresliding) {
      stuck = std::abs(reports_[h].sliding_speed) < v_eps;
    }
    out->hole_stuck[c].push_back(stuck ? 1 : 0);
  }
  out->input_length_change.resize(model_.num_cables());
  for (int c = 0; c < model_.num_cables(); ++c) {
    double value, rate, accel;
    inputs_.Evaluate(c, t, &value, &rate, &accel);
    out->input_length_change[c] = value;
  }
  out->constraint_violation = ConstraintViolation(t, y);
  out->kinetic_energy = kinetic_;
  out->elastic_energy = elastic_;
  out->dissipated_energy = y[2 * n_];
}

}  // namespace ccsrm::sim::internal
