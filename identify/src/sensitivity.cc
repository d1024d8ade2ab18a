// DerivativeCheck: the derivatives of the sampled joint angles at several
// relative steps, and how well they agree.
#include "ccsrm/identify/sensitivity.h"
#include "ccsrm/identify/runs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <thread>

#include "ccsrm/common/error.h"
#include "finite_difference.h"
#include "run_pool.h"
#include "text.h"

namespace ccsrm::identify {
namespace {

using internal::Rms;

// ||a - b|| / max(||a||, ||b||); 0 when both are exactly zero.
double Disagreement(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0.0, na = 0.0, nb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff += (a[i] - b[i]) * (a[i] - b[i]);
    na += a[i] * a[i];
    nb += b[i] * b[i];
  }
  const double denominator = std::sqrt(std::max(na, nb));
  return denominator == 0.0 ? 0.0 : std::sqrt(diff) / denominator;
}

// Where each step's runs sit in the list of requests (0 is the base run).
struct StepRuns {
  internal::DifferencePlan plan;
  std::size_t trial[2] = {0, 0};
};

// The derivative of one step from its runs, or nothing (with the reason in
// *note) when a run it needs did not complete.
void FormDerivative(const StepRuns& runs, const std::vector<internal::RunOutcome>& outcomes,
                    StepDerivative* step, std::string* note) {
  const internal::RunOutcome& base = outcomes[0];
  const internal::RunOutcome& a = outcomes[runs.trial[0]];
  const internal::RunOutcome& b = outcomes[runs.trial[1]];
  const bool needs_base = runs.plan.base_weight != 0.0;
  for (const internal::RunOutcome* o : {needs_base ? &base : nullptr, &a, &b}) {
    if (o != nullptr && !o->summary.completed()) {
      if (note->empty())
        *note = "run " + std::string(sim::SimulationStatusName(o->summary.status)) + ": " +
                o->summary.message;
      return;
    }
  }
  CCSRM_CHECK(a.angles_deg.size() == b.angles_deg.size());
  CCSRM_CHECK(!needs_base || base.angles_deg.size() == a.angles_deg.size());
  const double wb = runs.plan.base_weight;
  const double wa = runs.plan.trial_weights[0];
  const double wc = runs.plan.trial_weights[1];
  const double denominator = 2.0 * step->relative_step;
  std::vector<double>& d = step->derivative_deg;
  d.resize(a.angles_deg.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double base_term = needs_base ? wb * base.angles_deg[i] : 0.0;
    d[i] = (base_term + wa * a.angles_deg[i] + wc * b.angles_deg[i]) / denominator;
  }
  step->rms_deg = Rms(d);
}

void Classify(double tolerance, double negligible_change_deg, ParameterDerivative* p) {
  bool all_available = true;
  double largest_change = 0.0;
  for (const StepDerivative& s : p->steps) {
    all_available = all_available && s.available();
    largest_change = std::max(largest_change, 0.01 * s.rms_deg);
  }
  p->max_disagreement = 0.0;
  for (std::size_t k = 0; k + 1 < p->steps.size(); ++k) {
    const StepDerivative &a = p->steps[k], &b = p->steps[k + 1];
    const double value = a.available() && b.available()
                             ? Disagreement(a.derivative_deg, b.derivative_deg)
                             : std::nan("");
    p->disagreement.push_back(value);
    p->max_disagreement = std::isnan(value) || std::isnan(p->max_disagreement)
                              ? std::nan("")
                              : std::max(p->max_disagreement, value);
  }
  p->negligible = all_available && largest_change < negligible_change_deg;
  if (!all_available) {
    p->status = DerivativeStatus::kRunFailed;
  } else if (p->negligible) {
    p->status = DerivativeStatus::kNegligible;
  } else {
    p->status =
        p->max_disagreement <= tolerance ? DerivativeStatus::kAgrees : DerivativeStatus::kDisagrees;
  }
}

// The status as a JSON word.
const char* StatusKey(DerivativeStatus status) {
  switch (status) {
    case DerivativeStatus::kAgrees:
      return "agrees";
    case DerivativeStatus::kDisagrees:
      return "disagrees";
    case DerivativeStatus::kNegligible:
      return "negligible";
    case DerivativeStatus::kRunFailed:
      return "run_failed";
    case DerivativeStatus::kNotChecked:
      return "not_checked";
  }
  return "?";
}

std::string StepList(const std::vector<double>& steps) {
  std::string text;
  for (double r : steps) text += (text.empty() ? "" : ", ") + Format("%g", r);
  return text;
}

}  // namespace

bool DerivativeCheckOptions::IsValid(std::string* error) const {
  std::set<std::string> seen;
  if (parameters.empty()) {
    *error = "parameters: none given";
    return false;
  }
  for (const std::string& name : parameters) {
    try {
      sim::FindParameter(name, "parameters");
    } catch (const InputError& e) {
      *error = e.what();
      return false;
    }
    if (!seen.insert(name).second) {
      *error = "parameters: '" + name + "' given twice";
      return false;
    }
  }
  if (relative_steps.size() < 2) {
    *error = "relative_steps: needs at least two steps to compare, found " +
             std::to_string(relative_steps.size());
    return false;
  }
  for (std::size_t k = 0; k < relative_steps.size(); ++k) {
    const double r = relative_steps[k];
    if (!(r > 0.0 && r < 0.5)) {
      *error = "relative_steps: " + Format("%g", r) + " is outside (0, 0.5)";
      return false;
    }
    for (std::size_t j = 0; j < k; ++j) {
      if (relative_steps[j] == r) {
        *error = "relative_steps: " + Format("%g", r) + " given twice";
        return false;
      }
    }
  }
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    *error = problem + ", found " + std::to_string(threads);
    return false;
  }
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    *error = "tolerance: must be > 0";
    return false;
  }
  if (!(negligible_change_deg >= 0.0) || !std::isfinite(negligible_change_deg)) {
    *error = "negligible_change_deg: must be >= 0";
    return false;
  }
  return true;
}

const char* SchemeName(DifferenceScheme scheme) {
  switch (scheme) {
    case DifferenceScheme::kCentral:
      return "central";
    case DifferenceScheme::kForward:
      return "forward";
    case DifferenceScheme::kBackward:
      return "backward";
  }
  return "?";
}

const char* StatusName(DerivativeStatus status) {
  switch (status) {
    case DerivativeStatus::kAgrees:
      return "agrees";
    case DerivativeStatus::kDisagrees:
      return "DISAGREES";
    case DerivativeStatus::kNegligible:
      return "negligible";
    case DerivativeStatus::kRunFailed:
      return "RUN FAILED";
    case DerivativeStatus::kNotChecked:
      return "not checked";
  }
  return "?";
}

double ParameterDerivative::change_per_percent_deg() const {
  double largest = 0.0;
  for (const StepDerivative& s : steps) largest = std::max(largest, 0.01 * s.rms_deg);
  return largest;
}

bool DerivativeCheckSummary::passed() const {
  for (const ParameterDerivative& p : parameters) {
    if (p.status == DerivativeStatus::kDisagrees || p.status == DerivativeStatus::kRunFailed) {
      return false;
    }
  }
  return true;
}

bool DerivativeCheckSummary::all_runs_completed() const {
  if (!base_run.completed()) return false;
  for (const ParameterDerivative& p : parameters) {
    for (const StepDerivative& s : p.steps) {
      for (const TrialRun& t : s.trials) {
        if (!t.summary.completed()) return false;
      }
    }
  }
  return true;
}

DerivativeCheckSummary DerivativeCheck(const sim::ArmModel& model, const sim::ArmParameters& base,
                                       const sim::CableInputs& inputs,
                                       const sim::SimulationOptions& simulation,
                                       const DerivativeCheckOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("DerivativeCheckOptions", "", error);
  if (!base.IsValid(&error)) ThrowInputError("base parameters", "", error);
  if (!simulation.IsValid(&error)) ThrowInputError("SimulationOptions", "", error);

  DerivativeCheckSummary summary;
  summary.relative_steps = options.relative_steps;
  summary.tolerance = options.tolerance;
  summary.negligible_change_deg = options.negligible_change_deg;
  summary.threads = options.backend ? options.backend->parallelism() : options.threads;

  // Plan every run: the base run first, then two trials per parameter and step.
  std::vector<internal::RunRequest> requests = {{base, "base"}};
  std::vector<std::vector<StepRuns>> plans;
  for (const std::string& name : options.parameters) {
    const sim::ParameterInfo& info = sim::FindParameter(name, "parameters");
    ParameterDerivative p;
    p.name = info.name;
    p.units = info.units;
    p.value = sim::GetParameter(base, info.name);
    p.scale = internal::ParameterScale(info, p.value, options.scale_at_zero);
    std::vector<StepRuns> step_runs;
    if (p.scale == 0.0) {
      p.status = DerivativeStatus::kNotChecked;
      p.note = "value 0 and no scale at zero: a relative step does not move it";
    } else {
      for (double r : options.relative_steps) {
        const double h = r * p.scale;
        const std::optional<internal::DifferencePlan> plan =
            internal::PlanDifference(p.value, h, info.lower, info.upper);
        if (!plan) {
          ThrowInputError(name, "",
                          "bounds [" + Format("%g", info.lower) + ", " + Format("%g", info.upper) +
                              "] leave no room for a step of " + Format("%g", h) +
                              " on either side of " + Format("%g", p.value));
        }
        StepRuns runs{*plan, {}};
        StepDerivative step;
        step.relative_step = r;
        step.step = h;
        step.scheme = plan->scheme;
        for (int k = 0; k < 2; ++k) {
          sim::ArmParameters trial = base;
          sim::SetParameter(info.name, plan->trial_values[k], "derivative trial", &trial);
          runs.trial[k] = requests.size();
          requests.push_back({trial, name + " = " + Format("%.6g", plan->trial_values[k]) +
                                         " (step " + Format("%g", r) + ")"});
          step.trials.push_back({plan->trial_values[k], {}});
        }
        step_runs.push_back(runs);
        p.steps.push_back(std::move(step));
      }
    }
    plans.push_back(std::move(step_runs));
    summary.parameters.push_back(std::move(p));
  }

  const std::vector<internal::RunOutcome> outcomes =
      internal::RunAll(model, inputs, simulation, requests, options.threads, options.progress,
                       options.backend.get());
  summary.runs = outcomes.size();
  summary.base_run = outcomes[0].summary;
  summary.sampled_angles = outcomes[0].angles_deg.size();

  for (std::size_t i = 0; i < summary.parameters.size(); ++i) {
    ParameterDerivative& p = summary.parameters[i];
    if (p.status == DerivativeStatus::kNotChecked) continue;
    for (std::size_t k = 0; k < p.steps.size(); ++k) {
      for (int t = 0; t < 2; ++t) {
        p.steps[k].trials[t].summary = outcomes[plans[i][k].trial[t]].summary;
      }
      FormDerivative(plans[i][k], outcomes, &p.steps[k], &p.note);
      summary.sampled_angles = std::max(summary.sampled_angles, p.steps[k].derivative_deg.size());
    }
    Classify(options.tolerance, options.negligible_change_deg, &p);
  }
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::string DerivativeCheckSummary::BriefReport() const {
  int counts[5] = {0, 0, 0, 0, 0};
  int negligible_beyond = 0;  // negligible, but beyond the tolerance
  for (const ParameterDerivative& p : parameters) {
    ++counts[static_cast<int>(p.status)];
    negligible_beyond +=
        p.status == DerivativeStatus::kNegligible && !(p.max_disagreement <= tolerance);
  }
  char text[360];
  std::snprintf(text, sizeof(text),
                "derivative check %s: %zu parameters, %d agree within %g %%, %d negligible (%d of "
                "them beyond it), %d disagree, %d with failed runs, %d not checked (%zu runs, "
                "%.1f s wall)",
                passed() ? "passed" : "FAILED", parameters.size(),
                counts[static_cast<int>(DerivativeStatus::kAgrees)], 100.0 * tolerance,
                counts[static_cast<int>(DerivativeStatus::kNegligible)], negligible_beyond,
                counts[static_cast<int>(DerivativeStatus::kDisagrees)],
                counts[static_cast<int>(DerivativeStatus::kRunFailed)],
                counts[static_cast<int>(DerivativeStatus::kNotChecked)], runs, wall_time_s);
  return text;
}

std::string DerivativeCheckSummary::FullReport() const {
  std::ostringstream out;
  char line[512];
  out << "derivatives of the sampled joint angles, relative steps " << StepList(relative_steps)
      << "\n";
  std::snprintf(line, sizeof(line),
                "  %zu runs on %d threads, %.1f s wall; %zu sampled angles per run (every frame, "
                "joint and axis)\n",
                runs, threads, wall_time_s, sampled_angles);
  out << line;
  out << "  base run: " << base_run.BriefReport() << "\n";
  std::snprintf(
      line, sizeof(line),
      "  d = s dθ/dp [deg per unit relative change], s = |p|; RMS over the sampled angles\n"
      "  agreement: ||d1 - d2|| / max(||d1||, ||d2||) <= %g %% between consecutive steps\n"
      "  negligible: a 1 %% change moves the angles by < %g deg RMS\n\n",
      100.0 * tolerance, negligible_change_deg);
  out << line;

  out << "  parameter  value        scheme  ";
  for (double r : relative_steps) {
    std::snprintf(line, sizeof(line), " %12s", ("RMS d " + Format("%g", r)).c_str());
    out << line;
  }
  out << "      1 % moves  disagreement  result\n";
  for (const ParameterDerivative& p : parameters) {
    std::string scheme = p.steps.empty() ? "-" : SchemeName(p.steps[0].scheme);
    for (const StepDerivative& s : p.steps) {
      if (s.scheme != p.steps[0].scheme) scheme = "mixed";
    }
    std::snprintf(line, sizeof(line), "  %-9s  %-11.6g  %-8s", p.name.c_str(), p.value,
                  scheme.c_str());
    out << line;
    for (std::size_t k = 0; k < relative_steps.size(); ++k) {
      if (k < p.steps.size() && p.steps[k].available()) {
        std::snprintf(line, sizeof(line), " %12.5g", p.steps[k].rms_deg);
      } else {
        std::snprintf(line, sizeof(line), " %12s", "-");
      }
      out << line;
    }
    if (p.status == DerivativeStatus::kNotChecked || p.status == DerivativeStatus::kRunFailed) {
      std::snprintf(line, sizeof(line), "  %13s  %12s  %s\n", "-", "-", StatusName(p.status));
    } else {
      std::snprintf(line, sizeof(line), "  %9.3g deg  %10.3g %%  %s\n", p.change_per_percent_deg(),
                    100.0 * p.max_disagreement,
                    p.status == DerivativeStatus::kNegligible && !(p.max_disagreement <= tolerance)
                        ? "negligible (beyond tolerance)"
                        : StatusName(p.status));
    }
    out << line;
  }
  bool any_note = false;
  for (const ParameterDerivative& p : parameters) {
    bool one_sided = false;
    for (const StepDerivative& s : p.steps) one_sided |= s.scheme != DifferenceScheme::kCentral;
    if (p.note.empty() && !one_sided && p.scale == std::abs(p.value)) continue;
    if (!any_note) out << "\n";
    any_note = true;
    out << "  " << p.name << ":";
    if (p.scale != std::abs(p.value) && p.scale != 0.0) {
      out << " value 0, steps relative to s = " << Format("%g", p.scale) << ";";
    }
    for (const StepDerivative& s : p.steps) {
      if (s.scheme == DifferenceScheme::kCentral) continue;
      out << " step " << Format("%g", s.relative_step) << " " << SchemeName(s.scheme) << " (trials "
          << Format("%.6g", s.trials[0].value) << ", " << Format("%.6g", s.trials[1].value)
          << ", inside the bounds);";
    }
    if (!p.note.empty()) out << " " << p.note;
    out << "\n";
  }
  out << "\n" << BriefReport() << "\n";
  return out.str();
}

nlohmann::json ToJson(const DerivativeCheckSummary& s) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const ParameterDerivative& p : s.parameters) {
    nlohmann::json steps = nlohmann::json::array();
    for (const StepDerivative& d : p.steps) {
      nlohmann::json trials = nlohmann::json::array();
      for (const TrialRun& t : d.trials) {
        trials.push_back({{"value", t.value}, {"run", internal::RunJson(t.summary)}});
      }
      steps.push_back({{"relative_step", d.relative_step},
                       {"step", d.step},
                       {"scheme", SchemeName(d.scheme)},
                       {"available", d.available()},
                       {"rms_deg", d.rms_deg},
                       {"trials", trials}});
    }
    parameters.push_back({{"name", p.name},
                          {"units", p.units},
                          {"value", p.value},
                          {"scale", p.scale},
                          {"status", StatusKey(p.status)},
                          {"negligible", p.negligible},
                          {"change_per_percent_deg", p.change_per_percent_deg()},
                          {"disagreement", p.disagreement},
                          {"max_disagreement", p.max_disagreement},
                          {"note", p.note},
                          {"steps", steps}});
  }
  return {{"schema", "ccsrm-derivatives/1"},
          {"passed", s.passed()},
          {"relative_steps", s.relative_steps},
          {"tolerance", s.tolerance},
          {"negligible_change_deg", s.negligible_change_deg},
          {"derivative_units", "deg per unit relative change"},
          {"sampled_angles", s.sampled_angles},
          {"runs", s.runs},
          {"threads", s.threads},
          {"wall_time_s", s.wall_time_s},
          {"base_run", internal::RunJson(s.base_run)},
          {"parameters", parameters}};
}

}  // namespace ccsrm::identify
