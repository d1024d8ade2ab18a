#include "output_kinds.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/common/atomic_file.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

}  // namespace

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
            return CameraFileOutput().recognises((fs::path(p) / "cameras.yaml").string());
          }};
}

OutputKind BoardImagesFolderOutput() {
  return {"folder of checkerboard images (PNG files only)", true, [](const std::string& p) {
            std::error_code ec;
            for (const fs::directory_entry& e : fs::directory_iterator(p, ec)) {
              if (e.path().filename() == kOutputManifestName) continue;
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
