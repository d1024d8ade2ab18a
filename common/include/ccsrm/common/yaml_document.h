#pragma once
// The one door through which every YAML file of ccsrm is read.
#include <yaml-cpp/yaml.h>

#include <string>

namespace ccsrm {

// Parses `text` (the contents of `file`, named in messages) as one YAML
// document and refuses what yaml-cpp lets through silently: a key given
// twice in the same mapping (yaml-cpp keeps both and `node[key]` finds the
// first, so the second value would be ignored without a word). Every
// mapping is checked, also those inside sequences.
// Throws InputError:
//   "<file>: line N: YAML syntax error: <yaml-cpp's reason>"
//   "<file>: line N, key 'a.b[0].c': duplicate key (first at line M)"
// Lines are 1-based; the key path joins mapping keys with '.' and numbers
// sequence items from 0 as [i].
YAML::Node ParseYamlDocument(const std::string& text, const std::string& file);

// The finite number a scalar node holds (ParseNumberText). `where` names the
// field in the message ("line N, key 'a.b'"). Throws InputError
// "<file>: <where>: expected a number, found 'heavy'" (or "expected a
// number" for a list or mapping), "...: '1e400' is outside the range of a
// double ...", "...: '.nan' is not a finite number".
double ReadYamlNumber(const YAML::Node& node, const std::string& file, const std::string& where);

}  // namespace ccsrm
