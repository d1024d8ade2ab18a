#pragma once
// A lab's recording made into an experiment: the motion-capture file, the
// actuators' log on its own clock, and the map of the log's columns
// (`ccsrm dataset assemble`). The markers go through the mocap pipeline
// (ProcessRecording), the log is put on the mocap clock (clock_alignment.h)
// and resampled onto the mocap frames, and the alignment is recorded in the
// experiment (datasets::ClockAlignment). Nothing is written.
#include <string>

#include "ccsrm/mocap/clock_alignment.h"
#include "ccsrm/mocap/recording.h"

namespace ccsrm::mocap {

enum class ClockSync {
  kTrigger,  // edges of a C3D analog channel against the log's trigger column
  // The offset that best maps the measured joint angles onto those of one
  // simulation of the arm driven by the log (AlignBySimulation): right for
  // an arm that lags its inputs (friction).
  kEstimate,
  // The offset at which the logged lengths best explain the measured angles
  // through the kinematics (AlignByKinematics): no simulation, but biased by
  // the arm's lag (about 50 ms on the generated case-2 arm).
  kEstimateKinematic,
  kOffset,  // given: clock_offset_s and clock_drift_ppm
};

struct LabRecordingRequest {
  std::string markers;       // marker file (a C3D file for kTrigger)
  std::string actuators;     // the actuators' log (CSV/TSV)
  std::string actuator_map;  // its map (ccsrm-actuators/1 YAML)
  std::string config;        // the arm's configuration (required: kinematics, cables)
  std::string rigid_bodies;  // optional: default "", the config's default layout
  std::string static_trial;  // optional: default "", no refinement
  std::string name;          // the experiment's name; default "": the marker file's stem
  // kEstimate: YAML of prior parameter values (name: value) over the
  // configuration's, for the simulation; default "": the configuration's.
  std::string params;

  ClockSync sync = ClockSync::kTrigger;
  // kOffset: the log's time at mocap time 0 [s], and its rate difference.
  double clock_offset_s = 0.0;
  double clock_drift_ppm = 0.0;

  // kTrigger: the C3D analog channel holding the pulse (its label; default
  // "": the file's only channel, or the one named "trigger" or "sync",
  // case-insensitive), and how its edges are found (threshold default: half
  // way between its extremes; rising edges; interpolated crossings).
  std::string trigger_channel;
  EdgeOptions mocap_edges;
  // Edge timings left at 0 are filled in: the C3D channel's from its rate
  // (one sample / √12), the log's from the jitter of its stamps.
  TriggerAlignmentOptions trigger;
  KinematicAlignmentOptions estimate;

  ProcessingOptions processing;

  // All files named, valid options; else false with the reason.
  bool IsValid(std::string* error) const;
};

struct AssembledRecording {
  // The experiment: processed markers, measured joint angles, the log's
  // inputs on /mocap/time, clock_alignment set, source recorded.
  ProcessedRecording processed;
  ClockFit clock;
  std::string log_summary;  // one line: what the log held
  // For a trigger or a given offset: the kinematic estimate as a check (one
  // line), and whether it disagrees with the alignment used by more than
  // 4 standard deviations and two mocap frames (a wrong offset, a pulse
  // paired with the wrong tick). Empty / false for the estimates. The
  // estimate assumes a quasi-static arm: an arm that lags its inputs
  // (friction: about 50 ms on the generated case-2 arm) shows as a
  // disagreement too, so this is a warning, not a refusal.
  std::string kinematic_check;
  bool misaligned = false;
  // Lines saying what was done (alignment, resampling), for the command.
  std::string Report() const;
};

// Throws InputError (one line naming file and field) for an invalid
// request, a bad map or log, a marker file the pipeline refuses, a trigger
// that cannot be found or paired, an ambiguous alignment, a log that does
// not cover the recording, or a log with another number of cables than the
// arm.
AssembledRecording AssembleLabRecording(const LabRecordingRequest& request);

}  // namespace ccsrm::mocap
