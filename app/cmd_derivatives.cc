// ccsrm derivatives: the finite-difference derivatives of the simulated
// joint angles with respect to the named parameters, at two relative steps,
// and whether they agree (issue 10); or a sweep of one parameter fitted by
// a cubic. The work is identify::DerivativeCheck / identify::ParameterSweep.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/name_list.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/identify/mpi_backend.h"
#include "ccsrm/identify/sensitivity.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/paper_run.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"
#include "output_kinds.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

// Exit statuses besides 0 (passed) and 2 (bad input).
constexpr int kRunDidNotComplete = 3;
constexpr int kDerivativesDisagree = 4;

// Values are taken as text and parsed here, so that a bad one exits with
// status 2 and one line naming its option, like every other bad input.
struct DerivativesArgs {
  sim::PaperRunOptions run;
  MotionArgs motion;                      // --protocol or --inputs instead of the paper protocol
  std::optional<std::string> parameters;  // unset: every parameter
  std::string steps = "1e-2,3e-3";
  std::string threads = std::to_string(identify::DefaultThreads());
  std::string negligible;
  std::string sweep;
  std::string points;
  std::string span;
  std::string json;
  bool quiet = false;
  double run_timeout_s = identify::MpiOptions().run_timeout_s;
};

int ParseCount(const std::string& text, const std::string& option) {
  const double value = ParseNumber(text, option);
  if (value != std::floor(value) || std::abs(value) > 1e6) {
    ThrowInputError(option, "", "'" + text + "' is not a whole number");
  }
  return static_cast<int>(value);
}

// An options struct's IsValid message begins with the field's name; the
// user typed an option, so the message names that instead.
[[noreturn]] void ThrowOptionError(const std::string& error) {
  static const std::vector<std::pair<std::string, std::string>> options = {
      {"parameters", "--parameters"},
      {"relative_steps", "--steps"},
      {"threads", "--threads"},
      {"points", "--points"},
      {"span", "--span"},
      {"parameter", "--sweep"},
      {"negligible_change_deg", "--negligible-deg"}};
  for (const auto& [field, option] : options) {
    if (error.rfind(field + ": ", 0) == 0)
      ThrowInputError(option, "", error.substr(field.size() + 2));
  }
  throw InputError(error);
}

identify::ProgressCallback Progress(bool quiet) {
  if (quiet) return nullptr;
  return [](const identify::RunProgress& p) {
    // A backend (MPI) does not say which run finished: no label then.
    std::fprintf(stderr, "  [%zu/%zu] %s%s%s\n", p.finished, p.total, p.label.c_str(),
                 p.label.empty() ? "" : ": ", p.summary.BriefReport().c_str());
  };
}

// The motion in words: the paper protocol's amplitude, a protocol file's
// name, or the recorded inputs' file.
std::string MotionOf(const sim::PaperRun& run) {
  if (run.protocol && !run.default_protocol) return "protocol '" + run.protocol->name + "'";
  if (!run.inputs_source.empty()) return "inputs " + run.inputs_source;
  char text[32];
  std::snprintf(text, sizeof(text), "%+.3g deg", run.config.protocol.amplitude_rad * 180.0 / M_PI);
  return text;
}

std::string Describe(const DerivativesArgs& a, const sim::PaperRun& run) {
  std::string text = "ccsrm derivatives: " + a.run.config_path + ", case " +
                     (run.case_number != 0 ? std::to_string(run.case_number) : "as configured");
  char figures[64];
  std::snprintf(figures, sizeof(figures), ", %.4g s simulated", run.simulation.duration_s);
  text += ", " + MotionOf(run) + figures;
  if (!a.run.params_path.empty()) text += ", --params " + a.run.params_path;
  for (const std::string& s : a.run.sets) text += ", --set " + s;
  return text;
}

nlohmann::json RunJson(const DerivativesArgs& a, const sim::PaperRun& run) {
  return {{"config", a.run.config_path},
          {"case", run.case_number},
          {"amplitude_deg", run.config.protocol.amplitude_rad * 180.0 / M_PI},
          {"duration_s", run.simulation.duration_s},
          {"protocol_yaml", sim::ProtocolYamlOf(run)},
          {"inputs_file", run.inputs_source},
          {"params", a.run.params_path},
          {"sets", a.run.sets}};
}

int RunDerivatives(const DerivativesArgs& a) {
  // Check every option and the output path before spending minutes on runs.
  const int threads = ParseCount(a.threads, "--threads");
  const bool sweep = !a.sweep.empty();
  if (!sweep && !a.points.empty()) ThrowInputError("--points", "", "needs --sweep");
  if (!sweep && !a.span.empty()) ThrowInputError("--span", "", "needs --sweep");
  if (sweep && !a.negligible.empty()) {
    ThrowInputError("--negligible-deg", "", "cannot be combined with --sweep");
  }
  if (sweep && a.parameters) {
    ThrowInputError("--parameters", "", "cannot be combined with --sweep");
  }
  std::string error;
  identify::DerivativeCheckOptions check;
  identify::SweepOptions sweep_options;
  if (sweep) {
    sweep_options.parameter = a.sweep;
    if (!a.points.empty()) sweep_options.points = ParseCount(a.points, "--points");
    if (!a.span.empty()) sweep_options.span = ParseNumber(a.span, "--span");
    sweep_options.threads = threads;
    sweep_options.progress = Progress(a.quiet);
    if (!sweep_options.IsValid(&error)) ThrowOptionError(error);
  } else {
    if (a.parameters) check.parameters = SplitNameList(*a.parameters, "--parameters");
    check.relative_steps.clear();
    for (const std::string& s : SplitNameList(a.steps, "--steps")) {
      check.relative_steps.push_back(ParseNumber(s, "--steps"));
    }
    check.threads = threads;
    if (!a.negligible.empty()) {
      check.negligible_change_deg = ParseNumber(a.negligible, "--negligible-deg");
    }
    check.progress = Progress(a.quiet);
    if (!check.IsValid(&error)) ThrowOptionError(error);
  }
  if (!a.json.empty()) {
    CheckOutputPath(a.json, "--json", DerivativesJsonOutput(),
                    {a.run.config_path, a.run.params_path, sim::ProtocolFileOf(a.run.protocol_path),
                     a.motion.inputs_path});
  }

  const sim::PaperRun run = PrepareRun(a.run, a.motion);
  PrintConfigWarnings(run.config);
  // A parameter at 0 (the friction a case switches off) is stepped relative
  // to its value in the configuration file as written.
  const sim::ArmParameters nominal =
      sim::ParseConfig(run.config_text, a.run.config_path).parameters;
  std::printf("%s\n", Describe(a, run).c_str());

  // Under mpirun with more than one rank, every rank has prepared the same
  // run from the command line (milliseconds) and rank 0 hands the runs to
  // all of them (docs/cluster.md). The runs are experiment 0 of
  // FrameExperiment, every frame's angles, so the check sees what it sees
  // on threads, to the bit. Alone, the runs stay on this process's threads.
  std::vector<identify::Experiment> experiments;
  std::shared_ptr<identify::SimulationBackend> backend;
  if (identify::MpiRanks() > 1) {
    experiments.push_back(
        identify::FrameExperiment(Describe(a, run), run.model, run.inputs, run.simulation));
    const auto backends =
        identify::JobBackends({&experiments}, {threads, a.run_timeout_s}, PrintNow);
    if (backends.empty()) return 0;  // another rank of an MPI job: it served rank 0's runs
    backend = backends[0];
  }

  nlohmann::json json;
  int status = 0;
  if (sweep) {
    sweep_options.scale_at_zero = nominal;
    sweep_options.backend = backend;
    const identify::SweepSummary summary = identify::ParameterSweep(
        run.model, run.config.parameters, run.inputs, run.simulation, sweep_options);
    std::printf("%s", summary.FullReport().c_str());
    json = identify::ToJson(summary);
    if (!summary.all_runs_completed()) status = kRunDidNotComplete;
  } else {
    check.scale_at_zero = nominal;
    check.backend = backend;
    const identify::DerivativeCheckSummary summary = identify::DerivativeCheck(
        run.model, run.config.parameters, run.inputs, run.simulation, check);
    std::printf("%s", summary.FullReport().c_str());
    json = identify::ToJson(summary);
    if (!summary.all_runs_completed()) {
      status = kRunDidNotComplete;
    } else if (!summary.passed()) {
      status = kDerivativesDisagree;
    }
  }
  if (!a.json.empty()) {
    json["run"] = RunJson(a, run);
    WriteTextFileAtomically(a.json, json.dump(2) + "\n");
    std::printf("  json: %s\n", a.json.c_str());
  }
  return status;
}

}  // namespace

void AddDerivativesCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "derivatives",
      "Finite-difference derivatives of the simulated joint angles with respect to the named "
      "parameters at two relative steps, and whether they agree (exit 4 if not, 3 if a run "
      "did not complete); or, with --sweep, a sweep of one parameter fitted by a cubic");
  auto a = std::make_shared<DerivativesArgs>();
  AddPaperRunOptions(cmd, &a->run);
  AddParameterOptions(cmd, &a->run);
  AddMotionOptions(cmd, &a->run, &a->motion);
  cmd->add_option("--parameters", a->parameters,
                  "Parameters to differentiate, comma-separated (default: all of them)");
  cmd->add_option("--steps", a->steps, "Relative steps, comma-separated, at least two")
      ->capture_default_str();
  cmd->add_option("--threads", a->threads, "Runs at a time (per rank under mpirun)")
      ->capture_default_str();
  cmd->add_option("--negligible-deg", a->negligible,
                  "A derivative is negligible (does not fail) when a 1 % change moves the angles "
                  "by less than this, RMS [deg] (default 0.003, a tenth of the mocap noise "
                  "floor; 0: none)");
  cmd->add_option("--sweep", a->sweep,
                  "Instead of derivatives: sweep this parameter and fit a cubic to every angle")
      ->check(NotEmpty());
  cmd->add_option("--points", a->points, "Values in the sweep (default 21)");
  cmd->add_option("--span", a->span, "Relative half-width of the sweep (default 0.05)");
  cmd->add_option("--json", a->json, "Also write the summary as JSON to this file");
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  AddRunTimeoutOption(cmd, &a->run_timeout_s);
  cmd->callback([a] {
    const int code = RunDerivatives(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
