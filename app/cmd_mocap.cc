// ccsrm mocap inspect FILE [--json]
// ccsrm mocap process --in FILE (--rigid-bodies rb.yaml | --config cfg.yaml) ... --out exp.h5
// ccsrm mocap rigid-bodies --config cfg.yaml [--static-trial FILE] --out rb.yaml
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "commands.h"
#include "option_checks.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

bool IsHdf5Name(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".h5" || ext == ".hdf5";
}

// Never write onto an input (SPEC 11): the same path or the same file.
void RefuseToOverwrite(const std::string& input, const std::string& output) {
  std::error_code ec;
  if (input == output || fs::equivalent(input, output, ec)) {
    ThrowInputError(output, "--out", "is the input file; inputs are never modified");
  }
}

struct Layout {
  mocap::MarkerLayout layout;
  std::string config_yaml;  // the configuration text, when --config was given
  // Joint positions of the arm, from --config or else the experiment's
  // nominal configuration; none when neither is there.
  std::optional<mocap::JointChain> chain;
  // For labelling camera reconstructions; 0 without an arm configuration.
  double max_link_spacing_m = 0.0;
};

// The rigid bodies: --rigid-bodies, else the default layout of --config, else
// (for an experiment input) the experiment's own; --static-trial refines them.
Layout ResolveLayout(const std::string& rigid_bodies, const std::string& config,
                     const std::string& static_trial, const datasets::ExperimentFile* experiment,
                     const std::string& input) {
  Layout out;
  std::unique_ptr<sim::ArmModel> model;
  if (!config.empty()) {
    out.config_yaml = ReadTextFile(config);
    model = std::make_unique<sim::ArmModel>(sim::ParseConfig(out.config_yaml, config).arm);
  } else if (experiment != nullptr && !experiment->config_yaml.empty()) {
    model = std::make_unique<sim::ArmModel>(
        sim::ParseConfig(experiment->config_yaml, input + ": attribute 'config_yaml'").arm);
  }
  if (model) {
    out.chain = mocap::JointChain::FromModel(*model);
    out.max_link_spacing_m = cameras::MaxLinkSpacing(*model);
  }
  if (!rigid_bodies.empty()) {
    out.layout = mocap::ReadRigidBodiesFile(rigid_bodies);
  } else if (model) {
    out.layout = mocap::DefaultMarkerLayout(*model);
  } else if (experiment != nullptr && !experiment->rigid_bodies.empty()) {
    out.layout = mocap::LayoutFromExperiment(experiment->rigid_bodies, input);
  } else {
    ThrowInputError(input, "rigid bodies",
                    "give --rigid-bodies FILE or --config FILE (the default marker layout)");
  }
  if (!static_trial.empty()) {
    if (!model)
      ThrowInputError(static_trial, "--static-trial", "needs --config (the arm's kinematics)");
    const mocap::StaticTrialRefinement refined = mocap::RefineFromStaticTrial(
        out.layout, *model, mocap::ReadMarkerFile(static_trial), static_trial);
    double largest = 0.0;
    for (double d : refined.displacement_m) {
      if (std::isfinite(d)) largest = std::max(largest, d);
    }
    std::printf("static trial %s: marker positions refined (largest change %.3f mm)\n",
                static_trial.c_str(), largest * 1e3);
    for (const std::string& w : refined.warnings) std::printf("  warning: %s\n", w.c_str());
    out.layout = refined.layout;
  }
  return out;
}

struct ProcessArgs {
  std::string in;
  std::string cameras;
  std::vector<std::string> videos;
  std::string rigid_bodies;
  std::string config;
  std::string static_trial;
  std::string inputs;
  std::string out;
  mocap::ProcessingOptions options;
  bool no_rigid_fill = false;
  bool quiet = false;
};

// /input/time and /input/length_change of a run or experiment file.
void CopyInputs(const std::string& path, datasets::ExperimentFile* experiment) {
  const datasets::FileSummary summary = datasets::InspectFile(path);
  if (summary.kind == datasets::FileKind::kExperiment) {
    const datasets::ExperimentFile source = datasets::ReadExperimentFile(path);
    experiment->input_time = source.input_time;
    experiment->input_length_change = source.input_length_change;
  } else {
    const datasets::RunFile run = datasets::ReadRunFile(path);
    experiment->input_time = run.time;
    experiment->input_length_change = run.input_length_change;
  }
}

void RunProcess(ProcessArgs a) {
  a.options.rigid_fill = !a.no_rigid_fill;
  if (a.in.empty() && a.cameras.empty()) {
    ThrowInputError("mocap process", "--in", "give --in FILE or --cameras FILE --video ...");
  }
  if (!a.cameras.empty() && a.config.empty() && a.rigid_bodies.empty()) {
    ThrowInputError(a.cameras, "--config",
                    "videos need --config or --rigid-bodies (the markers to label)");
  }
  if (!a.in.empty()) RefuseToOverwrite(a.in, a.out);
  if (!a.cameras.empty()) RefuseToOverwrite(a.cameras, a.out);
  for (const std::string& video : a.videos) RefuseToOverwrite(video, a.out);
  { const AtomicOutputFile probe(a.out); }  // fail on a bad output path before working

  // What is read, and the experiment the result goes into.
  datasets::ExperimentFile experiment;
  mocap::MarkerTable table;
  std::vector<double> time;
  bool from_experiment = false;
  std::string run_config_yaml;
  if (IsHdf5Name(a.in) && datasets::InspectFile(a.in).kind == datasets::FileKind::kExperiment) {
    experiment = datasets::ReadExperimentFile(a.in);
    table = mocap::MarkerTableFromExperiment(experiment);
    time = experiment.mocap_time.values;
    from_experiment = true;
  } else if (IsHdf5Name(a.in)) {  // a run with virtual markers
    const datasets::RunFile run = datasets::ReadRunFile(a.in);
    table = mocap::ReadHdf5Markers(a.in);
    time = run.time.values;
    experiment.input_time = run.time;
    experiment.input_length_change = run.input_length_change;
    experiment.source = datasets::ExperimentSource::kGenerated;
    run_config_yaml = run.config_yaml;
  } else if (a.cameras.empty()) {
    table = mocap::ReadMarkerFile(a.in);
  }

  const std::string& source = a.cameras.empty() ? a.in : a.cameras;
  const Layout layout = ResolveLayout(a.rigid_bodies, a.config, a.static_trial,
                                      from_experiment ? &experiment : nullptr, source);
  if (!a.cameras.empty()) {
    // Camera front end (mocap/cameras): the same marker table a file gives.
    const cameras::CameraRig rig = cameras::LoadCameraRig(a.cameras);
    cameras::ReconstructionOptions options;
    if (layout.max_link_spacing_m > 0.0)
      options.labelling.max_link_spacing_m = layout.max_link_spacing_m;
    if (!a.quiet) {
      options.progress = [](std::size_t done, std::size_t total) {
        if (done % 25 == 0 || done == total) {
          std::fprintf(stderr, "\rreconstructing frame %zu / %zu", done, total);
          if (done == total) std::fprintf(stderr, "\n");
        }
      };
    }
    const cameras::ReconstructionResult reconstruction =
        cameras::ReconstructMarkers(rig, a.videos, layout.layout, options);
    std::printf("%s", reconstruction.quality.BriefReport().c_str());
    table = reconstruction.markers;
  }
  const mocap::ProcessingResult result = mocap::ProcessMarkers(
      table, time, layout.layout, a.options, a.in, layout.chain ? &*layout.chain : nullptr);

  if (!from_experiment) {
    experiment.name = fs::path(a.out).stem().string();
    experiment.description = "markers of " + fs::path(source).filename().string() + " (" +
                             table.format + "), processed by ccsrm mocap process";
    experiment.config_yaml = !layout.config_yaml.empty() ? layout.config_yaml : run_config_yaml;
    experiment.mocap_time = datasets::Array({result.time.size()});
    experiment.mocap_time.values = result.time;
    experiment.mocap_markers = result.raw_markers;
    experiment.marker_names = result.marker_names;
    if (experiment.input_time.rows() == 0) {
      // No actuator record: one sample at the start with no cable columns.
      experiment.input_time = datasets::Array({1}, result.time.front());
      experiment.input_length_change = datasets::Array({1, 0});
    }
  }
  if (!a.inputs.empty()) CopyInputs(a.inputs, &experiment);
  experiment.rigid_bodies = mocap::ToExperimentRigidBodies(layout.layout);
  experiment.mocap_quality.clear();
  experiment.mocap_quality_units.clear();
  experiment.created.clear();
  mocap::StoreInExperiment(result, &experiment);
  datasets::WriteExperimentFile(a.out, experiment);
  if (a.quiet) {
    std::printf("%s\n", result.summary.BriefReport().c_str());
  } else {
    std::printf("%s", result.summary.FullReport().c_str());
  }
  std::printf("  output: %s (%zu frames, %zu joints)\n", a.out.c_str(), result.time.size(),
              result.summary.joints.size());
}

}  // namespace

void AddMocapCommands(CLI::App& root) {
  CLI::App* mocap = root.add_subcommand(
      "mocap", "Motion capture: inspect marker files, turn markers into joint angles");
  mocap->require_subcommand(1);

  CLI::App* inspect = mocap->add_subcommand(
      "inspect",
      "Summarise a marker file (C3D, TRC, Vicon Nexus CSV, OptiTrack Motive CSV, or a ccsrm "
      "HDF5 experiment/run): frames, rate, labels, gaps");
  struct InspectArgs {
    std::string path;
    bool json = false;
  };
  auto inspect_args = std::make_shared<InspectArgs>();
  inspect->add_option("FILE", inspect_args->path, "Marker file")->required();
  inspect->add_flag("--json", inspect_args->json, "Print one JSON object instead of text");
  inspect->callback([inspect_args] {
    const mocap::MarkerTable table = mocap::ReadMarkerFile(inspect_args->path);
    if (inspect_args->json) {
      std::printf("%s\n", mocap::InspectJson(table).dump(2).c_str());
    } else {
      std::printf("%s", mocap::InspectText(table).c_str());
    }
  });

  CLI::App* process = mocap->add_subcommand(
      "process",
      "Fill gaps, low-pass filter, fit every link's pose and write joint angles and quality "
      "figures into a ccsrm-dataset/1 experiment");
  auto a = std::make_shared<ProcessArgs>();
  const mocap::ProcessingOptions defaults;
  auto* in = process->add_option("--in", a->in, "Marker file (any format mocap inspect reads)");
  auto* cams = process->add_option(
      "--cameras", a->cameras,
      "Calibrated camera file (ccsrm-cameras/1) for videos instead of a marker file");
  process->add_option("--video", a->videos, "With --cameras: one video per camera, in file order")
      ->needs(cams);
  in->excludes(cams);
  cams->needs("--video");
  process->add_option("--rigid-bodies", a->rigid_bodies,
                      "Rigid bodies (ccsrm-rigid-bodies/1 YAML, mocap/README.md)");
  process->add_option("--config", a->config,
                      "Arm configuration: its default marker layout when --rigid-bodies is not "
                      "given, its joint positions for the joint-constrained fit (an "
                      "experiment's own config_yaml otherwise); stored as the experiment's "
                      "config_yaml");
  process->add_option("--static-trial", a->static_trial,
                      "Marker file of a static trial with the arm straight: refines the marker "
                      "positions (needs --config)");
  process->add_option("--inputs", a->inputs,
                      "Run or experiment file whose /input (cable length changes) the output "
                      "experiment records");
  // Ranges from ProcessingOptions::IsValid, checked while parsing.
  using mocap::ProcessingOptions;
  process->add_option("--cutoff-hz", a->options.cutoff_hz, "Low-pass cutoff [Hz], 0 = no filter")
      ->default_val(defaults.cutoff_hz)
      ->check(ValidIn(&ProcessingOptions::cutoff_hz));
  process->add_option("--order", a->options.filter_order, "Butterworth order per pass (1..8)")
      ->default_val(defaults.filter_order)
      ->check(ValidIn(&ProcessingOptions::filter_order));
  process
      ->add_option("--max-spline-gap", a->options.max_spline_gap_frames,
                   "Longest gap filled by a spline [frames]; longer gaps are filled from the "
                   "link's other markers")
      ->default_val(defaults.max_spline_gap_frames)
      ->check(ValidIn(&ProcessingOptions::max_spline_gap_frames));
  process->add_flag("--no-rigid-fill", a->no_rigid_fill,
                    "Do not fill gaps from the link's other markers");
  process->add_option("--out", a->out, "Output experiment (.h5)")->required();
  process->add_flag("--quiet", a->quiet, "One summary line instead of the quality tables");
  process->callback([a] { RunProcess(*a); });

  CLI::App* rigid = mocap->add_subcommand(
      "rigid-bodies",
      "Write the rigid-bodies file of an arm's default marker layout (optionally refined from "
      "a static trial), to edit or to pass to mocap process");
  struct RigidArgs {
    std::string config;
    std::string static_trial;
    std::string out;
  };
  auto r = std::make_shared<RigidArgs>();
  rigid->add_option("--config", r->config, "Arm configuration (YAML)")->required();
  rigid->add_option("--static-trial", r->static_trial,
                    "Marker file of a static trial with the arm straight");
  rigid->add_option("--out", r->out, "Output rigid-bodies file (.yaml)")->required();
  rigid->callback([r] {
    const Layout layout = ResolveLayout("", r->config, r->static_trial, nullptr, r->config);
    mocap::WriteRigidBodiesFile(r->out, layout.layout);
    std::printf("%s: %zu bodies, %zu markers\n", r->out.c_str(), layout.layout.bodies.size(),
                layout.layout.marker_count());
  });
}

}  // namespace ccsrm::app
