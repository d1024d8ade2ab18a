// ccsrm dataset inspect FILE [--json]
#include <cstdio>
#include <memory>
#include <string>
#include <variant>

#include "ccsrm/datasets/inspect.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "commands.h"

namespace ccsrm::app {

void AddDatasetCommands(CLI::App& root) {
  CLI::App* dataset =
      root.add_subcommand("dataset", "Inspect ccsrm HDF5 files (runs and experiments)");
  dataset->require_subcommand(1);
  CLI::App* inspect = dataset->add_subcommand(
      "inspect",
      "Validate a ccsrm-run/1 or ccsrm-dataset/1 file (an experiment also against its own "
      "config_yaml) and print its schema, sizes, time span and attributes");
  struct Args {
    std::string path;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  inspect->add_option("FILE", args->path, "HDF5 file")->required();
  inspect->add_flag("--json", args->json, "Print one JSON object instead of text");
  inspect->callback([args] {
    // Read once; an experiment is also checked against its own config_yaml
    // and the joints' range, as identification and mocap process check it.
    const datasets::AnyFile file = datasets::ReadAnyFile(args->path);
    if (const auto* experiment = std::get_if<datasets::ExperimentFile>(&file)) {
      sim_io::CheckExperimentAgainstConfig(*experiment, args->path);
    }
    const datasets::FileSummary summary = datasets::Summarise(file, args->path);
    if (args->json) {
      std::printf("%s\n", datasets::ToJson(summary).dump(2).c_str());
    } else {
      std::printf("%s", datasets::ToText(summary).c_str());
    }
  });
}

}  // namespace ccsrm::app
