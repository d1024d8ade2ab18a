// ccsrm generate: a virtual experiment from a simulation — markers on the
// simulated links with noise and occlusions, the inputs that drove the arm,
// and the ground truth in two side files no fitting code reads.
#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/virtual_experiment.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"
#include "ccsrm/sim_io/run_file.h"
#include "commands.h"
#include "output_kinds.h"
#include "paper_run.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

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
                e.library ? "" : " (not of the library: the loop's terms found in the data)",
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

// "<dir>/exp.h5" -> "<dir>/exp": the stem the side files share.
std::string OutputStem(const std::string& out) {
  const std::string suffix = ".h5";
  if (out.size() <= suffix.size() ||
      out.compare(out.size() - suffix.size(), suffix.size(), suffix) != 0) {
    ThrowInputError(out, "--out",
                    "must end in .h5 (the truth files are named <name>.truth.h5/.yaml)");
  }
  return out.substr(0, out.size() - suffix.size());
}

// The planned amplitude [deg] of the run's protocol: the configuration's
// for the paper protocol by default, a protocol file's amplitude_deg
// parameter, NaN when there is none (another protocol, recorded inputs).
double PlannedAmplitudeDeg(const sim::PaperRun& run, const sim::Config& truth) {
  if (run.default_protocol) return truth.protocol.amplitude_rad * 180.0 / M_PI;
  if (!run.protocol) return NAN;
  const auto it = run.protocol->parameters.find("amplitude_deg");
  return it == run.protocol->parameters.end() ? NAN : it->second * 180.0 / M_PI;
}

std::string TruthYaml(const GenerateArgs& a, const sim::PaperRun& run, const sim::Config& truth,
                      double duration_s, const mocap::VirtualRecordingOptions& recording,
                      const mocap::VirtualExperiment& generated) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // 0.05, not 0.050000000000000003
  out << YAML::Comment(
      "Ground truth of a generated experiment (ccsrm generate). No fitting code reads this.");
  out << YAML::BeginMap;
  out << YAML::Key << "schema" << YAML::Value << "ccsrm-truth/1";
  out << YAML::Key << "experiment" << YAML::Value << fs::path(a.out).filename().string();
  out << YAML::Key << "config" << YAML::Value << a.run.config_path;
  out << YAML::Key << "case" << YAML::Value
      << (a.run.case_number != 0 ? std::to_string(a.run.case_number)
                                 : std::string("as configured"));
  const double amplitude_deg = PlannedAmplitudeDeg(run, truth);
  if (!std::isnan(amplitude_deg)) {
    out << YAML::Key << "amplitude_deg" << YAML::Value << amplitude_deg;
  }
  if (!run.default_protocol && run.protocol) {
    out << YAML::Key << "protocol" << YAML::Value << run.protocol->source_name;
  }
  if (!run.inputs_source.empty()) {
    out << YAML::Key << "inputs" << YAML::Value << run.inputs_source;
  }
  out << YAML::Key << "duration_s" << YAML::Value << duration_s;
  out << YAML::Key << "seed" << YAML::Value << a.seed;
  out << YAML::Key << "parameters" << YAML::Comment("true values, SPEC 6 names");
  out << YAML::Value << YAML::BeginMap;
  for (const sim::ParameterInfo& p : sim::Parameters()) {
    out << YAML::Key << p.name << YAML::Value << truth.parameters.*p.field;
  }
  // Declared-value errors given with --set (declared.<value>), by full name.
  for (const auto& [name, value] : truth.parameters.declared_deltas) {
    out << YAML::Key << name << YAML::Value << value;
  }
  out << YAML::EndMap;
  out << YAML::Key << "effects" << YAML::Comment("effects switched on, true values");
  out << YAML::Value << YAML::BeginMap;
  for (const std::string& effect : truth.parameters.EnabledEffects()) {
    out << YAML::Key << effect << YAML::Value << YAML::BeginMap;
    for (const std::string& name :
         sim::EffectParameterNames(effect, truth.parameters.arm, "truth")) {
      out << YAML::Key << name.substr(effect.size() + 1) << YAML::Value
          << sim::GetParameter(truth.parameters, name);
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  out << YAML::Key << "noise" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "sigma_mm" << YAML::Value << recording.noise_sigma_m * 1e3;
  out << YAML::EndMap;
  const mocap::OcclusionOptions& o = recording.occlusions;
  out << YAML::Key << "occlusions" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << o.enabled;
  out << YAML::Key << "marker_gap_rate_per_s" << YAML::Value << o.marker_gap_rate_per_s;
  out << YAML::Key << "gap_frames" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << o.min_gap_frames << o.max_gap_frames << YAML::EndSeq;
  out << YAML::Key << "link_loss_rate_per_s" << YAML::Value << o.link_loss_rate_per_s;
  out << YAML::Key << "link_loss_frames" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << o.min_link_loss_frames << o.max_link_loss_frames << YAML::EndSeq;
  out << YAML::Key << "marker_gaps" << YAML::Value << generated.recording.marker_gaps;
  out << YAML::Key << "link_losses" << YAML::Value << generated.recording.link_losses;
  out << YAML::Key << "hidden_fraction" << YAML::Value << generated.recording.hidden_fraction;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// "amplitude 6 deg" (the paper protocol), "protocol 'two-axis'", or
// "recorded inputs from FILE".
std::string MotionWords(const sim::PaperRun& run, const sim::Config& truth) {
  char text[64];
  if (run.default_protocol) {
    std::snprintf(text, sizeof(text), "amplitude %.4g deg", PlannedAmplitudeDeg(run, truth));
    return text;
  }
  if (run.protocol) return "protocol '" + run.protocol->name + "'";
  return "recorded inputs from " + run.inputs_source;
}

int RunGenerate(const GenerateArgs& a) {
  if (a.list_effects) {
    ListEffects(a.json, a.run.config_path);
    return 0;
  }
  if (a.out.empty()) ThrowInputError("--out", "", "is required (or --list-effects)");
  const std::string stem = OutputStem(a.out);
  const std::string truth_yaml_path = stem + ".truth.yaml";
  const std::string truth_h5_path = stem + ".truth.h5";
  // Check the output paths before spending minutes on the run.
  const std::vector<std::string> inputs = {a.run.config_path, a.run.params_path, a.effects_path,
                                           sim::ProtocolFileOf(a.run.protocol_path),
                                           a.motion.inputs_path};
  CheckOut(a.out, ExperimentFileOutput(), inputs);
  CheckOut(truth_yaml_path, YamlFileOutput("ccsrm-truth/1", "ccsrm truth file"), inputs);
  CheckOut(truth_h5_path, RunFileOutput(), inputs);
  if (!(a.noise_mm >= 0.0) || !std::isfinite(a.noise_mm)) {
    ThrowInputError("--noise-mm", "", "must be >= 0");
  }

  // The nominal configuration goes into the experiment as given; the truth
  // is that configuration with the case, amplitude and parameters applied.
  // Effects join the truth only.
  const sim::PaperRun run = PrepareRun(a.run, a.motion);
  PrintConfigWarnings(run.config);
  sim::Config truth = run.config;
  if (!a.effects_path.empty()) {
    sim::ApplyEffectsYaml(ReadTextFile(a.effects_path), a.effects_path, &truth.parameters);
  }
  for (const std::string& spec : a.effects)
    sim::ApplyEffectSpec(spec, "--effect", &truth.parameters);
  const double duration = run.simulation.duration_s;

  mocap::VirtualExperimentOptions options;
  options.name = fs::path(stem).filename().string();
  options.nominal_config_yaml = run.config_text;
  {
    // A configuration that itself switches effects on is written without
    // them: the experiment states the nominal model only. A paper case is
    // part of the arm as built (which cables have friction), so the nominal
    // configuration carries it; --set, --params and effects are the truth
    // that identification must find, so it does not.
    sim::Config nominal = sim::ParseConfig(run.config_text, a.run.config_path);
    bool changed = false;
    if (nominal.parameters.AnyEffectOn()) {
      for (const std::string& effect : nominal.parameters.EnabledEffects()) {
        nominal.parameters.DisableEffect(effect);
      }
      changed = true;
    }
    if (a.run.case_number != 0) {
      sim::ApplyPaperCase(a.run.case_number, &nominal.parameters);
      changed = true;
    }
    if (changed) options.nominal_config_yaml = sim::ToYaml(nominal);
  }
  options.recording.noise_sigma_m = a.noise_mm * 1e-3;
  options.recording.resolution_m = a.resolution_mm * 1e-3;
  options.recording.seed = a.seed;
  options.recording.occlusions.enabled = !a.no_occlusions;
  std::string error;
  if (!options.recording.IsValid(&error)) ThrowInputError("generate", "recording", error);

  sim::SimulationOptions sim_options = run.simulation;
  const std::string case_name =
      a.run.case_number != 0 ? std::to_string(a.run.case_number) : "custom";
  if (!a.quiet) {
    sim_options.progress = [](const sim::SimulationProgress& p) {
      std::fprintf(stderr, "  t = %6.2f / %.2f s   real-time factor %.2f\n", p.simulated_s,
                   p.duration_s, p.real_time_factor);
    };
  }
  const sim::SimulationResult result =
      sim::Simulate(run.model, truth.parameters, run.inputs, sim_options);
  if (!result.summary.completed()) {
    std::fprintf(stderr, "ccsrm: simulation diverged: %s (nothing written)\n",
                 result.summary.message.c_str());
    return 3;
  }
  // Wall time is the one thing a rerun changes: keep it out of the truth file
  // so that the same seed gives the same files (it is printed below).
  datasets::RunFile truth_run = sim_io::ToRunFile(
      run.model, result, {case_name, sim::ToYaml(truth), sim::ProtocolYamlOf(run), run.inputs_source});
  const double wall_time_s = truth_run.wall_time_s;
  truth_run.wall_time_s = 0.0;

  char description[512];
  std::snprintf(description, sizeof(description),
                "generated by ccsrm generate: case %s, %s, %.4g s, marker noise "
                "%.3g mm, occlusions %s, seed %llu",
                case_name.c_str(), MotionWords(run, truth).c_str(), duration, a.noise_mm,
                a.no_occlusions ? "off" : "on", static_cast<unsigned long long>(a.seed));
  options.description = description;
  // Motion capture sees the links as the measurement effects (mocap_offset)
  // make them look; the truth keeps the physical run.
  const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(run.model);
  datasets::RunFile seen = truth_run;
  for (std::size_t f = 0; f < result.trajectory.size(); ++f) {
    const auto poses =
        sim::RecordedLinkPoses(run.model, truth.parameters, result.trajectory.frames[f]);
    for (std::size_t l = 0; l < poses.size(); ++l)
      for (int k = 0; k < 7; ++k) seen.link_pose.at(f, l, k) = poses[l][k];
  }
  mocap::VirtualExperiment generated = mocap::MakeVirtualExperiment(seen, layout, options);
  generated.truth.link_pose = truth_run.link_pose;
  generated.truth.markers = mocap::MarkersFromLinkPoses(layout, truth_run.link_pose);
  // The experiment records the commanded inputs; what actuator effects
  // (delay, creep) made of them stays in the truth run.
  datasets::Array& commanded = generated.experiment.input_length_change;
  for (std::size_t f = 0; f < commanded.shape[0]; ++f) {
    for (std::size_t c = 0; c < commanded.shape[1]; ++c) {
      double value, rate, accel;
      run.inputs.Evaluate(static_cast<int>(c), generated.experiment.input_time.at(f), &value, &rate,
                          &accel);
      commanded.at(f, c) = value;
    }
  }

  generated.experiment.protocol_yaml = sim::ProtocolYamlOf(run);
  generated.experiment.inputs_file = run.inputs_source;
  datasets::WriteExperimentFile(a.out, generated.experiment);
  datasets::WriteRunFile(truth_h5_path, generated.truth);
  WriteTextFileAtomically(truth_yaml_path,
                          TruthYaml(a, run, truth, duration, options.recording, generated));

  std::printf("%s", sim::DescribeRun(run).c_str());
  std::printf("simulated %.4g s (case %s) in %.2f s wall\n", duration, case_name.c_str(),
              wall_time_s);
  std::string effects;
  for (const std::string& e : truth.parameters.EnabledEffects()) effects += " " + e;
  std::printf("effects on (truth only):%s\n", effects.empty() ? " none" : effects.c_str());
  std::printf(
      "recorded %zu frames of %zu markers: noise %.3g mm, %zu marker gaps, %zu whole-link "
      "losses, %.2f %% of samples hidden\n",
      generated.experiment.mocap_time.rows(), generated.experiment.marker_names.size(), a.noise_mm,
      generated.recording.marker_gaps, generated.recording.link_losses,
      100.0 * generated.recording.hidden_fraction);
  std::printf("  experiment: %s\n  truth:      %s, %s\n", a.out.c_str(), truth_yaml_path.c_str(),
              truth_h5_path.c_str());
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
  cmd->add_option("--noise-mm", a->noise_mm, "Marker noise, standard deviation [mm]")
      ->capture_default_str();
  cmd->add_option("--resolution-mm", a->resolution_mm,
                  "Round every marker coordinate to this resolution [mm] (the largest power of "
                  "two in m not above it), as a C3D file's integer storage does; shrinks the "
                  "file about four times (default 0: full precision)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--seed", a->seed, "Seed of the noise and occlusion generator")
      ->capture_default_str();
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
