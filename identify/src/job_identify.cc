// RunIdentifyJob: `ccsrm identify` and ccsrm.identify.
#include "ccsrm/common/error.h"
#include "ccsrm/identify/job.h"
#include "job_stages.h"
#include "text.h"

namespace ccsrm::identify {

namespace {

// What decides the fit's result besides the files' bytes (not the threads,
// the reporting, the run timeout or the number of ranks: the result is the
// same), for the checkpoint's digest.
std::string ResultOptions(const IdentifyJobOptions& o) {
  const std::vector<std::string>* free = o.parameters.free ? &*o.parameters.free : nullptr;
  return "free=" + DigestText(free, "(default)") + "\nsets=" + DigestText(o.parameters.values) +
         Format(
             "\nmax_iterations=%d relative_step=%.17g noise_deg=%.17g central=%d "
             "point_noise_mm=%.17g",
             o.max_iterations, o.relative_step, o.noise_deg.value_or(0.0),
             o.central_differences_throughout ? 1 : 0, o.point_noise_mm);
}

}  // namespace

IdentifyJobResult RunIdentifyJob(const IdentifyJobOptions& job) {
  const auto say = [&job](const std::string& text) { internal::Say(job.reporting, text); };
  // Everything is checked before the first simulation: options, output path,
  // every experiment file.
  IdentificationOptions options;
  options.relative_step = job.relative_step;
  options.central_differences_throughout = job.central_differences_throughout;
  internal::ApplyFitJob(job, &options);
  const FitParameterChoice& p = job.parameters;
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("identify", "", error);
  std::vector<std::string> inputs = job.data;
  inputs.push_back(p.params_path);
  if (!job.out.empty()) {
    const CheckpointKey key = MakeCheckpointKey("identify", ResultOptions(job), inputs);
    // The checkpoint first: a corrupt one is named as such, not as a folder
    // of another kind.
    if (job.resume) {
      options.resume = std::make_shared<FitCheckpoint>(
          FitCheckpointFromJson(ReadCheckpoint(job.out, key), CheckpointPath(job.out)));
    }
    CheckOutputPath(job.out, "--out", FitFolderOutput(), inputs);
    options.on_checkpoint = [out = job.out, key](const FitCheckpoint& c) {
      WriteCheckpoint(out, key, ToJson(c));
    };
  } else if (job.resume) {
    ThrowInputError("--resume", "", "needs the folder of the stopped fit (--out)");
  }

  IdentifyJobResult result;
  result.experiments =
      LoadExperiments(job.data, job.noise_deg, job.point_noise_mm, "experiment", "", say);
  const auto backends = JobBackends({&result.experiments}, job.runs, say);
  if (backends.empty()) {  // another rank of an MPI job: it served rank 0's runs
    result.served = true;
    return result;
  }
  options.backend = backends.front();
  say(Format("fitting %s on %d thread%s\n", Join(options.free_parameters).c_str(), options.threads,
             Plural(static_cast<std::size_t>(options.threads))));
  options.on_iteration = job.reporting.on_iteration;
  options.on_run = job.reporting.on_run;
  result.summary = Identify(result.experiments, options);
  say(result.summary.FullReport());
  if (!job.out.empty()) {
    result.written = WriteFitDirectory(result.summary, result.experiments, job.out);
    RemoveCheckpoint(job.out);  // the fit is there now
    say(Format("  output: %s (%zu files)\n", job.out.c_str(), result.written.size()));
  }
  return result;
}

}  // namespace ccsrm::identify
