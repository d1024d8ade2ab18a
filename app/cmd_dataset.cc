// ccsrm dataset inspect FILE [--json]
#include <cstdio>
#include <memory>
#include <string>

#include "ccsrm/datasets/inspect.h"
#include "commands.h"

namespace ccsrm::app {

void AddDatasetCommands(CLI::App& root) {
  CLI::App* dataset =
      root.add_subcommand("dataset", "Inspect ccsrm HDF5 files (runs and experiments)");
  dataset->require_subcommand(1);
  CLI::App* inspect = dataset->add_subcommand(
      "inspect",
      "Validate a ccsrm-run/1 or ccsrm-dataset/1 file and print its schema, sizes, "
      "time span and attributes");
  struct Args {
    std::string path;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  inspect->add_option("FILE", args->path, "HDF5 file")->required();
  inspect->add_flag("--json", args->json, "Print one JSON object instead of text");
  inspect->callback([args] {
    const datasets::FileSummary summary = datasets::InspectFile(args->path);
    if (args->json) {
      std::printf("%s\n", datasets::ToJson(summary).dump(2).c_str());
    } else {
      std::printf("%s", datasets::ToText(summary).c_str());
    }
  });
}

}  // namespace ccsrm::app
