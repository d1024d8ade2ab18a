#pragma once
// Reading the JSON files the commands write (fit.json, loop.json) for their
// pages: every value is fetched by its key path, and anything missing or of
// the wrong type is one InputError naming the file and that path
// ("parameters.T_p.value", "rounds[0].candidates[2].score").
#include <array>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ccsrm::reports::internal {

// NaN: what a JSON null (an unknown number) is read as.
inline constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

// Parses `file` as JSON and checks that it is an object whose "schema" is
// `schema`. Throws InputError "<file>: not valid JSON", "<file>: no 'schema'
// key; ...", or "<file>: key 'schema': is ..., expected ... (written by
// <writer>)".
nlohmann::json ReadSchemaFile(const std::string& file, const std::string& schema,
                              const std::string& writer);

class JsonReader {
 public:
  using json = nlohmann::json;

  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  // Throws "<file>: key '<key>': <what>".
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;

  // The member `key` of `object`, which `parent` names.
  const json& At(const json& object, const std::string& parent, const std::string& key) const;
  // A number; null is NaN where `nullable` (JSON has no NaN or infinity).
  double Number(const json& value, const std::string& key, bool nullable = false) const;
  double NumberAt(const json& object, const std::string& parent, const std::string& key,
                  bool nullable = false) const;
  std::string Text(const json& object, const std::string& parent, const std::string& key) const;
  bool Flag(const json& object, const std::string& parent, const std::string& key) const;
  const json& List(const json& object, const std::string& parent, const std::string& key) const;
  const json& Object(const json& object, const std::string& parent, const std::string& key) const;
  std::vector<double> Numbers(const json& object, const std::string& parent, const std::string& key,
                              bool nullable = false) const;
  std::vector<std::string> Texts(const json& object, const std::string& parent,
                                 const std::string& key) const;
  // A pair [a, b] of numbers.
  std::array<double, 2> Pair(const json& value, const std::string& key, bool nullable) const;

  static std::string Join(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
  }
  static std::string Index(const std::string& list, std::size_t i) {
    return list + "[" + std::to_string(i) + "]";
  }

 private:
  std::string file_;
};

}  // namespace ccsrm::reports::internal
