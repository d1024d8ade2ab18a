#include "declared_values.h"

#include "ccsrm/sim/declared_values.h"

namespace ccsrm::identify::internal {

std::vector<LoopCandidateSpec> DeclaredValueCandidates(const sim::ArmConfig& arm) {
  std::vector<LoopCandidateSpec> blocks;
  const auto block_of = [](const std::string& name) {
    // "declared.segment2.link_length" -> "declared:segment2"; arm-wide -> "declared:arm".
    const std::string rest = name.substr(std::string("declared.").size());
    if (rest.rfind("segment", 0) == 0) return "declared:" + rest.substr(0, rest.find('.'));
    return std::string("declared:arm");
  };
  std::vector<LoopCandidateSpec> out;
  for (const sim::ParameterInfo& p : sim::DeclaredValueParameters(arm.size())) {
    // A value the arm does not have (a mechanism its pattern does not use,
    // on a backbone segment) has nothing to correct.
    if (sim::DeclaredValue(arm, p.name) == 0.0) continue;
    const std::string block = block_of(p.name);
    if (out.empty() || out.back().block != block) {
      // A new block: its own entry first, then its members.
      LoopCandidateSpec b;
      b.kind = LoopCandidateSpec::Kind::kDeclaredBlock;
      b.name = block;
      b.block = block;
      out.push_back(b);
    }
    LoopCandidateSpec m;
    m.kind = LoopCandidateSpec::Kind::kDeclaredValue;
    m.name = p.name;
    m.parameters = {p.name};
    m.block = block;
    out.push_back(m);
    for (auto it = out.rbegin(); it != out.rend(); ++it) {
      if (it->kind == LoopCandidateSpec::Kind::kDeclaredBlock && it->name == block) {
        it->parameters.push_back(p.name);
        break;
      }
    }
  }
  return out;
}

std::string DeclaredValueLabel(const std::string& parameter) {
  std::string rest = parameter.rfind("declared.", 0) == 0
                         ? parameter.substr(std::string("declared.").size())
                         : parameter;
  std::string out;
  for (char c : rest) {
    if (c == '.' || c == '_') {
      out += ' ';
    } else {
      out += c;
    }
  }
  // "segment2 link length" -> "segment 2 link length"
  if (out.rfind("segment", 0) == 0 && out.size() > 7) out.insert(7, " ");
  return out;
}

}  // namespace ccsrm::identify::internal
