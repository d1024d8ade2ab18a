// The analog channels of C3D files: the real vendor files of
// ../shared/data/mocap/c3d against an independent decoder
// (c3d_analog_reference.py, Python standard library only), the writer's
// round trip, and the vendor quirks (missing OFFSET, POINT:DATA_START = 0).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "ccsrm/mocap/c3d.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::InputErrorOf;
using testing::ReadBytes;

bool Contains(const std::vector<std::string>& lines, const std::string& part) {
  for (const std::string& line : lines) {
    if (line.find(part) != std::string::npos) return true;
  }
  return false;
}

// What the reference decoder prints for some frames of a file.
struct Reference {
  std::size_t channels = 0;
  std::size_t samples_per_frame = 0;
  double rate_hz = 0.0;
  std::vector<std::string> labels;
  std::vector<std::string> units;
  std::vector<std::vector<double>> rows;  // one per analog sample of the frames asked
};

// Runs tests/mocap/c3d_analog_reference.py; false when Python is missing.
bool RunReference(const std::string& path, const std::vector<std::size_t>& frames, Reference* out) {
#ifndef CCSRM_PYTHON3
  (void)path;
  (void)frames;
  (void)out;
  return false;
#else
  std::string command = std::string("\"") + CCSRM_PYTHON3 + "\" \"" + CCSRM_SOURCE_DIR +
                        "/tests/mocap/c3d_analog_reference.py\" \"" + path + "\"";
  for (std::size_t f : frames) command += " " + std::to_string(f);
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return false;
  std::string text;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe.get()) != nullptr) text += buffer.data();
  std::istringstream lines(text);
  std::string line;
  if (!std::getline(lines, line)) return false;
  std::istringstream head(line);
  std::string word;
  head >> word >> out->channels >> word >> out->samples_per_frame >> word >> out->rate_hz;
  for (std::size_t c = 0; c < out->channels && std::getline(lines, line); ++c) {
    const std::size_t tab = line.find('\t');
    out->labels.push_back(line.substr(0, tab));
    out->units.push_back(tab == std::string::npos ? "" : line.substr(tab + 1));
  }
  while (std::getline(lines, line)) {
    std::istringstream row_text(line);
    std::vector<double> row;
    double v = 0.0;
    while (row_text >> v) row.push_back(v);
    out->rows.push_back(row);
  }
  return out->rows.size() == frames.size() * out->samples_per_frame;
#endif
}

// Every analog value of `frames` agrees with the reference decoder. The
// reference prints 9 significant digits of the same double computation:
// agreement to 1e-7 relative (or 1e-9 absolute near 0) is what that
// printing allows; a wrong scale, offset, byte order or sample order is
// off by far more.
void ExpectMatchesReference(const std::string& file, const std::string& storage,
                            const std::string& processor) {
  SCOPED_TRACE(file);
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/" + file);
  const C3dRecording recording = ReadC3dRecording(path);
  const C3dAnalog& analog = recording.analog;
  EXPECT_EQ(recording.markers.storage, storage);
  EXPECT_EQ(recording.markers.processor, processor);
  const std::size_t frames = recording.markers.frames();
  ASSERT_GT(frames, 2u);
  const std::vector<std::size_t> asked = {0, frames / 2, frames - 1};
  Reference ref;
  if (!RunReference(path, asked, &ref)) {
    GTEST_SKIP() << "python3 (for the reference decoder) is not available";
  }
  ASSERT_EQ(analog.channels(), ref.channels);
  EXPECT_EQ(analog.samples_per_frame, ref.samples_per_frame);
  EXPECT_DOUBLE_EQ(analog.rate_hz, ref.rate_hz);
  EXPECT_EQ(analog.sample_count, frames * analog.samples_per_frame);
  EXPECT_EQ(analog.labels, ref.labels);
  EXPECT_EQ(analog.units, ref.units);
  std::size_t compared = 0;
  std::size_t nonzero = 0;
  for (std::size_t k = 0; k < asked.size(); ++k) {
    for (std::size_t s = 0; s < analog.samples_per_frame; ++s) {
      const std::vector<double>& row = ref.rows[k * analog.samples_per_frame + s];
      ASSERT_EQ(row.size(), analog.channels());
      const std::size_t sample = asked[k] * analog.samples_per_frame + s;
      for (std::size_t c = 0; c < analog.channels(); ++c) {
        const double got = analog.value(sample, c);
        EXPECT_NEAR(got, row[c], 1e-7 * std::abs(row[c]) + 1e-9)
            << "frame " << asked[k] << " sample " << s << " channel " << analog.labels[c];
        ++compared;
        if (row[c] != 0.0) ++nonzero;
      }
    }
  }
  EXPECT_EQ(compared, asked.size() * analog.samples_per_frame * analog.channels());
  // A decoder that read zeros everywhere must not pass.
  EXPECT_GT(nonzero, compared / 2);
}

TEST(C3dAnalog, IntegerIntelFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("pc_int.c3d", "integer", "intel");
}
TEST(C3dAnalog, FloatIntelFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("pc_real.c3d", "float", "intel");
}
TEST(C3dAnalog, IntegerDecFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("dec_int.c3d", "integer", "dec");
}
TEST(C3dAnalog, FloatDecFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("Eb015vr.c3d", "float", "dec");
}
TEST(C3dAnalog, IntegerMipsFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("Eb015si.c3d", "integer", "mips");
}
TEST(C3dAnalog, FloatMipsFileMatchesAnIndependentDecoder) {
  ExpectMatchesReference("sgi_real.c3d", "float", "mips");
}

// The six stored forms of one trial decode to the same channels: integer
// files hold the integer the float files hold, so they agree to float
// precision (1e-6 relative), whatever the processor.
TEST(C3dAnalog, AllSixFormsOfOneTrialAgree) {
  CCSRM_SHARED_FILE_OR_SKIP(ref_path, "data/mocap/c3d/pc_real.c3d");
  const C3dAnalog ref = ReadC3dRecording(ref_path).analog;
  ASSERT_EQ(ref.channels(), 16u);  // c3d.org sample 02: two force plates
  for (const char* file :
       {"pc_int.c3d", "dec_int.c3d", "dec_real.c3d", "sgi_int.c3d", "sgi_real.c3d"}) {
    SCOPED_TRACE(file);
    CCSRM_SHARED_FILE_OR_SKIP(path, std::string("data/mocap/c3d/") + file);
    const C3dAnalog a = ReadC3dRecording(path).analog;
    ASSERT_EQ(a.values.size(), ref.values.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      worst =
          std::max(worst, std::abs(a.values[i] - ref.values[i]) / (1e-6 + std::abs(ref.values[i])));
    }
    EXPECT_LT(worst, 1e-6);
  }
}

TEST(C3dAnalog, ReadC3dAloneStillReadsThePoints) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  const MarkerTable points = ReadC3d(path);
  const C3dRecording whole = ReadC3dRecording(path);
  EXPECT_EQ(points.frames(), whole.markers.frames());
  EXPECT_TRUE(testing::SameStart(points.positions_m, whole.markers.positions_m));
}

// Writer → reader: the channels come back with their labels, units, rate
// and values (to float precision: the writer stores 32-bit floats).
TEST(C3dAnalog, WriterRoundTripKeepsTheChannels) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/dec_int.c3d");
  const C3dRecording original = ReadC3dRecording(path);
  const std::vector<std::uint8_t> bytes = EncodeC3d(original);
  const C3dRecording back = ReadC3dRecordingFromMemory(bytes, "round_trip.c3d");
  const C3dAnalog& a = original.analog;
  const C3dAnalog& b = back.analog;
  EXPECT_EQ(b.labels, a.labels);
  EXPECT_EQ(b.units, a.units);
  EXPECT_EQ(b.samples_per_frame, a.samples_per_frame);
  EXPECT_NEAR(b.rate_hz, a.rate_hz, 1e-6 * a.rate_hz);
  ASSERT_EQ(b.values.size(), a.values.size());
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    ASSERT_NEAR(b.values[i], a.values[i], 1e-6 * std::abs(a.values[i]) + 1e-12) << i;
  }
  EXPECT_TRUE(back.markers.warnings.empty()) << back.markers.warnings.front();
  // A table without channels is written as before (no analog values).
  const C3dRecording points_only =
      ReadC3dRecordingFromMemory(EncodeC3d(original.markers), "points.c3d");
  EXPECT_EQ(points_only.analog.channels(), 0u);
}

TEST(C3dAnalog, WriterRefusesChannelsThatDoNotFitTheFrames) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  C3dRecording r = ReadC3dRecording(path);
  r.analog.rate_hz *= 1.5;  // not samples_per_frame × the point rate
  EXPECT_NE(InputErrorOf([&] { EncodeC3d(r); }).find("point rate"), std::string::npos);
  r = ReadC3dRecording(path);
  r.analog.values.pop_back();
  EXPECT_NE(InputErrorOf([&] { EncodeC3d(r); }).find("analog channels"), std::string::npos);
}

// Offset of the data of parameter `group`:`name` in an Intel file (walking
// the records from the parameter section), and of its name.
struct Record {
  std::size_t name_at = 0;
  std::size_t data_at = 0;
};
Record FindParameter(const std::vector<std::uint8_t>& bytes, const std::string& group,
                     const std::string& name) {
  const std::size_t begin = (bytes.at(0) - 1u) * 512 + 4;
  int group_id = 0;
  for (int pass = 0; pass < 2; ++pass) {
    std::size_t at = begin;
    while (at + 4 < bytes.size()) {
      const int length = std::abs(static_cast<std::int8_t>(bytes[at]));
      const int id = static_cast<std::int8_t>(bytes[at + 1]);
      if (length == 0 || id == 0) break;
      const std::string record(bytes.begin() + at + 2, bytes.begin() + at + 2 + length);
      const std::size_t offset_at = at + 2 + length;
      if (pass == 0 && id < 0 && record == group) group_id = -id;
      if (pass == 1 && id == group_id && record == name) {
        return Record{at + 2, offset_at + 4 + bytes[offset_at + 3]};
      }
      const std::size_t next = bytes[offset_at] | (bytes[offset_at + 1] << 8);
      if (next == 0) break;
      at = offset_at + next;
    }
  }
  ADD_FAILURE() << group << ":" << name << " not found";
  return Record{};
}

// A file without ANALOG:OFFSET reads with offset 0 and a warning; the values
// move by OFFSET × SCALE × GEN_SCALE exactly.
TEST(C3dAnalog, MissingOffsetIsTakenAsZeroWithAWarning) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  const C3dRecording original = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  const Record offset = FindParameter(bytes, "ANALOG", "OFFSET");
  bytes[offset.name_at + 5] = 'X';  // "OFFSEX": a parameter nobody reads
  const C3dRecording patched = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  EXPECT_TRUE(Contains(patched.markers.warnings, "ANALOG:OFFSET is missing"));
  const C3dAnalog& a = original.analog;
  std::size_t nonzero_offsets = 0;
  for (std::size_t c = 0; c < a.channels(); ++c) {
    if (a.offset[c] != 0.0) ++nonzero_offsets;
    const double shift = a.offset[c] * a.scale[c] * a.gen_scale;
    EXPECT_NEAR(patched.analog.value(5, c), a.value(5, c) + shift, 1e-9 * (1 + std::abs(shift)));
  }
  // Sample 02 has non-zero offsets on its force channels; else this test
  // would not tell the two readings apart.
  EXPECT_GT(nonzero_offsets, 0u);
}

// SCALE with fewer values than channels cannot be applied: refused.
TEST(C3dAnalog, ShortScaleIsRefused) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  const Record scale = FindParameter(bytes, "ANALOG", "SCALE");
  bytes.at(scale.data_at - 1) = 4;  // dimension 16 → 4
  const std::string error = InputErrorOf([&] { ReadC3dRecordingFromMemory(bytes, "pc_int.c3d"); });
  EXPECT_NE(error.find("ANALOG:SCALE: expected 16 values (ANALOG:USED), found 4"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("pc_int.c3d"), std::string::npos) << error;
}

// 2-byte unsigned samples (ANALOG:FORMAT = "UNSIGNED"): the same bytes read
// as unsigned words, so every sample stored as a negative int16 moves up by
// 65536 steps of SCALE × GEN_SCALE, the others stay. pc_int.c3d has no
// FORMAT parameter; its ANALOG:DESCRIPTIONS record (32 strings of 32
// characters) is renamed FORMAT in place and its first string set to
// "UNSIGNED".
TEST(C3dAnalog, UnsignedFormatReadsTheWordsAsUnsigned) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  // The file's 12-bit samples are all non-negative words; make a few
  // negative as int16 (0xFFF0: -16 signed, 65520 unsigned). Data from block
  // 13, frames of 36 points × 8 bytes then 64 analog words.
  for (std::size_t frame : {0u, 10u, 88u}) {
    const std::size_t at = 12 * 512 + frame * (36 * 8 + 64 * 2) + 36 * 8 + 2 * frame % 16;
    bytes.at(at) = 0xF0;
    bytes.at(at + 1) = 0xFF;
  }
  const C3dAnalog signed_analog = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d").analog;
  const Record d = FindParameter(bytes, "ANALOG", "DESCRIPTIONS");
  const std::size_t old_offset_at = d.name_at + 12;
  const std::size_t next_record =
      old_offset_at + (bytes[old_offset_at] | (bytes[old_offset_at + 1] << 8));
  const std::size_t new_offset_at = d.name_at + 6;
  bytes[d.name_at - 2] = 6;
  const std::string format = "FORMAT";
  std::copy(format.begin(), format.end(), bytes.begin() + d.name_at);
  std::copy(bytes.begin() + old_offset_at + 2, bytes.begin() + next_record,
            bytes.begin() + new_offset_at + 2);
  const std::size_t next = next_record - new_offset_at;
  bytes[new_offset_at] = static_cast<std::uint8_t>(next & 0xFF);
  bytes[new_offset_at + 1] = static_cast<std::uint8_t>(next >> 8);
  const Record f = FindParameter(bytes, "ANALOG", "FORMAT");
  std::string value = "UNSIGNED";
  value.resize(32, ' ');  // the record's strings are 32 characters wide
  std::copy(value.begin(), value.end(), bytes.begin() + f.data_at);

  const C3dAnalog unsigned_analog = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d").analog;
  EXPECT_TRUE(unsigned_analog.unsigned_integers);
  ASSERT_EQ(unsigned_analog.values.size(), signed_analog.values.size());
  std::size_t moved = 0;
  for (std::size_t s = 0; s < signed_analog.sample_count; ++s) {
    for (std::size_t c = 0; c < signed_analog.channels(); ++c) {
      const double step = signed_analog.scale[c] * signed_analog.gen_scale;
      const double raw = std::round(signed_analog.value(s, c) / step + signed_analog.offset[c]);
      const double expected =
          raw < 0 ? signed_analog.value(s, c) + 65536.0 * step : signed_analog.value(s, c);
      if (raw < 0) ++moved;
      ASSERT_NEAR(unsigned_analog.value(s, c), expected, 1e-9 * std::abs(65536.0 * step))
          << "sample " << s << " channel " << c;
    }
  }
  // The comparison above saw both branches: the three patched words.
  EXPECT_EQ(moved, 3u);
  // An unknown format is refused.
  std::string other = "OFFSETBN";
  other.resize(32, ' ');
  std::copy(other.begin(), other.end(), bytes.begin() + f.data_at);
  const std::string error = InputErrorOf([&] { ReadC3dRecordingFromMemory(bytes, "pc_int.c3d"); });
  EXPECT_NE(error.find("ANALOG:FORMAT: expected \"SIGNED\" or \"UNSIGNED\", found \"OFFSETBN\""),
            std::string::npos)
      << error;
}

// The header's analog counts (words 3 and 10) disagreeing with ANALOG:USED
// and ANALOG:RATE: the parameters set the layout, with a warning each, and
// the values are those of the unpatched file.
TEST(C3dAnalog, HeaderCountsThatDisagreeWithTheParametersWarn) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  const C3dRecording original = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  bytes[4] = 60;  // header word 3: 60 analog values per frame (16 × 4 = 64)
  bytes[18] = 5;  // header word 10: 5 samples per frame (ANALOG:RATE 200 / 50 = 4)
  const C3dRecording patched = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  EXPECT_TRUE(Contains(patched.markers.warnings,
                       "header word 3 gives 60 analog values per frame, the parameters 64"));
  EXPECT_TRUE(Contains(patched.markers.warnings,
                       "header word 10 gives 5 analog samples per frame, ANALOG:RATE / "
                       "POINT:RATE 4; used the parameters"));
  EXPECT_EQ(patched.analog.values, original.analog.values);
}

// The field quirk: POINT:DATA_START = 0 with a valid header word 9 opens
// with a warning (as established readers do); with both 0, refused.
TEST(C3dAnalog, DataStartZeroFallsBackToTheHeaderWord) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  const C3dRecording original = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  const Record data_start = FindParameter(bytes, "POINT", "DATA_START");
  bytes[data_start.data_at] = 0;
  bytes[data_start.data_at + 1] = 0;
  const C3dRecording patched = ReadC3dRecordingFromMemory(bytes, "pc_int.c3d");
  EXPECT_TRUE(Contains(patched.markers.warnings,
                       "POINT:DATA_START is 0, not a block number; used header word 9 (block 13)"));
  EXPECT_TRUE(testing::SameStart(patched.markers.positions_m, original.markers.positions_m));
  EXPECT_EQ(patched.analog.values, original.analog.values);
  bytes[16] = 0;  // header word 9 too
  bytes[17] = 0;
  const std::string error = InputErrorOf([&] { ReadC3dRecordingFromMemory(bytes, "pc_int.c3d"); });
  EXPECT_NE(error.find("POINT:DATA_START: expected a block number >= 2, found 0"),
            std::string::npos)
      << error;
}

}  // namespace
}  // namespace ccsrm::mocap
