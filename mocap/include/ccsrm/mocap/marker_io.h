#pragma once
// One entry point for every marker file format, and the summary printed by
// `ccsrm mocap inspect FILE [--json]`.
#include <nlohmann/json.hpp>

#include <string>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::mocap {

// Reads a marker file, choosing the reader by extension (case-insensitive):
// .c3d → ReadC3d, .trc → ReadTrc, .csv → ReadNexusCsv or ReadMotiveCsv by the
// first line ("Format Version,..." is Motive; "Trajectories" or "Devices" is
// Nexus), .h5/.hdf5 → our HDF5 files: a ccsrm-dataset/1 experiment's
// /mocap/markers, or a ccsrm-run/1 run's /markers (ReadHdf5Markers). Throws
// InputError for an unknown extension or an unrecognised CSV.
MarkerTable ReadMarkerFile(const std::string& path);

// The same, with a C3D file's analog channels (ReadC3dRecording); other
// formats give no channels. The file is read once.
C3dRecording ReadMarkerFileWithAnalog(const std::string& path);

// The markers of a ccsrm-dataset/1 experiment (/mocap/markers, format
// "ccsrm-dataset") or of a ccsrm-run/1 run with /markers (format "ccsrm-run"),
// in metres; the rate is the mean rate of the file's time base. The file is
// validated by the datasets readers. Throws InputError for a bad file or a
// run without markers.
MarkerTable ReadHdf5Markers(const std::string& path);

// An experiment's markers as a table (the rate as in ReadHdf5Markers).
MarkerTable MarkerTableFromExperiment(const datasets::ExperimentFile& experiment);

// A run's virtual markers as a table (the rate as in ReadHdf5Markers). `file`
// names the run in errors. Throws InputError when the run has no /markers.
MarkerTable MarkerTableFromRun(const datasets::RunFile& run, const std::string& file);

// A JSON summary with the keys: format, frames, markers, rate_hz,
// first_frame_number, duration_s, labels, units_in_file, up_axis,
// invalid_points, invalid_fraction, longest_gap_frames, longest_gap_marker,
// visibility (label → fraction seen), first_frame (label → [x, y, z] in
// metres, or null where not seen), has_residual, warnings, and for C3D
// processor, storage and point_scale_m. When a label repeats, the first
// marker with it is reported.
nlohmann::json InspectJson(const MarkerTable& table);

// The same summary as human-readable text (several lines).
std::string InspectText(const MarkerTable& table);

// A summary of analog channels: {channels, rate_hz, samples_per_frame,
// samples, gen_scale, unsigned_integers, list: [{label, units, scale, offset,
// min, max, non_finite}]} (min/max of the scaled values, null when none is
// finite).
nlohmann::json InspectAnalogJson(const C3dAnalog& analog);
// The same as text (empty when there are no channels).
std::string InspectAnalogText(const C3dAnalog& analog);

}  // namespace ccsrm::mocap
