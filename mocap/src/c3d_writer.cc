// C3D writer: Intel processor, float storage, points and analog channels.
// The layout is described at the top of c3d_reader.cc.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "c3d_format.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/mocap/c3d.h"

namespace ccsrm::mocap {
namespace {

using internal::EncodeIntelF32;
using internal::EncodeIntelU16;
using internal::kC3dBlockSize;

constexpr std::size_t kMaxStringsPerParameter = 255;  // one uint8 dimension

// Builds the records of a parameter section (Intel format).
class ParameterWriter {
 public:
  void Group(int id, const std::string& name, const std::string& description) {
    StartRecord(-id, name);
    const std::size_t offset_at = ReserveOffset();
    bytes_.push_back(static_cast<std::uint8_t>(description.size()));
    Append(description);
    EndRecord(offset_at);
  }

  // Returns the byte offset (in the section) of the parameter's data.
  std::size_t Parameter(int group_id, const std::string& name, int type,
                        const std::vector<std::size_t>& dims,
                        const std::vector<std::uint8_t>& data) {
    StartRecord(group_id, name);
    const std::size_t offset_at = ReserveOffset();
    bytes_.push_back(static_cast<std::uint8_t>(static_cast<std::int8_t>(type)));
    bytes_.push_back(static_cast<std::uint8_t>(dims.size()));
    for (std::size_t d : dims) bytes_.push_back(static_cast<std::uint8_t>(d));
    const std::size_t data_at = bytes_.size();
    bytes_.insert(bytes_.end(), data.begin(), data.end());
    bytes_.push_back(0);  // no description
    EndRecord(offset_at);
    return data_at;
  }

  std::size_t Words(int group_id, const std::string& name, const std::vector<std::uint16_t>& v,
                    bool scalar) {
    std::vector<std::uint8_t> data(2 * v.size());
    for (std::size_t i = 0; i < v.size(); ++i) EncodeIntelU16(v[i], &data[2 * i]);
    return Parameter(group_id, name, 2,
                     scalar ? std::vector<std::size_t>{} : std::vector<std::size_t>{v.size()},
                     data);
  }

  void Float(int group_id, const std::string& name, float value) {
    std::vector<std::uint8_t> data(4);
    EncodeIntelF32(value, data.data());
    Parameter(group_id, name, 4, {}, data);
  }

  // At most 255 values (one uint8 dimension).
  void FloatArray(int group_id, const std::string& name, const std::vector<float>& v) {
    std::vector<std::uint8_t> data(4 * v.size());
    for (std::size_t i = 0; i < v.size(); ++i) EncodeIntelF32(v[i], &data[4 * i]);
    Parameter(group_id, name, 4, {v.size()}, data);
  }

  void String(int group_id, const std::string& name, const std::string& value) {
    Parameter(group_id, name, -1, {value.size()},
              std::vector<std::uint8_t>(value.begin(), value.end()));
  }

  // Strings padded with spaces to a common width: dimensions [width, count].
  void Strings(int group_id, const std::string& name, const std::vector<std::string>& values) {
    std::size_t width = 1;
    for (const std::string& s : values) width = std::max(width, s.size());
    std::vector<std::uint8_t> data;
    data.reserve(width * values.size());
    for (const std::string& s : values) {
      data.insert(data.end(), s.begin(), s.end());
      data.insert(data.end(), width - s.size(), ' ');
    }
    Parameter(group_id, name, -1, {width, values.size()}, data);
  }

  // The records; the last one's next-record offset is 0 (end of list).
  std::vector<std::uint8_t> Finish() {
    if (last_offset_at_ != kNone) EncodeIntelU16(0, &bytes_[last_offset_at_]);
    return bytes_;
  }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  void StartRecord(int id, const std::string& name) {
    bytes_.push_back(static_cast<std::uint8_t>(name.size()));
    bytes_.push_back(static_cast<std::uint8_t>(static_cast<std::int8_t>(id)));
    Append(name);
  }
  std::size_t ReserveOffset() {
    bytes_.push_back(0);
    bytes_.push_back(0);
    return bytes_.size() - 2;
  }
  void EndRecord(std::size_t offset_at) {
    EncodeIntelU16(static_cast<std::uint16_t>(bytes_.size() - offset_at), &bytes_[offset_at]);
    last_offset_at_ = offset_at;
  }
  void Append(const std::string& s) { bytes_.insert(bytes_.end(), s.begin(), s.end()); }

  std::vector<std::uint8_t> bytes_;
  std::size_t last_offset_at_ = kNone;
};

constexpr int kPointGroup = 1;
constexpr int kAnalogGroup = 2;
constexpr int kTrialGroup = 3;
constexpr int kManufacturerGroup = 4;

std::vector<std::uint16_t> TwoWords(std::uint64_t value) {
  return {static_cast<std::uint16_t>(value & 0xFFFF), static_cast<std::uint16_t>(value >> 16)};
}

std::vector<std::uint8_t> Encode(const MarkerTable& table, const C3dAnalog& analog,
                                 const C3dWriteOptions& options, const std::string& name) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError(name, "C3D write options", error);
  if (!table.IsConsistent(&error)) ThrowInputError(name, "marker table", error);
  if (!analog.IsConsistent(&error)) ThrowInputError(name, "analog channels", error);
  const std::size_t channels = analog.channels();
  const std::size_t samples_per_frame = channels == 0 ? 0 : analog.samples_per_frame;
  if (channels > 0) {
    if (analog.sample_count != table.frames() * samples_per_frame) {
      ThrowInputError(name, "analog channels",
                      std::to_string(analog.sample_count) + " samples for " +
                          std::to_string(table.frames()) + " frames of " +
                          std::to_string(samples_per_frame) + " samples each");
    }
    // ANALOG:RATE must be a whole multiple of POINT:RATE (readers derive the
    // samples per frame from their ratio).
    const double expected_rate = table.rate_hz * static_cast<double>(samples_per_frame);
    if (std::abs(analog.rate_hz - expected_rate) > 1e-9 * expected_rate) {
      ThrowInputError(name, "analog channels",
                      "rate " + std::to_string(analog.rate_hz) + " Hz is not " +
                          std::to_string(samples_per_frame) + " × the point rate " +
                          std::to_string(table.rate_hz) + " Hz");
    }
    // One uint8 dimension per ANALOG:SCALE/OFFSET array; header word 3 is
    // 16 bits.
    if (channels > kMaxStringsPerParameter || channels * samples_per_frame > 65535) {
      ThrowInputError(name, "analog channels",
                      "the writer holds at most 255 channels and 65535 analog values per frame, "
                      "found " +
                          std::to_string(channels) + " × " + std::to_string(samples_per_frame));
    }
    for (const std::vector<std::string>* names : {&analog.labels, &analog.units}) {
      for (const std::string& s : *names) {
        if (s.size() > 255) {
          ThrowInputError(
              name, "analog channels",
              "label or unit \"" + s.substr(0, 32) + "...\" is longer than 255 characters");
        }
      }
    }
  }
  if (table.markers() > 65535) {
    ThrowInputError(
        name, "marker table",
        "C3D holds at most 65535 points, the table has " + std::to_string(table.markers()));
  }
  if (table.frames() > 0xFFFFFFFFull) {
    ThrowInputError(name, "marker table", "too many frames for C3D");
  }
  for (const std::string& label : table.labels) {
    if (label.size() > 255) {
      ThrowInputError(name, "marker table",
                      "label \"" + label.substr(0, 32) + "...\" is longer than 255 characters");
    }
  }

  const double metres_per_unit = options.units == "m" ? 1.0 : 1e-3;
  double resolution_m = options.residual_resolution_m;
  if (resolution_m <= 0.0) {
    resolution_m = table.point_scale_m > 0.0 ? table.point_scale_m : metres_per_unit;
  }
  float scale = -static_cast<float>(resolution_m / metres_per_unit);
  if (!std::isfinite(scale) || -scale < std::numeric_limits<float>::min()) {
    // Not representable as a float (a reader would see 0 or Inf): 1 unit.
    resolution_m = metres_per_unit;
    scale = -1.0f;
  }
  const auto rate = static_cast<float>(table.rate_hz);
  if (!std::isfinite(rate) || !(rate > 0.0f)) {
    ThrowInputError(name, "marker table",
                    "rate_hz " + std::to_string(table.rate_hz) +
                        " is not representable as a "
                        "positive 32-bit float (POINT:RATE)");
  }
  const std::uint64_t frames = table.frames();
  const std::int64_t first = std::clamp<std::int64_t>(table.first_frame_number, 0, 0xFFFFFFFFll);
  const bool long_trial = frames > 65535;

  // ---- Parameter section --------------------------------------------------------
  ParameterWriter params;
  params.Group(kPointGroup, "POINT", "3-D point parameters");
  params.Words(kPointGroup, "USED", {static_cast<std::uint16_t>(table.markers())}, true);
  params.Words(kPointGroup, "FRAMES", {static_cast<std::uint16_t>(long_trial ? 65535 : frames)},
               true);
  // Filled in once the section's size is known.
  const std::size_t data_start_at = params.Words(kPointGroup, "DATA_START", {0}, true);
  params.Float(kPointGroup, "SCALE", scale);
  params.Float(kPointGroup, "RATE", rate);
  params.String(kPointGroup, "UNITS", options.units);
  for (std::size_t begin = 0, k = 1; begin < table.markers() || k == 1;
       begin += kMaxStringsPerParameter, ++k) {
    const std::size_t end = std::min(table.markers(), begin + kMaxStringsPerParameter);
    const std::vector<std::string> chunk(table.labels.begin() + begin, table.labels.begin() + end);
    params.Strings(kPointGroup, k == 1 ? "LABELS" : "LABELS" + std::to_string(k), chunk);
  }
  if (table.up_axis == "y" || table.up_axis == "z") {
    params.String(kPointGroup, "X_SCREEN", "+X");
    params.String(kPointGroup, "Y_SCREEN", table.up_axis == "y" ? "+Y" : "+Z");
  }
  // A float holds whole numbers exactly up to 2^24; beyond, readers use TRIAL.
  if (long_trial && frames <= (1u << 24)) {
    params.Float(kPointGroup, "LONG_FRAMES", static_cast<float>(frames));
  }
  params.Group(kAnalogGroup, "ANALOG", "analog data parameters");
  params.Words(kAnalogGroup, "USED", {static_cast<std::uint16_t>(channels)}, true);
  params.Float(kAnalogGroup, "RATE", channels == 0 ? rate : static_cast<float>(analog.rate_hz));
  if (channels > 0) {
    // The values are stored already scaled: SCALE 1, OFFSET 0, GEN_SCALE 1.
    params.Strings(kAnalogGroup, "LABELS", analog.labels);
    params.Strings(kAnalogGroup, "UNITS", analog.units);
    params.FloatArray(kAnalogGroup, "SCALE", std::vector<float>(channels, 1.0f));
    params.Words(kAnalogGroup, "OFFSET", std::vector<std::uint16_t>(channels, 0), false);
    params.Float(kAnalogGroup, "GEN_SCALE", 1.0f);
  }
  if (long_trial) {
    params.Group(kTrialGroup, "TRIAL", "frame range beyond 65535 frames");
    params.Words(kTrialGroup, "ACTUAL_START_FIELD", TwoWords(first), false);
    params.Words(kTrialGroup, "ACTUAL_END_FIELD", TwoWords(first + frames - 1), false);
  }
  params.Group(kManufacturerGroup, "MANUFACTURER", "software that wrote the file");
  params.String(kManufacturerGroup, "COMPANY", "ccsrm");
  params.String(kManufacturerGroup, "SOFTWARE", "ccsrm mocap");
  std::vector<std::uint8_t> records = params.Finish();

  const std::size_t section_bytes = 4 + records.size();
  const std::size_t parameter_blocks = (section_bytes + kC3dBlockSize - 1) / kC3dBlockSize;
  if (parameter_blocks > 255) {
    ThrowInputError(name, "marker table", "the parameter section would need more than 255 blocks");
  }
  const std::size_t data_block = 2 + parameter_blocks;  // header is block 1
  EncodeIntelU16(static_cast<std::uint16_t>(data_block), &records[data_start_at]);

  // ---- Header (block 1) -------------------------------------------------------------
  const std::size_t markers = table.markers();
  const std::size_t analog_values = channels * samples_per_frame;
  std::vector<std::uint8_t> out(
      kC3dBlockSize * (data_block - 1) + frames * (markers * 16 + analog_values * 4), 0);
  out[0] = 2;
  out[1] = internal::kC3dMagic;
  EncodeIntelU16(static_cast<std::uint16_t>(markers), &out[2]);
  EncodeIntelU16(static_cast<std::uint16_t>(analog_values), &out[4]);
  const std::int64_t last = frames == 0 ? first : first + static_cast<std::int64_t>(frames) - 1;
  EncodeIntelU16(static_cast<std::uint16_t>(std::min<std::int64_t>(first, 65535)), &out[6]);
  EncodeIntelU16(static_cast<std::uint16_t>(std::min<std::int64_t>(last, 65535)), &out[8]);
  EncodeIntelU16(0, &out[10]);  // maximum interpolation gap
  EncodeIntelF32(scale, &out[12]);
  EncodeIntelU16(static_cast<std::uint16_t>(data_block), &out[16]);
  EncodeIntelU16(static_cast<std::uint16_t>(samples_per_frame), &out[18]);
  EncodeIntelF32(rate, &out[20]);

  // ---- Parameter section (block 2 ...) ------------------------------------------------
  std::uint8_t* section = &out[kC3dBlockSize];
  section[0] = 1;  // conventional values of the two reserved bytes
  section[1] = internal::kC3dMagic;
  section[2] = static_cast<std::uint8_t>(parameter_blocks);
  section[3] = internal::kProcessorIntel;
  std::copy(records.begin(), records.end(), section + 4);

  // ---- Data ------------------------------------------------------------------------------
  std::uint8_t* data = &out[kC3dBlockSize * (data_block - 1)];
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t m = 0; m < markers; ++m, data += 16) {
      if (!table.is_valid(f, m)) {
        EncodeIntelF32(0.0f, data);
        EncodeIntelF32(0.0f, data + 4);
        EncodeIntelF32(0.0f, data + 8);
        EncodeIntelF32(-1.0f, data + 12);  // residual word -1: not seen
        continue;
      }
      const Eigen::Vector3d p = table.position(f, m) / metres_per_unit;
      EncodeIntelF32(static_cast<float>(p.x()), data);
      EncodeIntelF32(static_cast<float>(p.y()), data + 4);
      EncodeIntelF32(static_cast<float>(p.z()), data + 8);
      int word = 0;
      if (table.has_residual) {
        const std::size_t i = f * markers + m;
        const double residual = table.residual_m[i];
        const long byte =
            residual > 0.0 ? std::min(255l, std::lround(residual / resolution_m)) : 0l;
        word = ((table.camera_mask[i] & 0x7F) << 8) | static_cast<int>(byte);
      }
      EncodeIntelF32(static_cast<float>(word), data + 12);
    }
    // The frame's analog samples, each holding every channel.
    const double* values = analog.values.data() + f * analog_values;
    for (std::size_t k = 0; k < analog_values; ++k, data += 4) {
      EncodeIntelF32(static_cast<float>(values[k]), data);
    }
  }
  return out;
}

}  // namespace

bool C3dWriteOptions::IsValid(std::string* error) const {
  if (units != "mm" && units != "m") {
    if (error != nullptr) *error = "units must be \"mm\" or \"m\", found \"" + units + "\"";
    return false;
  }
  if (!std::isfinite(residual_resolution_m) || residual_resolution_m < 0.0) {
    if (error != nullptr) *error = "residual_resolution_m must be finite and >= 0";
    return false;
  }
  return true;
}

std::vector<std::uint8_t> EncodeC3d(const MarkerTable& table, const C3dWriteOptions& options) {
  return Encode(table, C3dAnalog(), options, "C3D output");
}

std::vector<std::uint8_t> EncodeC3d(const C3dRecording& recording, const C3dWriteOptions& options) {
  return Encode(recording.markers, recording.analog, options, "C3D output");
}

void WriteC3d(const std::string& path, const MarkerTable& table, const C3dWriteOptions& options) {
  WriteC3d(path, C3dRecording{table, C3dAnalog()}, options);
}

void WriteC3d(const std::string& path, const C3dRecording& recording,
              const C3dWriteOptions& options) {
  const std::vector<std::uint8_t> bytes =
      Encode(recording.markers, recording.analog, options, path);
  AtomicOutputFile out(path);
  {
    std::ofstream stream(out.temp_path(), std::ios::binary);
    if (!stream) ThrowInputError(path, "", "cannot open for writing");
    stream.write(reinterpret_cast<const char*>(bytes.data()),
                 static_cast<std::streamsize>(bytes.size()));
    stream.flush();
    if (!stream) ThrowInputError(path, "", "write failed");
  }
  out.Commit();
}

OutputKind C3dFileOutput() {
  return {"C3D file", false, [](const std::string& p) {
            // Every C3D file's second byte is 0x50 (the header's key word).
            std::ifstream in(p, std::ios::binary);
            char header[2] = {0, 0};
            return static_cast<bool>(in.read(header, 2)) && header[1] == 0x50;
          }};
}

}  // namespace ccsrm::mocap
