#pragma once
// C3D marker files (https://www.c3d.org): reader and writer.
//
// The reader decodes the three processor formats (Intel: little-endian IEEE;
// DEC: little-endian words, VAX F-floats; MIPS/SGI: big-endian IEEE), integer
// and float storage, and the residual word of every point (negative = the
// point was not seen → NaN position). Analog samples are skipped. Every read
// is bounds-checked: a malformed file throws ccsrm::InputError whose one-line
// message names the file, the byte offset and what was expected. A file that
// contradicts itself (a parameter block count, a frame count larger than the
// data) is read as far as it really goes, with a warning in
// MarkerTable::warnings (mocap/README.md lists the cases).
#include <cstdint>
#include <string>
#include <vector>

#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::mocap {

// Reads the 3D points of a C3D file. Throws InputError when the file cannot
// be read or is not a well-formed C3D file.
MarkerTable ReadC3d(const std::string& path);

// Same, from bytes in memory; name_for_errors stands for the file name in
// error messages.
MarkerTable ReadC3dFromMemory(const std::vector<std::uint8_t>& bytes,
                              const std::string& name_for_errors);

struct C3dWriteOptions {
  // Unit of the stored coordinates: "mm" (default: what most tools expect)
  // or "m".
  std::string units = "mm";
  // Resolution of the residual byte, in metres; POINT:SCALE is written as
  // -(resolution in `units`) (negative = float storage). 0 = automatic: the
  // table's point_scale_m when it came from a C3D file, else 1 unit.
  double residual_resolution_m = 0.0;

  bool IsValid(std::string* error) const;
};

// Writes the table as an Intel, float-storage C3D file with no analog data:
// POINT:USED/SCALE/RATE/DATA_START/FRAMES/UNITS/LABELS (LABELS2, ... beyond
// 255 markers), and for more than 65535 frames POINT:FRAMES = 65535 with
// POINT:LONG_FRAMES and TRIAL:ACTUAL_START_FIELD/ACTUAL_END_FIELD. Invalid
// samples are written as (0, 0, 0) with residual word -1. The file appears
// atomically (temporary + rename). Throws InputError when the table is
// inconsistent, a label is longer than 255 characters, or the file cannot be
// written.
void WriteC3d(const std::string& path, const MarkerTable& table,
              const C3dWriteOptions& options = C3dWriteOptions());

// The bytes WriteC3d would write.
std::vector<std::uint8_t> EncodeC3d(const MarkerTable& table,
                                    const C3dWriteOptions& options = C3dWriteOptions());

}  // namespace ccsrm::mocap
