#include "ccsrm/common/yaml_document.h"

#include <map>
#include <set>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm {
namespace {

std::string LineOf(const YAML::Mark& mark) { return std::to_string(mark.line + 1); }

class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& file) : file_(file) {}

  void Walk(const YAML::Node& node, const std::string& path) {
    if (!node.IsMap() && !node.IsSequence()) return;
    // An alias shares its anchor's node: walk each collection once, which
    // also ends a walk round an alias to an enclosing anchor (a cycle).
    const YAML::Mark mark = node.Mark();
    if (!mark.is_null() && !walked_.insert(mark.pos).second) return;
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) {
        Walk(node[i], path + "[" + std::to_string(i) + "]");
      }
      return;
    }
    std::map<std::string, YAML::Mark> first;  // key -> where it first appeared
    for (const auto& entry : node) {
      // A complex key (a mapping or a list as key) is never a ccsrm key:
      // the reader refuses it as unknown, so it is not compared here.
      if (!entry.first.IsScalar()) continue;
      const std::string& key = entry.first.Scalar();
      const std::string child = path.empty() ? key : path + "." + key;
      const auto [it, inserted] = first.emplace(key, entry.first.Mark());
      if (!inserted) {
        ThrowInputError(file_, "line " + LineOf(entry.first.Mark()) + ", key '" + child + "'",
                        "duplicate key (first at line " + LineOf(it->second) + ")");
      }
      Walk(entry.second, child);
    }
  }

 private:
  const std::string& file_;
  std::set<int> walked_;  // YAML::Mark::pos of the collections walked
};

}  // namespace

YAML::Node ParseYamlDocument(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    ThrowInputError(file, e.mark.is_null() ? "" : "line " + LineOf(e.mark),
                    "YAML syntax error: " + e.msg);
  }
  DuplicateKeyCheck(file).Walk(root, "");
  return root;
}

double ReadYamlNumber(const YAML::Node& node, const std::string& file, const std::string& where) {
  if (!node.IsScalar()) ThrowInputError(file, where, "expected a number");
  double value = 0.0;
  const std::string problem = ParseNumberText(node.Scalar(), &value);
  if (problem == kNotANumber) {
    ThrowInputError(file, where, "expected a number, found '" + node.Scalar() + "'");
  }
  if (!problem.empty()) ThrowInputError(file, where, "'" + node.Scalar() + "' " + problem);
  return value;
}

}  // namespace ccsrm
