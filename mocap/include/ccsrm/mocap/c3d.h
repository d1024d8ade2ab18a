#pragma once
// C3D marker files (https://www.c3d.org): reader and writer.
//
// The reader decodes the three processor formats (Intel: little-endian IEEE;
// DEC: little-endian words, VAX F-floats; MIPS/SGI: big-endian IEEE), integer
// and float storage, and the residual word of every point (negative = the
// point was not seen → NaN position). ReadC3dRecording also decodes the
// analog channels (C3dAnalog); ReadC3d skips them. Every read
// is bounds-checked: a malformed file throws ccsrm::InputError whose one-line
// message names the file, the byte offset and what was expected. A file that
// contradicts itself (a parameter block count, a frame count larger than the
// data) is read as far as it really goes, with a warning in
// MarkerTable::warnings (mocap/README.md lists the cases).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/common/output_policy.h"
#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::mocap {

// The ANALOG section of a C3D file: channels sampled `samples_per_frame`
// times per point frame, in the units the file names (ANALOG:UNITS).
struct C3dAnalog {
  std::vector<std::string> labels;  // ANALOG:LABELS, one per channel
  std::vector<std::string> units;   // ANALOG:UNITS ("" where the file gives none)
  double rate_hz = 0.0;             // ANALOG:RATE = point rate × samples_per_frame
  std::size_t samples_per_frame = 0;
  std::size_t sample_count = 0;  // frames × samples_per_frame
  // Scaled values, row-major [sample * channels() + channel]:
  // (raw − OFFSET[c]) × SCALE[c] × GEN_SCALE (C3D user guide, "Analog data
  // scaling"), for integer and float storage alike. NaN where a float sample
  // is not finite (counted in the table's warnings).
  std::vector<double> values;
  // How the file stored them (kept for `mocap inspect`).
  std::vector<double> scale;       // ANALOG:SCALE per channel (1 when missing)
  std::vector<double> offset;      // ANALOG:OFFSET per channel (0 when missing)
  double gen_scale = 1.0;          // ANALOG:GEN_SCALE (1 when missing)
  bool unsigned_integers = false;  // ANALOG:FORMAT = "UNSIGNED" (integer files)

  std::size_t channels() const { return labels.size(); }
  // Requires sample < sample_count and channel < channels() (checked, aborts).
  double value(std::size_t sample, std::size_t channel) const;
  // Time of analog sample `sample` from the first frame's start, seconds.
  double time_s(std::size_t sample) const { return static_cast<double>(sample) / rate_hz; }
  std::optional<std::size_t> index_of(const std::string& label) const;
  // True when the vectors have the sizes the counts imply (reason in *error).
  bool IsConsistent(std::string* error) const;
};

// A whole C3D file: its points and its analog channels (no channels when the
// file has none). Warnings about either are in markers.warnings.
struct C3dRecording {
  MarkerTable markers;
  C3dAnalog analog;
};

// Reads the 3D points of a C3D file. Throws InputError when the file cannot
// be read or is not a well-formed C3D file.
MarkerTable ReadC3d(const std::string& path);

// Same, from bytes in memory; name_for_errors stands for the file name in
// error messages.
MarkerTable ReadC3dFromMemory(const std::vector<std::uint8_t>& bytes,
                              const std::string& name_for_errors);

// Reads points and analog channels. Beyond ReadC3d's checks, throws
// InputError on ANALOG parameters that cannot be applied (SCALE or OFFSET
// with fewer values than ANALOG:USED, an unknown ANALOG:FORMAT); a missing
// OFFSET, SCALE or GEN_SCALE is taken as 0, 1, 1 and channels without a
// label are named analog_<n>, with a warning.
C3dRecording ReadC3dRecording(const std::string& path);
C3dRecording ReadC3dRecordingFromMemory(const std::vector<std::uint8_t>& bytes,
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

// A C3D file as an output of the one output policy (common/output_policy.h):
// an earlier C3D file (its header's key byte) is replaced, anything else
// refused. mocap export, cameras reconstruct, ccsrm.write_c3d.
OutputKind C3dFileOutput();

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

// The same with analog channels: ANALOG:USED/RATE/LABELS/UNITS and
// SCALE = 1, OFFSET = 0, GEN_SCALE = 1, the scaled values stored as floats
// after each frame's points. Requires analog.sample_count = frames ×
// samples_per_frame and rate_hz = the table's rate × samples_per_frame
// (throws InputError otherwise); no channels writes what WriteC3d writes.
void WriteC3d(const std::string& path, const C3dRecording& recording,
              const C3dWriteOptions& options = C3dWriteOptions());
std::vector<std::uint8_t> EncodeC3d(const C3dRecording& recording,
                                    const C3dWriteOptions& options = C3dWriteOptions());

}  // namespace ccsrm::mocap
