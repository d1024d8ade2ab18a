// RunPredictJob: `ccsrm predict`.
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/job.h"
#include "job_stages.h"
#include "text.h"

namespace ccsrm::identify {

PredictJobResult RunPredictJob(const PredictJobOptions& job) {
  const auto say = [&job](const std::string& text) { internal::Say(job.reporting, text); };
  if (job.data.empty()) ThrowInputError("--data", "", "give at least one recording");
  // Everything is checked before the first simulation: options, output
  // path, the model, every recording against it.
  PredictionOptions options;
  options.threads = job.threads;
  std::vector<std::string> inputs = job.data;
  inputs.insert(inputs.end(), {job.params_path, job.effects_path, job.config_path});
  if (!job.out.empty()) CheckOutputPath(job.out, "--out", PredictionFolderOutput(), inputs);
  PredictionModel model = LoadPredictionModel(job.params_path);
  if (!job.effects_path.empty()) {
    model.effects.push_back({ReadTextFile(job.effects_path), job.effects_path});
  }
  PredictJobResult result;
  result.recordings = LoadExperiments(job.data, job.noise_deg, job.point_noise_mm, "recording",
                                      job.config_path, say);
  say(Format("predicting %zu recording%s with %s (%s) on %d thread%s\n", result.recordings.size(),
             Plural(result.recordings.size()), model.source.c_str(), model.kind.c_str(),
             options.threads, Plural(static_cast<std::size_t>(options.threads))));
  options.on_run = job.reporting.on_run;
  result.summary = Predict(result.recordings, model, options);
  say(result.summary.FullReport());
  if (!job.out.empty()) {
    result.written = WritePredictionDirectory(result.summary, result.recordings, job.out);
    say(Format("  output: %s (%zu files)\n", job.out.c_str(), result.written.size()));
  }
  return result;
}

}  // namespace ccsrm::identify
