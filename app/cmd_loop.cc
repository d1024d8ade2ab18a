// ccsrm loop --data exp1.h5 [exp2.h5 ...] [--holdout exp3.h5 ...] [--candidates a,b,...]
//            [--free ...] [--params p.yaml] [--set name=value ...] [--config arm.yaml]
//            [--threads N] --out loop/
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/name_list.h"
#include "ccsrm/identify/job.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"

namespace ccsrm::app {
namespace {

struct LoopArgs : JobArgs {
  std::vector<std::string> holdout;
  std::optional<std::string> candidates;  // unset: every effect
  std::string config;                     // the declared configuration (default: each file's own)
  int max_rounds = identify::LoopOptions().max_rounds;
};

int RunLoop(const LoopArgs& a) {
  identify::LoopJobOptions job;
  FillFitJob(a, "    ", &job);
  job.holdout = a.holdout;
  if (a.candidates) job.candidates = SplitNameList(*a.candidates, "--candidates");
  job.config_path = a.config;
  job.max_rounds = a.max_rounds;
  const identify::LoopJobResult r = identify::RunLoopJob(job);
  if (!r.served && r.summary.declared.termination == identify::IdentificationTermination::kFailed) {
    std::fprintf(stderr, "ccsrm: the declared model's fit failed: %s (outputs written)\n",
                 r.summary.declared.message.c_str());
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
  AddFitParameterOptions(cmd, a.get());
  cmd->add_option("--config", a->config,
                  "The declared arm configuration, instead of each recording's own config_yaml "
                  "(same joints and driving cables): what the declared values are checked against");
  cmd->add_option("--max-rounds", a->max_rounds, "Effects added at most")
      ->capture_default_str()
      ->check(ValidIn(&identify::LoopOptions::max_rounds));
  cmd->add_option("--max-iterations", a->max_iterations, "Levenberg-Marquardt iterations per fit")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::max_iterations));
  AddJobOptions(cmd, a.get());
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
