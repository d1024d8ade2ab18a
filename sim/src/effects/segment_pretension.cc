// segment_pretension: each segment's driving cables hold their own
// pre-tension, T_d0 + `segment_pretension.segment<k>_n` for segment k, as
// when a lab tensions each segment's tendons apart (the tendon-driven
// robot of issue 46, whose publishing project fits 0.0006, 1.2 and 3.9 N
// by segment). A pre-tension is a pre-strain of the straight arm at rest,
// (T_d0 + change) / EA along each of the segment's cables; a total below
// zero starts them slack. A calibration of the arm rather than physics the
// model lacks, so not one of the loop's candidates (library false): a fit
// frees it by name.
#include <memory>
#include <string>
#include <vector>

#include "effect.h"

namespace ccsrm::sim::internal {
namespace {

class SegmentPretension final : public Effect {
 public:
  explicit SegmentPretension(const ArmParameters& p) {
    for (int k = 1; k <= p.arm.segments; ++k)
      change_n_.push_back(GetParameter(p, "segment_pretension.segment" + std::to_string(k) + "_n"));
  }

  double DrivingPretensionChange(int segment) const override {
    return segment >= 1 && segment <= static_cast<int>(change_n_.size()) ? change_n_[segment - 1]
                                                                         : 0.0;
  }

 private:
  std::vector<double> change_n_;
};

}  // namespace

EffectDefinition SegmentPretensionEffect() {
  EffectDefinition d;
  d.name = "segment_pretension";
  d.library = false;
  d.fingerprint = {"constant"};
  d.description =
      "each segment's driving cables pre-tensioned apart: T_d0 plus a change per segment (a "
      "calibration, not a loop candidate)";
  IndexedParameters per_segment;
  per_segment.per = IndexedParameters::Per::kSegment;
  per_segment.patterns = {"segment<k>_n"};
  // Bounds: the paper's T_d0 (80 N) either way; realistic: the spread of
  // the robot's published per-segment pre-tensions (about 2 N).
  per_segment.make = [](int k) {
    return std::vector<ParameterInfo>{EffectParameter(
        "segment" + std::to_string(k) + "_n", "N", -80.0, 80.0, 0.0, 2.0,
        "pre-tension of segment " + std::to_string(k) + "'s driving cables beyond T_d0")};
  };
  d.indexed = {per_segment};
  d.make = [](const ArmParameters& p) { return std::make_unique<SegmentPretension>(p); };
  return d;
}

}  // namespace ccsrm::sim::internal
