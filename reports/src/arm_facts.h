#pragma once
// What the report pages take from the simulator library: the arm's segments
// and cable routing, the protocol's phases, the arm and protocol in words,
// whether the arm is the paper's and, for a run of the protocol, the planned
// motion. All calls into ccsrm::sim live in arm_facts.cc, so a change of the
// simulator's API touches one file.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/datasets/array.h"

namespace ccsrm::reports::internal {

// A run of consecutive joints shown in one panel (a segment of the arm).
struct JointGroup {
  std::string title;    // e.g. "Segment 1 (joints 1–6)"
  int first_joint = 1;  // 1-based
  int joints = 0;
};

// The paper's protocol phases (SPEC 3) from the configuration.
struct ProtocolPhases {
  double amplitude_deg = 0.0;
  double ramp_s = 0.0;
  double hold_s = 0.0;
  double return_s = 0.0;
  double rest_s = 0.0;
};

struct ArmFacts {
  // Cover joints 1..J in order. One group of every joint when the
  // configuration cannot be read or does not match the file's arrays.
  std::vector<JointGroup> segments;
  // Index into `segments` of the segment each driving cable drives (C
  // entries; all 0 in the fallback).
  std::vector<int> cable_segment;
  std::optional<ProtocolPhases> protocol;
  // The arm and the protocol as configured, in words (sim/describe.h);
  // empty when the configuration cannot be read.
  std::string arm_words;
  std::string protocol_words;
  // The arm is the paper's (sim::IsPaperArm): only then may a page cite the
  // paper's cases and figures.
  bool paper_arm = false;
  // Planned joint angles at the requested times: T × J × 2 (θx, θy), rad.
  std::optional<datasets::Array> plan;
  // Why something above is missing, one sentence each (shown on the page).
  std::vector<std::string> problems;
};

// Reads `config_yaml` (sim::ParseConfig; `source` names it in messages) for
// an arm with `joints` joints and `cables` driving cables (either 0: the file
// has no such data, not checked against the configuration). With `plan_times`
// given, also plans the paper's protocol at those times (sim::ArmModel,
// sim::PaperTrajectory). Never throws for a bad configuration: the problem
// is reported in `problems` and the facts fall back as documented above.
//
// With `protocol_yaml` (a run's protocol_yaml attribute: the protocol that
// drove it), the plan and the protocol's words come from that protocol
// (sim::ParseProtocol on the stored arm); its phases only when it has the
// paper protocol's five parameters (configs/protocols/paper.yaml).
ArmFacts ReadArmFacts(const std::string& config_yaml, const std::string& source, std::size_t joints,
                      std::size_t cables, const std::vector<double>* plan_times,
                      const std::string& protocol_yaml = "");

// The friction case of a run file's `case` attribute ("1".."4"), 0 for any
// other ("custom"), and its words: "paper case 2 (friction on all cables)"
// on the paper's arm, "case 2 (friction on all cables)" on another.
int CaseNumber(const std::string& case_name);
std::string CaseFriction(int case_number);  // "no friction", ...
std::string CaseWords(const std::string& case_name, bool paper_arm);

}  // namespace ccsrm::reports::internal
