// backlash: a dead band in the connecting cables. The couple's spring acts
// only once the relative rotation d = θ_j − θ_i of its two joints has taken
// up the play b (`backlash.dead_band_rad`, the half-width of the band):
//
//   spring moment k D(d),  D(d) = d − b tanh(d / b)
//
// D is a smooth dead zone: slope tanh²(d/b), 0 at d = 0 (no stiffness
// inside the band) and → 1 beyond it, where D → d ∓ b (the spring stretched
// by what exceeds the play). Smooth, so the explicit integrator needs no
// events. It applies to both axes of every small-S and large-S couple, to
// the spring term only (the conduit friction and the damping act on the
// rates as before), and the couples' energy becomes k ∫D = k (d²/2 − b² ln
// cosh(d/b)), so the energy bookkeeping still closes.
#include <cmath>
#include <memory>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

// ln cosh x without overflow: |x| + log1p(e^(−2|x|)) − ln 2.
double LogCosh(double x) {
  const double a = std::abs(x);
  return a + std::log1p(std::exp(-2.0 * a)) - std::log(2.0);
}

class Backlash final : public Effect {
 public:
  explicit Backlash(const ArmParameters& p)
      : band_rad_(GetParameter(p, "backlash.dead_band_rad")) {}

  bool deflects_couples() const override { return band_rad_ > 0.0; }

  CoupleDeflection Deflect(double d) const override {
    const double x = d / band_rad_;
    const double t = std::tanh(x);
    return {d - band_rad_ * t, t * t, 0.5 * d * d - band_rad_ * band_rad_ * LogCosh(x)};
  }

 private:
  double band_rad_;
};

}  // namespace

EffectDefinition BacklashEffect() {
  EffectDefinition d;
  d.name = "backlash";
  d.fingerprint = {"constant", "angle", "rate_sign", "hysteresis"};
  d.description = "a dead band in the connecting cables before their stiffness acts";
  // Realistic: play of a crimped cable loop on ~5 mm pulleys: 10 µm of slack
  // per side is 2e-3 rad of relative rotation (0.11°). Upper bound 0.05 rad
  // (2.9°, a visibly loose couple).
  d.parameters = {
      EffectParameter("dead_band_rad", "rad", 0.0, 0.05, 0.0, 2e-3,
                      "half-width of the dead band of a couple's relative rotation"),
  };
  d.make = [](const ArmParameters& p) { return std::make_unique<Backlash>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
