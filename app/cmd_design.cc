// ccsrm design --free mu,mu_s,mu_c,T_p --plans PLAN [PLAN ...] [--config arm.yaml] [--case N]
//              [--params prior.yaml] [--set name=value ...] [--noise-deg D]
//              [--effective-fraction F] [--frame-rate HZ] [--threads N] --out design/
//
// A PLAN is one or more protocol files joined by '+', each optionally with
// parameter values after '@': "paper.yaml@amplitude_deg=6+paper.yaml@amplitude_deg=-5".
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/identify/design.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/identify/mpi_backend.h"
#include "ccsrm/identify/run_journal.h"
#include "ccsrm/sim/paper_run.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

struct DesignArgs {
  std::string config;
  int case_number = 0;
  std::string params;
  std::vector<std::string> set;
  std::string free;
  std::vector<std::string> plans;
  double noise_deg = identify::DesignOptions().noise_deg;
  double effective_fraction = identify::DesignOptions().effective_sample_fraction;
  double frame_rate_hz = identify::DesignOptions().frame_rate_hz;
  double low_pass_hz = identify::DesignOptions().low_pass_hz;
  int threads = identify::DesignOptions().threads;
  std::string noise_from;
  bool propose = false;
  identify::ProposalSpace space;
  std::vector<std::string> chirps;     // start:end [Hz]
  std::vector<std::string> prior_box;  // name=lower:upper
  int robust_candidates = identify::DesignOptions().robust_candidates;
  std::string out;
  bool quiet = false;
  double run_timeout_s = identify::MpiOptions().run_timeout_s;
  bool resume = false;
};

// What decides the design besides the input files' bytes (not --threads,
// --quiet, --run-timeout or the number of ranks), for the checkpoint's digest.
std::string ResultOptions(const DesignArgs& a) {
  const auto numbers = [](const std::vector<double>& values) {
    std::string text;
    char number[32];
    for (const double v : values) {
      std::snprintf(number, sizeof(number), "%.17g,", v);
      text += number;
    }
    return text;
  };
  std::string text = "free=" + a.free + "\nplans=";
  for (const std::string& p : a.plans) text += p + "\n";
  text += "sets=";
  for (const std::string& s : a.set) text += s + ",";
  text += "\nprior_box=";
  for (const std::string& b : a.prior_box) text += b + ",";
  text += "\nchirps=";
  for (const std::string& c : a.chirps) text += c + ",";
  text += "\npropose=" + std::to_string(a.propose) +
          " amplitudes=" + numbers(a.space.amplitudes_deg) +
          " move_times=" + numbers(a.space.move_times_s) +
          " sines=" + numbers(a.space.sine_frequencies_hz) +
          " planes=" + numbers(a.space.planes_deg) + " figures=" +
          numbers({a.space.budget_s, a.space.hold_s, a.noise_deg, a.effective_fraction,
                   a.frame_rate_hz, a.low_pass_hz, static_cast<double>(a.case_number),
                   static_cast<double>(a.robust_candidates),
                   static_cast<double>(a.space.opposed_segments)});
  return text;
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

// One experiment of a plan: "file.yaml" or "file.yaml@name=value,name=value".
identify::PlannedExperiment PlanExperiment(const std::string& spec, const DesignArgs& a) {
  sim::PaperRunOptions run;
  run.config_path = a.config;
  run.case_number = a.case_number;
  run.params_path = a.params;
  run.sets = a.set;
  ApplyProtocolSpec(spec, "--plans '" + spec + "'", &run);
  sim::PaperRun prepared = sim::PreparePaperRun(run);
  identify::PlannedExperiment e;
  e.name = spec;
  e.duration_s = prepared.simulation.duration_s;
  e.config = prepared.config;
  e.model = std::make_shared<const sim::ArmModel>(std::move(prepared.model));
  e.inputs = std::make_shared<const sim::CableInputs>(std::move(prepared.inputs));
  return e;
}

// The noise of recordings like those an earlier fit saw (its fit.json):
// the RMS of its experiments' per-joint noise times the root of its
// residual variance (what the residuals were, against that noise), and its
// effective samples per residual.
void NoiseFromFit(const std::string& path, identify::DesignOptions* options) {
  nlohmann::json fit;
  try {
    fit = nlohmann::json::parse(ReadTextFile(path));
  } catch (const nlohmann::json::exception& e) {
    ThrowInputError(path, "", std::string("not JSON: ") + e.what());
  }
  if (!fit.is_object() || fit.value("schema", "") != "ccsrm-fit/1") {
    ThrowInputError(path, "schema", "expected a fit.json of ccsrm identify (ccsrm-fit/1)");
  }
  const auto number = [&](const char* key) {
    if (!fit.contains(key) || !fit[key].is_number() || !std::isfinite(fit[key].get<double>())) {
      ThrowInputError(path, key, "missing or not a finite number");
    }
    return fit[key].get<double>();
  };
  const double residuals = number("residuals"), effective = number("effective_samples");
  const double variance = number("residual_variance");
  if (!(residuals > 0.0) || !(effective > 0.0) || effective > residuals || !(variance > 0.0)) {
    ThrowInputError(path, "effective_samples",
                    "needs 0 < effective_samples <= residuals and residual_variance > 0");
  }
  double sum = 0.0;
  int count = 0;
  if (fit.contains("experiments") && fit["experiments"].is_array()) {
    for (const nlohmann::json& e : fit["experiments"]) {
      if (!e.contains("noise_deg") || !e["noise_deg"].is_array()) continue;
      for (const nlohmann::json& v : e["noise_deg"]) {
        if (v.is_number() && v.get<double>() > 0.0) {
          sum += v.get<double>() * v.get<double>();
          ++count;
        }
      }
    }
  }
  if (count == 0) ThrowInputError(path, "experiments[].noise_deg", "no noise recorded");
  options->noise_deg = std::sqrt(sum / count * variance);
  options->effective_sample_fraction = effective / residuals;
}

int RunDesign(const DesignArgs& a) {
  identify::DesignOptions options;
  options.free_parameters = Split(a.free, ',');
  for (const std::string& name : options.free_parameters) {
    if (name.empty()) ThrowInputError("--free", "", "has an empty name: give mu,mu_s,...");
  }
  options.noise_deg = a.noise_deg;
  options.effective_sample_fraction = a.effective_fraction;
  options.frame_rate_hz = a.frame_rate_hz;
  options.low_pass_hz = a.low_pass_hz;
  options.threads = a.threads;
  if (!a.noise_from.empty()) NoiseFromFit(a.noise_from, &options);
  for (const std::string& text : a.prior_box) {
    const std::string where = "--prior-box '" + text + "'";
    const std::size_t eq = text.find('='), colon = text.find(':', eq);
    if (eq == std::string::npos || eq == 0 || colon == std::string::npos) {
      ThrowInputError(where, "", "expected name=lower:upper (mu=0.15:0.27)");
    }
    identify::PriorRange range;
    range.name = text.substr(0, eq);
    for (const auto& [part, value] : {std::pair{text.substr(eq + 1, colon - eq - 1), &range.lower},
                                      std::pair{text.substr(colon + 1), &range.upper}}) {
      const std::string problem = ParseNumberText(part, value);
      if (!problem.empty()) ThrowInputError(where, range.name, problem);
    }
    options.prior_box.push_back(range);
  }
  options.robust_candidates = a.robust_candidates;
  identify::ProposalSpace space = a.space;
  for (const std::string& band : a.chirps) {
    const std::size_t colon = band.find(':');
    double start = 0.0, end = 0.0;
    if (colon == std::string::npos || !ParseNumberText(band.substr(0, colon), &start).empty() ||
        !ParseNumberText(band.substr(colon + 1), &end).empty()) {
      ThrowInputError("--chirps '" + band + "'", "", "expected start:end in Hz (0.05:0.5)");
    }
    space.chirp_bands_hz.emplace_back(start, end);
  }
  std::string error;
  if (!options.IsValid(&error)) {
    const std::string field = error.rfind("prior_box", 0) == 0  ? "--prior-box"
                              : error.rfind("low_pass", 0) == 0 ? "--low-pass-hz"
                                                                : "--free";
    ThrowInputError(field, "", error);
  }
  std::string space_error;
  if (a.propose && !space.IsValid(&space_error)) ThrowInputError("--propose", "", space_error);
  if (!a.propose && a.plans.empty()) {
    ThrowInputError("--plans", "", "give the plans to compare, or --propose (or both)");
  }
  std::vector<std::string> inputs = {a.config, a.params, a.noise_from};
  std::vector<identify::DesignCandidate> candidates;
  for (const std::string& plan : a.plans) {
    identify::DesignCandidate candidate;
    candidate.name = plan;
    for (const std::string& spec : Split(plan, '+')) {
      candidate.experiments.push_back(PlanExperiment(spec, a));
      inputs.push_back(spec.substr(0, spec.find('@')));
    }
    candidates.push_back(std::move(candidate));
  }
  CheckOutputPath(a.out, "--out", identify::DesignFolderOutput(), inputs);
  // A design is resumed by running it again over the journal of its runs
  // (as a loop is): it asks for the same runs in the same order.
  const identify::CheckpointKey key =
      identify::MakeCheckpointKey("design", ResultOptions(a), inputs);
  if (a.resume) identify::ReadCheckpoint(a.out, key);  // refuses other data, options or version
  std::vector<std::string> skipped;
  // The prior: the arm with the case, --params and --set, as a plan's.
  sim::PaperRunOptions prior_run;
  prior_run.config_path = a.config;
  prior_run.case_number = a.case_number;
  prior_run.params_path = a.params;
  prior_run.sets = a.set;
  const sim::Config prior = sim::PreparePaperRun(prior_run).config;
  // Under mpirun every rank builds the candidates itself from the same
  // command line and files rather than receiving them from rank 0: building
  // them is a function of those alone and takes milliseconds, and a run
  // request then stays an experiment index and parameter values, as for
  // identify and loop. ShareRuns checks that every rank built the same.
  if (a.propose) candidates = identify::ProposalCandidates(prior, space, candidates, &skipped);
  identify::CheckDesign(candidates, options);  // before the checkpoint is written
  const std::vector<identify::Experiment> experiments =
      identify::DesignExperiments(candidates, options);
  const auto backends =
      identify::JobBackends({&experiments}, {options.threads, a.run_timeout_s}, PrintNow);
  if (backends.empty()) return 0;  // another rank of an MPI job: it served rank 0's runs
  identify::WriteCheckpoint(a.out, key, {{"runs_journal", "runs.journal"}});
  const auto journal = std::make_shared<identify::RunJournal>(
      (std::filesystem::path(a.out) / "runs.journal").string(), a.resume);
  if (a.resume) {
    std::printf("resuming: %lld runs recorded in %s\n", static_cast<long long>(journal->recorded()),
                journal->path().c_str());
  }
  options.backend = identify::WithJournal(backends[0], journal, 0);
  std::printf("design: %zu plan%s, free %s, on %d thread%s\n", candidates.size(),
              candidates.size() == 1 ? "" : "s", a.free.c_str(), options.threads,
              options.threads == 1 ? "" : "s");
  std::fflush(stdout);
  if (!a.quiet) options.on_run = RunProgress();
  const identify::DesignSummary summary = identify::EvaluateDesigns(candidates, options);
  std::printf("%s", summary.FullReport().c_str());
  for (const std::string& why : skipped) std::printf("  left out: %s\n", why.c_str());
  AtomicOutputDirectory out(a.out);
  const std::filesystem::path tmp(out.temp_path());
  nlohmann::json json = identify::ToJson(summary);
  json["config_yaml"] = prior.source_yaml;  // the arm, for the report's page
  WriteTextFileAtomically((tmp / "design.json").string(), json.dump(2) + "\n");
  // The best proposed motion, ready for the lab and for `ccsrm generate`.
  const identify::CandidateInformation* best = nullptr;
  for (const std::size_t k : summary.ranking) {
    const identify::CandidateInformation& c = summary.candidates[k];
    if (c.completed && !c.protocol_yaml.empty()) {
      best = &c;
      break;
    }
  }
  if (best != nullptr) {
    WriteTextFileAtomically((tmp / "proposed.yaml").string(), best->protocol_yaml);
    WriteTextFileAtomically(
        (tmp / "proposed.inputs.csv").string(),
        identify::PlannedMotionCsv(prior, best->protocol_yaml, best->name, options.frame_rate_hz));
  }
  out.Commit();  // the folder replaced as a whole: the checkpoint and journal go with it
  identify::RemoveCheckpoint(a.out);
  std::printf("  output: %s/design.json\n", a.out.c_str());
  std::printf("  runs: %lld simulated, %lld taken from the journal of a stopped run\n",
              static_cast<long long>(journal->simulated()),
              static_cast<long long>(journal->replayed()));
  if (best != nullptr) {
    std::printf(
        "  proposed: %s/proposed.yaml (%s), planned inputs and angles in %s/"
        "proposed.inputs.csv\n",
        a.out.c_str(), best->name.c_str(), a.out.c_str());
  }
  for (const identify::CandidateInformation& c : summary.candidates) {
    if (!c.completed) {
      std::fprintf(stderr, "ccsrm: plan '%s' was not evaluated: %s (outputs written)\n",
                   c.name.c_str(), c.message.c_str());
      return 3;
    }
  }
  return 0;
}

// Options valid but for the field checked (DesignOptions needs a free
// parameter to be valid at all).
identify::DesignOptions Checkable() {
  identify::DesignOptions options;
  options.free_parameters = {"mu"};
  return options;
}

}  // namespace

void AddDesignCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "design",
      "Rank plans of motions by the standard errors a fit of their recordings would give: the "
      "Fisher information of the identification's residuals at the prior values, summed over "
      "each plan's experiments (writes design.json; exit 3 if a plan could not be evaluated)");
  auto a = std::make_shared<DesignArgs>();
  cmd->add_option("--free", a->free, "Parameters a fit would free, comma-separated")->required();
  cmd->add_option("--plans", a->plans,
                  "Candidate plans, one or more: protocol files joined by '+' (one experiment "
                  "each), each with optional parameter values after '@' "
                  "(paper.yaml@amplitude_deg=6+paper.yaml@amplitude_deg=-5)")
      ->expected(1, -1);
  cmd->add_flag("--propose", a->propose,
                "Also search motions filling --budget-s: reversals (every segment between +A and "
                "-A, --amplitudes x --move-times), and sines and chirps when --sines or --chirps "
                "are given, in each of --planes, segments together and opposed; write the best as "
                "proposed.yaml");
  cmd->add_option("--budget-s", a->space.budget_s, "Recording time of a proposed plan [s]")
      ->capture_default_str()
      ->check(Above(0.0, "s"));
  cmd->add_option("--amplitudes", a->space.amplitudes_deg, "Amplitudes A the proposal tries [deg]")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--move-times", a->space.move_times_s, "Times of one move the proposal tries [s]")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sines", a->space.sine_frequencies_hz,
                  "Also propose sines A sin(2 pi f t) filling --budget-s, at these frequencies "
                  "[Hz] (default: none)")
      ->delimiter(',');
  cmd->add_option("--chirps", a->chirps,
                  "Also propose chirps filling --budget-s, the frequency swept linearly over each "
                  "band start:end [Hz] (0.05:0.5,...; default: none)")
      ->delimiter(',');
  cmd->add_option("--planes", a->space.planes_deg,
                  "Bending planes the proposal tries [deg] (0: toward +x, 90: toward +y; default: "
                  "theta_x alone, the paper's plane)")
      ->delimiter(',');
  cmd->add_option("--prior-box", a->prior_box,
                  "Range of a parameter the truth may lie in, name=lower:upper (repeatable, up "
                  "to 6): the best plans at the prior are evaluated at every corner of the box "
                  "too and ranked by their worst case (robust design)");
  cmd->add_option("--robust-top", a->robust_candidates,
                  "How many of the best plans at the prior --prior-box evaluates at its corners")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--config", a->config,
                  "Arm configuration (YAML); default: the bundled paper.yaml");
  cmd->add_option("--case", a->case_number,
                  "Paper case whose friction the prior takes: 1 no friction, 2 all friction, "
                  "3 driving cables only, 4 connecting cables only")
      ->check(CLI::Range(1, 4));
  cmd->add_option("--params", a->params, "YAML file of prior values (name: value)");
  cmd->add_option("--set", a->set, "Prior value, name=value (repeatable, after --params)");
  CLI::Option* noise_option =
      cmd->add_option("--noise-deg", a->noise_deg,
                      "Standard deviation of every measured joint angle [deg]")
          ->capture_default_str()
          ->check(Above(0.0, "deg"));
  CLI::Option* fraction_option =
      cmd->add_option("--effective-fraction", a->effective_fraction,
                      "N_eff / N of the recordings' residuals (a fit.json's effective_samples / "
                      "residuals; 1: white noise)")
          ->capture_default_str()
          ->check(CLI::Range(1e-6, 1.0));
  cmd->add_option("--noise-from", a->noise_from,
                  "A fit.json of recordings like those planned: their noise (times the root of "
                  "the fit's residual variance) and N_eff / N, instead of --noise-deg and "
                  "--effective-fraction")
      ->excludes(noise_option)
      ->excludes(fraction_option);
  cmd->add_option("--frame-rate", a->frame_rate_hz, "Mocap frames per second [Hz]")
      ->capture_default_str()
      ->check(Above(0.0, "Hz"));
  cmd->add_option("--low-pass-hz", a->low_pass_hz,
                  "Cutoff of the zero-lag low-pass the recordings' angles will pass through "
                  "(the mocap pipeline's; a fit filters its simulated angles alike) [Hz]; 0: "
                  "none, angles measured directly")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", a->threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::DesignOptions::threads, Checkable()));
  cmd->add_option("--out", a->out, "Output folder")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  AddRunTimeoutOption(cmd, &a->run_timeout_s);
  cmd->add_flag("--resume", a->resume,
                "Continue the design stopped in --out: it runs again, taking every run it had "
                "done from its journal (runs.journal); refused for other plans, data, options or "
                "version");
  cmd->callback([a] {
    const int code = RunDesign(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
