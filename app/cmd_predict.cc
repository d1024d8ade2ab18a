// ccsrm predict --data new.h5 [new2.h5 ...] --params fit/fit.json [--effects effects.yaml]
//               [--config arm.yaml] [--threads N] [--noise-deg D] --out pred/
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/prediction.h"
#include "commands.h"
#include "fit_inputs.h"
#include "option_checks.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

// Exit status when a run did not complete (the outputs are written).
constexpr int kRunFailed = 3;

struct PredictArgs {
  std::vector<std::string> data;
  std::string params;
  std::string effects;
  std::string config;
  int threads = identify::PredictionOptions().threads;
  double noise_deg = 0.0;  // 0: estimated
  std::string out;
  bool quiet = false;
};

int RunPredict(const PredictArgs& a) {
  // Everything is checked before the first simulation: options, output
  // path, the model, every recording against it.
  identify::PredictionOptions options;
  options.threads = a.threads;
  std::vector<std::string> inputs = a.data;
  inputs.insert(inputs.end(), {a.params, a.effects, a.config});
  CheckOut(a.out, PredictionFolderOutput(), inputs);
  identify::PredictionModel model = identify::LoadPredictionModel(a.params);
  if (!a.effects.empty()) model.effects.push_back({ReadTextFile(a.effects), a.effects});
  const std::vector<identify::Experiment> recordings =
      LoadExperiments(a.data, a.noise_deg, "recording", a.config);
  std::printf("predicting %zu recording%s with %s (%s) on %d thread%s\n", recordings.size(),
              recordings.size() == 1 ? "" : "s", model.source.c_str(), model.kind.c_str(),
              options.threads, options.threads == 1 ? "" : "s");
  std::fflush(stdout);
  if (!a.quiet) options.on_run = RunProgress();
  const identify::PredictionSummary summary = identify::Predict(recordings, model, options);
  std::printf("%s", summary.FullReport().c_str());
  const std::vector<std::string> written =
      identify::WritePredictionDirectory(summary, recordings, a.out);
  std::printf("  output: %s (%zu files)\n", a.out.c_str(), written.size());
  if (!summary.completed) {
    std::fprintf(stderr, "ccsrm: a prediction run did not complete: %s (outputs written)\n",
                 summary.message.c_str());
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
  cmd->add_option("--threads", a->threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::PredictionOptions::threads));
  cmd->add_option("--noise-deg", a->noise_deg,
                  "Measurement noise of the joint angles [deg] (default: estimated per joint "
                  "from the measured twist)")
      ->check(Above(0.0, "deg"));
  cmd->add_option("--out", a->out, "Output folder")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  cmd->callback([a] {
    const int code = RunPredict(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
