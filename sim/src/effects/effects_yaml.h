#pragma once
// Reading an `effects:` mapping (configuration, truth file, --effects file).
#include <yaml-cpp/yaml.h>

#include <string>

#include "ccsrm/sim/parameters.h"

namespace ccsrm::sim::internal {

// Applies `node`, a mapping from effect name to a mapping of its parameters
// (short names) to numbers, or null / an empty mapping for "on at its
// defaults", to *parameters: every effect named is switched on. Errors name
// `file`, the line and the key `key_prefix` + "effect.parameter" (e.g.
// key_prefix "effects."). Applies nothing when it throws.
void ApplyEffectsNode(const YAML::Node& node, const std::string& file,
                      const std::string& key_prefix, ArmParameters* parameters);

}  // namespace ccsrm::sim::internal
