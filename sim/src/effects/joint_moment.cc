// joint_moment: the carrier of the terms the loop discovers in data
// (issue 28; identify/include/ccsrm/identify/loop.h). Not an effect of the
// library: nothing in it is a physical mechanism named in advance. It adds
// at every joint axis a moment
//
//   M = Σ_terms c(segment, axis, term) φ_term(θ, θ̇, t)
//
// with φ from JointMomentTerms() in the joint's own angle θ and rate θ̇ of
// that axis, the bending rate θ̇_in its segment's inputs command about that
// axis (EffectLoads::commanded_bending_rate), and time. One coefficient per
// segment rather than per joint: the connecting cables make a segment's
// joints turn together (the mechanism's synchrony), so per-joint coefficients
// of the same term would be seen only through their sum.
//
// A term's slope in θ̇ is model-smoothed by the simulator like joint
// friction's (EffectLoads::AddJointMoment, only where it damps); the power
// -M θ̇ is booked as dissipation, so that the energy balance still closes
// with conservative terms (θ³ stores energy as a spring would: it is booked
// with its sign).
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/effects.h"
#include "effect.h"

namespace ccsrm::sim {

const std::vector<JointMomentTerm>& JointMomentTerms() {
  static const std::vector<JointMomentTerm> terms = {
      {"const", "1", "N m", 0.01, 1},
      {"angle", "θ", "N m/rad", -0.1, 1},
      {"angle2", "θ²", "N m/rad^2", 1.0, 2},
      {"angle3", "θ³", "N m/rad^3", -10.0, 3},
      {"rate", "θ̇", "N m s/rad", -1.0, 1},
      {"sign_rate", "sign(θ̇)", "N m", -0.01, 1},
      {"abs_angle_sign_rate", "|θ| sign(θ̇)", "N m/rad", -0.1, 2},
      {"input_rate", "θ̇_in", "N m s/rad", -1.0, 1},
      {"time", "t", "N m/s", 0.001, 1},
  };
  return terms;
}

std::string JointMomentParameter(int segment, int axis, const std::string& term) {
  return "joint_moment.segment" + std::to_string(segment) + (axis == 0 ? "_x_" : "_y_") + term;
}

namespace internal {
namespace {

// The rate over which sign(θ̇) is smoothed: joint friction's default
// (joint_friction.cc), a tenth of the paper's peak ramp rate.
constexpr double kSignRateRadps = 1e-3;
// The number of terms and the index of the input rate's, in
// JointMomentTerms()' order (checked against it where the effect is built).
constexpr std::size_t kNumTerms = 9, kInputRate = 7;

class JointMoment final : public Effect {
 public:
  explicit JointMoment(const ArmParameters& p) {
    const std::vector<JointMomentTerm>& terms = JointMomentTerms();
    CCSRM_CHECK(terms.size() == kNumTerms && terms[kInputRate].name == "input_rate");
    coefficients_.resize(static_cast<std::size_t>(p.arm.segments));
    for (int k = 1; k <= p.arm.segments; ++k) {
      for (int axis = 0; axis < 2; ++axis) {
        std::vector<double>& c = coefficients_[static_cast<std::size_t>(k - 1)][axis];
        for (const JointMomentTerm& term : terms) {
          c.push_back(GetParameter(p, JointMomentParameter(k, axis, term.name)));
        }
      }
    }
  }

  bool adds_loads() const override { return true; }

  void AddLoads(EffectLoads* loads) const override {
    const double t = loads->time();
    for (int j = 1; j <= loads->num_joints(); ++j) {
      const int segment = loads->joint_segment(j);
      if (segment < 1 || segment > static_cast<int>(coefficients_.size())) continue;
      for (int axis = 0; axis < 2; ++axis) {
        const std::vector<double>& c = coefficients_[static_cast<std::size_t>(segment - 1)][axis];
        const double q = loads->joint_angle(j)[axis], w = loads->joint_rate(j)[axis];
        const double s = std::tanh(w / kSignRateRadps);
        const double ds = (1.0 - s * s) / kSignRateRadps;  // d sign / d θ̇
        // The inputs' rate is asked for only where its term is on: it
        // costs an evaluation of every cable's input spline.
        const double w_in =
            c[kInputRate] != 0.0 ? loads->commanded_bending_rate(segment, axis) : 0.0;
        // φ and dφ/dθ̇ in JointMomentTerms()' order.
        const double phi[] = {1.0, q, q * q, q * q * q, w, s, std::abs(q) * s, w_in, t};
        const double dphi[] = {0.0, 0.0, 0.0, 0.0, 1.0, ds, std::abs(q) * ds, 0.0, 0.0};
        static_assert(std::size(phi) == kNumTerms && std::size(dphi) == kNumTerms);
        double moment = 0.0, slope = 0.0;
        for (std::size_t k = 0; k < c.size(); ++k) {
          moment += c[k] * phi[k];
          slope += c[k] * dphi[k];
        }
        if (moment == 0.0 && slope == 0.0) continue;
        // Model smoothing only for a moment that damps (-dM/dθ̇ > 0).
        loads->AddJointMoment(j, axis, moment, std::max(-slope, 0.0));
        loads->AddDissipation(-moment * w);
      }
    }
  }

 private:
  // [segment - 1][axis][term]
  std::vector<std::array<std::vector<double>, 2>> coefficients_;
};

}  // namespace

EffectDefinition JointMomentEffect() {
  EffectDefinition d;
  d.name = "joint_moment";
  d.library = false;
  d.description =
      "discovered terms: a moment at every joint axis, a combination of terms in the joint's "
      "angle, rate and time, one coefficient per segment, axis and term (not a library effect)";
  IndexedParameters per_segment;
  per_segment.per = IndexedParameters::Per::kSegment;
  for (int axis = 0; axis < 2; ++axis) {
    for (const JointMomentTerm& term : JointMomentTerms()) {
      per_segment.patterns.push_back(std::string("segment<k>") + (axis == 0 ? "_x_" : "_y_") +
                                     term.name);
    }
  }
  per_segment.make = [](int k) {
    std::vector<ParameterInfo> list;
    for (int axis = 0; axis < 2; ++axis) {
      for (const JointMomentTerm& term : JointMomentTerms()) {
        const std::string name = JointMomentParameter(k, axis, term.name);
        // Bounds: 50 times the realistic magnitude either way (0.5 N m at
        // the reference state: as much as the large-S conduits' friction
        // moment, SPEC 3).
        const double bound = 50.0 * std::abs(term.realistic);
        list.push_back(EffectParameter(
            name.substr(name.find('.') + 1), term.units, -bound, bound, 0.0, term.realistic,
            "coefficient of " + term.formula + " in the moment on segment " + std::to_string(k) +
                "'s joints about " + (axis == 0 ? "x" : "y")));
      }
    }
    return list;
  };
  d.indexed = {per_segment};
  d.make = [](const ArmParameters& p) { return std::make_unique<JointMoment>(p); };
  return d;
}

}  // namespace internal
}  // namespace ccsrm::sim
