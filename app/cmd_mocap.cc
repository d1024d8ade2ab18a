// ccsrm mocap inspect FILE [--json]
// ccsrm mocap process --in FILE (--rigid-bodies rb.yaml | --config cfg.yaml) ... --out exp.h5
// ccsrm mocap rigid-bodies --config cfg.yaml [--static-trial FILE] --out rb.yaml
// ccsrm mocap export --in FILE [--units mm|m] --out markers.c3d
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/mocap/recording.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "commands.h"
#include "option_checks.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

void PrintRefinement(const std::string& static_trial, const mocap::StaticTrialRefinement& refined) {
  double largest = 0.0;
  for (double d : refined.displacement_m) {
    if (std::isfinite(d)) largest = std::max(largest, d);
  }
  std::printf("static trial %s: marker positions refined (largest change %.3f mm)\n",
              static_trial.c_str(), largest * 1e3);
  for (const std::string& w : refined.warnings) std::printf("  warning: %s\n", w.c_str());
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

// Parse (done by CLI11) -> mocap::ProcessRecording -> write -> print.
void RunProcess(const ProcessArgs& a) {
  if (a.in.empty() && a.cameras.empty()) {
    ThrowInputError("mocap process", "--in", "give --in FILE or --cameras FILE --video ...");
  }
  if (!a.cameras.empty() && a.config.empty() && a.rigid_bodies.empty()) {
    ThrowInputError(a.cameras, "--config",
                    "videos need --config or --rigid-bodies (the markers to label)");
  }
  std::vector<std::string> inputs = {a.in,     a.cameras,      a.rigid_bodies,
                                     a.config, a.static_trial, a.inputs};
  inputs.insert(inputs.end(), a.videos.begin(), a.videos.end());
  CheckOut(a.out, datasets::ExperimentFileOutput(), inputs);  // before any work

  mocap::RecordingRequest request;
  request.in = a.in;
  if (!a.cameras.empty()) {
    // Camera front end (mocap/cameras): the same marker table a file gives.
    cameras::ReconstructionOptions options;
    if (!a.quiet) {
      options.progress = [](std::size_t done, std::size_t total) {
        if (done % 25 == 0 || done == total) {
          std::fprintf(stderr, "\rreconstructing frame %zu / %zu", done, total);
          if (done == total) std::fprintf(stderr, "\n");
        }
      };
    }
    request.reconstruct = cameras::VideoMarkerSource(a.cameras, a.videos, options);
    request.reconstruction_source = a.cameras;
  }
  request.rigid_bodies = a.rigid_bodies;
  request.config = a.config;
  request.static_trial = a.static_trial;
  request.inputs = a.inputs;
  request.name = fs::path(a.out).stem().string();
  request.processing = a.options;
  request.processing.rigid_fill = !a.no_rigid_fill;
  const mocap::ProcessedRecording processed = mocap::ProcessRecording(request);

  if (processed.static_trial) PrintRefinement(a.static_trial, *processed.static_trial);
  std::printf("%s", processed.reconstruction_report.c_str());
  // The experiment checked against its own config_yaml before it is written.
  sim_io::CheckExperimentAgainstConfig(processed.experiment, a.in.empty() ? a.cameras : a.in);
  datasets::WriteExperimentFile(a.out, processed.experiment);
  const mocap::ProcessingResult& result = processed.result;
  if (a.quiet) {
    std::printf("%s\n", result.summary.BriefReport().c_str());
  } else {
    std::printf("%s", result.summary.FullReport().c_str());
  }
  std::printf("  output: %s (%zu frames, %zu joints)\n", a.out.c_str(), result.time.size(),
              result.summary.joints.size());
}

// The rigid bodies of `ccsrm mocap rigid-bodies`: the default layout of the
// configuration, refined from a static trial when one is given.
mocap::MarkerLayout DefaultLayout(const std::string& config, const std::string& static_trial) {
  const sim::ArmModel model(sim::LoadConfig(config).arm);
  mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(model);
  if (static_trial.empty()) return layout;
  const mocap::StaticTrialRefinement refined = mocap::RefineFromStaticTrial(
      layout, model, mocap::ReadMarkerFile(static_trial), static_trial);
  PrintRefinement(static_trial, refined);
  return refined.layout;
}

struct ExportArgs {
  std::string in;
  std::string out;
  std::string units = mocap::C3dWriteOptions().units;
};

// ccsrm mocap export: any marker file as C3D.
void RunExport(const ExportArgs& a) {
  std::string extension = fs::path(a.out).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".c3d") ThrowInputError(a.out, "--out", "unsupported format (expected .c3d)");
  CheckOut(a.out, mocap::C3dFileOutput(), {a.in});
  mocap::C3dWriteOptions options;
  options.units = a.units;
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("mocap export", "--units", error);
  // A C3D input keeps its analog channels (scaled values, SCALE 1).
  const mocap::C3dRecording recording = mocap::ReadMarkerFileWithAnalog(a.in);
  const mocap::MarkerTable& table = recording.markers;
  mocap::WriteC3d(a.out, recording, options);
  std::printf(
      "%s: %zu frames, %zu markers at %g Hz, %zu analog channel(s) (C3D, Intel, float "
      "storage, %s)\n",
      a.out.c_str(), table.frames(), table.markers(), table.rate_hz, recording.analog.channels(),
      options.units.c_str());
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
    const mocap::C3dRecording recording = mocap::ReadMarkerFileWithAnalog(inspect_args->path);
    if (inspect_args->json) {
      nlohmann::json j = mocap::InspectJson(recording.markers);
      if (recording.analog.channels() > 0) j["analog"] = mocap::InspectAnalogJson(recording.analog);
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("%s%s", mocap::InspectText(recording.markers).c_str(),
                  mocap::InspectAnalogText(recording.analog).c_str());
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

  CLI::App* exporter = mocap->add_subcommand(
      "export",
      "Write any marker file (C3D, TRC, Nexus/Motive CSV, our HDF5 experiment or run) as a C3D "
      "file: Intel, float storage; times restart at 0 (C3D keeps a rate, not a start time)");
  auto e = std::make_shared<ExportArgs>();
  exporter->add_option("--in", e->in, "Marker file (any format mocap inspect reads)")->required();
  exporter->add_option("--units", e->units, "Unit of the stored coordinates: mm or m")
      ->default_val(e->units)
      ->check(CLI::IsMember({"mm", "m"}));
  exporter->add_option("--out", e->out, "Output C3D file (.c3d)")->required();
  exporter->callback([e] { RunExport(*e); });

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
    CheckOut(r->out, YamlFileOutput(mocap::kRigidBodiesSchema, "rigid-bodies file"),
             {r->config, r->static_trial});
    const mocap::MarkerLayout layout = DefaultLayout(r->config, r->static_trial);
    mocap::WriteRigidBodiesFile(r->out, layout);
    std::printf("%s: %zu bodies, %zu markers\n", r->out.c_str(), layout.bodies.size(),
                layout.marker_count());
  });
}

}  // namespace ccsrm::app
