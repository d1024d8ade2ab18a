// ccsrm design --free mu,mu_s,mu_c,T_p --plans PLAN [PLAN ...] [--config arm.yaml] [--case N]
//              [--params prior.yaml] [--set name=value ...] [--noise-deg D]
//              [--effective-fraction F] [--frame-rate HZ] [--threads N] --out design/
//
// A PLAN is one or more protocol files joined by '+', each optionally with
// parameter values after '@': "paper.yaml@amplitude_deg=6+paper.yaml@amplitude_deg=-5".
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/common/name_list.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/identify/job.h"
#include "commands.h"
#include "job_options.h"
#include "option_checks.h"

namespace ccsrm::app {
namespace {

struct DesignArgs {
  identify::DesignJobOptions job;
  std::string free;
  std::vector<std::string> chirps;     // start:end [Hz]
  std::vector<std::string> prior_box;  // name=lower:upper
  bool quiet = false;
};

// --prior-box name=lower:upper.
identify::PriorRange PriorRangeOf(const std::string& text) {
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
  return range;
}

// --chirps start:end [Hz].
std::pair<double, double> ChirpBandOf(const std::string& band) {
  const std::size_t colon = band.find(':');
  double start = 0.0, end = 0.0;
  if (colon == std::string::npos || !ParseNumberText(band.substr(0, colon), &start).empty() ||
      !ParseNumberText(band.substr(colon + 1), &end).empty()) {
    ThrowInputError("--chirps '" + band + "'", "", "expected start:end in Hz (0.05:0.5)");
  }
  return {start, end};
}

int RunDesign(DesignArgs a) {
  identify::DesignJobOptions& job = a.job;
  job.design.free_parameters = SplitNameList(a.free, "--free");
  for (const std::string& text : a.prior_box) job.design.prior_box.push_back(PriorRangeOf(text));
  for (const std::string& band : a.chirps) job.space.chirp_bands_hz.push_back(ChirpBandOf(band));
  job.reporting.line = PrintNow;
  if (!a.quiet) job.reporting.on_run = RunProgress();
  const identify::DesignJobResult r = identify::RunDesignJob(job);
  for (const identify::CandidateInformation& c : r.summary.candidates) {
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
  cmd->add_option("--plans", a->job.plans,
                  "Candidate plans, one or more: protocol files joined by '+' (one experiment "
                  "each), each with optional parameter values after '@' "
                  "(paper.yaml@amplitude_deg=6+paper.yaml@amplitude_deg=-5)")
      ->expected(1, -1);
  cmd->add_flag("--propose", a->job.propose,
                "Also search motions filling --budget-s: reversals (every segment between +A and "
                "-A, --amplitudes x --move-times), and sines and chirps when --sines or --chirps "
                "are given, in each of --planes, segments together and opposed; write the best as "
                "proposed.yaml");
  cmd->add_option("--budget-s", a->job.space.budget_s, "Recording time of a proposed plan [s]")
      ->capture_default_str()
      ->check(Above(0.0, "s"));
  cmd->add_option("--amplitudes", a->job.space.amplitudes_deg,
                  "Amplitudes A the proposal tries [deg]")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--move-times", a->job.space.move_times_s,
                  "Times of one move the proposal tries [s]")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sines", a->job.space.sine_frequencies_hz,
                  "Also propose sines A sin(2 pi f t) filling --budget-s, at these frequencies "
                  "[Hz] (default: none)")
      ->delimiter(',');
  cmd->add_option("--chirps", a->chirps,
                  "Also propose chirps filling --budget-s, the frequency swept linearly over each "
                  "band start:end [Hz] (0.05:0.5,...; default: none)")
      ->delimiter(',');
  cmd->add_option("--planes", a->job.space.planes_deg,
                  "Bending planes the proposal tries [deg] (0: toward +x, 90: toward +y; default: "
                  "theta_x alone, the paper's plane)")
      ->delimiter(',');
  cmd->add_option("--prior-box", a->prior_box,
                  "Range of a parameter the truth may lie in, name=lower:upper (repeatable, up "
                  "to 6): the best plans at the prior are evaluated at every corner of the box "
                  "too and ranked by their worst case (robust design)");
  cmd->add_option("--robust-top", a->job.design.robust_candidates,
                  "How many of the best plans at the prior --prior-box evaluates at its corners")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--check-top", a->job.design.checked_candidates,
                  "How many of the best plans, in rank order, have their derivatives at the "
                  "prior checked at a third of the step (as a fit checks its own) until one is "
                  "smooth; a plan that is not ranks last (0: no check)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--config", a->job.config_path,
                  "Arm configuration (YAML); default: the bundled paper.yaml");
  cmd->add_option("--case", a->job.case_number,
                  "Paper case whose friction the prior takes: 1 no friction, 2 all friction, "
                  "3 driving cables only, 4 connecting cables only")
      ->check(CLI::Range(1, 4));
  cmd->add_option("--params", a->job.params_path, "YAML file of prior values (name: value)");
  cmd->add_option("--set", a->job.sets, "Prior value, name=value (repeatable, after --params)");
  CLI::Option* noise_option =
      cmd->add_option("--noise-deg", a->job.design.noise_deg,
                      "Standard deviation of every measured joint angle [deg]")
          ->capture_default_str()
          ->check(Above(0.0, "deg"));
  CLI::Option* fraction_option =
      cmd->add_option("--effective-fraction", a->job.design.effective_sample_fraction,
                      "N_eff / N of the recordings' residuals (a fit.json's effective_samples / "
                      "residuals; 1: white noise)")
          ->capture_default_str()
          ->check(CLI::Range(1e-6, 1.0));
  cmd->add_option("--noise-from", a->job.noise_from,
                  "A fit.json of recordings like those planned: their noise (times the root of "
                  "the fit's residual variance) and N_eff / N, instead of --noise-deg and "
                  "--effective-fraction")
      ->excludes(noise_option)
      ->excludes(fraction_option);
  cmd->add_option("--frame-rate", a->job.design.frame_rate_hz, "Mocap frames per second [Hz]")
      ->capture_default_str()
      ->check(Above(0.0, "Hz"));
  cmd->add_option("--low-pass-hz", a->job.design.low_pass_hz,
                  "Cutoff of the zero-lag low-pass the recordings' angles will pass through "
                  "(the mocap pipeline's; a fit filters its simulated angles alike) [Hz]; 0: "
                  "none, angles measured directly")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", a->job.runs.threads, "Simulations at a time (default: every core)")
      ->check(ValidIn(&identify::DesignOptions::threads, Checkable()));
  cmd->add_option("--out", a->job.out, "Output folder")->required();
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  AddRunTimeoutOption(cmd, &a->job.runs.run_timeout_s);
  cmd->add_flag("--resume", a->job.resume,
                "Continue the design stopped in --out: it runs again, taking every run it had "
                "done from its journal (runs.journal); refused for other plans, data, options or "
                "version");
  cmd->callback([a] {
    const int code = RunDesign(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
