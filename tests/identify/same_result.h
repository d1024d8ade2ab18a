#pragma once
// Comparing the JSON outputs of two runs of the same command that differ
// only in where or when they ran (threads or ranks, stopped and resumed).
#include <initializer_list>
#include <nlohmann/json.hpp>

namespace ccsrm::testing {

// Removes, at every depth, the keys that differ between such runs by design
// (clocks, parallelism, counts of repeated runs).
inline void DropKeys(nlohmann::json* j, std::initializer_list<const char*> keys) {
  if (j->is_object()) {
    for (const char* key : keys) j->erase(key);
    for (auto& [key, value] : j->items()) DropKeys(&value, keys);
  } else if (j->is_array()) {
    for (auto& value : *j) DropKeys(&value, keys);
  }
}

}  // namespace ccsrm::testing
