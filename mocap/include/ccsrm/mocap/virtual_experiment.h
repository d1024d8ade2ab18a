#pragma once
// Virtual motion capture of a simulation: markers placed on every output
// frame's link poses, Gaussian noise and realistic occlusions from a seeded
// generator, packed as a ccsrm-dataset/1 experiment (what `ccsrm generate`
// writes). The same seed gives the same recording, bit for bit.
#include <cstddef>
#include <cstdint>
#include <string>

#include "ccsrm/datasets/array.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/marker_layout.h"

namespace ccsrm::mocap {

struct OcclusionOptions {
  bool enabled = true;
  // Marker gaps start as a Poisson process: expected gaps per marker per
  // second of recording. Lengths are uniform in [min, max] frames. The default
  // (0.1/s, 1–30 frames) hides about 1.5 % of the samples, in line with a
  // small lab system watching a moving arm.
  double marker_gap_rate_per_s = 0.1;
  int min_gap_frames = 1;
  int max_gap_frames = 30;
  // Occasional whole-link losses (every marker of one link hidden at once,
  // e.g. an arm segment passing behind a fixture): expected losses per link
  // per second, uniform lengths in frames. The ground cluster is never lost
  // whole.
  double link_loss_rate_per_s = 0.005;
  int min_link_loss_frames = 5;
  int max_link_loss_frames = 40;

  bool IsValid(std::string* error) const;
};

struct VirtualRecordingOptions {
  // Standard deviation of the isotropic Gaussian noise on every coordinate [m].
  double noise_sigma_m = 0.2e-3;
  // Resolution of the recorded coordinates [m]: after the noise, every
  // coordinate is rounded to a multiple of the largest power of two (in m)
  // not above it, as a C3D file's integer storage with its POINT:SCALE
  // rounds (0.1 mm: 2^-14 m = 0.061 mm). A power of two leaves the low
  // mantissa bits zero, so the HDF5 file's shuffle and deflate shrink it
  // about four times. Default 0: full double precision.
  double resolution_m = 0.0;
  OcclusionOptions occlusions;
  // Seed of the std::mt19937_64 generator.
  std::uint64_t seed = 1;

  bool IsValid(std::string* error) const;
};

// What the occlusion model hid.
struct VirtualRecordingSummary {
  std::size_t marker_gaps = 0;  // single-marker gaps
  std::size_t link_losses = 0;  // whole-link losses
  std::size_t link_loss_frames =
      0;                           // frames summed over the losses (overlaps counted once per link)
  std::size_t hidden_samples = 0;  // (frame, marker) samples set to NaN
  double hidden_fraction = 0.0;    // of frames × markers
};

// p_WM of every layout marker (MarkerNames() order) at every frame of
// `link_pose` (F × L × 7, as in a run file), F × K × 3 [m]. Requires every
// body's link to be in 0..L (checked, aborts).
datasets::Array MarkersFromLinkPoses(const MarkerLayout& layout, const datasets::Array& link_pose);

// A noisy, occluded copy of `clean` (F × K × 3, layout order) recorded at
// rate_hz. Throws InputError ("virtual recording: ...") for invalid options.
datasets::Array RecordMarkers(const datasets::Array& clean, const MarkerLayout& layout,
                              double rate_hz, const VirtualRecordingOptions& options,
                              VirtualRecordingSummary* summary);

struct VirtualExperimentOptions {
  std::string name;         // experiment name (root attribute)
  std::string description;  // free text
  // The NOMINAL configuration text (as the user gave it), never the truth.
  std::string nominal_config_yaml;
  VirtualRecordingOptions recording;
};

struct VirtualExperiment {
  datasets::ExperimentFile experiment;  // source = generated
  datasets::RunFile truth;              // the run with noise-free /markers, /marker_names
  VirtualRecordingSummary recording;
};

// Builds the experiment from a simulated run: /input from the run's time and
// input length change, /mocap/time = the run's time, markers placed with
// `layout` on /link_pose, recorded with noise and occlusions, rigid bodies
// from the layout. Throws InputError for invalid options or a run of fewer
// than two frames.
VirtualExperiment MakeVirtualExperiment(const datasets::RunFile& run, const MarkerLayout& layout,
                                        const VirtualExperimentOptions& options);

}  // namespace ccsrm::mocap
