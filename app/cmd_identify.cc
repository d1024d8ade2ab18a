// ccsrm identify --data exp1.h5 [exp2.h5 ...] [--free mu,mu_s,...] [--params p.yaml]
//                [--set name=value ...] [--threads N] --out fit/
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim/parameters.h"
#include "commands.h"
#include "fit_inputs.h"
#include "option_checks.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

// Exit status of a fit that did not converge (its outputs are written) and
// of one that failed.
constexpr int kNotConverged = 4;
constexpr int kFitFailed = 3;

struct IdentifyArgs {
  std::vector<std::string> data;
  std::optional<std::string> free;  // unset: the default list
  std::string params;
  std::vector<std::string> set;
  int threads = identify::DefaultThreads();
  int max_iterations = identify::IdentificationOptions().max_iterations;
  double relative_step = identify::IdentificationOptions().relative_step;
  double noise_deg = 0.0;  // 0: estimated
  bool central_throughout = false;
  std::string out;
  bool quiet = false;
  double run_timeout_s = identify::MpiOptions().run_timeout_s;
  bool resume = false;
};

// What decides the fit's result besides the files' bytes (not --threads,
// --quiet, --run-timeout or the number of ranks: the result is the same).
std::string ResultOptions(const IdentifyArgs& a) {
  std::string text = "free=" + a.free.value_or("(default)") + "\nsets=";
  for (const std::string& s : a.set) text += s + ",";
  char numbers[160];
  std::snprintf(numbers, sizeof(numbers),
                "\nmax_iterations=%d relative_step=%.17g "
                "noise_deg=%.17g central=%d",
                a.max_iterations, a.relative_step, a.noise_deg, a.central_throughout ? 1 : 0);
  return text + numbers;
}

int RunIdentify(const IdentifyArgs& a) {
  // Everything is checked before the first simulation: options, output path,
  // every experiment file.
  identify::IdentificationOptions options;
  options.threads = a.threads;
  options.max_iterations = a.max_iterations;
  options.relative_step = a.relative_step;
  options.central_differences_throughout = a.central_throughout;
  ApplyFitOptions(a.free, a.params, a.set, &options);
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("identify", "", error);
  std::vector<std::string> inputs = a.data;
  inputs.push_back(a.params);
  CheckOut(a.out, FitFolderOutput(), inputs);
  const CheckpointKey key = MakeCheckpointKey("identify", ResultOptions(a), inputs);
  if (a.resume) {
    options.resume = std::make_shared<identify::FitCheckpoint>(
        identify::FitCheckpointFromJson(ReadCheckpoint(a.out, key), CheckpointPath(a.out)));
  }
  options.on_checkpoint = [&](const identify::FitCheckpoint& c) {
    WriteCheckpoint(a.out, key, identify::ToJson(c));
  };
  std::vector<identify::Experiment> experiments =
      LoadExperiments(a.data, a.noise_deg, "experiment");
  const auto backends = RunBackends({&experiments}, a.threads, a.run_timeout_s);
  if (backends.empty()) return 0;  // another rank of an MPI job: it served rank 0's runs
  options.backend = backends.front();
  std::string free_list;
  for (const std::string& n : options.free_parameters)
    free_list += (free_list.empty() ? "" : ", ") + n;
  std::printf("fitting %s on %d thread%s\n", free_list.c_str(), options.threads,
              options.threads == 1 ? "" : "s");
  std::fflush(stdout);
  if (!a.quiet) PrintFitProgress(&options, "");
  const identify::IdentificationSummary summary = identify::Identify(experiments, options);
  std::printf("%s", summary.FullReport().c_str());
  const std::vector<std::string> written = identify::WriteFitDirectory(summary, experiments, a.out);
  RemoveCheckpoint(a.out);  // the fit is there now
  std::printf("  output: %s (%zu files)\n", a.out.c_str(), written.size());
  switch (summary.termination) {
    case identify::IdentificationTermination::kConverged:
      return 0;
    case identify::IdentificationTermination::kNoConvergence:
      std::fprintf(stderr, "ccsrm: the fit did not converge in %d iterations (outputs written)\n",
                   summary.iterations);
      return kNotConverged;
    case identify::IdentificationTermination::kFailed:
      std::fprintf(stderr, "ccsrm: the fit failed: %s (outputs written)\n",
                   summary.message.c_str());
      return kFitFailed;
  }
  return kFitFailed;
}

}  // namespace

void AddIdentifyCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "identify",
      "Fit friction, damping and pre-tension to recorded experiments (Ceres): estimates, "
      "standard errors, correlations, identifiability; writes fit.json and the fitted runs "
      "(exit 4 if the fit did not converge, 3 if it failed)");
  auto a = std::make_shared<IdentifyArgs>();
  cmd->add_option("--data", a->data, "Experiment files (ccsrm-dataset/1), one or more")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--free", a->free,
                  "Parameters to fit, comma-separated (default: mu,mu_s,mu_c,mu_c_s,beta,c_sc,"
                  "c_lc,T_p,T_d0)");
  cmd->add_option("--params", a->params,
                  "YAML file: name: value, or name: {value, free, bounds: [lo, hi]}");
  cmd->add_option("--set", a->set,
                  "Value of a parameter, name=value (start of a free one; repeatable, applied "
                  "after --params)");
  cmd->add_option("--threads", a->threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::IdentificationOptions::threads));
  cmd->add_option("--max-iterations", a->max_iterations, "Levenberg-Marquardt iterations")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::max_iterations));
  cmd->add_option("--relative-step", a->relative_step, "Finite-difference step, relative")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::relative_step));
  cmd->add_flag("--central-throughout", a->central_throughout,
                "Second-order differences in every Jacobian (default: first-order forward "
                "while descending, second order at the final point, for the uncertainty)");
  cmd->add_option("--noise-deg", a->noise_deg,
                  "Measurement noise of the joint angles [deg] (default: estimated per joint "
                  "from the measured twist)")
      ->check(Above(0.0, "deg"));
  cmd->add_option("--out", a->out, "Output folder")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  AddRunTimeoutOption(cmd, &a->run_timeout_s);
  cmd->add_flag("--resume", a->resume,
                "Continue the fit stopped in --out from its checkpoint (written after every "
                "accepted iteration); refused for other data, options or version");
  cmd->callback([a] {
    const int code = RunIdentify(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
