#pragma once
// The mocap pipeline as one call: from a recording (a marker file, an
// experiment or run file, or markers reconstructed from videos) to a complete
// ccsrm-dataset/1 experiment with measured joint angles and quality figures.
// Nothing is written: `ccsrm mocap process` is ProcessRecording plus writing
// and printing; identification calls AddMeasuredJointAngles on an experiment
// it has read. Each input file is read once.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/marker_table.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::mocap {

// Markers that come from somewhere other than a marker file.
struct ReconstructedMarkers {
  MarkerTable markers;
  // What the reconstruction reports about its quality, printed by the command
  // before the processing summary ("" or lines ending in a newline).
  std::string report;
};

// Makes the markers once the layout is known: called with the resolved layout
// and the arm model (null when there is no configuration). The camera front
// end gives one: cameras::VideoMarkerSource (mocap/cameras, which depends on
// this library, not the other way round).
using MarkerReconstruction =
    std::function<ReconstructedMarkers(const MarkerLayout& layout, const sim::ArmModel* model)>;

// What to process and how. Paths are read once each; nothing is written.
struct RecordingRequest {
  // Where the markers come from: exactly one of `in` and `reconstruct`.
  // `in`: any file ReadMarkerFile reads. A ccsrm-dataset/1 experiment (.h5)
  // is extended (its inputs and attributes kept); a ccsrm-run/1 run (.h5)
  // with /markers gives a "generated" experiment with the run's inputs; any
  // other marker file a new "recorded" experiment.
  std::string in;
  MarkerReconstruction reconstruct;
  // Names the reconstruction's input (e.g. the camera file) in errors and in
  // the experiment's description. Default "": "reconstructed markers".
  std::string reconstruction_source;

  // The rigid bodies, first that applies: `rigid_bodies` (a
  // ccsrm-rigid-bodies/1 file); the default layout of `config`; an
  // experiment input's own /mocap/rigid_bodies; the default layout of an
  // experiment input's config_yaml. Default "": none given.
  std::string rigid_bodies;
  // Arm configuration (YAML): joint positions for the joint-constrained fit
  // (else an experiment input's config_yaml; else every link is fitted on
  // its own), the config_yaml of a new experiment. Default "": none.
  std::string config;
  // Marker file of a static trial with the arm straight: refines the marker
  // positions (RefineFromStaticTrial). Needs an arm model (`config` or an
  // experiment input's config_yaml). Default "": no refinement.
  std::string static_trial;
  // Run or experiment file whose /input (time and cable length changes) the
  // experiment records. Default "": an experiment input keeps its own, a run
  // gives its own, any other file gives one sample with no cable columns.
  std::string inputs;
  // Root attribute `name` of a new experiment. Default "": the stem of the
  // marker source's file name. An experiment input keeps its name.
  std::string name;

  ProcessingOptions processing;

  // Exactly one marker source; a reconstruction needs `rigid_bodies` or
  // `config` (the markers to label); valid processing options. On failure
  // returns false with the reason in *error.
  bool IsValid(std::string* error) const;
};

struct ProcessedRecording {
  // The finished experiment, validated (ValidateExperimentFile): the input's
  // markers, inputs and attributes, the layout as /mocap/rigid_bodies, the
  // measured joint angles, link poses, twists and /mocap/quality
  // (StoreInExperiment). `created` is empty: WriteExperimentFile stamps it.
  datasets::ExperimentFile experiment;
  // The processing's result; result.summary holds the quality figures.
  ProcessingResult result;
  // The static-trial refinement, when one was asked for.
  std::optional<StaticTrialRefinement> static_trial;
  // ReconstructedMarkers::report of a reconstruction, else "".
  std::string reconstruction_report;
};

// Runs the pipeline the request describes (SPEC 5): reads the inputs,
// resolves the rigid bodies, reconstructs the markers when asked, processes
// them (ProcessMarkers) and assembles the experiment. Throws InputError for an
// invalid request, a file that cannot be read or is bad (the reader's
// message, naming file and field), a layout that cannot be resolved ("give
// --rigid-bodies FILE or --config FILE"), a run file without markers, a
// static trial without an arm model, or what ProcessMarkers throws (e.g. no
// marker of the layout in the file).
ProcessedRecording ProcessRecording(const RecordingRequest& request);

// The pipeline with default settings on an experiment already read, as
// identification needs for an experiment without /measured/joint_angles: the
// layout is the experiment's own rigid bodies, else the default layout of its
// config_yaml; the joint chain comes from its config_yaml (none without one).
// Returns the experiment with /measured/* and /mocap/quality filled in
// (existing ones replaced, as `ccsrm mocap process --in exp.h5` does) and
// everything else kept; no file is read or written. `source` names the
// experiment in errors. The same as ProcessRecording with `in` = the
// experiment's file and `processing` = options. Throws InputError when the
// experiment does not validate, has neither rigid bodies nor config_yaml, or
// its markers match none of the layout's. `arm`: the arm of its config_yaml
// when the caller has built it (identification parses the configuration
// once); null: built here.
ProcessedRecording AddMeasuredJointAngles(const datasets::ExperimentFile& experiment,
                                          const std::string& source,
                                          const ProcessingOptions& options = {},
                                          std::shared_ptr<const sim::ArmModel> arm = nullptr);

}  // namespace ccsrm::mocap
