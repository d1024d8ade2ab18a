#pragma once
// The one interface every effect implements (ccsrm/sim/effects.h lists the
// effects). An Effect is built for one run from that run's ArmParameters
// when the effect is on; the simulator calls its hooks at fixed places and
// never asks which effect it is:
//
//   before the run      RealisedInputs     what the actuators do with the command
//                       DrivingPretensionChange  a segment's driving cables' pre-tension
//   every evaluation    PretensionFactor   the connecting cables' T_p(t) / T_p
//                       CoupleDeflection   the deflection the couples' springs see
//                       AddLoads           forces on links, moments on joints
//   every sampled frame Record             what motion capture records
//
// Every hook has a neutral default, so an effect overrides only what it
// changes. To add an effect: write sim/src/effects/<name>.cc with an
// EffectDefinition (its parameters with units, bounds, default and
// realistic magnitude, and a factory), and list it in registry.cc.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::sim::internal {

// What an effect may read and add while the right-hand side is evaluated.
// Joints and links are 1-based; angles, rates and moments follow SPEC 2's
// X-Y Cardan convention (axis 0 = θx, 1 = θy).
class EffectLoads {
 public:
  virtual ~EffectLoads() = default;
  virtual double time() const = 0;  // [s]
  virtual int num_links() const = 0;
  virtual int num_joints() const = 0;
  virtual const Eigen::Vector2d& joint_angle(int joint) const = 0;  // [rad]
  virtual const Eigen::Vector2d& joint_rate(int joint) const = 0;   // [rad/s]
  virtual int joint_segment(int joint) const = 0;                   // 1-based
  virtual Eigen::Vector3d link_velocity(int link) const = 0;        // mass centre, world [m/s]
  virtual double link_mass(int link) const = 0;                     // [kg]
  // The bending rate [rad/s] about axis `axis` that the driving cables'
  // input rates command of every joint of segment `segment` (1-based),
  // kinematically (SegmentBendingPerPulledLength, sim/kinematics.h): the
  // inputs' motion in the joints' own units. Realised inputs, after any
  // effect that changes them (actuator_delay).
  virtual double commanded_bending_rate(int segment, int axis) const = 0;
  // A force on link `link`'s mass centre, world frame [N].
  virtual void AddLinkForce(int link, const Eigen::Vector3d& f_W) = 0;
  // A joint-space moment [N m] on joint `joint`'s angle `axis`, and its
  // damping -dM/dθ̇ >= 0 [N m s/rad]. The simulator model-smooths that
  // damping as it does the conduit friction (docs/model-notes.md row 6):
  // (h/2) damping is added to the joint's inertia, which keeps a steep
  // friction law integrable by the explicit RK45.
  virtual void AddJointMoment(int joint, int axis, double moment, double damping) = 0;
  // Power the effect takes out of the arm [W] (>= 0 for a dissipative one),
  // booked in the dissipated energy.
  virtual void AddDissipation(double power_w) = 0;
};

// The deflection a connecting couple's spring sees for a relative rotation
// d = θ_j − θ_i (value), its slope d value / d d, and the spring's energy
// per unit stiffness, ∫ value dd.
struct CoupleDeflection {
  double value = 0.0;   // [rad]
  double slope = 1.0;   // [1]
  double energy = 0.0;  // [rad^2]
};

class Effect {
 public:
  virtual ~Effect() = default;

  // The inputs the actuators realise from the commanded ones over
  // [0, duration_s]; null when this effect leaves them as they are.
  virtual std::unique_ptr<CableInputs> RealisedInputs(const ArmModel& /*model*/,
                                                      const CableInputs& /*commanded*/,
                                                      double /*duration_s*/) const {
    return nullptr;
  }

  // Does this effect use the per-evaluation hooks below? The simulator
  // calls only those an effect declares, so an effect that is on costs
  // nothing where it acts nowhere.
  virtual bool scales_pretension() const { return false; }
  virtual bool deflects_couples() const { return false; }
  virtual bool adds_loads() const { return false; }

  // What the driving cables of segment `segment` (1-based) hold at the
  // start beyond T_d0 [N]: their pre-strain is (T_d0 + change) / EA.
  virtual double DrivingPretensionChange(int /*segment*/) const { return 0.0; }
  // T_p(t) / T_p of the connecting cables.
  virtual double PretensionFactor(double /*t*/) const { return 1.0; }
  // The couples' deflection for relative rotation d [rad].
  virtual CoupleDeflection Deflect(double d) const { return {d, 1.0, 0.5 * d * d}; }
  // Forces and moments at the current state.
  virtual void AddLoads(EffectLoads* /*loads*/) const {}

  // Turns the physical joint angles of a frame into what is recorded.
  virtual void Record(std::vector<Eigen::Vector2d>* /*joint_angles*/) const {}
};

// Parameters that come one set per joint, per driving cable, or per
// segment of the arm (mocap_offset: an offset per joint and axis). How many there are is the
// arm's (ArmParameters::arm), never a constant of the effect.
struct IndexedParameters {
  enum class Per { kJoint, kCable, kSegment };
  Per per = Per::kJoint;
  // Their short names with "<k>" for the 1-based index ("joint<k>_x_rad"),
  // in the order `make` returns them.
  std::vector<std::string> patterns;
  // The entries of index k (>= 1), one per pattern, made by EffectParameter
  // with the short name of that index; the registry fills in the rest.
  std::function<std::vector<ParameterInfo>(int k)> make;
};

// One effect's description and factory.
struct EffectDefinition {
  std::string name;
  std::string description;
  bool measurement = false;
  bool library = true;  // EffectInfo::library
  // The residual signals it leaves (EffectInfo::fingerprint).
  std::vector<std::string> fingerprint;
  // Its fixed parameters with short names ("coulomb_nm") and `field` null;
  // the registry fills in the full name, `effect` and `config_key`.
  std::vector<ParameterInfo> parameters;
  // Its per-joint and per-cable parameters, after the fixed ones.
  std::vector<IndexedParameters> indexed;
  // Builds the effect from a run's parameters (read with GetParameter).
  std::function<std::unique_ptr<Effect>(const ArmParameters&)> make;
};

// Every parameter of `definition` on an arm of `arm`'s size, full names
// filled in: the fixed ones, then per index k = 1.. the indexed ones.
std::vector<ParameterInfo> ParametersOnArm(const EffectDefinition& definition, const ArmSize& arm);

// An effect parameter by full name, or null when no effect has it. With
// `arm` given, an indexed parameter beyond the arm's joints or cables is
// null too and *beyond says why ("this arm has 9 joints"); without, any
// index from 1 is taken. The entry lives as long as the program.
const ParameterInfo* FindEffectParameter(const std::string& name, const ArmSize* arm,
                                         std::string* beyond);

// The parameters of `definition` for a message: full or short names, the
// indexed ones by pattern with their range ("joint<k>_x_rad, joint<k>_y_rad
// (k = 1..9, one per joint)"; "k = 1, 2, ..." without an arm).
std::string DescribeParameters(const EffectDefinition& definition, const ArmSize* arm,
                               bool full_names);

// The definition of effect `name`, or null.
const EffectDefinition* FindEffectDefinition(const std::string& name);

// An effect parameter's entry: short name, SI units, bounds, its default
// while the effect is on (the neutral value where there is one), its
// realistic magnitude and a description.
ParameterInfo EffectParameter(const std::string& short_name, const std::string& units, double lower,
                              double upper, double default_value, double realistic,
                              const std::string& description);

// Every effect, in the order of Effects() (registry.cc).
const std::vector<EffectDefinition>& EffectDefinitions();

// The effects that are on in `parameters`, built, in registry order.
std::vector<std::unique_ptr<Effect>> MakeEffects(const ArmParameters& parameters);

// The inputs the actuators realise: `commanded` passed through every effect
// that is on, in registry order; null when none changes them.
std::unique_ptr<CableInputs> RealisedInputs(const ArmModel& model, const ArmParameters& parameters,
                                            const CableInputs& commanded, double duration_s);

// The definitions of the seven effects (one file each).
EffectDefinition JointFrictionEffect();
EffectDefinition TableTiltEffect();
EffectDefinition ActuatorDelayEffect();
EffectDefinition BacklashEffect();
EffectDefinition PretensionCreepEffect();
EffectDefinition AirDragEffect();
EffectDefinition MocapOffsetEffect();
EffectDefinition SegmentPretensionEffect();
// Not of the library: the discovered terms' carrier (joint_moment.cc).
EffectDefinition JointMomentEffect();

}  // namespace ccsrm::sim::internal
