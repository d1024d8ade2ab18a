#include "output_kinds.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/datasets/inspect.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

bool HasSchemaPrefix(const std::string& path, const std::string& prefix) {
  return datasets::ReadSchemaAttribute(path).rfind(prefix, 0) == 0;
}

// A line "schema: X" (or "schema: \"X\"", as OpenCV writes it) at the top
// level of a YAML file, within its first 64 KiB: our YAML outputs all carry
// one, and a user's file of another kind does not.
bool YamlHasSchema(const std::string& path, const std::string& schema) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t read = 0;
  while (read < 65536 && std::getline(in, line)) {
    read += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "schema: " + schema || line == "schema: \"" + schema + "\"") return true;
  }
  return false;
}

}  // namespace

OutputKind RunFileOutput() {
  return {"ccsrm run file (ccsrm-run/1)", false,
          [](const std::string& p) { return HasSchemaPrefix(p, "ccsrm-run/"); }};
}

OutputKind ExperimentFileOutput() {
  return {"ccsrm experiment (ccsrm-dataset/1)", false,
          [](const std::string& p) { return HasSchemaPrefix(p, "ccsrm-dataset/"); }};
}

OutputKind C3dFileOutput() {
  return {"C3D file", false, [](const std::string& p) {
            // Every C3D file's second byte is 0x50 (the header's key word).
            std::ifstream in(p, std::ios::binary);
            char header[2] = {0, 0};
            return static_cast<bool>(in.read(header, 2)) && header[1] == 0x50;
          }};
}

OutputKind YamlFileOutput(const std::string& schema, const std::string& description) {
  return {description + " (" + schema + ")", false,
          [schema](const std::string& p) { return YamlHasSchema(p, schema); }};
}

OutputKind CameraFileOutput() { return YamlFileOutput(cameras::kCameraSchema, "camera file"); }

OutputKind DerivativesJsonOutput() {
  return {"ccsrm derivatives JSON file", false, [](const std::string& p) {
            std::ifstream in(p);
            const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
            return json.is_object() && json.contains("run") && json["run"].is_object() &&
                   json["run"].contains("config");
          }};
}

OutputKind RenderFolderOutput() {
  return {"ccsrm camera render folder (cameras.yaml, ccsrm-cameras/1)", true,
          [](const std::string& p) {
            return YamlHasSchema((fs::path(p) / "cameras.yaml").string(), "ccsrm-cameras/1");
          }};
}

OutputKind BoardImagesFolderOutput() {
  return {"folder of checkerboard images (PNG files only)", true, [](const std::string& p) {
            std::error_code ec;
            for (const fs::directory_entry& e : fs::directory_iterator(p, ec)) {
              if (!e.is_regular_file() || e.path().extension() != ".png") return false;
            }
            return !ec;
          }};
}

void CheckOut(const std::string& path, const OutputKind& kind,
              const std::vector<std::string>& inputs) {
  CheckOutputPath(path, "--out", kind, inputs);
}

}  // namespace ccsrm::app
