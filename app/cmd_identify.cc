// ccsrm identify --data exp1.h5 [exp2.h5 ...] [--free mu,mu_s,...] [--params p.yaml]
//                [--set name=value ...] [--threads N] --out fit/
#include <cstdio>
#include <memory>
#include <string>

#include "ccsrm/identify/job.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"

namespace ccsrm::app {
namespace {

// Exit status of a fit that did not converge (its outputs are written) and
// of one that failed.
constexpr int kNotConverged = 4;
constexpr int kFitFailed = 3;

struct IdentifyArgs : JobArgs {
  double relative_step = identify::IdentificationOptions().relative_step;
  bool central_throughout = false;
};

int RunIdentify(const IdentifyArgs& a) {
  identify::IdentifyJobOptions job;
  FillFitJob(a, "", &job);
  job.relative_step = a.relative_step;
  job.central_differences_throughout = a.central_throughout;
  const identify::IdentifyJobResult r = identify::RunIdentifyJob(job);
  if (r.served) return 0;
  switch (r.summary.termination) {
    case identify::IdentificationTermination::kConverged:
      return 0;
    case identify::IdentificationTermination::kNoConvergence:
      std::fprintf(stderr, "ccsrm: the fit did not converge in %d iterations (outputs written)\n",
                   r.summary.iterations);
      return kNotConverged;
    case identify::IdentificationTermination::kFailed:
      std::fprintf(stderr, "ccsrm: the fit failed: %s (outputs written)\n",
                   r.summary.message.c_str());
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
  AddFitParameterOptions(cmd, a.get());
  cmd->add_option("--max-iterations", a->max_iterations, "Levenberg-Marquardt iterations")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::max_iterations));
  cmd->add_option("--relative-step", a->relative_step, "Finite-difference step, relative")
      ->capture_default_str()
      ->check(ValidIn(&identify::IdentificationOptions::relative_step));
  cmd->add_flag("--central-throughout", a->central_throughout,
                "Second-order differences in every Jacobian (default: first-order forward "
                "while descending, second order at the final point, for the uncertainty)");
  AddJobOptions(cmd, a.get());
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
