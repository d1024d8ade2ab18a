// ccsrm generate: a virtual experiment from a simulation — markers on the
// simulated links with noise and occlusions, the inputs that drove the arm,
// and the ground truth in two side files no fitting code reads.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/generate.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/parameters.h"
#include "commands.h"
#include "option_checks.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

struct GenerateArgs {
  sim::PaperRunOptions run;  // its named parameters are the truth
  MotionArgs motion;
  double noise_mm = 0.2;
  double resolution_mm = 0.0;
  std::uint64_t seed = 1;
  bool no_occlusions = false;
  std::string out;
  bool quiet = false;
  // Effects switched on in the truth (never in the experiment's nominal
  // configuration): a YAML file, then --effect items in order.
  std::string effects_path;
  std::vector<std::string> effects;
  bool list_effects = false;
  bool json = false;
};

std::string FormatNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

// ccsrm generate --list-effects [--json] [--config FILE]: every effect with
// its parameters on the arm of the configuration (per-joint and per-cable
// ones for each of its joints and cables), units, bounds, default and
// realistic magnitude.
void ListEffects(bool json, const std::string& config_path) {
  const sim::Config config = sim::LoadConfig(config_path);
  const sim::ArmSize arm = config.parameters.arm;
  if (json) {
    nlohmann::json effects = nlohmann::json::array();
    for (const sim::EffectInfo& e : sim::Effects()) {
      nlohmann::json parameters = nlohmann::json::array();
      for (const std::string& name : sim::EffectParameterNames(e.name, arm)) {
        const sim::ParameterInfo& p = sim::FindParameter(name, "--list-effects", arm);
        parameters.push_back({{"name", p.name},
                              {"units", p.units},
                              {"lower", p.lower},
                              {"upper", p.upper},
                              {"default", p.absent_value},
                              {"realistic", p.realistic},
                              {"description", p.description}});
      }
      effects.push_back({{"name", e.name},
                         {"description", e.description},
                         {"measurement", e.measurement},
                         {"library", e.library},
                         {"parameters", parameters}});
    }
    const nlohmann::json about = {{"config", config_path},
                                  {"joints", arm.joints},
                                  {"driving_cables", arm.cables},
                                  {"segments", arm.segments}};
    std::printf("%s\n", nlohmann::json{{"arm", about}, {"effects", effects}}.dump(2).c_str());
    return;
  }
  std::printf("effects on the arm of %s (%d joints, %d driving cables, %d segments)\n",
              config_path.c_str(), arm.joints, arm.cables, arm.segments);
  for (const sim::EffectInfo& e : sim::Effects()) {
    std::printf("%s%s%s: %s\n", e.name.c_str(), e.measurement ? " (measurement)" : "",
                e.library ? "" : " (not of the library: the loop never tries it)",
                e.description.c_str());
    for (const std::string& name : sim::EffectParameterNames(e.name, arm)) {
      const sim::ParameterInfo& p = sim::FindParameter(name, "--list-effects", arm);
      const std::string bounds =
          "[" + FormatNumber(p.lower) + ", " + FormatNumber(p.upper) + "] " + p.units;
      std::printf("  %-36s %-24s default %-7s realistic %-8s %s\n", p.name.c_str(), bounds.c_str(),
                  FormatNumber(p.absent_value).c_str(), FormatNumber(p.realistic).c_str(),
                  p.description.c_str());
    }
  }
}

int RunGenerate(const GenerateArgs& a) {
  if (a.list_effects) {
    ListEffects(a.json, a.run.config_path);
    return 0;
  }
  if (a.out.empty()) ThrowInputError("--out", "", "is required (or --list-effects)");
  mocap::GenerateOptions options;
  mocap::GeneratedOutputStem(a.out);  // the name is refused before a file is read
  options.run = WithMotion(a.run, a.motion);
  options.effects_path = a.effects_path;
  options.effects = a.effects;
  options.recording.noise_sigma_m = a.noise_mm * 1e-3;
  options.recording.resolution_m = a.resolution_mm * 1e-3;
  options.recording.seed = a.seed;
  options.recording.occlusions.enabled = !a.no_occlusions;
  options.out = a.out;
  options.on_prepared = [](const sim::PaperRun& run) { PrintConfigWarnings(run.config); };
  if (!a.quiet) {
    options.progress = [](const sim::SimulationProgress& p) {
      std::fprintf(stderr, "  t = %6.2f / %.2f s   real-time factor %.2f\n", p.simulated_s,
                   p.duration_s, p.real_time_factor);
    };
  }
  const mocap::GeneratedExperiment g = mocap::GenerateExperiment(options);
  if (!g.simulation.completed()) {
    std::fprintf(stderr, "ccsrm: simulation diverged: %s (nothing written)\n",
                 g.simulation.message.c_str());
    return 3;
  }
  std::printf("%s", sim::DescribeRun(g.run).c_str());
  const std::string case_name =
      a.run.case_number != 0 ? std::to_string(a.run.case_number) : "custom";
  std::printf("simulated %.4g s (case %s) in %.2f s wall\n", g.run.simulation.duration_s,
              case_name.c_str(), g.wall_time_s);
  std::string effects;
  for (const std::string& e : g.truth.parameters.EnabledEffects()) effects += " " + e;
  std::printf("effects on (truth only):%s\n", effects.empty() ? " none" : effects.c_str());
  std::printf(
      "recorded %zu frames of %zu markers: noise %.3g mm, %zu marker gaps, %zu whole-link "
      "losses, %.2f %% of samples hidden\n",
      g.frames, g.markers, a.noise_mm, g.recording.marker_gaps, g.recording.link_losses,
      100.0 * g.recording.hidden_fraction);
  std::printf("  experiment: %s\n  truth:      %s, %s\n", g.experiment_path.c_str(),
              g.truth_yaml_path.c_str(), g.truth_h5_path.c_str());
  return 0;
}

}  // namespace

void AddGenerateCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "generate",
      "Simulate the arm and record it with virtual motion capture (noise, occlusions): a "
      "ccsrm-dataset/1 experiment plus <name>.truth.yaml and <name>.truth.h5");
  auto a = std::make_shared<GenerateArgs>();
  AddPaperRunOptions(cmd, &a->run);
  AddParameterOptions(cmd, &a->run);
  AddMotionOptions(cmd, &a->run, &a->motion);
  // A capture system's noise is well below a millimetre; 50 mm (a tenth of
  // the arm) is no recording of it at all.
  cmd->add_option("--noise-mm", a->noise_mm, "Marker noise, standard deviation [mm]")
      ->capture_default_str()
      ->check(InRange(0.0, 50.0, "mm"));
  cmd->add_option("--resolution-mm", a->resolution_mm,
                  "Round every marker coordinate to this resolution [mm] (the largest power of "
                  "two in m not above it), as a C3D file's integer storage does; shrinks the "
                  "file about four times (default 0: full precision)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--seed", a->seed, "Seed of the noise and occlusion generator")
      ->capture_default_str()
      ->check(Unsigned64());
  cmd->add_flag("--no-occlusions", a->no_occlusions, "Every marker seen in every frame");
  cmd->add_option("--effects", a->effects_path,
                  "YAML file switching effects on: effect name -> {parameter: value} (truth "
                  "only; the experiment keeps the nominal configuration)");
  cmd->add_option("--effect", a->effects,
                  "An effect on: NAME (at its realistic magnitude) or NAME:param=value,... "
                  "(the others at their defaults); repeatable, after --effects");
  cmd->add_flag("--list-effects", a->list_effects,
                "List the effects, their parameters on the arm of --config (one per joint or "
                "cable where an effect has such), units, bounds and realistic magnitudes");
  cmd->add_flag("--json", a->json, "With --list-effects: one JSON object");
  cmd->add_option("--out", a->out, "Output experiment (.h5)");
  cmd->add_flag("--quiet", a->quiet, "No progress lines");
  cmd->callback([a] {
    const int code = RunGenerate(*a);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace ccsrm::app
