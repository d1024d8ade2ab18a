// RunLoopJob: `ccsrm loop` and ccsrm.loop.
#include <filesystem>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/identify/run_journal.h"
#include "job_stages.h"
#include "text.h"

namespace ccsrm::identify {

namespace {

// What decides the loop's result besides the files' bytes (not the threads,
// the reporting, the run timeout or the number of ranks), for the
// checkpoint's digest.
std::string ResultOptions(const LoopJobOptions& o) {
  const std::vector<std::string>* free = o.parameters.free ? &*o.parameters.free : nullptr;
  const std::vector<std::string>* candidates = o.candidates ? &*o.candidates : nullptr;
  return Format("data=%zu holdout=%zu", o.data.size(), o.holdout.size()) +
         "\ncandidates=" + DigestText(candidates, "(default)") +
         "\nfree=" + DigestText(free, "(default)") + "\nsets=" + DigestText(o.parameters.values) +
         Format("\nmax_rounds=%d max_iterations=%d noise_deg=%.17g point_noise_mm=%.17g",
                o.max_rounds, o.max_iterations, o.noise_deg.value_or(0.0), o.point_noise_mm);
}

std::string JournalPath(const std::string& out) {
  return (std::filesystem::path(out) / "runs.journal").string();
}

}  // namespace

LoopJobResult RunLoopJob(const LoopJobOptions& job) {
  const auto say = [&job](const std::string& text) { internal::Say(job.reporting, text); };
  LoopOptions options;
  options.max_rounds = job.max_rounds;
  internal::ApplyFitJob(job, &options.fit);
  internal::RefuseRepeatedFiles(job.holdout, "--holdout", {}, "");
  internal::RefuseRepeatedFiles(job.data, "--data", job.holdout, "--holdout");
  const FitParameterChoice& p = job.parameters;
  if (job.candidates) options.candidates = *job.candidates;
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("loop", "", error);
  std::vector<std::string> inputs = job.data;
  inputs.insert(inputs.end(), job.holdout.begin(), job.holdout.end());
  inputs.push_back(p.params_path);
  inputs.push_back(job.config_path);
  // A loop is resumed by running it again over the journal of its runs.
  std::optional<CheckpointKey> key;
  if (!job.out.empty()) {
    key = MakeCheckpointKey("loop", ResultOptions(job), inputs);
    // The checkpoint first: a corrupt one is named as such, not as a folder
    // of another kind. It refuses other data, options or version.
    if (job.resume) ReadCheckpoint(job.out, *key);
    CheckOutputPath(job.out, "--out", LoopFolderOutput(), inputs);
  } else if (job.resume) {
    ThrowInputError("--resume", "", "needs the folder of the stopped loop (--out)");
  }

  LoopJobResult result;
  result.training = LoadExperiments(job.data, job.noise_deg, job.point_noise_mm, "training",
                                    job.config_path, say);
  result.holdout = LoadExperiments(job.holdout, job.noise_deg, job.point_noise_mm, "held out",
                                   job.config_path, say);
  const auto backends = JobBackends({&result.training, &result.holdout}, job.runs, say);
  if (backends.empty()) {  // another rank of an MPI job: it served rank 0's runs
    result.served = true;
    return result;
  }
  std::shared_ptr<RunJournal> journal;
  if (key) {
    WriteCheckpoint(job.out, *key, {{"runs_journal", "runs.journal"}});
    journal = std::make_shared<RunJournal>(JournalPath(job.out), job.resume);
    if (job.resume) {
      say(Format("resuming: %lld runs recorded in %s\n",
                 static_cast<long long>(journal->recorded()), journal->path().c_str()));
    }
    options.fit.backend = WithJournal(backends[0], journal, 0);
    options.holdout_backend = WithJournal(backends[1], journal, 1);
  } else {
    options.fit.backend = backends[0];
    options.holdout_backend = backends[1];
  }

  say(Format("declared model: %s free; %zu training, %zu held-out experiment%s; %d thread%s\n",
             Join(options.fit.free_parameters).c_str(), result.training.size(),
             result.holdout.size(), Plural(result.holdout.size()), options.fit.threads,
             Plural(static_cast<std::size_t>(options.fit.threads))));
  options.fit.on_iteration = job.reporting.on_iteration;
  options.fit.on_run = job.reporting.on_run;
  options.on_progress = job.reporting.on_loop_progress;
  result.summary = CloseLoop(result.training, result.holdout, options);
  say("\n" + result.summary.FullReport());
  if (!job.out.empty()) {
    result.written = WriteLoopDirectory(result.summary, result.training, result.holdout, job.out);
    say(Format("  output: %s (%zu files)\n", job.out.c_str(), result.written.size()));
  }
  if (journal) {
    result.simulated = journal->simulated();
    result.replayed = journal->replayed();
    // The loop is there now: its journal and checkpoint are not needed.
    say(Format("  runs: %lld simulated, %lld taken from the journal of a stopped run\n",
               static_cast<long long>(result.simulated), static_cast<long long>(result.replayed)));
    RemoveCheckpoint(job.out);
    std::filesystem::remove(JournalPath(job.out));
  }
  return result;
}

}  // namespace ccsrm::identify
