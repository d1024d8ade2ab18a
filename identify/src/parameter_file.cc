// `ccsrm identify --params FILE`: values, free flags and bounds by name.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::identify {
namespace {

double Number(const YAML::Node& node, const std::string& file, const std::string& where) {
  return ReadYamlNumber(node, file, where);
}

}  // namespace

void ApplyParameterFile(const std::string& yaml_text, const std::string& file,
                        IdentificationOptions* options) {
  YAML::Node root = ParseYamlDocument(yaml_text, file);
  std::string prefix;
  if (root.IsMap() && root["parameters"]) {  // a truth file of ccsrm generate
    root = root["parameters"];
    prefix = "parameters.";
  }
  if (!root.IsMap()) {
    ThrowInputError(file, "",
                    "expected a mapping of parameter names to values or to {value, free, "
                    "bounds} (e.g. 'mu: 0.18')");
  }
  // Built aside and applied only when the whole file is good.
  IdentificationOptions updated = *options;
  for (const auto& entry : root) {
    const std::string name = entry.first.as<std::string>();
    const std::string where =
        "line " + std::to_string(entry.first.Mark().line + 1) + ", key '" + prefix + name + "'";
    const sim::ParameterInfo* info = nullptr;
    try {
      info = &sim::FindParameter(name, file);
    } catch (const InputError& error) {
      // FindParameter's message lists the known names after the file's.
      const std::string text = error.what();
      const std::size_t known = text.find("(known:");
      ThrowInputError(file, where,
                      "unknown parameter" +
                          (known == std::string::npos ? std::string() : " " + text.substr(known)));
    }
    const auto set_value = [&](double value, const std::string& at) {
      const std::string problem = sim::ParameterValueProblem(*info, value);
      if (!problem.empty()) ThrowInputError(file, at, problem);
      updated.values[name] = value;
    };
    if (entry.second.IsScalar()) {
      set_value(Number(entry.second, file, where), where);
      continue;
    }
    if (!entry.second.IsMap()) {
      ThrowInputError(file, where, "expected a number or a mapping {value, free, bounds}");
    }
    std::string value_at;   // where this entry gives the start value, if it does
    std::string bounds_at;  // where it gives bounds, if it does
    for (const auto& field : entry.second) {
      const std::string key = field.first.as<std::string>();
      const std::string at = "line " + std::to_string(field.first.Mark().line + 1) + ", key '" +
                             prefix + name + "." + key + "'";
      if (key == "value" || key == "start") {
        set_value(Number(field.second, file, at), at);
        value_at = at;
      } else if (key == "free") {
        bool free = false;
        try {
          free = field.second.as<bool>();
        } catch (const YAML::Exception&) {
          ThrowInputError(file, at, "expected true or false");
        }
        auto& list = updated.free_parameters;
        const auto it = std::find(list.begin(), list.end(), name);
        if (free && it == list.end()) list.push_back(name);
        if (!free && it != list.end()) list.erase(it);
      } else if (key == "bounds") {
        if (!field.second.IsSequence() || field.second.size() != 2) {
          ThrowInputError(file, at, "expected [lower, upper]");
        }
        const double lower = Number(field.second[0], file, at);
        const double upper = Number(field.second[1], file, at);
        if (!(lower < upper) || lower < info->lower || upper > info->upper) {
          char text[256];
          std::snprintf(text, sizeof(text),
                        "[%g, %g] must be increasing and inside the parameter's bounds [%g, %g] %s",
                        lower, upper, info->lower, info->upper, info->units.c_str());
          ThrowInputError(file, at, text);
        }
        updated.bounds[name] = {lower, upper};
        bounds_at = at;
      } else {
        ThrowInputError(file, at, "unknown field (known: value, free, bounds)");
      }
    }
    // The start must lie inside the bounds given with it (Identify checks
    // a start taken from the experiment, which this file does not know).
    const auto value = updated.values.find(name);
    if (!bounds_at.empty() && value != updated.values.end()) {
      const auto [lower, upper] = updated.bounds.at(name);
      if (value->second < lower || value->second > upper) {
        char text[256];
        std::snprintf(text, sizeof(text), "start value %g is outside the bounds [%g, %g]%s%s",
                      value->second, lower, upper,
                      info->units == "1" ? "" : (" " + info->units).c_str(),
                      value_at.empty() ? " (the start was set before this file)" : "");
        ThrowInputError(file, value_at.empty() ? bounds_at : value_at, text);
      }
    }
  }
  *options = std::move(updated);
}

void ApplyFitParameters(const std::vector<std::string>* free, const std::string& params_path,
                        const std::vector<std::pair<std::string, double>>& values,
                        IdentificationOptions* options) {
  if (free != nullptr) options->free_parameters = *free;
  for (const std::string& name : options->free_parameters) sim::FindParameter(name, "--free");
  if (!params_path.empty()) {
    ApplyParameterFile(ReadTextFile(params_path), params_path, options);
  }
  for (const auto& [name, value] : values) {
    const std::string problem =
        sim::ParameterValueProblem(sim::FindParameter(name, "--set"), value);
    if (!problem.empty()) ThrowInputError("--set", "", problem);
    options->values[name] = value;
  }
}

}  // namespace ccsrm::identify
