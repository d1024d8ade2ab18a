// Malformed marker files: each is rejected with an InputError that names the
// file and the byte offset or line, and nothing crashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/text_formats.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::InputErrorOf;
using testing::ReadBytes;
using testing::SameStart;

bool Contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

std::vector<std::uint8_t> Prefix(const std::vector<std::uint8_t>& bytes, std::size_t n) {
  return std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + n);
}

// Offset of the data of the parameter `name` (e.g. "FRAMES") in an Intel
// file; the record is: length, group id, name, 2-byte offset, type, number
// of dimensions, dimensions, data.
std::size_t ParameterDataOffset(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                std::size_t* dims_at = nullptr) {
  for (std::size_t i = 512; i + name.size() + 6 < bytes.size(); ++i) {
    const int length = std::abs(static_cast<std::int8_t>(bytes[i]));  // < 0: locked
    if (static_cast<std::size_t>(length) == name.size() &&
        static_cast<std::int8_t>(bytes[i + 1]) > 0 &&
        std::equal(name.begin(), name.end(), bytes.begin() + i + 2)) {
      const std::size_t type_at = i + 2 + name.size() + 2;
      if (dims_at != nullptr) *dims_at = type_at + 2;
      return type_at + 2 + bytes[type_at + 1];
    }
  }
  ADD_FAILURE() << "parameter " << name << " not found";
  return 0;
}

std::string C3dError(const std::vector<std::uint8_t>& bytes) {
  return InputErrorOf([&] { ReadC3dFromMemory(bytes, "Eb015pi.c3d"); });
}

// A file cut before its first complete frame has nothing to read: refused.
TEST(BadC3d, TruncatedFileNamesTheFileAndByteOffset) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  const std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  // Header, parameters (blocks 2-10), data from byte 5120 in frames of 336 bytes.
  for (std::size_t n : {0, 1, 100, 511, 512, 515, 900, 5119, 5120, 5121, 5120 + 335}) {
    SCOPED_TRACE(n);
    const std::string error = C3dError(Prefix(bytes, n));
    EXPECT_TRUE(Contains(error, "Eb015pi.c3d: byte ")) << error;
    EXPECT_TRUE(Contains(error, "expected")) << error;
  }
  // The messages say what was missing.
  EXPECT_TRUE(Contains(C3dError(Prefix(bytes, 100)), "512-byte C3D header"));
  EXPECT_TRUE(Contains(C3dError(Prefix(bytes, 900)), "but the file ends at byte 900"))
      << C3dError(Prefix(bytes, 900));
  EXPECT_TRUE(Contains(C3dError(Prefix(bytes, 5119)), "expected the data section at block 11"))
      << C3dError(Prefix(bytes, 5119));
  EXPECT_TRUE(Contains(C3dError(Prefix(bytes, 5200)),
                       "byte 5120: expected 450 frames of 336 bytes from byte 5120 (POINT:FRAMES), "
                       "but the file (5200 bytes) holds no complete frame"))
      << C3dError(Prefix(bytes, 5200));
}

// A recording cut within its data gives the complete frames it holds, with
// a warning, as other readers do (the text readers read the rows there are).
TEST(BadC3d, TruncatedDataSectionGivesItsCompleteFramesWithAWarning) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  const std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  const MarkerTable whole = ReadC3dFromMemory(bytes, "Eb015pi.c3d");
  for (std::size_t n : {std::size_t{100000}, bytes.size() - 400}) {
    SCOPED_TRACE(n);
    const MarkerTable cut = ReadC3dFromMemory(Prefix(bytes, n), "Eb015pi.c3d");
    const std::size_t complete = (n - 5120) / 336;  // 282 and 449
    ASSERT_EQ(cut.frames(), complete);
    EXPECT_EQ(cut.labels, whole.labels);
    EXPECT_TRUE(SameStart(cut.positions_m, whole.positions_m));
    EXPECT_TRUE(SameStart(cut.residual_m, whole.residual_m));
    ASSERT_EQ(cut.warnings.size(), whole.warnings.size() + 1);
    EXPECT_TRUE(Contains(cut.warnings.back(),
                         "should hold 450 frames of 336 bytes from byte 5120 "
                         "(POINT:FRAMES), but the file (" +
                             std::to_string(n) + " bytes) holds only " + std::to_string(complete) +
                             " complete frame(s)"))
        << cut.warnings.back();
  }
}

TEST(BadC3d, WrongMagicByteIsNotAC3dFile) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  bytes[1] = 0x51;
  const std::string error = C3dError(bytes);
  EXPECT_TRUE(Contains(error, "Eb015pi.c3d: byte 1: expected 0x50")) << error;
}

TEST(BadC3d, ParameterSectionPointerPastTheEnd) {
  CCSRM_SHARED_FILE_OR_SKIP(pc_int_c3d, "data/mocap/c3d/pc_int.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(pc_int_c3d);  // 85 blocks
  bytes[0] = 200;
  const std::string error = C3dError(bytes);
  EXPECT_TRUE(Contains(error, "Eb015pi.c3d: byte 0: expected the parameter section at block 200"))
      << error;
  EXPECT_TRUE(Contains(error, "past the end of the file")) << error;
}

TEST(BadC3d, UnknownProcessorType) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  bytes[512 + 3] = 99;
  EXPECT_TRUE(Contains(C3dError(bytes), "byte 515: expected a processor type of 84"));
}

TEST(BadC3d, ParameterDimensionsExceedingTheSection) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  std::size_t dims_at = 0;
  ParameterDataOffset(bytes, "LABELS", &dims_at);
  bytes[dims_at] = 255;
  bytes[dims_at + 1] = 255;  // 255 × 255 characters: more than the 9 blocks hold
  const std::string error = C3dError(bytes);
  EXPECT_TRUE(Contains(error, "data of parameter LABELS (dimensions 255x255)")) << error;
  EXPECT_TRUE(Contains(error, "but the data section starts at byte 5120 (block 11, header word 9)"))
      << error;
}

// A frame count larger than the data holds reads the frames there are; the
// zero padding of the last 512-byte block is not taken for a frame (it would
// read as every marker seen at the origin).
TEST(BadC3d, FrameCountLargerThanTheDataSectionReadsTheFramesThere) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  const MarkerTable whole = ReadC3dFromMemory(bytes, "Eb015pi.c3d");
  // 450 frames of 336 bytes from byte 5120 end at 156320; the last block is
  // padded with zeros to 156672, room for a 451st frame.
  ASSERT_EQ(bytes.size(), 156672u);
  const std::size_t at = ParameterDataOffset(bytes, "FRAMES");
  ASSERT_EQ(bytes[at] | (bytes[at + 1] << 8), 450);
  bytes[at] = 0xCC;  // 460 frames
  bytes[at + 1] = 0x01;
  const MarkerTable t = ReadC3dFromMemory(bytes, "Eb015pi.c3d");
  EXPECT_EQ(t.frames(), 450u);
  EXPECT_TRUE(SameStart(t.positions_m, whole.positions_m));
  EXPECT_EQ(Summarize(t).invalid_points, Summarize(whole).invalid_points);
  ASSERT_FALSE(t.warnings.empty());
  EXPECT_TRUE(Contains(t.warnings.back(),
                       "should hold 460 frames of 336 bytes from byte 5120 "
                       "(POINT:FRAMES), but the file (156672 bytes) holds only "
                       "450 complete frame(s)"))
      << t.warnings.back();
}

TEST(BadC3d, DataStartPastTheEnd) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  std::vector<std::uint8_t> bytes = ReadBytes(eb015pi_c3d);
  const std::size_t at = ParameterDataOffset(bytes, "DATA_START");
  bytes[at] = 0x00;
  bytes[at + 1] = 0x10;  // block 4096
  const std::string error = C3dError(bytes);
  EXPECT_TRUE(Contains(error, "expected the data section at block 4096")) << error;
}

TEST(BadC3d, EveryTruncationOfASmallFileIsAnInputErrorOrItsCompleteFrames) {
  CCSRM_SHARED_FILE_OR_SKIP(pc_int_c3d, "data/mocap/c3d/pc_int.c3d");
  const std::vector<std::uint8_t> bytes = ReadBytes(pc_int_c3d);
  const MarkerTable whole = ReadC3dFromMemory(bytes, "pc_int.c3d");
  // The data starts at 12 × 512 and holds 89 frames of 36 × 8 + 64 × 2
  // bytes. A prefix without a complete frame must be rejected; a longer one
  // gives its complete frames, the same as the whole file's, with a warning
  // when some are missing. A prefix of whole 512-byte blocks looks like a
  // padded file: its frames that start in the last block may be padding and
  // are not read. Every length is tried through the header, the parameters
  // and the first frames, then every 13th (a prime stride, to land at every
  // offset within a frame and within a block).
  const std::size_t data_start = 12 * 512;
  const std::size_t frame_bytes = 36 * 8 + 64 * 2;
  const std::size_t data_end = data_start + 89 * frame_bytes;
  std::size_t tried = 0;
  for (std::size_t n = 0; n <= bytes.size();
       n += (n < data_start + 3 * frame_bytes || n + frame_bytes > data_end) ? 1 : 13) {
    ++tried;
    const std::vector<std::uint8_t> prefix = Prefix(bytes, n);
    std::size_t frames =
        n < data_start ? 0 : std::min<std::size_t>(89, (n - data_start) / frame_bytes);
    if (frames < 89 && n % 512 == 0) {
      const std::size_t last_block = n - 512;
      frames = last_block <= data_start
                   ? 0
                   : std::min(frames, (last_block - data_start + frame_bytes - 1) / frame_bytes);
    }
    if (frames == 0) {
      const std::string error = InputErrorOf([&] { ReadC3dFromMemory(prefix, "pc_int.c3d"); });
      ASSERT_EQ(error.rfind("pc_int.c3d: byte ", 0), 0u) << "prefix " << n << ": " << error;
      continue;
    }
    const MarkerTable t = ReadC3dFromMemory(prefix, "pc_int.c3d");
    ASSERT_EQ(t.frames(), frames) << "prefix " << n;
    ASSERT_EQ(t.warnings.size(), whole.warnings.size() + (frames < 89 ? 1 : 0)) << "prefix " << n;
    ASSERT_TRUE(SameStart(t.positions_m, whole.positions_m)) << "prefix " << n;
    ASSERT_TRUE(SameStart(t.residual_m, whole.residual_m)) << "prefix " << n;
  }
  EXPECT_GT(tried, 10000u);
}

// ---- Text files ----------------------------------------------------------------

std::string ReplaceFirst(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(BadText, NonNumericCsvCellNamesLineAndColumn) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  const std::string text = ReplaceFirst(ReadTextFile(nexus_csv), "1,0,44.1628,", "1,0,44.16x8,");
  const std::string error =
      InputErrorOf([&] { ReadNexusCsvFromString(text, "nexus_markers.csv"); });
  EXPECT_TRUE(Contains(error, "nexus_markers.csv: line 6, column 3: expected a coordinate"))
      << error;
  EXPECT_TRUE(Contains(error, "'44.16x8'")) << error;
}

TEST(BadText, CsvRowWithTooFewColumns) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  std::string text = ReadTextFile(nexus_csv);
  // Cut line 7 (frame 2) after its 10th cell.
  const std::size_t line7 = text.find("\n2,0,") + 1;
  std::size_t cut = line7;
  for (int i = 0; i < 10; ++i) cut = text.find(',', cut) + 1;
  text.erase(cut - 1, text.find('\r', cut) - cut + 1);
  const std::string error = InputErrorOf([&] { ReadNexusCsvFromString(text, "short.csv"); });
  EXPECT_TRUE(Contains(error, "short.csv: line 7: expected 155 columns")) << error;
}

TEST(BadText, TrcWithMissingHeaderLine) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_trc, "data/mocap/text/nexus_markers.trc");
  std::string text = ReadTextFile(nexus_trc);
  const std::size_t line2 = text.find('\n') + 1;
  text.erase(line2, text.find('\n', line2) + 1 - line2);  // drop "DataRate,CameraRate,..."
  const std::string error = InputErrorOf([&] { ReadTrcFromString(text, "markers.trc"); });
  EXPECT_TRUE(Contains(error, "markers.trc: line 2: expected the TRC header keys")) << error;
}

TEST(BadText, TrcWithoutPathFileTypeAndNonNumericRate) {
  EXPECT_TRUE(Contains(InputErrorOf([] { ReadTrcFromString("hello\n", "a.trc"); }),
                       "a.trc: line 1: expected the TRC header 'PathFileType'"));
  const std::string text =
      "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tNumMarkers\tUnits\nfast\t1\tmm\n"
      "Frame#\tTime\tA\n\t\tX1\tY1\tZ1\n1\t0\t1\t2\t3\n";
  EXPECT_TRUE(Contains(InputErrorOf([&] { ReadTrcFromString(text, "b.trc"); }),
                       "b.trc: line 3, column 1: expected a number (DataRate), found 'fast'"));
}

TEST(BadText, MotiveWithoutTypeRowOrWithABadCell) {
  const std::string no_type =
      "Format Version,1.23,Export Frame Rate,100,Length Units,Meters\n\n"
      ",Name,A,A,A\n,,Position,Position,Position\nFrame,Time (Seconds),X,Y,Z\n0,0,1,2,3\n";
  EXPECT_TRUE(Contains(InputErrorOf([&] { ReadMotiveCsvFromString(no_type, "m.csv"); }),
                       "m.csv: line 5: missing the Type row"));
  const std::string bad_cell =
      "Format Version,1.23,Export Frame Rate,100,Length Units,Meters\n\n"
      ",Type,Marker,Marker,Marker\n,Name,A,A,A\n,,Position,Position,Position\n"
      "Frame,Time (Seconds),X,Y,Z\n0,0,1,two,3\n";
  EXPECT_TRUE(Contains(InputErrorOf([&] { ReadMotiveCsvFromString(bad_cell, "m.csv"); }),
                       "m.csv: line 7, column 4: expected a coordinate"));
}

TEST(BadText, EveryTruncationOfTheTextFilesIsAnInputErrorOrAValidRead) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_trc, "data/mocap/text/nexus_markers.trc");
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  // The header lines and first data rows of each file, cut at every length.
  const std::size_t kLength = 3000;
  const std::string trc = ReadTextFile(nexus_trc).substr(0, kLength);
  const std::string csv = ReadTextFile(nexus_csv).substr(0, kLength);
  std::size_t errors = 0;
  for (std::size_t n = 0; n <= kLength; ++n) {
    for (int reader = 0; reader < 2; ++reader) {
      try {
        if (reader == 0) ReadTrcFromString(trc.substr(0, n), "trc");
        if (reader == 1) ReadNexusCsvFromString(csv.substr(0, n), "csv");
      } catch (const InputError& e) {
        ASSERT_TRUE(Contains(e.what(), ": line ")) << e.what();
        ++errors;
      }
    }
  }
  // Every cut inside the 5 header lines is an error; cuts inside a data row
  // are errors (too few columns) unless they fall just after a line end.
  EXPECT_GT(errors, kLength);
}

}  // namespace
}  // namespace ccsrm::mocap
