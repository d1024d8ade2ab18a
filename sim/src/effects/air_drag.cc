// air_drag: the viscous air film under each link's air bearing drags it,
// linearly in the velocity of its mass centre:
//
//   f = −c v_link,   power taken out c |v|² (booked as dissipation).
//
// c is `air_drag.linear_nspm`, the same for every link. A film of
// viscosity η, pad area A and gap h has c = η A / h.
#include <memory>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

class AirDrag final : public Effect {
 public:
  explicit AirDrag(const ArmParameters& p) : c_nspm_(GetParameter(p, "air_drag.linear_nspm")) {}

  bool adds_loads() const override { return c_nspm_ > 0.0; }

  void AddLoads(EffectLoads* loads) const override {
    for (int i = 1; i <= loads->num_links(); ++i) {
      const Eigen::Vector3d v = loads->link_velocity(i);
      loads->AddLinkForce(i, -c_nspm_ * v);
      loads->AddDissipation(c_nspm_ * v.squaredNorm());
    }
  }

 private:
  double c_nspm_;
};

}  // namespace

EffectDefinition AirDragEffect() {
  EffectDefinition d;
  d.name = "air_drag";
  d.fingerprint = {"rate", "lag"};
  d.description = "air-bearing drag on the links, linear in the velocity of each link";
  // Realistic: air (η = 1.8e-5 Pa s) under a 30 mm x 30 mm pad with a 10 µm
  // gap gives η A / h = 1.6e-3 N s/m; 2e-3 N s/m. Upper bound 1 N s/m (a
  // link stopping within its own mass / c = 0.1 s).
  d.parameters = {
      EffectParameter("linear_nspm", "N s/m", 0.0, 1.0, 0.0, 2e-3,
                      "drag coefficient of every link: force per velocity of its mass centre"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<AirDrag>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
