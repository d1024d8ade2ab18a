#pragma once
// One entry point for every marker file format, and the summary printed by
// `ccsrm mocap inspect FILE [--json]`.
#include <nlohmann/json.hpp>

#include <string>

#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::mocap {

// Reads a marker file, choosing the reader by extension (case-insensitive):
// .c3d → ReadC3d, .trc → ReadTrc, .csv → ReadNexusCsv or ReadMotiveCsv by the
// first line ("Format Version,..." is Motive; "Trajectories" or "Devices" is
// Nexus). Throws InputError for an unknown extension or an unrecognised CSV.
MarkerTable ReadMarkerFile(const std::string& path);

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

}  // namespace ccsrm::mocap
