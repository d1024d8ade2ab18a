// ccsrm dataset inspect FILE [--json]
// ccsrm dataset assemble --markers rec.c3d --actuators log.csv --actuator-map map.yaml
//   --config arm.yaml [--rigid-bodies rb.yaml] [--static-trial FILE]
//   [--sync trigger|estimate|estimate-kinematic|offset=S] [--params prior.yaml] --out exp.h5
// ccsrm dataset tendon-map --log pulls.csv [--out map.yaml] [--actuator-map actuators.yaml]
// ccsrm dataset import-pose-log --log poses.csv --actuator-map actuators.yaml --config arm.yaml
//   --out exp.h5 [--rows A-B] [--tip-unit mm] [--tip-marker-mm X,Y,Z] [--name NAME]
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/common/output_policy.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/mocap/lab_recording.h"
#include "ccsrm/mocap/pose_log.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "commands.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

struct AssembleArgs {
  mocap::LabRecordingRequest request;
  std::string sync = "trigger";
  std::string trigger_polarity = "rising";
  double trigger_threshold = std::nan("");
  std::string out;
  bool quiet = false;
};

// --sync trigger | estimate | estimate-kinematic | offset=S (S in seconds, the log's time at
// mocap time 0).
void ParseSync(const std::string& sync, mocap::LabRecordingRequest* request) {
  if (sync == "trigger") {
    request->sync = mocap::ClockSync::kTrigger;
  } else if (sync == "estimate") {
    request->sync = mocap::ClockSync::kEstimate;
  } else if (sync == "estimate-kinematic") {
    request->sync = mocap::ClockSync::kEstimateKinematic;
  } else if (sync.rfind("offset=", 0) == 0) {
    request->sync = mocap::ClockSync::kOffset;
    const std::string problem = ParseNumberText(sync.substr(7), &request->clock_offset_s);
    if (!problem.empty()) {
      ThrowInputError("dataset assemble", "--sync", "offset '" + sync.substr(7) + "' " + problem);
    }
  } else {
    ThrowInputError(
        "dataset assemble", "--sync",
        "expected trigger, estimate, estimate-kinematic or offset=S, found '" + sync + "'");
  }
}

// --rows A-B: the log's data rows A to B (1-based, inclusive).
void ParseRows(const std::string& text, mocap::PoseLogImportRequest* request) {
  const std::size_t dash = text.find('-');
  double first = 0.0, last = 0.0;
  const bool parsed = dash != std::string::npos &&
                      ParseNumberText(text.substr(0, dash), &first).empty() &&
                      ParseNumberText(text.substr(dash + 1), &last).empty();
  if (!parsed || first < 1.0 || last < first || first != std::floor(first) ||
      last != std::floor(last)) {
    ThrowInputError("dataset import-pose-log", "--rows",
                    "expected A-B, whole numbers with 1 <= A <= B, found '" + text + "'");
  }
  request->first_row = static_cast<std::size_t>(first);
  request->last_row = static_cast<std::size_t>(last);
}

// Parse -> mocap::AssembleLabRecording -> check, write, print.
void RunAssemble(AssembleArgs a) {
  mocap::LabRecordingRequest& request = a.request;
  ParseSync(a.sync, &request);
  request.mocap_edges.threshold = a.trigger_threshold;
  request.mocap_edges.rising = a.trigger_polarity == "rising";
  CheckOut(a.out, datasets::ExperimentFileOutput(),
           {request.markers, request.actuators, request.actuator_map, request.config,
            request.rigid_bodies, request.static_trial, request.params});
  const mocap::AssembledRecording assembled = mocap::AssembleLabRecording(request);
  const datasets::ExperimentFile& experiment = assembled.processed.experiment;
  sim_io::CheckExperimentAgainstConfig(experiment, request.markers);
  datasets::WriteExperimentFile(a.out, experiment);
  std::printf("%s", assembled.Report().c_str());
  const mocap::ProcessingResult& result = assembled.processed.result;
  if (a.quiet) {
    std::printf("%s\n", result.summary.BriefReport().c_str());
  } else {
    std::printf("%s", result.summary.FullReport().c_str());
  }
  std::printf("  output: %s (%zu frames, %zu cables, source recorded)\n", a.out.c_str(),
              experiment.mocap_time.size(), experiment.input_length_change.shape[1]);
}

// ccsrm dataset tendon-map: parse -> mocap::IdentifyTendonMap -> print, write.
void AddTendonMap(CLI::App* dataset) {
  CLI::App* tendon_map = dataset->add_subcommand(
      "tendon-map",
      "Identify which actuator drives which tendon, with its sign and the reading at which it "
      "engages, from a pose log that pulls one tendon at a time (CSV/TSV: time, pattern "
      "label, actuator readings, tip position; docs/tdcr-recordings.md)");
  struct TendonMapArgs {
    std::string log, out, actuator_map, unit = "mm";
    mocap::PoseLogColumns columns;
    mocap::TendonMapOptions options;
    std::string axis = "z";
  };
  auto t = std::make_shared<TendonMapArgs>();
  tendon_map->add_option("--log", t->log, "The pose log (CSV or TSV)")->required();
  tendon_map
      ->add_option("--tendons-per-segment", t->options.tendons_per_segment,
                   "Tendons per segment, evenly spread around the backbone")
      ->capture_default_str()
      ->check(CLI::Range(1, 15));
  tendon_map->add_option("--axis", t->axis, "The arm's axis in the capture frame: x, y or z")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y", "z"}));
  tendon_map
      ->add_option("--actuator-prefix", t->columns.actuator_prefix,
                   "Columns whose names start with this are the actuators' readings")
      ->capture_default_str();
  tendon_map->add_option("--label-column", t->columns.label, "Column of the pattern labels")
      ->capture_default_str();
  tendon_map->add_option("--time-column", t->columns.time, "Column of the time [s]")
      ->capture_default_str();
  tendon_map
      ->add_option("--min-rows", t->options.min_rows,
                   "A pattern of fewer rows is not a pull (a hold, a label's tail)")
      ->capture_default_str()
      ->check(CLI::Range(3, 1000000));
  tendon_map->add_option("--out", t->out, "Write the map (ccsrm-tendon-map/1 YAML)");
  tendon_map->add_option(
      "--actuator-map", t->actuator_map,
      "Write the map as the actuators' (ccsrm-actuators/1 YAML: column, sign and "
      "zero of every cable, tendon k as cable k)");
  tendon_map->add_option("--unit", t->unit, "Unit of the actuators' readings (m or mm)")
      ->capture_default_str()
      ->check(CLI::IsMember({"m", "mm"}));
  tendon_map->callback([t] {
    if (!t->out.empty()) {
      CheckOut(t->out, YamlFileOutput(mocap::kTendonMapSchema, "tendon map"), {t->log});
    }
    if (!t->actuator_map.empty()) {
      // Neither the log nor the other output.
      std::vector<std::string> not_these = {t->log};
      if (!t->out.empty()) not_these.push_back(t->out);
      CheckOutputPath(t->actuator_map, "--actuator-map",
                      YamlFileOutput("ccsrm-actuators/1", "actuator map"), not_these);
    }
    t->options.axis = t->axis == "x" ? 0 : t->axis == "y" ? 1 : 2;
    const mocap::PoseLog log = mocap::ReadPoseLog(t->log, t->columns);
    const mocap::TendonMap map = mocap::IdentifyTendonMap(log, t->options);
    std::printf("%s: %zu rows, %zu actuator columns; %zu tendons pulled one at a time\n%s",
                t->log.c_str(), log.time_s.size(), log.actuator_columns.size(), map.tendons.size(),
                map.Report().c_str());
    if (!t->out.empty()) {
      WriteTextFileAtomically(t->out, map.ToYaml(t->log));
      std::printf("  output: %s\n", t->out.c_str());
    }
    if (!t->actuator_map.empty()) {
      WriteTextFileAtomically(t->actuator_map,
                              map.ActuatorMapYaml(t->log, t->columns.time, t->unit));
      std::printf("  actuator map: %s\n", t->actuator_map.c_str());
    }
  });
}

// ccsrm dataset import-pose-log: parse -> mocap::ImportPoseLog -> check, write, print.
void AddImportPoseLog(CLI::App* dataset) {
  CLI::App* import_log = dataset->add_subcommand(
      "import-pose-log",
      "Make a ccsrm-dataset/1 experiment of settled poses from a lab's pose log (CSV/TSV: "
      "time, pattern label, actuator readings, a tracked tip position): the readings through "
      "an actuator map (e.g. tendon-map --actuator-map's) as the cables' pulled-in lengths, "
      "the tip as a marker on the last link, in the capture frame");
  struct ImportArgs {
    mocap::PoseLogImportRequest request;
    std::string out, rows;
    std::vector<double> tip_marker_mm = {0.0, 0.0, 0.0};
  };
  auto im = std::make_shared<ImportArgs>();
  mocap::PoseLogImportRequest& q = im->request;
  import_log->add_option("--log", q.log, "The pose log (CSV or TSV)")->required();
  import_log
      ->add_option("--actuator-map", q.actuator_map,
                   "Which column drives which cable, its sign, zero and unit, and the time "
                   "column (ccsrm-actuators/1 YAML)")
      ->required();
  import_log->add_option("--config", q.config, "Arm configuration (YAML)")->required();
  import_log->add_option("--out", im->out, "Output experiment (.h5)")->required();
  import_log->add_option("--rows", im->rows,
                         "The rows to import, A-B (1-based, inclusive, the log's data rows); "
                         "default: all");
  import_log->add_option("--label-column", q.columns.label, "Column of the pattern labels")
      ->capture_default_str();
  import_log->add_option("--tip-unit", q.tip_unit, "Unit of the tip columns (m or mm)")
      ->capture_default_str()
      ->check(CLI::IsMember({"m", "mm"}));
  import_log
      ->add_option("--tip-marker-mm", im->tip_marker_mm,
                   "The tip marker in the last link's frame, from the centre of its distal end "
                   "[mm]: X,Y,Z")
      ->delimiter(',')
      ->expected(3);
  import_log->add_option("--name", q.name, "Experiment name (default: the log's stem)");
  import_log->callback([im] {
    mocap::PoseLogImportRequest request = im->request;
    if (!im->rows.empty()) ParseRows(im->rows, &request);
    for (int k = 0; k < 3; ++k) request.tip_from_link_end_m[k] = 1e-3 * im->tip_marker_mm[k];
    CheckOut(im->out, datasets::ExperimentFileOutput(),
             {request.log, request.actuator_map, request.config});
    const mocap::ImportedPoseLog imported = mocap::ImportPoseLog(request);
    sim_io::CheckExperimentAgainstConfig(imported.experiment, request.log);
    datasets::WriteExperimentFile(im->out, imported.experiment);
    std::printf("%s  output: %s (settled poses, source recorded)\n", imported.report.c_str(),
                im->out.c_str());
  });
}

}  // namespace

void AddDatasetCommands(CLI::App& root) {
  CLI::App* dataset =
      root.add_subcommand("dataset", "Inspect ccsrm HDF5 files (runs and experiments)");
  dataset->require_subcommand(1);
  CLI::App* inspect = dataset->add_subcommand(
      "inspect",
      "Validate a ccsrm-run/1 or ccsrm-dataset/1 file (an experiment also against its own "
      "config_yaml) and print its schema, sizes, time span and attributes");
  struct Args {
    std::string path;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  inspect->add_option("FILE", args->path, "HDF5 file")->required();
  inspect->add_flag("--json", args->json, "Print one JSON object instead of text");
  inspect->callback([args] {
    // Read once, through the door every command reading a file whole uses:
    // an experiment or run checked against its own config_yaml.
    const datasets::AnyFile file = sim_io::ReadCheckedFile(args->path);
    const datasets::FileSummary summary = datasets::Summarise(file, args->path);
    if (args->json) {
      std::printf("%s\n", datasets::ToJson(summary).dump(2).c_str());
    } else {
      std::printf("%s", datasets::ToText(summary).c_str());
    }
  });

  AddTendonMap(dataset);
  AddImportPoseLog(dataset);

  CLI::App* assemble = dataset->add_subcommand(
      "assemble",
      "Make a ccsrm-dataset/1 experiment from a lab's recording: a marker file, the actuators' "
      "log (CSV/TSV, mapped by a ccsrm-actuators/1 YAML) and the arm's configuration; the log "
      "is aligned to the mocap clock (trigger pulse, estimate, or a given offset) and resampled "
      "onto the mocap frames");
  auto a = std::make_shared<AssembleArgs>();
  mocap::LabRecordingRequest& r = a->request;
  assemble->add_option("--markers", r.markers, "Marker file (C3D for --sync trigger)")->required();
  assemble->add_option("--actuators", r.actuators, "Actuator log (CSV or TSV)")->required();
  assemble
      ->add_option("--actuator-map", r.actuator_map,
                   "The log's columns (ccsrm-actuators/1 YAML, datasets/README.md)")
      ->required();
  assemble->add_option("--config", r.config, "Arm configuration (YAML)")->required();
  assemble->add_option("--rigid-bodies", r.rigid_bodies,
                       "Rigid bodies (ccsrm-rigid-bodies/1); default: the config's layout");
  assemble->add_option("--static-trial", r.static_trial,
                       "Marker file of a static trial with the arm straight");
  assemble
      ->add_option("--sync", a->sync,
                   "How the clocks are aligned: trigger (a C3D analog pulse against the log's "
                   "trigger column), estimate (the joint angles against one simulation of the "
                   "arm driven by the log), estimate-kinematic (the joint angles through the "
                   "kinematics of a quasi-static arm: no simulation, biased by the arm's lag) "
                   "or offset=S (the log's time at mocap time 0, s)")
      ->default_val("trigger");
  assemble
      ->add_option("--clock-drift-ppm", r.clock_drift_ppm,
                   "With --sync offset=S: how much faster the log's clock runs [ppm]")
      ->default_val(0.0);
  assemble->add_option("--trigger-channel", r.trigger_channel,
                       "C3D analog channel of the trigger pulse (default: the only channel, "
                       "or the one named trigger or sync)");
  assemble->add_option("--trigger-threshold", a->trigger_threshold,
                       "Level of the pulse's edges in the channel's units (default: half way "
                       "between its extremes)");
  assemble->add_option("--trigger-polarity", a->trigger_polarity, "rising or falling edges")
      ->default_val("rising")
      ->check(CLI::IsMember({"rising", "falling"}));
  assemble->add_option("--params", r.params,
                       "With --sync estimate: YAML file of prior parameter values (name: value) "
                       "for its simulation (default: the configuration's)");
  assemble->add_flag("--estimate-drift", r.estimate.estimate_drift,
                     "With --sync estimate or estimate-kinematic: also estimate the clocks' rate "
                     "difference (for long "
                     "recordings; default: drift 0)");
  assemble->add_option("--name", r.name, "Experiment name (default: the marker file's stem)");
  assemble->add_option("--out", a->out, "Output experiment (.h5)")->required();
  assemble->add_flag("--quiet", a->quiet, "One summary line instead of the quality tables");
  assemble->callback([a] { RunAssemble(*a); });
}

}  // namespace ccsrm::app
