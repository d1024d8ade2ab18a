#include "arm_facts.h"

#include <cmath>
#include <exception>

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/describe.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::reports::internal {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

std::string JointRange(int first, int count) {
  return count == 1 ? "joint " + std::to_string(first)
                    : "joints " + std::to_string(first) + "–" + std::to_string(first + count - 1);
}

void FallBack(std::size_t joints, std::size_t cables, ArmFacts* facts) {
  facts->segments = {
      {"All " + JointRange(1, static_cast<int>(joints)), 1, static_cast<int>(joints)}};
  facts->cable_segment.assign(cables, 0);
}

}  // namespace

ArmFacts ReadArmFacts(const std::string& config_yaml, const std::string& source, std::size_t joints,
                      std::size_t cables, const std::vector<double>* plan_times,
                      const std::string& protocol_yaml) {
  ArmFacts facts;
  sim::Config config;
  try {
    config = sim::ParseConfig(config_yaml, source);
  } catch (const InputError& e) {
    facts.problems.push_back(std::string("The stored configuration does not parse (") + e.what() +
                             "): joints are shown in one panel and no plan is drawn.");
    FallBack(joints, cables, &facts);
    return facts;
  }
  const sim::ArmConfig& arm = config.arm;
  if ((joints != 0 && static_cast<std::size_t>(arm.total_links()) != joints) ||
      (cables != 0 && arm.driving.cables.size() != cables)) {
    facts.problems.push_back(
        "The stored configuration describes " + std::to_string(arm.total_links()) + " joints and " +
        std::to_string(arm.driving.cables.size()) + " driving cables, the file's arrays " +
        std::to_string(joints) + " and " + std::to_string(cables) +
        ": joints are shown in one panel and no plan is drawn.");
    FallBack(joints, cables, &facts);
    return facts;
  }
  int first = 1;
  for (std::size_t s = 0; s < arm.segments.size(); ++s) {
    const int links = arm.segments[s].links;
    facts.segments.push_back(
        {"Segment " + std::to_string(s + 1) + " (" + JointRange(first, links) + ")", first, links});
    first += links;
  }
  for (std::size_t k = 0; k < cables; ++k) {
    facts.cable_segment.push_back(arm.driving.cables[k].segment - 1);
  }
  const sim::ProtocolConfig& p = config.protocol;
  facts.protocol =
      ProtocolPhases{p.amplitude_rad * kDegPerRad, p.ramp_s, p.hold_s, p.return_s, p.rest_s};
  facts.arm_words = sim::DescribeArm(arm);
  facts.protocol_words = sim::DescribeProtocol(p);
  facts.paper_arm = sim::IsPaperArm(arm);
  std::optional<sim::Protocol> protocol;
  if (!protocol_yaml.empty()) {
    try {
      protocol = sim::ParseProtocol(protocol_yaml, "the stored protocol_yaml", config.arm);
    } catch (const InputError& e) {
      facts.protocol.reset();
      facts.problems.push_back(std::string("The stored protocol does not parse (") + e.what() +
                               "): no plan is drawn.");
      return facts;
    }
    facts.protocol_words = sim::DescribeProtocolFile(*protocol);
    const std::map<std::string, double>& v = protocol->parameters;
    const bool paper_shape = v.count("amplitude_deg") && v.count("ramp_s") && v.count("hold_s") &&
                             v.count("return_s") && v.count("rest_s");
    if (paper_shape) {
      facts.protocol = ProtocolPhases{v.at("amplitude_deg") * kDegPerRad, v.at("ramp_s"),
                                      v.at("hold_s"), v.at("return_s"), v.at("rest_s")};
    } else {
      facts.protocol.reset();
    }
  }
  if (plan_times == nullptr || joints == 0) return facts;
  try {
    const sim::ArmModel model(config.arm);
    const sim::JointTrajectory plan =
        protocol ? protocol->Trajectory() : sim::PaperTrajectory(model, config.protocol);
    datasets::Array angles({plan_times->size(), joints, 2});
    for (std::size_t i = 0; i < plan_times->size(); ++i) {
      const sim::JointAngles q = plan((*plan_times)[i]);
      for (std::size_t j = 0; j < joints; ++j) {
        angles.at(i, j, 0) = q[j].x();
        angles.at(i, j, 1) = q[j].y();
      }
    }
    facts.plan = std::move(angles);
  } catch (const InputError& e) {
    facts.problems.push_back(std::string("The planned motion cannot be rebuilt from the stored "
                                         "configuration (") +
                             e.what() + "): no plan is drawn.");
  }
  return facts;
}

int CaseNumber(const std::string& case_name) {
  for (int k = 1; k <= 4; ++k) {
    if (case_name == std::to_string(k)) return k;
  }
  return 0;
}

std::string CaseFriction(int case_number) { return sim::CaseFriction(case_number); }

std::string CaseWords(const std::string& case_name, bool paper_arm) {
  const int number = CaseNumber(case_name);
  return number != 0 ? sim::DescribeCase(number, paper_arm) : "case '" + case_name + "'";
}

}  // namespace ccsrm::reports::internal
