// ccsrm loop --data exp1.h5 [exp2.h5 ...] [--holdout exp3.h5 ...] [--candidates a,b,...]
//            [--free ...] [--params p.yaml] [--set name=value ...] [--config arm.yaml]
//            [--threads N] --out loop/
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/loop.h"
#include "ccsrm/identify/run_journal.h"
#include "commands.h"
#include "fit_inputs.h"
#include "option_checks.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

struct LoopArgs {
  std::vector<std::string> data;
  std::vector<std::string> holdout;
  std::optional<std::string> candidates;  // unset: every effect
  std::optional<std::string> free;
  std::string params;
  std::string config;  // the declared configuration (default: each file's own)
  std::vector<std::string> set;
  int threads = identify::DefaultThreads();
  int max_rounds = identify::LoopOptions().max_rounds;
  int max_iterations = identify::IdentificationOptions().max_iterations;
  double noise_deg = 0.0;  // 0: estimated
  std::string out;
  bool quiet = false;
  double run_timeout_s = identify::MpiOptions().run_timeout_s;
  bool resume = false;
};

// What decides the loop's result besides the files' bytes (not --threads,
// --quiet, --run-timeout or the number of ranks).
std::string ResultOptions(const LoopArgs& a) {
  std::string text = "data=" + std::to_string(a.data.size()) +
                     " holdout=" + std::to_string(a.holdout.size()) +
                     "\ncandidates=" + a.candidates.value_or("(default)") +
                     "\nfree=" + a.free.value_or("(default)") + "\nsets=";
  for (const std::string& s : a.set) text += s + ",";
  char numbers[128];
  std::snprintf(numbers, sizeof(numbers), "\nmax_rounds=%d max_iterations=%d noise_deg=%.17g",
                a.max_rounds, a.max_iterations, a.noise_deg);
  return text + numbers;
}

std::string JournalPath(const std::string& out) {
  return (std::filesystem::path(out) / "runs.journal").string();
}

int RunLoop(const LoopArgs& a) {
  identify::LoopOptions options;
  options.fit.threads = a.threads;
  options.fit.max_iterations = a.max_iterations;
  options.max_rounds = a.max_rounds;
  ApplyFitOptions(a.free, a.params, a.set, &options.fit);
  if (a.candidates) options.candidates = SplitList(*a.candidates, "--candidates");
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("loop", "", error);
  std::vector<std::string> inputs = a.data;
  inputs.insert(inputs.end(), a.holdout.begin(), a.holdout.end());
  inputs.push_back(a.params);
  inputs.push_back(a.config);
  CheckOut(a.out, LoopFolderOutput(), inputs);
  // A loop is resumed by running it again over the journal of its runs.
  const CheckpointKey key = MakeCheckpointKey("loop", ResultOptions(a), inputs);
  if (a.resume) ReadCheckpoint(a.out, key);  // refuses other data, options or version
  const std::vector<identify::Experiment> training =
      LoadExperiments(a.data, a.noise_deg, "training", a.config);
  const std::vector<identify::Experiment> holdout =
      LoadExperiments(a.holdout, a.noise_deg, "held out", a.config);
  const auto backends = RunBackends({&training, &holdout}, a.threads, a.run_timeout_s);
  if (backends.empty()) return 0;  // another rank of an MPI job: it served rank 0's runs
  WriteCheckpoint(a.out, key, {{"runs_journal", "runs.journal"}});
  const auto journal = std::make_shared<identify::RunJournal>(JournalPath(a.out), a.resume);
  if (a.resume) {
    std::printf("resuming: %lld runs recorded in %s\n", static_cast<long long>(journal->recorded()),
                journal->path().c_str());
  }
  options.fit.backend = identify::WithJournal(backends[0], journal, 0);
  options.holdout_backend = identify::WithJournal(backends[1], journal, 1);

  std::string free_list;
  for (const std::string& n : options.fit.free_parameters)
    free_list += (free_list.empty() ? "" : ", ") + n;
  std::printf("declared model: %s free; %zu training, %zu held-out experiment%s; %d thread%s\n",
              free_list.c_str(), training.size(), holdout.size(), holdout.size() == 1 ? "" : "s",
              options.fit.threads, options.fit.threads == 1 ? "" : "s");
  std::fflush(stdout);
  if (!a.quiet) {
    PrintFitProgress(&options.fit, "    ");
    options.on_progress = [](const identify::LoopProgress& p) {
      std::fprintf(stderr, "\r%-100s\r", "");
      std::printf("%s\n", p.message.c_str());
      std::fflush(stdout);
    };
  }
  const identify::LoopSummary summary = identify::CloseLoop(training, holdout, options);
  std::printf("\n%s", summary.FullReport().c_str());
  const std::vector<std::string> written =
      identify::WriteLoopDirectory(summary, training, holdout, a.out);
  std::printf("  output: %s (%zu files)\n", a.out.c_str(), written.size());
  // The loop is there now: its journal and checkpoint are not needed.
  std::printf("  runs: %lld simulated, %lld taken from the journal of a stopped run\n",
              static_cast<long long>(journal->simulated()),
              static_cast<long long>(journal->replayed()));
  RemoveCheckpoint(a.out);
  std::filesystem::remove(JournalPath(a.out));
  if (summary.declared.termination == identify::IdentificationTermination::kFailed) {
    std::fprintf(stderr, "ccsrm: the declared model's fit failed: %s (outputs written)\n",
                 summary.declared.message.c_str());
    return 3;
  }
  return 0;
}

}  // namespace

void AddLoopCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "loop",
      "Fit the declared model, trace what its residual lacks to an effect of the effect "
      "library, add it, refit, and report the error before and after (writes loop.json and the "
      "fitted runs; exit 3 if the declared fit failed)");
  auto a = std::make_shared<LoopArgs>();
  cmd->add_option("--data", a->data, "Training experiments (ccsrm-dataset/1), one or more")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--holdout", a->holdout,
                  "Held-out experiments: not fitted, each candidate's refit is scored on them")
      ->expected(1, -1);
  cmd->add_option("--candidates", a->candidates,
                  "Candidate effects, comma-separated, 'declared' for the configuration's "
                  "declared values and 'terms' for terms found in the data (a joint moment, "
                  "docs/loop.md) (default: every effect of the library that is off, declared "
                  "and terms; ccsrm generate --list-effects)");
  cmd->add_option("--free", a->free,
                  "The declared model's free parameters, comma-separated (default: mu,mu_c,T_p)");
  cmd->add_option("--params", a->params,
                  "YAML file: name: value, or name: {value, free, bounds: [lo, hi]}");
  cmd->add_option("--set", a->set, "Value of a parameter, name=value (repeatable)");
  cmd->add_option("--config", a->config,
                  "The declared arm configuration, instead of each recording's own config_yaml "
                  "(same joints and driving cables): what the declared values are checked against");
  cmd->add_option("--threads", a->threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::IdentificationOptions::threads));
  cmd->add_option("--max-rounds", a->max_rounds, "Effects added at most")
      ->capture_default_str()
      ->check(ValidIn(&identify::LoopOptions::max_rounds));
  cmd->add_option("--max-iterations", a->max_iterations, "Levenberg-Marquardt iterations per fit")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::max_iterations));
  cmd->add_option("--noise-deg", a->noise_deg,
                  "Measurement noise of the joint angles [deg] (default: estimated per joint "
                  "from the measured twist)")
      ->check(Above(0.0, "deg"));
  cmd->add_option("--out", a->out, "Output folder")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  AddRunTimeoutOption(cmd, &a->run_timeout_s);
  cmd->add_flag("--resume", a->resume,
                "Continue the loop stopped in --out: it runs again, taking every run it had done "
                "from its journal (runs.journal); refused for other data, options or version");
  cmd->callback([a] {
    const int code = RunLoop(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
