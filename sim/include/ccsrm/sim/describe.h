#pragma once
// Runs in words for any arm: the arm as configured, the protocol, the
// friction case, and whether a run is one of the paper's (a case of the
// paper on the paper's arm), which alone may be compared with the paper's
// figures. Summaries and reports take their words from here.
#include <string>

#include "ccsrm/sim/config.h"

namespace ccsrm::sim {

// True when `arm` is the paper's: that of configs/paper.yaml as built into
// ccsrm (segment names aside, every link, disk, inertia, cable material and
// route equal to a relative 1e-9). A case number says only which cables have
// friction, on any arm; a run is one of the paper's cases when its arm is
// this one too. An arm edited from the paper's (another link, another hole
// angle) is the user's.
bool IsPaperArm(const ArmConfig& arm);

// What friction case `case_number` keeps (ApplyPaperCase): "no friction",
// "friction on all cables", "friction on the driving cables only",
// "friction on the connecting cables only"; "" for any other number.
std::string CaseFriction(int case_number);

// "3 segments of 4, 4 and 4 links (12 joints), 9 driving cables".
std::string DescribeArm(const ArmConfig& arm);

// The configured protocol (SPEC 3's shape): "θx of every joint 0 → 8° along
// a quintic over 20 s, held 4 s, back over 20 s, at rest 4 s; θy planned 0".
std::string DescribeProtocol(const ProtocolConfig& protocol);

// "paper case 2 (friction on all cables)" when `paper_arm`, "case 2
// (friction on all cables)" on any other arm, "friction as configured" for
// case 0 (no --case).
std::string DescribeCase(int case_number, bool paper_arm);

}  // namespace ccsrm::sim
