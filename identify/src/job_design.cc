// RunDesignJob: `ccsrm design`.
#include <filesystem>
#include <memory>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/fit_file.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/identify/run_journal.h"
#include "ccsrm/sim/paper_run.h"
#include "job_stages.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

// What decides the design besides the input files' bytes (not the threads,
// the reporting, the run timeout or the number of ranks), for the
// checkpoint's digest.
std::string ResultOptions(const DesignJobOptions& job, const DesignOptions& o) {
  const auto numbers = [](const std::vector<double>& values) {
    std::string text;
    for (const double v : values) text += Format("%.17g,", v);
    return text;
  };
  std::string text = "free=" + DigestText(&o.free_parameters, "") + "\nplans=";
  for (const std::string& p : job.plans) text += p + "\n";
  text += "sets=" + DigestText(&job.sets, "") + "\nprior_box=";
  for (const PriorRange& r : o.prior_box) {
    text += Format("%s=%.17g:%.17g,", r.name.c_str(), r.lower, r.upper);
  }
  text += "\nchirps=";
  for (const auto& [start, end] : job.space.chirp_bands_hz)
    text += Format("%.17g:%.17g,", start, end);
  const ProposalSpace& s = job.space;
  text +=
      Format("\npropose=%d", job.propose ? 1 : 0) + " amplitudes=" + numbers(s.amplitudes_deg) +
      " move_times=" + numbers(s.move_times_s) + " sines=" + numbers(s.sine_frequencies_hz) +
      " planes=" + numbers(s.planes_deg) + " figures=" +
      numbers({s.budget_s, s.hold_s, o.noise_deg, o.effective_sample_fraction, o.frame_rate_hz,
               o.low_pass_hz, static_cast<double>(job.case_number),
               static_cast<double>(o.robust_candidates), static_cast<double>(s.opposed_segments),
               static_cast<double>(o.checked_candidates)});
  return text;
}

// The prior's run options: the arm with the case, parameter file and values.
sim::PaperRunOptions PriorRun(const DesignJobOptions& job) {
  sim::PaperRunOptions run;
  run.config_path = job.config_path;
  run.case_number = job.case_number;
  run.params_path = job.params_path;
  run.sets = job.sets;
  return run;
}

// One experiment of a plan: "file.yaml" or "file.yaml@name=value,...", on
// the arm of `config` (the job's, parsed once).
PlannedExperiment PlanFromSpec(const std::string& spec, const DesignJobOptions& job,
                               const sim::Config& config) {
  sim::PaperRunOptions run = PriorRun(job);
  sim::ApplyProtocolSpec(spec, "--plans '" + spec + "'", &run);
  sim::PaperRun prepared = sim::PreparePaperRun(run, config);
  PlannedExperiment e;
  e.name = spec;
  e.duration_s = prepared.simulation.duration_s;
  e.config = prepared.config;
  e.model = std::make_shared<const sim::ArmModel>(std::move(prepared.model));
  e.inputs = std::make_shared<const sim::CableInputs>(std::move(prepared.inputs));
  return e;
}

// The options checked, blamed on the command-line option each comes from.
DesignOptions CheckedOptions(const DesignJobOptions& job) {
  DesignOptions options = job.design;
  options.threads = job.runs.threads;
  for (const std::string& name : options.free_parameters) {
    if (name.empty()) ThrowInputError("--free", "", "has an empty name: give mu,mu_s,...");
  }
  if (!job.noise_from.empty()) {
    const RecordingNoise noise = RecordingNoiseOf(ReadFitFile(job.noise_from));
    options.noise_deg = noise.noise_deg;
    options.effective_sample_fraction = noise.effective_sample_fraction;
  }
  std::string error;
  if (!options.IsValid(&error)) {
    const std::string field = error.rfind("prior_box", 0) == 0  ? "--prior-box"
                              : error.rfind("low_pass", 0) == 0 ? "--low-pass-hz"
                                                                : "--free";
    ThrowInputError(field, "", error);
  }
  if (job.propose && !job.space.IsValid(&error)) ThrowInputError("--propose", "", error);
  if (!job.propose && job.plans.empty()) {
    ThrowInputError("--plans", "", "give the plans to compare, or --propose (or both)");
  }
  return options;
}

// The best proposed motion of the summary (completed, with a protocol), if
// any.
const CandidateInformation* BestProposal(const DesignSummary& summary) {
  for (const std::size_t k : summary.ranking) {
    const CandidateInformation& c = summary.candidates[k];
    if (c.completed && !c.protocol_yaml.empty()) return &c;
  }
  return nullptr;
}

}  // namespace

std::vector<std::string> WriteDesignDirectory(const DesignSummary& summary,
                                              const sim::Config& prior, const std::string& out) {
  AtomicOutputDirectory folder(out);
  const std::filesystem::path tmp(folder.temp_path());
  std::vector<std::string> written = {"design.json"};
  nlohmann::json json = ToJson(summary);
  json["config_yaml"] = prior.source_yaml;  // the arm, for the report's page
  WriteTextFileAtomically((tmp / "design.json").string(), json.dump(2) + "\n");
  // The best proposed motion, ready for the lab and for `ccsrm generate`.
  if (const CandidateInformation* best = BestProposal(summary)) {
    WriteTextFileAtomically((tmp / "proposed.yaml").string(), best->protocol_yaml);
    WriteTextFileAtomically(
        (tmp / "proposed.inputs.csv").string(),
        PlannedMotionCsv(prior, best->protocol_yaml, best->name, summary.options.frame_rate_hz));
    written.insert(written.end(), {"proposed.yaml", "proposed.inputs.csv"});
  }
  folder.Commit();  // the folder replaced as a whole: a checkpoint and journal go with it
  return written;
}

DesignJobResult RunDesignJob(const DesignJobOptions& job) {
  const auto say = [&job](const std::string& text) { internal::Say(job.reporting, text); };
  DesignOptions options = CheckedOptions(job);
  // The configuration is parsed here once, for the prior and every plan.
  const sim::Config config = sim::LoadConfig(sim::ConfigPathOrBundled(job.config_path));
  std::vector<std::string> inputs = {job.config_path, job.params_path, job.noise_from};
  std::vector<DesignCandidate> candidates;
  for (const std::string& plan : job.plans) {
    DesignCandidate candidate;
    candidate.name = plan;
    std::size_t start = 0;
    while (true) {  // the plan's experiments, joined by '+'
      const std::size_t end = plan.find('+', start);
      const std::string spec = plan.substr(start, end == std::string::npos ? end : end - start);
      candidate.experiments.push_back(PlanFromSpec(spec, job, config));
      inputs.push_back(sim::ProtocolFileOf(spec));
      if (end == std::string::npos) break;
      start = end + 1;
    }
    candidates.push_back(std::move(candidate));
  }
  if (job.out.empty()) ThrowInputError("--out", "", "is required");
  // A design is resumed by running it again over the journal of its runs
  // (as a loop is): it asks for the same runs in the same order. The
  // checkpoint is read first, so that a corrupt one is named as such.
  const CheckpointKey key = MakeCheckpointKey("design", ResultOptions(job, options), inputs);
  if (job.resume) ReadCheckpoint(job.out, key);  // refuses other data, options or version
  CheckOutputPath(job.out, "--out", DesignFolderOutput(), inputs);
  DesignJobResult result;
  const sim::Config prior = sim::PreparePaperRun(PriorRun(job), config).config;
  // Under mpirun every rank builds the candidates itself from the same
  // options and files rather than receiving them from rank 0: building them
  // is a function of those alone and takes milliseconds, and a run request
  // then stays an experiment index and parameter values, as for identify and
  // loop. ShareRuns checks that every rank built the same.
  if (job.propose) {
    candidates = ProposalCandidates(prior, job.space, candidates, &result.skipped);
  }
  CheckDesign(candidates, options);  // before the checkpoint is written
  const std::vector<Experiment> experiments = DesignExperiments(candidates, options);
  const auto backends = JobBackends({&experiments}, job.runs, say);
  if (backends.empty()) {  // another rank of an MPI job: it served rank 0's runs
    result.served = true;
    return result;
  }
  WriteCheckpoint(job.out, key, {{"runs_journal", "runs.journal"}});
  const auto journal = std::make_shared<RunJournal>(
      (std::filesystem::path(job.out) / "runs.journal").string(), job.resume);
  if (job.resume) {
    say(Format("resuming: %lld runs recorded in %s\n", static_cast<long long>(journal->recorded()),
               journal->path().c_str()));
  }
  options.backend = WithJournal(backends[0], journal, 0);
  std::string free;
  for (const std::string& name : options.free_parameters) free += (free.empty() ? "" : ",") + name;
  say(Format("design: %zu plan%s, free %s, on %d thread%s\n", candidates.size(),
             Plural(candidates.size()), free.c_str(), options.threads,
             Plural(static_cast<std::size_t>(options.threads))));
  options.on_run = job.reporting.on_run;
  result.summary = EvaluateDesigns(candidates, options);
  say(result.summary.FullReport());
  for (const std::string& why : result.skipped) say("  left out: " + why + "\n");
  result.written = WriteDesignDirectory(result.summary, prior, job.out);
  RemoveCheckpoint(job.out);
  result.simulated = journal->simulated();
  result.replayed = journal->replayed();
  say(Format("  output: %s/design.json\n", job.out.c_str()));
  say(Format("  runs: %lld simulated, %lld taken from the journal of a stopped run\n",
             static_cast<long long>(result.simulated), static_cast<long long>(result.replayed)));
  if (const CandidateInformation* best = BestProposal(result.summary)) {
    say(
        Format("  proposed: %s/proposed.yaml (%s), planned inputs and angles in %s/"
               "proposed.inputs.csv\n",
               job.out.c_str(), best->name.c_str(), job.out.c_str()));
  }
  return result;
}

}  // namespace ccsrm::identify
