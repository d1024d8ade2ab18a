#include "json_reader.h"

#include <fstream>

#include "ccsrm/common/error.h"

namespace ccsrm::reports::internal {

using nlohmann::json;

json ReadSchemaFile(const std::string& file, const std::string& schema, const std::string& writer) {
  std::ifstream stream(file);
  if (!stream) ThrowInputError(file, "", "cannot be read");
  json root = json::parse(stream, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) ThrowInputError(file, "", "not valid JSON");
  if (!root.is_object() || !root.contains("schema")) {
    ThrowInputError(file, "", "no 'schema' key; expected schema " + schema);
  }
  if (root["schema"] != schema) {
    ThrowInputError(file, "key 'schema'",
                    "is " + root["schema"].dump() + ", expected \"" + schema + "\" (written by " +
                        writer + ")");
  }
  return root;
}

void JsonReader::Fail(const std::string& key, const std::string& what) const {
  ThrowInputError(file_, "key '" + key + "'", what);
}

const json& JsonReader::At(const json& object, const std::string& parent,
                           const std::string& key) const {
  if (!object.is_object()) Fail(parent, "expected an object");
  const auto it = object.find(key);
  if (it == object.end()) Fail(Join(parent, key), "missing");
  return *it;
}

double JsonReader::Number(const json& value, const std::string& key, bool nullable) const {
  if (value.is_null() && nullable) return kUnknown;
  if (!value.is_number()) Fail(key, nullable ? "expected a number or null" : "expected a number");
  return value.get<double>();
}

double JsonReader::NumberAt(const json& object, const std::string& parent, const std::string& key,
                            bool nullable) const {
  return Number(At(object, parent, key), Join(parent, key), nullable);
}

std::string JsonReader::Text(const json& object, const std::string& parent,
                             const std::string& key) const {
  const json& value = At(object, parent, key);
  if (!value.is_string()) Fail(Join(parent, key), "expected a string");
  return value.get<std::string>();
}

bool JsonReader::Flag(const json& object, const std::string& parent, const std::string& key) const {
  const json& value = At(object, parent, key);
  if (!value.is_boolean()) Fail(Join(parent, key), "expected true or false");
  return value.get<bool>();
}

const json& JsonReader::List(const json& object, const std::string& parent,
                             const std::string& key) const {
  const json& value = At(object, parent, key);
  if (!value.is_array()) Fail(Join(parent, key), "expected a list");
  return value;
}

const json& JsonReader::Object(const json& object, const std::string& parent,
                               const std::string& key) const {
  const json& value = At(object, parent, key);
  if (!value.is_object()) Fail(Join(parent, key), "expected an object");
  return value;
}

std::vector<double> JsonReader::Numbers(const json& object, const std::string& parent,
                                        const std::string& key, bool nullable) const {
  const json& list = List(object, parent, key);
  std::vector<double> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.push_back(Number(list[i], Index(Join(parent, key), i), nullable));
  }
  return out;
}

std::vector<std::string> JsonReader::Texts(const json& object, const std::string& parent,
                                           const std::string& key) const {
  const json& list = List(object, parent, key);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!list[i].is_string()) Fail(Index(Join(parent, key), i), "expected a string");
    out.push_back(list[i].get<std::string>());
  }
  return out;
}

std::array<double, 2> JsonReader::Pair(const json& value, const std::string& key,
                                       bool nullable) const {
  if (!value.is_array() || value.size() != 2) Fail(key, "expected a list of two numbers");
  return {Number(value[0], key + "[0]", nullable), Number(value[1], key + "[1]", nullable)};
}

}  // namespace ccsrm::reports::internal
