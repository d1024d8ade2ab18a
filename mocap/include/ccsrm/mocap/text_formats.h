#pragma once
// Text marker files: OpenSim TRC, Vicon Nexus CSV ("Trajectories" block) and
// OptiTrack Motive CSV. Blank cells mean "not seen" (NaN position). A malformed
// file throws ccsrm::InputError naming the file, the line (1-based) and, for a
// bad cell, the column (1-based).
#include <string>

#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::mocap {

// OpenSim TRC, tab- or comma-separated:
//   PathFileType  4  (X/Y/Z)  name.trc
//   DataRate CameraRate NumFrames NumMarkers Units [OrigDataRate ...]
//   <their values>
//   Frame#  Time  M1 _ _  M2 _ _ ...
//   _       _     X1 Y1 Z1 X2 Y2 Z2 ...
//   [blank line]
//   data rows: frame number, time, x y z per marker.
// The rate is DataRate; the frame count is the number of data rows (a
// different NumFrames gives a warning).
MarkerTable ReadTrc(const std::string& path);
MarkerTable ReadTrcFromString(const std::string& text, const std::string& name_for_errors);

// Vicon Nexus CSV export: the "Trajectories" block (a line whose first cell is
// "Trajectories", the rate line, the subject:marker name line, the X/Y/Z
// component line, the units line, then "Frame,Sub Frame,x,y,z,..." rows up to
// a blank line or the next block). Labels keep the "subject:" prefix.
MarkerTable ReadNexusCsv(const std::string& path);
MarkerTable ReadNexusCsvFromString(const std::string& text, const std::string& name_for_errors);

// OptiTrack Motive CSV export (format 1.2x): a first line of key,value pairs
// (Capture/Export Frame Rate, Length Units, ...), a blank line, the Type,
// Name, ID (and optional Parent) rows, the Rotation/Position row, the
// "Frame,Time (Seconds),X,Y,Z,..." row, then data. Only columns of Type
// "Marker" with component Position X/Y/Z are read. Motive is Y-up: the
// coordinates are kept as in the file and up_axis is set to "y".
MarkerTable ReadMotiveCsv(const std::string& path);
MarkerTable ReadMotiveCsvFromString(const std::string& text, const std::string& name_for_errors);

}  // namespace ccsrm::mocap
