// table_tilt: the air table is not level. The bearings carry the gravity
// component normal to the table (world x, SPEC 2); what is left acts in the
// table plane (world y and z) on every link's mass centre:
//
//   f = m g (0, sin α_lateral, sin α_longitudinal)
//
// α_lateral (`table_tilt.lateral_rad`) tilts the table about the straight
// arm's axis z: gravity pulls across the arm (+y) and bends it in the table
// plane, towards negative θx (Rx(θ) turns z towards −y). α_longitudinal
// (`table_tilt.longitudinal_rad`) tilts it about y: gravity pulls along the arm (+z, towards the
// tip) and loads the cables. g = 9.80665 m/s². Conservative: the potential energy is not part of
// /diagnostics/energy (kinetic, elastic, dissipated).
#include <cmath>
#include <memory>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

constexpr double kStandardGravity = 9.80665;  // m/s²

class TableTilt final : public Effect {
 public:
  explicit TableTilt(const ArmParameters& p)
      : g_W_(0.0, kStandardGravity * std::sin(GetParameter(p, "table_tilt.lateral_rad")),
             kStandardGravity * std::sin(GetParameter(p, "table_tilt.longitudinal_rad"))) {}

  bool adds_loads() const override { return true; }

  void AddLoads(EffectLoads* loads) const override {
    for (int i = 1; i <= loads->num_links(); ++i) {
      loads->AddLinkForce(i, loads->link_mass(i) * g_W_);
    }
  }

 private:
  Eigen::Vector3d g_W_;  // in-plane gravity [m/s²]
};

}  // namespace

EffectDefinition TableTiltEffect() {
  EffectDefinition d;
  d.name = "table_tilt";
  d.fingerprint = {"constant", "heading"};
  d.description = "the table is not level: gravity in the table plane from two small tilt angles";
  // Realistic: an air table levelled with a machinist's spirit level is
  // within ~0.1 mm/m (1e-4 rad); levelled by eye or settled since, ~1 mm/m.
  // 1e-3 rad is the realistic magnitude; bounds ±0.05 rad (±2.9°), beyond
  // which the air bearings would slide off by themselves.
  d.parameters = {
      EffectParameter("lateral_rad", "rad", -0.05, 0.05, 0.0, 1e-3,
                      "tilt about the arm's axis (world z): gravity across the arm, +y"),
      EffectParameter("longitudinal_rad", "rad", -0.05, 0.05, 0.0, 1e-3,
                      "tilt about world y: gravity along the arm, +z (towards the tip)"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<TableTilt>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
