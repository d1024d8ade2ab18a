#pragma once
// The loop's candidates beyond the effect library (issue 28): the declared
// values of the arm's configuration (sim/declared_values.h), grouped so the
// score test stays cheap and reads well: a block per segment (its
// geometry, mass and inertia) and one for the arm-wide values (joint disk
// gap, the cables' axial stiffness, the input offset), each block scored
// as one, then its members one by one from the same sensitivity columns.
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"

namespace ccsrm::identify::internal {

// A candidate of the loop: an effect of the library, a block of declared
// values (scored only) or one declared value (scored and refitted).
struct LoopCandidateSpec {
  enum class Kind { kEffect, kDeclaredBlock, kDeclaredValue };
  Kind kind = Kind::kEffect;
  std::string name;                      // the effect's, the block's or the parameter's
  std::vector<std::string> parameters;   // its size parameters
  bool measurement = false;              // a measurement effect (columns recorded, not simulated)
  std::vector<std::string> fingerprint;  // an effect's signals (evidence)
  std::string block;                     // a declared value's block
};

// The candidate names that stand for every declared value in
// LoopOptions::candidates.
constexpr const char* kDeclaredCandidates = "declared";

// The declared-value blocks and members of `arm`: "declared:arm" and its
// members, then "declared:segment<k>" and its members, k = 1..segments;
// values the arm does not have (0: a mechanism its segment does not use)
// left out.
std::vector<LoopCandidateSpec> DeclaredValueCandidates(const sim::ArmConfig& arm);

// "segment 2 link length" for "declared.segment2.link_length".
std::string DeclaredValueLabel(const std::string& parameter);

}  // namespace ccsrm::identify::internal
