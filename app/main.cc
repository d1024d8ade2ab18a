#include <cstdio>
#include <exception>

#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "commands.h"

int main(int argc, char** argv) {
  CLI::App root{"ccsrm: simulate, measure and identify cable-driven continuum manipulators"};
  root.set_version_flag("--version", ccsrm::kVersion);
  root.require_subcommand(1);
  ccsrm::app::AddConfigCommands(root);
  ccsrm::app::AddDatasetCommands(root);
  ccsrm::app::AddSimulateCommand(root);
  ccsrm::app::AddBenchCommand(root);
  ccsrm::app::AddMocapCommands(root);
  ccsrm::app::AddGenerateCommand(root);
  ccsrm::app::AddCamerasCommands(root);
  ccsrm::app::AddDerivativesCommand(root);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return root.exit(e);
  } catch (const ccsrm::InputError& e) {
    std::fprintf(stderr, "ccsrm: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ccsrm: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
