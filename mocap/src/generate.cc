#include "ccsrm/mocap/generate.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/output_policy.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/output_kinds.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim_io/run_file.h"

namespace ccsrm::mocap {
namespace {

namespace fs = std::filesystem;

// The planned amplitude [deg] of the run's protocol: the configuration's
// for the paper protocol by default, a protocol file's amplitude_deg
// parameter, NaN when there is none (another protocol, recorded inputs).
double PlannedAmplitudeDeg(const sim::PaperRun& run, const sim::Config& truth) {
  if (run.default_protocol) return truth.protocol.amplitude_rad * 180.0 / M_PI;
  if (!run.protocol) return NAN;
  const auto it = run.protocol->parameters.find("amplitude_deg");
  return it == run.protocol->parameters.end() ? NAN : it->second * 180.0 / M_PI;
}

// <name>.truth.yaml (ccsrm-truth/1).
std::string TruthYaml(const GenerateOptions& o, const GeneratedExperiment& g) {
  const sim::Config& truth = g.truth;
  YAML::Emitter out;
  out.SetDoublePrecision(12);  // 0.05, not 0.050000000000000003
  out << YAML::Comment(
      "Ground truth of a generated experiment (ccsrm generate). No fitting code reads this.");
  out << YAML::BeginMap;
  out << YAML::Key << "schema" << YAML::Value << "ccsrm-truth/1";
  out << YAML::Key << "experiment" << YAML::Value << fs::path(o.out).filename().string();
  out << YAML::Key << "config" << YAML::Value << o.run.config_path;
  out << YAML::Key << "case" << YAML::Value
      << (o.run.case_number != 0 ? std::to_string(o.run.case_number)
                                 : std::string("as configured"));
  const double amplitude_deg = PlannedAmplitudeDeg(g.run, truth);
  if (!std::isnan(amplitude_deg)) {
    out << YAML::Key << "amplitude_deg" << YAML::Value << amplitude_deg;
  }
  if (!g.run.default_protocol && g.run.protocol) {
    out << YAML::Key << "protocol" << YAML::Value << g.run.protocol->source_name;
  }
  if (!g.run.inputs_source.empty()) {
    out << YAML::Key << "inputs" << YAML::Value << g.run.inputs_source;
  }
  out << YAML::Key << "duration_s" << YAML::Value << g.run.simulation.duration_s;
  out << YAML::Key << "seed" << YAML::Value << o.recording.seed;
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
  out << YAML::Key << "sigma_mm" << YAML::Value << o.recording.noise_sigma_m * 1e3;
  out << YAML::EndMap;
  const OcclusionOptions& occ = o.recording.occlusions;
  out << YAML::Key << "occlusions" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << occ.enabled;
  out << YAML::Key << "marker_gap_rate_per_s" << YAML::Value << occ.marker_gap_rate_per_s;
  out << YAML::Key << "gap_frames" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << occ.min_gap_frames << occ.max_gap_frames << YAML::EndSeq;
  out << YAML::Key << "link_loss_rate_per_s" << YAML::Value << occ.link_loss_rate_per_s;
  out << YAML::Key << "link_loss_frames" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << occ.min_link_loss_frames << occ.max_link_loss_frames << YAML::EndSeq;
  out << YAML::Key << "marker_gaps" << YAML::Value << g.recording.marker_gaps;
  out << YAML::Key << "link_losses" << YAML::Value << g.recording.link_losses;
  out << YAML::Key << "hidden_fraction" << YAML::Value << g.recording.hidden_fraction;
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

// The configuration the experiment states: the one given, with the paper
// case (which cables have friction is part of the arm as built) and without
// effects it switches on (the experiment states the nominal model only).
std::string NominalConfigYaml(const GenerateOptions& o, sim::Config nominal) {
  bool changed = false;
  if (nominal.parameters.AnyEffectOn()) {
    for (const std::string& effect : nominal.parameters.EnabledEffects()) {
      nominal.parameters.DisableEffect(effect);
    }
    changed = true;
  }
  if (o.run.case_number != 0) {
    sim::ApplyPaperCase(o.run.case_number, &nominal.parameters);
    changed = true;
  }
  return changed ? sim::ToYaml(nominal) : nominal.source_yaml;
}

// The virtual recording of the truth's run: motion capture sees the links
// as the measurement effects (mocap_offset) make them look; the truth keeps
// the physical run, and the experiment the commanded inputs (what actuator
// effects, delay or creep, made of them stays in the truth run).
VirtualExperiment Record(const GeneratedExperiment& g, const sim::SimulationResult& result,
                         const datasets::RunFile& truth_run,
                         const VirtualExperimentOptions& options) {
  const MarkerLayout layout = DefaultMarkerLayout(g.run.model);
  datasets::RunFile seen = truth_run;
  for (std::size_t f = 0; f < result.trajectory.size(); ++f) {
    const auto poses =
        sim::RecordedLinkPoses(g.run.model, g.truth.parameters, result.trajectory.frames[f]);
    for (std::size_t l = 0; l < poses.size(); ++l)
      for (int k = 0; k < 7; ++k) seen.link_pose.at(f, l, k) = poses[l][k];
  }
  VirtualExperiment generated = MakeVirtualExperiment(seen, layout, options);
  generated.truth.link_pose = truth_run.link_pose;
  generated.truth.markers = MarkersFromLinkPoses(layout, truth_run.link_pose);
  datasets::Array& commanded = generated.experiment.input_length_change;
  for (std::size_t f = 0; f < commanded.shape[0]; ++f) {
    for (std::size_t c = 0; c < commanded.shape[1]; ++c) {
      double value, rate, accel;
      g.run.inputs.Evaluate(static_cast<int>(c), generated.experiment.input_time.at(f), &value,
                            &rate, &accel);
      commanded.at(f, c) = value;
    }
  }
  generated.experiment.protocol_yaml = sim::ProtocolYamlOf(g.run);
  generated.experiment.inputs_file = g.run.inputs_source;
  return generated;
}

}  // namespace

std::string GeneratedOutputStem(const std::string& out) {
  const std::string suffix = ".h5";
  if (out.size() <= suffix.size() ||
      out.compare(out.size() - suffix.size(), suffix.size(), suffix) != 0) {
    ThrowInputError(out, "--out",
                    "must end in .h5 (the truth files are named <name>.truth.h5/.yaml)");
  }
  return out.substr(0, out.size() - suffix.size());
}

GeneratedExperiment GenerateExperiment(const GenerateOptions& o) {
  const std::string stem = GeneratedOutputStem(o.out);
  const std::string truth_yaml_path = stem + ".truth.yaml", truth_h5_path = stem + ".truth.h5";
  // The output paths are checked before minutes are spent on the run.
  const std::vector<std::string> inputs = {
      o.run.config_path, o.run.params_path, o.effects_path,
      sim::ProtocolFileOf(o.run.protocol_path),
      o.run.recorded_inputs ? o.run.recorded_inputs->source_name : std::string()};
  CheckOutputPath(o.out, "--out", datasets::GeneratedExperimentFileOutput(), inputs);
  CheckOutputPath(truth_yaml_path, "--out", YamlFileOutput("ccsrm-truth/1", "ccsrm truth file"),
                  inputs);
  CheckOutputPath(truth_h5_path, "--out", datasets::RunFileOutput(), inputs);
  if (!(o.recording.noise_sigma_m >= 0.0) || !std::isfinite(o.recording.noise_sigma_m)) {
    ThrowInputError("--noise-mm", "", "must be >= 0");
  }

  // The configuration is parsed once: the truth's run and the nominal
  // configuration are made from it.
  const sim::Config given = sim::LoadConfig(sim::ConfigPathOrBundled(o.run.config_path));
  GeneratedExperiment g{sim::PreparePaperRun(o.run, given)};
  g.experiment_path = o.out;
  g.truth_yaml_path = truth_yaml_path;
  g.truth_h5_path = truth_h5_path;
  if (o.on_prepared) o.on_prepared(g.run);
  // The truth is the configuration with the case, amplitude and parameters
  // applied; effects join the truth only.
  g.truth = g.run.config;
  if (!o.effects_path.empty()) {
    sim::ApplyEffectsYaml(ReadTextFile(o.effects_path), o.effects_path, &g.truth.parameters);
  }
  for (const std::string& spec : o.effects) {
    sim::ApplyEffectSpec(spec, "--effect", &g.truth.parameters);
  }
  VirtualExperimentOptions options;
  options.name = fs::path(stem).filename().string();
  options.nominal_config_yaml = NominalConfigYaml(o, given);
  options.recording = o.recording;
  std::string error;
  if (!options.recording.IsValid(&error)) ThrowInputError("generate", "recording", error);

  sim::SimulationOptions simulation = g.run.simulation;
  simulation.progress = o.progress;
  simulation.progress_interval_s = o.progress_interval_s;
  simulation.cancel = o.cancel;
  const sim::SimulationResult result =
      sim::Simulate(g.run.model, g.truth.parameters, g.run.inputs, simulation);
  g.simulation = result.summary;
  if (!result.summary.completed()) return g;
  const std::string case_name =
      o.run.case_number != 0 ? std::to_string(o.run.case_number) : "custom";
  // Wall time is the one thing a rerun changes: keep it out of the truth
  // file so that the same seed gives the same files.
  datasets::RunFile truth_run = sim_io::ToRunFile(
      g.run.model, result,
      {case_name, sim::ToYaml(g.truth), sim::ProtocolYamlOf(g.run), g.run.inputs_source});
  g.wall_time_s = truth_run.wall_time_s;
  truth_run.wall_time_s = 0.0;
  char description[512];
  std::snprintf(description, sizeof(description),
                "generated by ccsrm generate: case %s, %s, %.4g s, marker noise "
                "%.3g mm, occlusions %s, seed %llu",
                case_name.c_str(), MotionWords(g.run, g.truth).c_str(), g.run.simulation.duration_s,
                o.recording.noise_sigma_m * 1e3, o.recording.occlusions.enabled ? "on" : "off",
                static_cast<unsigned long long>(o.recording.seed));
  options.description = description;
  VirtualExperiment generated = Record(g, result, truth_run, options);
  // A quasi-static replay's frames are settled poses: what identification
  // replays the recording as (identify::Experiment::settled_poses).
  if (simulation.quasi_static)
    generated.experiment.motion = datasets::RecordedMotion::kSettledPoses;
  g.recording = generated.recording;
  g.frames = generated.experiment.mocap_time.rows();
  g.markers = generated.experiment.marker_names.size();
  datasets::WriteExperimentFile(g.experiment_path, generated.experiment);
  datasets::WriteRunFile(g.truth_h5_path, generated.truth);
  WriteTextFileAtomically(g.truth_yaml_path, TruthYaml(o, g));
  return g;
}

}  // namespace ccsrm::mocap
