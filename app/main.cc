#include <cstdio>
#include <exception>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/output_policy.h"
#include "ccsrm/common/version.h"
#include "ccsrm/identify/mpi_backend.h"
#include "commands.h"

namespace {

// A command-line error is bad input like any other (docs/conventions.md):
// one line on stderr, status 2, whichever subcommand and option it concerns.
// --help and --version print what was asked for (status 0), and a command
// that ends with its own status (CLI::RuntimeError, e.g. 3 for a diverged
// simulation) keeps it: both go through CLI11.
int ExitOnParseError(const CLI::App& root, const CLI::ParseError& e) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success) ||
      e.get_name() == "RuntimeError") {
    return root.exit(e);
  }
  std::string message = e.what();
  for (char& c : message) {
    if (c == '\n') c = ' ';
  }
  std::fprintf(stderr, "ccsrm: %s\n", message.c_str());
  return 2;
}

// The commands whose runs go to every rank of an MPI job (docs/cluster.md).
bool SharesRuns(const std::string& command) {
  return command == "identify" || command == "loop" || command == "design" ||
         command == "derivatives";
}

int Run(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (ccsrm::identify::MpiRanks() > 1 && !SharesRuns(command)) {
    // Every rank would run it and write the same outputs: rank 0 alone does.
    if (ccsrm::identify::MpiRank() > 0) return 0;
    std::fprintf(stderr,
                 "ccsrm: note: %s does not spread its runs over MPI ranks; rank 0 runs it alone\n",
                 command.c_str());
  }
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
  ccsrm::app::AddReportCommand(root);
  ccsrm::app::AddDerivativesCommand(root);
  ccsrm::app::AddIdentifyCommand(root);
  ccsrm::app::AddLoopCommand(root);
  ccsrm::app::AddPredictCommand(root);
  ccsrm::app::AddDesignCommand(root);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return ExitOnParseError(root, e);
  } catch (const ccsrm::InputError& e) {
    std::fprintf(stderr, "ccsrm: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ccsrm: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread starts: Ctrl-C or a scheduler's SIGTERM removes the
  // temporaries of unfinished outputs (docs/conventions.md, "Outputs").
  ccsrm::RemoveTemporariesOnInterrupt();
  ccsrm::identify::StartMpi(&argc, &argv);
  const int status = Run(argc, argv);
  ccsrm::identify::StopMpi(status);
  return status;
}
