// ccsrm predict --data new.h5 [new2.h5 ...] --params fit/fit.json [--effects effects.yaml]
//               [--config arm.yaml] [--threads N] [--noise-deg D] --out pred/
#include <cstdio>
#include <memory>
#include <string>

#include "ccsrm/identify/job.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"

namespace ccsrm::app {
namespace {

// Exit status when a run did not complete (the outputs are written).
constexpr int kRunFailed = 3;

struct PredictArgs : JobArgs {
  std::string effects;
  std::string config;
};

int RunPredict(const PredictArgs& a) {
  identify::PredictJobOptions job;
  job.data = a.data;
  job.params_path = a.params;
  job.effects_path = a.effects;
  job.config_path = a.config;
  job.noise_deg = NoiseOption(a.noise_deg);
  job.point_noise_mm = a.point_noise_mm;
  job.threads = a.threads;
  job.out = a.out;
  job.reporting = TerminalReporting(a.quiet, "");
  const identify::PredictJobResult r = identify::RunPredictJob(job);
  if (!r.summary.completed) {
    std::fprintf(stderr, "ccsrm: a prediction run did not complete: %s (outputs written)\n",
                 r.summary.message.c_str());
    return kRunFailed;
  }
  return 0;
}

}  // namespace

void AddPredictCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "predict",
      "Predict recordings with a fitted model: simulate each from its own inputs, compare at "
      "its mocap frames as identification does, write pred.json, the predicted runs and the "
      "angles (exit 3 if a run did not complete)");
  auto a = std::make_shared<PredictArgs>();
  cmd->add_option("--data", a->data, "Recordings to predict (ccsrm-dataset/1), one or more")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--params", a->params,
                  "The model: a fit.json (ccsrm identify, or ccsrm loop's final/fit.json), a fit "
                  "or loop folder, or a parameter YAML file (name: value)")
      ->required();
  cmd->add_option("--effects", a->effects,
                  "YAML file switching effects on over the model: effect name -> {parameter: "
                  "value}");
  cmd->add_option("--config", a->config,
                  "Arm configuration to use instead of each recording's own config_yaml (same "
                  "joints and driving cables)");
  AddJobOptions(cmd, a.get());
  cmd->callback([a] {
    const int code = RunPredict(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
