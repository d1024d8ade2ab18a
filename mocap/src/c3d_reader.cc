// C3D reader. Layout of the file (all offsets in bytes, blocks of 512 bytes):
//
//   header (block 1), 16-bit words in the processor's format:
//     byte 0: first block of the parameter section; byte 1: 0x50
//     word 2: number of 3D points        word 3: analog values per 3D frame
//     word 4: first frame number         word 5: last frame number (16-bit)
//     words 7-8: POINT:SCALE (float)     word 9: first block of the data
//     word 10: analog samples per frame  words 11-12: POINT:RATE (float)
//   parameter section: 4 bytes (reserved, reserved, number of blocks,
//     processor type 83 + {1 Intel, 2 DEC, 3 MIPS}), then records:
//       int8  name length (negative = locked), int8 group id (negative =
//       group, positive = parameter of group -id), the name, int16 offset to
//       the next record counted from this word (0 = last record);
//       group: uint8 description length, description;
//       parameter: int8 type (-1 char, 1 byte, 2 int16, 4 float), uint8
//       number of dimensions, the dimensions (uint8 each), the data
//       (column-major, first dimension fastest), description.
//   data section (block POINT:DATA_START): per frame, per point x, y, z and a
//     residual word (int16, or float when POINT:SCALE < 0), then the analog
//     samples of that frame (same storage), sample by sample, each sample
//     holding every channel (ANALOG:USED values).
//
// Every read is checked against the end of the buffer (and, for parameters,
// against the data start) before it happens. Counts the file can get wrong
// (the parameter block count, the frame count) are checked against what its
// bytes hold: the reader reads what is there and warns (mocap/README.md).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "c3d_format.h"
#include "ccsrm/common/error.h"
#include "ccsrm/mocap/c3d.h"
#include "utf8.h"

namespace ccsrm::mocap {
namespace {

using internal::C3dProcessor;
using internal::kC3dBlockSize;

std::string Hex(unsigned value) {
  std::ostringstream out;
  out << "0x" << std::hex << std::uppercase << value;
  return out.str();
}

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Trailing spaces and NULs are padding in C3D strings.
std::string TrimRight(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  return s;
}

// Bounds-checked access to the file's bytes in one processor's format.
class ByteReader {
 public:
  ByteReader(const std::vector<std::uint8_t>& bytes, std::string name)
      : bytes_(bytes), name_(std::move(name)) {}

  std::uint64_t size() const { return bytes_.size(); }
  const std::string& name() const { return name_; }
  void set_processor(C3dProcessor processor) { processor_ = processor; }

  [[noreturn]] void Fail(std::uint64_t offset, const std::string& what) const {
    ThrowInputError(name_, "byte " + std::to_string(offset), what);
  }

  // Throws unless bytes [offset, offset + count) lie before `limit` (itself at
  // most the file size); `what` names what was being read, `limit_is` what
  // lies at `limit` ("the file ends at byte 900").
  void Need(std::uint64_t offset, std::uint64_t count, std::uint64_t limit, const std::string& what,
            const std::string& limit_is) const {
    if (offset > limit || count > limit - offset) {
      Fail(offset,
           "expected " + std::to_string(count) + " byte(s) of " + what + ", but " + limit_is);
    }
  }
  void Need(std::uint64_t offset, std::uint64_t count, const std::string& what) const {
    Need(offset, count, size(), what, FileEnd());
  }
  std::string FileEnd() const { return "the file ends at byte " + std::to_string(size()); }

  std::uint8_t U8(std::uint64_t offset, const std::string& what) const {
    Need(offset, 1, what);
    return bytes_[offset];
  }
  std::int8_t I8(std::uint64_t offset, const std::string& what) const {
    return static_cast<std::int8_t>(U8(offset, what));
  }
  std::uint16_t U16(std::uint64_t offset, const std::string& what) const {
    Need(offset, 2, what);
    return internal::DecodeU16(&bytes_[offset], processor_);
  }
  std::int16_t I16(std::uint64_t offset, const std::string& what) const {
    return static_cast<std::int16_t>(U16(offset, what));
  }
  float F32(std::uint64_t offset, const std::string& what) const {
    Need(offset, 4, what);
    return internal::DecodeF32(&bytes_[offset], processor_);
  }
  // Unchecked variants for the data section, whose extent is checked once.
  std::int16_t RawI16(std::uint64_t offset) const {
    return internal::DecodeI16(&bytes_[offset], processor_);
  }
  std::uint16_t RawU16(std::uint64_t offset) const {
    return internal::DecodeU16(&bytes_[offset], processor_);
  }
  float RawF32(std::uint64_t offset) const {
    return internal::DecodeF32(&bytes_[offset], processor_);
  }
  std::string Chars(std::uint64_t offset, std::uint64_t count) const {
    return std::string(reinterpret_cast<const char*>(&bytes_[offset]), count);
  }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::string name_;
  C3dProcessor processor_ = C3dProcessor::kIntel;
};

struct Parameter {
  std::string group;  // upper case
  std::string name;   // upper case
  int type = 0;       // -1 char, 1 byte, 2 int16, 4 float
  std::vector<std::uint64_t> dims;
  std::uint64_t count = 1;  // product of dims (1 for a scalar)
  std::uint64_t data_offset = 0;
  std::uint64_t record_offset = 0;

  std::string full_name() const { return group + ":" + name; }
};

// The bytes the parameter records may occupy: from `begin` (after the
// section's 4-byte header) to `end`, where `end_is` says what lies
// ("the data section starts at byte 5120 (block 11, header word 9)").
struct SectionBounds {
  std::uint64_t first_block = 0;      // header byte 0
  std::uint64_t declared_blocks = 0;  // byte 2 of the section: a hint only
  std::uint64_t begin = 0;
  std::uint64_t end = 0;
  std::string end_is;
};

class ParameterSection {
 public:
  ParameterSection(const ByteReader& in, SectionBounds bounds)
      : in_(in), bounds_(std::move(bounds)) {
    Parse(bounds_);
  }

  const SectionBounds& bounds() const { return bounds_; }

  // One past the last byte the records use (names, offsets, types,
  // dimensions and data; descriptions are not read).
  std::uint64_t records_end() const { return records_end_; }

  const Parameter* Find(const std::string& group, const std::string& name) const {
    for (const Parameter& p : parameters_) {
      if (p.group == group && p.name == name) return &p;
    }
    return nullptr;
  }

  // Value `index` of a numeric parameter; int16 values are read as unsigned
  // when `unsigned_int` (C3D counts and block numbers are unsigned words).
  double Number(const Parameter& p, std::uint64_t index, bool unsigned_int) const {
    if (p.type == -1) {
      in_.Fail(p.record_offset, p.full_name() + ": expected a number, found a character parameter");
    }
    if (index >= p.count) {
      in_.Fail(p.record_offset, p.full_name() + ": expected at least " + std::to_string(index + 1) +
                                    " value(s), found " + std::to_string(p.count));
    }
    const std::uint64_t at = p.data_offset + index * static_cast<std::uint64_t>(std::abs(p.type));
    const std::string what = "parameter " + p.full_name();
    switch (p.type) {
      case 1:
        return unsigned_int ? in_.U8(at, what) : in_.I8(at, what);
      case 2:
        return unsigned_int ? in_.U16(at, what) : in_.I16(at, what);
      default:
        return in_.F32(at, what);
    }
  }

  // A character parameter as strings of dims[0] characters each, trailing
  // padding removed.
  std::vector<std::string> Strings(const Parameter& p) const {
    if (p.type != -1) {
      in_.Fail(p.record_offset, p.full_name() + ": expected a character parameter");
    }
    std::vector<std::string> out;
    if (p.count == 0) return out;
    const std::uint64_t length = p.dims.empty() ? 1 : p.dims[0];
    const std::uint64_t n = p.count / length;
    out.reserve(n);
    for (std::uint64_t i = 0; i < n; ++i) {
      out.push_back(TrimRight(in_.Chars(p.data_offset + i * length, length)));
    }
    return out;
  }

 private:
  void Parse(const SectionBounds& bounds) {
    const std::uint64_t end = bounds.end;
    auto need = [&](std::uint64_t offset, std::uint64_t count, const std::string& what) {
      in_.Need(offset, count, end, what, bounds.end_is);
      records_end_ = std::max(records_end_, offset + count);
    };
    struct RawParameter {
      int group_id;
      Parameter parameter;
    };
    std::vector<RawParameter> raw;
    std::vector<std::pair<int, std::string>> groups;
    std::uint64_t at = bounds.begin;
    records_end_ = bounds.begin;
    // Each record moves `at` strictly forward (the offset is unsigned and
    // non-zero), so the loop ends.
    while (at < end) {
      need(at, 2, "a parameter record header (name length, group id)");
      const int name_length = std::abs(static_cast<int>(in_.I8(at, "name length")));
      const int id = in_.I8(at + 1, "group id");
      if (name_length == 0 || id == 0) break;  // end of the parameter list
      const std::uint64_t name_at = at + 2;
      need(name_at, static_cast<std::uint64_t>(name_length) + 2,
           "a parameter name and next-record offset");
      // Names are ASCII by the format; a damaged file's bytes are escaped so
      // that a message naming one stays one line.
      const std::string name = internal::Printable(Upper(in_.Chars(name_at, name_length)));
      const std::uint64_t offset_at = name_at + name_length;
      const std::uint16_t next = in_.U16(offset_at, "next-record offset");
      if (id < 0) {
        groups.emplace_back(-id, name);
      } else {
        RawParameter r{id, Parameter()};
        Parameter& p = r.parameter;
        p.name = name;
        p.record_offset = at;
        need(offset_at + 2, 2, "the type and dimension count of parameter " + name);
        p.type = in_.I8(offset_at + 2, "parameter type");
        if (p.type != -1 && p.type != 1 && p.type != 2 && p.type != 4) {
          in_.Fail(offset_at + 2, "parameter " + name +
                                      ": expected a type of -1, 1, 2 or 4, found " +
                                      std::to_string(p.type));
        }
        const int dim_count = in_.U8(offset_at + 3, "dimension count");
        const std::uint64_t dims_at = offset_at + 4;
        need(dims_at, dim_count, "the dimensions of parameter " + name);
        const std::uint64_t limit = end - bounds.begin;  // no parameter can hold more values
        for (int d = 0; d < dim_count; ++d) {
          const std::uint64_t dim = in_.U8(dims_at + d, "a dimension");
          p.dims.push_back(dim);
          p.count *= dim;
          if (p.count > limit) break;  // reported just below, without overflow
        }
        p.data_offset = dims_at + dim_count;
        const std::uint64_t bytes = p.count * static_cast<std::uint64_t>(std::abs(p.type));
        std::string shape;
        for (std::size_t d = 0; d < p.dims.size(); ++d) {
          shape += (d == 0 ? "" : "x") + std::to_string(p.dims[d]);
        }
        need(p.data_offset, bytes,
             "data of parameter " + name + " (dimensions " + (shape.empty() ? "scalar" : shape) +
                 ")");
        raw.push_back(std::move(r));
      }
      if (next == 0) break;  // last record
      at = offset_at + next;
    }
    for (RawParameter& r : raw) {
      for (const auto& [group_id, group_name] : groups) {
        if (group_id == r.group_id) {
          r.parameter.group = group_name;
          break;
        }
      }
      // A parameter of an undeclared group cannot be looked up; keep the
      // first of duplicated names (Find returns the first).
      if (!r.parameter.group.empty()) parameters_.push_back(std::move(r.parameter));
    }
  }

  const ByteReader& in_;
  SectionBounds bounds_;
  std::vector<Parameter> parameters_;
  std::uint64_t records_end_ = 0;
};

// POINT:UNITS in lower case without spaces ("MM " → "mm").
std::string NormalizeUnit(const std::string& units) {
  std::string u;
  for (char c : units) {
    if (c != ' ') u += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return u;
}

// Metres per unit of a normalized POINT:UNITS.
std::optional<double> MetresPerUnit(const std::string& u) {
  if (u == "mm") return 1e-3;
  if (u == "cm") return 1e-2;
  if (u == "m") return 1.0;
  return std::nullopt;
}

// What the data section holds and how to decode it.
struct Layout {
  std::uint64_t points = 0;
  bool float_storage = false;         // POINT:SCALE < 0
  double scale = 0.0;                 // |POINT:SCALE| in file units
  double rate_hz = 0.0;               // POINT:RATE
  std::uint64_t data_offset = 0;      // byte where frame 0 starts
  std::uint64_t analog_channels = 0;  // ANALOG:USED
  std::uint64_t analog_samples_per_frame = 0;
  double analog_rate_hz = 0.0;
  std::uint64_t analog_values_per_frame = 0;  // channels × samples per frame
  std::uint64_t frame_bytes = 0;              // points and analog values of one frame
  std::uint64_t frames = 0;
  std::int64_t first_frame = 1;
  double metres_per_unit = 1e-3;
  std::string units;  // "mm", "cm" or "m"
};

// A frame count or frame number stored as a float must be a whole number in
// [0, 2^32).
std::uint64_t WholeCount(const ByteReader& in, const Parameter& p, double value) {
  if (!std::isfinite(value) || value < 0 || value >= 4294967296.0 || value != std::floor(value)) {
    in.Fail(p.record_offset, p.full_name() + ": expected a whole non-negative frame count, found " +
                                 std::to_string(value));
  }
  return static_cast<std::uint64_t>(value);
}

// TRIAL:ACTUAL_*_FIELD: two unsigned words, least significant first.
std::uint64_t TrialField(const ParameterSection& params, const ByteReader& in, const Parameter& p) {
  if (p.type == 4 && p.count == 1) return WholeCount(in, p, params.Number(p, 0, false));
  const auto low = static_cast<std::uint64_t>(params.Number(p, 0, true));
  const auto high = p.count >= 2 ? static_cast<std::uint64_t>(params.Number(p, 1, true)) : 0;
  if (p.type == 4) return WholeCount(in, p, static_cast<double>(low + high * 65536));
  return low + high * 65536;
}

std::uint64_t CountParameter(const ParameterSection& params, const ByteReader& in,
                             const Parameter& p) {
  if (p.type == 4) return WholeCount(in, p, params.Number(p, 0, false));
  return static_cast<std::uint64_t>(params.Number(p, 0, true));
}

// Stage 3: the shape of the analog values interleaved after the points of
// each frame.
void ReadAnalogLayout(const ParameterSection& params, const ByteReader& in, Layout* layout,
                      std::vector<std::string>* warnings) {
  const std::uint16_t header_values_per_frame = in.U16(4, "header word 3 (analog values)");
  const std::uint16_t header_samples = in.U16(18, "header word 10 (analog samples per frame)");
  std::uint64_t channels = 0;
  if (const Parameter* used = params.Find("ANALOG", "USED")) {
    channels = CountParameter(params, in, *used);
  } else if (header_samples > 0) {
    channels = header_values_per_frame / header_samples;
  }
  if (channels == 0) {
    layout->analog_values_per_frame = 0;
    return;
  }
  std::uint64_t samples = 0;
  const Parameter* analog_rate = params.Find("ANALOG", "RATE");
  if (analog_rate != nullptr) {
    const double ratio = params.Number(*analog_rate, 0, false) / layout->rate_hz;
    const double whole = std::round(ratio);
    if (!std::isfinite(ratio) || whole < 1 || whole > 65535 ||
        std::abs(ratio - whole) > 1e-3 * whole) {
      in.Fail(analog_rate->record_offset,
              "ANALOG:RATE / POINT:RATE = " + std::to_string(ratio) +
                  ": expected a whole number of analog samples per frame (1 to 65535)");
    }
    samples = static_cast<std::uint64_t>(whole);
    if (header_samples > 0 && header_samples != samples) {
      warnings->push_back("header word 10 gives " + std::to_string(header_samples) +
                          " analog samples per frame, ANALOG:RATE / POINT:RATE " +
                          std::to_string(samples) + "; used the parameters");
    }
  } else if (header_samples > 0) {
    samples = header_samples;
  } else {
    in.Fail(18, "expected ANALOG:RATE or header word 10 (analog samples per frame) for " +
                    std::to_string(channels) + " analog channel(s)");
  }
  layout->analog_channels = channels;
  layout->analog_samples_per_frame = samples;
  layout->analog_rate_hz = layout->rate_hz * static_cast<double>(samples);
  layout->analog_values_per_frame = channels * samples;
  if (header_values_per_frame != layout->analog_values_per_frame) {
    warnings->push_back("header word 3 gives " + std::to_string(header_values_per_frame) +
                        " analog values per frame, the parameters " +
                        std::to_string(layout->analog_values_per_frame) + "; used the parameters");
  }
}

// The frames to read when the frame count cannot be trusted: the complete
// frames of the data section, but in a file of whole 512-byte blocks none
// that starts in the last block. Writers pad that block after the last frame
// with zeros or whatever their buffer held (Eb015pi.c3d of the c3d.org
// samples holds leftover text there), which would read as markers seen at
// made-up positions; a recording cut at a block boundary loses at most the
// frames of that block. `*last_block_dropped` says whether any was dropped.
std::uint64_t FramesHeld(const ByteReader& in, const Layout& layout, bool* last_block_dropped) {
  const std::uint64_t complete =
      layout.frame_bytes == 0 ? 0 : (in.size() - layout.data_offset) / layout.frame_bytes;
  std::uint64_t held = complete;
  if (in.size() % kC3dBlockSize == 0 && complete > 0) {
    const std::uint64_t last_block_at = in.size() - kC3dBlockSize;
    const std::uint64_t before =
        last_block_at <= layout.data_offset
            ? 0
            : (last_block_at - layout.data_offset + layout.frame_bytes - 1) / layout.frame_bytes;
    held = std::min(complete, before);
  }
  *last_block_dropped = held < complete;
  return held;
}

// Stage 4: the frame count and first frame number, checked against the data
// section's size. A count larger than the data holds (a recording cut short)
// gives the complete frames there are, with a warning, as other readers do.
void ReadFrameCount(const ParameterSection& params, const ByteReader& in, Layout* layout,
                    std::vector<std::string>* warnings) {
  const std::uint16_t header_first = in.U16(6, "header word 4 (first frame)");
  const std::uint16_t header_last = in.U16(8, "header word 5 (last frame)");
  const std::uint64_t room = in.size() - layout->data_offset;
  const std::uint64_t frames_that_fit = layout->frame_bytes == 0 ? 0 : room / layout->frame_bytes;

  const Parameter* trial_start = params.Find("TRIAL", "ACTUAL_START_FIELD");
  const Parameter* trial_end = params.Find("TRIAL", "ACTUAL_END_FIELD");
  const bool have_trial = trial_start != nullptr && trial_end != nullptr;
  layout->first_frame =
      have_trial ? static_cast<std::int64_t>(TrialField(params, in, *trial_start)) : header_first;

  std::uint64_t frames = 0;
  std::string count_from = "POINT:FRAMES";
  if (const Parameter* p = params.Find("POINT", "FRAMES")) {
    frames = CountParameter(params, in, *p);
  } else {
    frames = header_last >= header_first ? header_last - header_first + 1u : 0u;
    count_from = "header words 4-5";
    warnings->push_back("POINT:FRAMES is missing; the frame count comes from the header");
  }
  // POINT:FRAMES is a 16-bit word in most files: 65535 means "look elsewhere"
  // (c3d.org, "Reading the frame count").
  if (frames == 65535) {
    if (const Parameter* long_frames = params.Find("POINT", "LONG_FRAMES")) {
      frames = long_frames->type == 4
                   ? WholeCount(in, *long_frames, params.Number(*long_frames, 0, false))
                   : TrialField(params, in, *long_frames);
      count_from = "POINT:LONG_FRAMES";
    } else if (have_trial) {
      const std::uint64_t last = TrialField(params, in, *trial_end);
      const auto first = static_cast<std::uint64_t>(layout->first_frame);
      if (last < first) {
        in.Fail(trial_end->record_offset, "TRIAL:ACTUAL_END_FIELD (" + std::to_string(last) +
                                              ") precedes TRIAL:ACTUAL_START_FIELD (" +
                                              std::to_string(first) + ")");
      }
      frames = last - first + 1;
      count_from = "TRIAL:ACTUAL_START_FIELD/ACTUAL_END_FIELD";
    } else if (frames_that_fit > 65535) {
      bool dropped = false;
      frames = FramesHeld(in, *layout, &dropped);
      warnings->push_back("POINT:FRAMES is 65535 with no LONG_FRAMES or TRIAL parameters; the " +
                          std::to_string(frames) + " frames the data section holds were read" +
                          (dropped ? " (not the last block, which may be padding)" : ""));
    }
  }
  if (layout->frame_bytes > 0 && frames > frames_that_fit) {
    bool dropped = false;
    const std::uint64_t held = FramesHeld(in, *layout, &dropped);
    const std::string what = std::to_string(frames) + " frames of " +
                             std::to_string(layout->frame_bytes) + " bytes from byte " +
                             std::to_string(layout->data_offset) + " (" + count_from +
                             "), but the file (" + std::to_string(in.size()) + " bytes) holds ";
    const std::string where = dropped ? " before its last block (which may be padding)" : "";
    if (held == 0) in.Fail(layout->data_offset, "expected " + what + "no complete frame" + where);
    warnings->push_back("the data section should hold " + what + "only " + std::to_string(held) +
                        " complete frame(s)" + where + "; read those (a recording cut short?)");
    frames = held;
  }
  layout->frames = frames;
}

// The names of the `points` points (POINT:USED, which sets the data layout):
// POINT:LABELS, then LABELS2, LABELS3, ... (255 names each) until there are
// enough. Names beyond POINT:USED have no data and are dropped silently:
// writers allocate spare names (the c3d.org samples hold 48 names for 26
// points, 75 for 36). Points beyond the names are named point_<n>, with a
// warning.
std::vector<std::string> ReadLabels(const ParameterSection& params, std::uint64_t points,
                                    std::vector<std::string>* warnings) {
  std::vector<std::string> labels;
  for (int k = 1; labels.size() < points; ++k) {
    const std::string name = k == 1 ? "LABELS" : "LABELS" + std::to_string(k);
    const Parameter* p = params.Find("POINT", name);
    if (p == nullptr) break;
    for (std::string& s : params.Strings(*p)) labels.push_back(std::move(s));
  }
  labels.resize(points);
  std::size_t unnamed = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    labels[i] = internal::AsUtf8(labels[i]);
    if (labels[i].empty()) {
      labels[i] = "point_" + std::to_string(i + 1);
      ++unnamed;
    }
  }
  if (unnamed > 0) {
    warnings->push_back(std::to_string(unnamed) +
                        " point(s) without a label in POINT:LABELS were named point_<n>");
  }
  return labels;
}

// Stage 1: the header key, the processor type and the parameter records.
ParameterSection ReadParameterSection(const std::vector<std::uint8_t>& bytes, ByteReader* in,
                                      MarkerTable* table) {
  if (in->size() < kC3dBlockSize) {
    in->Fail(in->size(), "expected a 512-byte C3D header, but the file ends at byte " +
                             std::to_string(in->size()));
  }
  if (bytes[1] != internal::kC3dMagic) {
    in->Fail(1, "expected 0x50 (the C3D key), found " + Hex(bytes[1]) + ": not a C3D file");
  }
  const std::uint8_t parameter_block = bytes[0];
  if (parameter_block < 2) {
    in->Fail(0, "expected the parameter section's block number (>= 2), found " +
                    std::to_string(parameter_block));
  }
  const std::uint64_t parameters_at = (parameter_block - 1u) * kC3dBlockSize;
  if (parameters_at + 4 > in->size()) {
    in->Fail(0, "expected the parameter section at block " + std::to_string(parameter_block) +
                    " (byte " + std::to_string(parameters_at) + "), past the end of the file (" +
                    std::to_string(in->size()) + " bytes)");
  }
  const std::uint8_t processor_code = bytes[parameters_at + 3];
  switch (processor_code) {
    case internal::kProcessorIntel:
      in->set_processor(C3dProcessor::kIntel);
      table->processor = "intel";
      break;
    case internal::kProcessorDec:
      in->set_processor(C3dProcessor::kDec);
      table->processor = "dec";
      break;
    case internal::kProcessorMips:
      in->set_processor(C3dProcessor::kMips);
      table->processor = "mips";
      break;
    default:
      in->Fail(parameters_at + 3,
               "expected a processor type of 84 (Intel), 85 (DEC) or 86 "
               "(MIPS), found " +
                   std::to_string(processor_code));
  }
  // The records are bounded by what the file holds, not by the block count
  // the section declares in its byte 2: some writers declare fewer blocks
  // than their parameters fill, and established readers follow the chain of
  // records up to the data. The bound is the data start of header word 9
  // when it lies after the section's first block and within the file, else
  // the end of the file; CheckParameterExtent compares the three once
  // POINT:DATA_START is known.
  SectionBounds bounds;
  bounds.first_block = parameter_block;
  bounds.declared_blocks = bytes[parameters_at + 2];
  bounds.begin = parameters_at + 4;
  const std::uint64_t data_block = in->U16(16, "header word 9 (data start block)");
  const std::uint64_t data_at = data_block == 0 ? 0 : (data_block - 1) * kC3dBlockSize;
  if (data_block > parameter_block && data_at <= in->size()) {
    bounds.end = data_at;
    bounds.end_is = "the data section starts at byte " + std::to_string(data_at) + " (block " +
                    std::to_string(data_block) + ", header word 9)";
  } else {
    bounds.end = in->size();
    bounds.end_is = in->FileEnd();
  }
  return ParameterSection(*in, std::move(bounds));
}

// The parameter records must end before the data starts (data_block, read
// at byte data_start_at); the block count the section declares is a hint,
// and a count that disagrees with the records or the data start is
// reported, not refused.
void CheckParameterExtent(const ParameterSection& params, const ByteReader& in,
                          std::uint64_t data_block, std::uint64_t data_start_at,
                          std::vector<std::string>* warnings) {
  const std::uint64_t data_at = (data_block - 1) * kC3dBlockSize;
  const std::uint64_t records_end = params.records_end();
  if (records_end > data_at) {
    in.Fail(data_start_at,
            "POINT:DATA_START: expected the data section after the parameter "
            "records, which end at byte " +
                std::to_string(records_end) + ", found block " + std::to_string(data_block) +
                " (byte " + std::to_string(data_at) + ")");
  }
  const SectionBounds& b = params.bounds();
  const std::uint64_t section_at = (b.first_block - 1) * kC3dBlockSize;
  const std::uint64_t declared_end = section_at + b.declared_blocks * kC3dBlockSize;
  const std::string declared = "the parameter section (byte " + std::to_string(section_at + 2) +
                               ") declares " + std::to_string(b.declared_blocks) + " block(s)";
  if (declared_end < records_end) {
    const std::uint64_t last_block = (records_end - 1) / kC3dBlockSize + 1;
    warnings->push_back(
        declared + ", but its records fill blocks " + std::to_string(b.first_block) + "-" +
        std::to_string(last_block) + " (to byte " + std::to_string(records_end) +
        "); read them all (the data starts at block " + std::to_string(data_block) + ")");
  } else if (declared_end > data_at) {
    warnings->push_back(declared + ", to byte " + std::to_string(declared_end) +
                        ", past the data start (block " + std::to_string(data_block) + ", byte " +
                        std::to_string(data_at) + "); its records end at byte " +
                        std::to_string(records_end) + ", before the data");
  }
}

// Stage 2: points, storage, scale, rate, units and the data start, from the
// POINT parameters (the header words only where a parameter is missing).
Layout ReadPointLayout(const ParameterSection& params, const ByteReader& in,
                       std::vector<std::string>* warnings) {
  Layout layout;
  std::uint64_t points_at = 2;
  layout.points = in.U16(2, "header word 2 (number of points)");
  if (const Parameter* p = params.Find("POINT", "USED")) {
    const std::uint64_t header_points = layout.points;
    layout.points = CountParameter(params, in, *p);
    points_at = p->record_offset;
    if (layout.points != header_points) {
      warnings->push_back("header word 2 gives " + std::to_string(header_points) +
                          " points, POINT:USED " + std::to_string(layout.points) +
                          "; used POINT:USED");
    }
  }
  if (layout.points > 65535) {
    in.Fail(points_at,
            "POINT:USED: expected at most 65535 points, found " + std::to_string(layout.points));
  }

  std::uint64_t scale_at = 12;
  double scale = in.F32(12, "header words 7-8 (scale)");
  if (const Parameter* p = params.Find("POINT", "SCALE")) {
    scale = params.Number(*p, 0, false);
    scale_at = p->record_offset;
  }
  if (!std::isfinite(scale) || scale == 0.0) {
    in.Fail(scale_at,
            "POINT:SCALE: expected a finite non-zero scale, found " + std::to_string(scale));
  }
  layout.float_storage = scale < 0;  // a negative scale means float storage
  layout.scale = std::abs(scale);

  std::uint64_t rate_at = 20;
  double rate = in.F32(20, "header words 11-12 (frame rate)");
  if (const Parameter* p = params.Find("POINT", "RATE")) {
    rate = params.Number(*p, 0, false);
    rate_at = p->record_offset;
  }
  if (!std::isfinite(rate) || rate <= 0.0) {
    in.Fail(rate_at, "POINT:RATE: expected a positive frame rate, found " + std::to_string(rate));
  }
  layout.rate_hz = rate;

  std::uint64_t data_start_at = 16;
  const std::uint64_t header_data_block = in.U16(16, "header word 9 (data start block)");
  std::uint64_t data_block = header_data_block;
  if (const Parameter* p = params.Find("POINT", "DATA_START")) {
    data_block = CountParameter(params, in, *p);
    data_start_at = p->record_offset;
    const bool header_usable =
        header_data_block >= 2 && (header_data_block - 1) * kC3dBlockSize <= in.size();
    if (data_block < 2 && header_usable) {
      // A field quirk: POINT:DATA_START left at 0 while the header's word is
      // right. Established readers (ezc3d, btk) take the header's word.
      warnings->push_back("POINT:DATA_START is " + std::to_string(data_block) +
                          ", not a block number; used header word 9 (block " +
                          std::to_string(header_data_block) + ")");
      data_block = header_data_block;
      data_start_at = 16;
    } else if (data_block != header_data_block) {
      warnings->push_back("header word 9 gives the data start as block " +
                          std::to_string(header_data_block) + ", POINT:DATA_START as block " +
                          std::to_string(data_block) + "; used POINT:DATA_START");
    }
  }
  if (data_block < 2) {
    in.Fail(data_start_at,
            "POINT:DATA_START: expected a block number >= 2, found " + std::to_string(data_block));
  }
  layout.data_offset = (data_block - 1) * kC3dBlockSize;
  if (layout.data_offset > in.size()) {
    in.Fail(data_start_at,
            "POINT:DATA_START: expected the data section at block " + std::to_string(data_block) +
                " (byte " + std::to_string(layout.data_offset) + "), past the end of the file (" +
                std::to_string(in.size()) + " bytes)");
  }
  CheckParameterExtent(params, in, data_block, data_start_at, warnings);

  if (const Parameter* p = params.Find("POINT", "UNITS")) {
    const std::vector<std::string> units = params.Strings(*p);
    const std::string unit = units.empty() ? std::string() : NormalizeUnit(units[0]);
    const std::optional<double> metres = MetresPerUnit(unit);
    if (!metres) {
      in.Fail(p->record_offset,
              "POINT:UNITS: expected \"mm\", \"cm\" or \"m\", found \"" + unit + "\"");
    }
    layout.metres_per_unit = *metres;
    layout.units = unit;
  } else {
    layout.units = "mm";
    warnings->push_back("POINT:UNITS is missing; assumed mm");
  }
  return layout;
}

// "+Z" in POINT:Y_SCREEN (the axis drawn upwards) → "z"; "" otherwise.
std::string UpAxis(const ParameterSection& params) {
  const Parameter* p = params.Find("POINT", "Y_SCREEN");
  if (p == nullptr || p->type != -1) return std::string();
  const std::vector<std::string> axis = params.Strings(*p);
  const std::string a = axis.empty() ? std::string() : Upper(axis[0]);
  if (a != "+X" && a != "+Y" && a != "+Z") return std::string();
  return std::string(1, static_cast<char>(std::tolower(static_cast<unsigned char>(a[1]))));
}

// Stage 5: the points of every frame. The caller has checked that
// frames × frame_bytes bytes follow data_offset, so the reads are unchecked.
void DecodePoints(const ByteReader& in, const Layout& layout, MarkerTable* table) {
  const double to_m = layout.metres_per_unit;
  const double coordinate_scale = layout.float_storage ? to_m : layout.scale * to_m;
  const double residual_scale = layout.scale * to_m;
  const std::uint64_t point_bytes = layout.float_storage ? 16 : 8;
  std::size_t non_finite = 0;
  for (std::uint64_t f = 0; f < layout.frames; ++f) {
    const std::uint64_t frame_at = layout.data_offset + f * layout.frame_bytes;
    for (std::uint64_t m = 0; m < layout.points; ++m) {
      const std::uint64_t at = frame_at + m * point_bytes;
      double x = 0, y = 0, z = 0;
      int word = -1;  // the residual word as a 16-bit integer
      if (layout.float_storage) {
        x = in.RawF32(at);
        y = in.RawF32(at + 4);
        z = in.RawF32(at + 8);
        // The 4th float holds the same 16-bit word as integer storage
        // (camera mask << 8 | residual byte), converted to float; NaN and
        // negative values mean "not seen".
        const float w = in.RawF32(at + 12);
        if (w >= 0.0f) word = static_cast<int>(std::min(std::round(w), 32767.0f));
      } else {
        x = in.RawI16(at);
        y = in.RawI16(at + 2);
        z = in.RawI16(at + 4);
        word = in.RawI16(at + 6);
      }
      if (word < 0) continue;  // not seen: NaN position, residual -1
      const Eigen::Vector3d p_m(x * coordinate_scale, y * coordinate_scale, z * coordinate_scale);
      if (!p_m.allFinite()) {
        ++non_finite;
        continue;
      }
      table->set_position(f, m, p_m);
      const std::size_t i = f * table->markers() + m;
      table->residual_m[i] = (word & 0xFF) * residual_scale;                  // low byte × |scale|
      table->camera_mask[i] = static_cast<std::uint8_t>((word >> 8) & 0x7F);  // high byte
    }
  }
  if (non_finite > 0) {
    table->warnings.push_back(std::to_string(non_finite) +
                              " sample(s) with a valid residual word but non-finite coordinates "
                              "were marked not seen");
  }
}

// Up to `count` strings of a character parameter and its continuations
// (NAME, NAME2, NAME3, ... as for POINT:LABELS); fewer when the file holds
// fewer.
std::vector<std::string> ChainedStrings(const ParameterSection& params, const std::string& group,
                                        const std::string& name, std::uint64_t count) {
  std::vector<std::string> out;
  for (int k = 1; out.size() < count; ++k) {
    const Parameter* p = params.Find(group, k == 1 ? name : name + std::to_string(k));
    if (p == nullptr || p->type != -1) break;
    for (std::string& s : params.Strings(*p)) out.push_back(internal::AsUtf8(std::move(s)));
  }
  if (out.size() > count) out.resize(count);
  return out;
}

// One value per channel of a numeric ANALOG parameter: `fallback` for every
// channel (with a warning) when it is missing; an error when it holds fewer
// values than there are channels, since the channels it misses cannot be
// scaled.
std::vector<double> PerChannel(const ParameterSection& params, const ByteReader& in,
                               const std::string& name, std::uint64_t channels, double fallback,
                               bool unsigned_int, std::vector<std::string>* warnings) {
  const Parameter* p = params.Find("ANALOG", name);
  if (p == nullptr) {
    warnings->push_back("ANALOG:" + name + " is missing; took " + std::to_string(fallback) +
                        " for every channel");
    return std::vector<double>(channels, fallback);
  }
  if (p->count < channels) {
    in.Fail(p->record_offset, "ANALOG:" + name + ": expected " + std::to_string(channels) +
                                  " values (ANALOG:USED), found " + std::to_string(p->count));
  }
  std::vector<double> out(channels);
  for (std::uint64_t c = 0; c < channels; ++c) {
    out[c] = params.Number(*p, c, unsigned_int && p->type == 2);
    if (!std::isfinite(out[c])) {
      in.Fail(p->record_offset, "ANALOG:" + name +
                                    ": expected finite values, found one at channel " +
                                    std::to_string(c + 1));
    }
  }
  return out;
}

// Stage 6: the analog channels: names, units, scaling, and the values of
// every frame. The caller has checked that the frames lie in the file.
void DecodeAnalog(const ParameterSection& params, const ByteReader& in, const Layout& layout,
                  C3dAnalog* analog, std::vector<std::string>* warnings) {
  const std::uint64_t channels = layout.analog_channels;
  analog->samples_per_frame = layout.analog_samples_per_frame;
  analog->rate_hz = layout.analog_rate_hz;
  analog->sample_count = channels == 0 ? 0 : layout.frames * layout.analog_samples_per_frame;
  if (channels == 0) return;

  analog->labels = ChainedStrings(params, "ANALOG", "LABELS", channels);
  std::size_t unnamed = 0;
  analog->labels.resize(channels);
  for (std::size_t c = 0; c < channels; ++c) {
    if (analog->labels[c].empty()) {
      analog->labels[c] = "analog_" + std::to_string(c + 1);
      ++unnamed;
    }
  }
  if (unnamed > 0) {
    warnings->push_back(std::to_string(unnamed) +
                        " analog channel(s) without a label in ANALOG:LABELS were named "
                        "analog_<n>");
  }
  analog->units = ChainedStrings(params, "ANALOG", "UNITS", channels);
  analog->units.resize(channels);

  // ANALOG:FORMAT says whether 16-bit samples are signed (the default) or
  // unsigned (some older A/D boards, with OFFSET near 2^(BITS-1)).
  if (const Parameter* p = params.Find("ANALOG", "FORMAT")) {
    const std::vector<std::string> format = params.Strings(*p);
    const std::string f = format.empty() ? std::string() : Upper(format[0]);
    if (f == "UNSIGNED") {
      analog->unsigned_integers = true;
    } else if (f != "SIGNED" && !f.empty()) {
      in.Fail(p->record_offset,
              "ANALOG:FORMAT: expected \"SIGNED\" or \"UNSIGNED\", found \"" + f + "\"");
    }
  }
  if (analog->unsigned_integers && layout.float_storage) {
    warnings->push_back("ANALOG:FORMAT is UNSIGNED in a float file; ignored (floats carry a sign)");
    analog->unsigned_integers = false;
  }
  analog->scale = PerChannel(params, in, "SCALE", channels, 1.0, false, warnings);
  // OFFSET is an int16 parameter; with unsigned samples its words are
  // unsigned too (an offset of 32768 for a 16-bit unsigned board).
  analog->offset =
      PerChannel(params, in, "OFFSET", channels, 0.0, analog->unsigned_integers, warnings);
  if (const Parameter* p = params.Find("ANALOG", "GEN_SCALE")) {
    analog->gen_scale = params.Number(*p, 0, false);
    if (!std::isfinite(analog->gen_scale)) {
      in.Fail(p->record_offset, "ANALOG:GEN_SCALE: expected a finite scale, found " +
                                    std::to_string(analog->gen_scale));
    }
  } else {
    warnings->push_back("ANALOG:GEN_SCALE is missing; took 1");
    analog->gen_scale = 1.0;
  }

  const std::uint64_t value_bytes = layout.float_storage ? 4 : 2;
  const std::uint64_t points_bytes = layout.points * 4 * value_bytes;
  std::vector<double> factor(channels);
  for (std::uint64_t c = 0; c < channels; ++c) factor[c] = analog->scale[c] * analog->gen_scale;
  analog->values.resize(analog->sample_count * channels);
  std::size_t non_finite = 0;
  std::size_t i = 0;
  for (std::uint64_t f = 0; f < layout.frames; ++f) {
    std::uint64_t at = layout.data_offset + f * layout.frame_bytes + points_bytes;
    for (std::uint64_t s = 0; s < layout.analog_samples_per_frame; ++s) {
      for (std::uint64_t c = 0; c < channels; ++c, ++i, at += value_bytes) {
        double raw = 0.0;
        if (layout.float_storage) {
          raw = in.RawF32(at);
        } else if (analog->unsigned_integers) {
          raw = in.RawU16(at);
        } else {
          raw = in.RawI16(at);
        }
        const double v = (raw - analog->offset[c]) * factor[c];
        if (!std::isfinite(v)) {
          ++non_finite;
          analog->values[i] = std::numeric_limits<double>::quiet_NaN();
        } else {
          analog->values[i] = v;
        }
      }
    }
  }
  if (non_finite > 0) {
    warnings->push_back(std::to_string(non_finite) +
                        " analog sample(s) are not finite numbers; kept as NaN");
  }
}

C3dRecording Read(const std::vector<std::uint8_t>& bytes, const std::string& name_for_errors,
                  bool with_analog) {
  ByteReader in(bytes, name_for_errors);
  C3dRecording recording;
  MarkerTable& table = recording.markers;
  table.format = "c3d";
  const ParameterSection params = ReadParameterSection(bytes, &in, &table);
  Layout layout = ReadPointLayout(params, in, &table.warnings);
  ReadAnalogLayout(params, in, &layout, &table.warnings);
  const std::uint64_t value_bytes = layout.float_storage ? 4 : 2;
  layout.frame_bytes = (layout.points * 4 + layout.analog_values_per_frame) * value_bytes;
  ReadFrameCount(params, in, &layout, &table.warnings);

  table.rate_hz = layout.rate_hz;
  table.first_frame_number = layout.first_frame;
  table.units_in_file = layout.units;
  table.storage = layout.float_storage ? "float" : "integer";
  table.point_scale_m = layout.scale * layout.metres_per_unit;
  table.up_axis = UpAxis(params);
  table.Reset(layout.frames, ReadLabels(params, layout.points, &table.warnings),
              /*with_residual=*/true);
  DecodePoints(in, layout, &table);
  if (with_analog) DecodeAnalog(params, in, layout, &recording.analog, &table.warnings);
  return recording;
}

std::vector<std::uint8_t> ReadBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "", "cannot open for reading");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(stream)),
                                  std::istreambuf_iterator<char>());
  if (stream.bad()) ThrowInputError(path, "", "read failed");
  return bytes;
}

}  // namespace

double C3dAnalog::value(std::size_t sample, std::size_t channel) const {
  CCSRM_CHECK(sample < sample_count && channel < channels());
  return values[sample * channels() + channel];
}

std::optional<std::size_t> C3dAnalog::index_of(const std::string& label) const {
  for (std::size_t c = 0; c < labels.size(); ++c) {
    if (labels[c] == label) return c;
  }
  return std::nullopt;
}

bool C3dAnalog::IsConsistent(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  const std::size_t n = channels();
  if (units.size() != n || scale.size() != n || offset.size() != n) {
    return fail("analog: units, scale and offset need one entry per label (" + std::to_string(n) +
                ")");
  }
  if (values.size() != sample_count * n) {
    return fail("analog: expected " + std::to_string(sample_count * n) + " values, found " +
                std::to_string(values.size()));
  }
  if (n > 0 && (samples_per_frame == 0 || !std::isfinite(rate_hz) || !(rate_hz > 0.0))) {
    return fail("analog: channels need samples_per_frame >= 1 and a positive rate");
  }
  return true;
}

C3dRecording ReadC3dRecordingFromMemory(const std::vector<std::uint8_t>& bytes,
                                        const std::string& name_for_errors) {
  return Read(bytes, name_for_errors, /*with_analog=*/true);
}

C3dRecording ReadC3dRecording(const std::string& path) {
  return ReadC3dRecordingFromMemory(ReadBytes(path), path);
}

MarkerTable ReadC3dFromMemory(const std::vector<std::uint8_t>& bytes,
                              const std::string& name_for_errors) {
  return Read(bytes, name_for_errors, /*with_analog=*/false).markers;
}

MarkerTable ReadC3d(const std::string& path) { return ReadC3dFromMemory(ReadBytes(path), path); }

}  // namespace ccsrm::mocap
