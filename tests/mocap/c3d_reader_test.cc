// The C3D reader against the real vendor files of ../shared/data/mocap/c3d
// (skipped, naming the file, where that folder is missing).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "c3d_test_files.h"
#include "ccsrm/mocap/c3d.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

struct Agreement {
  double max_position_deviation_m = 0.0;
  std::size_t validity_mismatches = 0;
  double max_residual_deviation_m = 0.0;
  std::size_t camera_mask_mismatches = 0;
};

// Compares two decodings of the same trial sample by sample.
Agreement Compare(const MarkerTable& a, const MarkerTable& b) {
  Agreement out;
  EXPECT_EQ(a.frames(), b.frames());
  EXPECT_EQ(a.labels, b.labels);
  if (a.frames() != b.frames() || a.markers() != b.markers()) return out;
  for (std::size_t f = 0; f < a.frames(); ++f) {
    for (std::size_t m = 0; m < a.markers(); ++m) {
      if (a.is_valid(f, m) != b.is_valid(f, m)) {
        ++out.validity_mismatches;
        continue;
      }
      if (!a.is_valid(f, m)) continue;
      out.max_position_deviation_m =
          std::max(out.max_position_deviation_m,
                   (a.position(f, m) - b.position(f, m)).cwiseAbs().maxCoeff());
      if (a.has_residual && b.has_residual) {
        const std::size_t i = f * a.markers() + m;
        out.max_residual_deviation_m =
            std::max(out.max_residual_deviation_m, std::abs(a.residual_m[i] - b.residual_m[i]));
        if (a.camera_mask[i] != b.camera_mask[i]) ++out.camera_mask_mismatches;
      }
    }
  }
  return out;
}

std::size_t CountInvalid(const MarkerTable& t) { return Summarize(t).invalid_points; }

struct Variant {
  std::string file;
  std::string processor;  // "intel", "dec", "mips"
  std::string storage;    // "integer", "float"
  // Samples whose camera mask differs from the reference in the file itself.
  std::size_t camera_mask_mismatches = 0;
};

// Reads the six processor × storage variants of one trial and checks they
// agree with the Intel float file: float files to 1e-6 m, integer files to
// one integer step (|POINT:SCALE|), with the same invalid samples, residuals
// and camera masks.
void ExpectAllFormatsAgree(const std::vector<Variant>& variants, const std::string& reference,
                           std::size_t frames, std::size_t markers, double rate_hz) {
  CCSRM_SHARED_FILE_OR_SKIP(reference_path, "data/mocap/c3d/" + reference);
  const MarkerTable ref = ReadC3d(reference_path);
  ASSERT_EQ(ref.frames(), frames);
  ASSERT_EQ(ref.markers(), markers);
  EXPECT_DOUBLE_EQ(ref.rate_hz, rate_hz);
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.file);
    CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/" + v.file);
    const MarkerTable t = ReadC3d(path);
    EXPECT_EQ(t.format, "c3d");
    EXPECT_EQ(t.processor, v.processor);
    EXPECT_EQ(t.storage, v.storage);
    EXPECT_EQ(t.frames(), frames);
    EXPECT_EQ(t.markers(), markers);
    EXPECT_DOUBLE_EQ(t.rate_hz, rate_hz);
    EXPECT_EQ(t.units_in_file, "mm");
    EXPECT_TRUE(t.has_residual);
    EXPECT_NEAR(t.point_scale_m, ref.point_scale_m, 1e-12);
    const Agreement agreement = Compare(ref, t);
    EXPECT_EQ(agreement.validity_mismatches, 0u);
    EXPECT_EQ(agreement.camera_mask_mismatches, v.camera_mask_mismatches);
    EXPECT_LT(agreement.max_residual_deviation_m, 1e-9);
    if (v.storage == "float") {
      EXPECT_LT(agreement.max_position_deviation_m, 1e-6);
    } else {
      EXPECT_LE(agreement.max_position_deviation_m, ref.point_scale_m);
    }
    EXPECT_EQ(CountInvalid(t), CountInvalid(ref));
    std::cout << "[ info ] " << v.file << " (" << t.processor << ", " << t.storage
              << "): max |p - p_ref| = " << agreement.max_position_deviation_m * 1e3 << " mm (ref "
              << reference << "), invalid points " << CountInvalid(t) << "\n";
  }
}

TEST(C3dReader, Eb015DecodesToOneTrialInAllProcessorAndStorageFormats) {
  ExpectAllFormatsAgree({{"Eb015pi.c3d", "intel", "integer"},
                         {"Eb015pr.c3d", "intel", "float"},
                         {"Eb015vi.c3d", "dec", "integer"},
                         {"Eb015vr.c3d", "dec", "float"},
                         {"Eb015si.c3d", "mips", "integer"},
                         {"Eb015sr.c3d", "mips", "float"}},
                        "Eb015pr.c3d", 450, 26, 50.0);
}

TEST(C3dReader, Sample02DecodesToOneTrialInAllProcessorAndStorageFormats) {
  ExpectAllFormatsAgree({{"pc_int.c3d", "intel", "integer"},
                         {"pc_real.c3d", "intel", "float"},
                         // This file's own residual words carry other camera
                         // bits in 96 samples (0x3A09 where pc_int.c3d has
                         // 0x3909): a property of the sample, not of decoding.
                         {"dec_int.c3d", "dec", "integer", 96},
                         {"dec_real.c3d", "dec", "float"},
                         {"sgi_int.c3d", "mips", "integer"},
                         {"sgi_real.c3d", "mips", "float"}},
                        "pc_real.c3d", 89, 36, 50.0);
}

TEST(C3dReader, Eb015HeaderValuesAndFirstFrameAreInMetres) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/Eb015vr.c3d");
  const MarkerTable t = ReadC3d(path);  // DEC floats in the parameters too
  EXPECT_NEAR(t.point_scale_m, 0.0833333e-3, 1e-9);
  EXPECT_EQ(t.first_frame_number, 1);
  EXPECT_EQ(t.labels.front(), "RFT1");  // "RFT1" padded with spaces in the file
  EXPECT_EQ(t.labels.back(), "pv4");
  EXPECT_EQ(t.up_axis, "z");  // POINT:Y_SCREEN = +Z
  const Eigen::Vector3d p = t.position(0, *t.index_of("RFT1"));
  EXPECT_NEAR(p.x(), 0.248583, 1e-6);
  EXPECT_NEAR(p.y(), 0.226833, 1e-6);
  EXPECT_NEAR(p.z(), 0.037417, 1e-6);
  EXPECT_FALSE(t.is_valid(0, *t.index_of("LFT1")));
  EXPECT_TRUE(std::isnan(t.position(0, *t.index_of("LFT1")).x()));
}

TEST(C3dReader, ResidualWordSplitsIntoCameraMaskAndResidual) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/Eb015pi.c3d");
  const MarkerTable t = ReadC3d(path);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < t.frames() * t.markers(); ++i) {
    const bool seen = std::isfinite(t.positions_m[3 * i]);
    if (!seen) {
      EXPECT_EQ(t.residual_m[i], -1.0);
      EXPECT_EQ(t.camera_mask[i], 0);
      continue;
    }
    ++valid;
    // Residual = low byte × |POINT:SCALE|: a whole number of steps in 0..255.
    const double steps = t.residual_m[i] / t.point_scale_m;
    EXPECT_NEAR(steps, std::round(steps), 1e-6);
    EXPECT_LE(steps, 255.5);
    EXPECT_LT(t.camera_mask[i], 128);
  }
  EXPECT_GT(valid, 0u);
  // The most common word of this file is 10501 = 0x2905: cameras 0x29, 5 steps.
  std::size_t matches = 0;
  for (std::size_t i = 0; i < t.frames() * t.markers(); ++i) {
    if (t.camera_mask[i] == 0x29 && std::abs(t.residual_m[i] - 5 * t.point_scale_m) < 1e-12) {
      ++matches;
    }
  }
  EXPECT_EQ(matches, 325u);
}

TEST(C3dReader, OptiTrackSprintHasAboutThirtyNinePercentInvalidPoints) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/optitrack_basket_sprint.c3d");
  const MarkerTable t = ReadC3d(path);
  EXPECT_EQ(t.frames(), 3678u);
  EXPECT_EQ(t.markers(), 26u);
  EXPECT_DOUBLE_EQ(t.rate_hz, 120.0);
  EXPECT_EQ(t.units_in_file, "m");
  EXPECT_EQ(t.storage, "float");
  EXPECT_EQ(t.first_frame_number, 0);
  const MarkerStatistics stats = Summarize(t);
  EXPECT_GT(stats.invalid_fraction, 0.37);
  EXPECT_LT(stats.invalid_fraction, 0.41);
  EXPECT_EQ(stats.invalid_points, 37068u);
  EXPECT_GT(stats.longest_gap_frames, 0u);
  std::cout << "[ info ] optitrack_basket_sprint.c3d: invalid fraction " << stats.invalid_fraction
            << " (" << stats.invalid_points << " of " << t.frames() * t.markers()
            << "), longest gap " << stats.longest_gap_frames << " frames ("
            << stats.longest_gap_marker << " from frame index " << stats.longest_gap_first_frame
            << ")\n";
  // Every marker's visibility is in (0, 1] and they average to 1 - invalid.
  double sum = 0;
  for (double v : stats.visibility) {
    EXPECT_GT(v, 0.0);
    EXPECT_LE(v, 1.0);
    sum += v;
  }
  EXPECT_NEAR(1.0 - sum / t.markers(), stats.invalid_fraction, 1e-12);
}

// ---- Files that disagree with themselves -----------------------------------------

using ccsrm::testing::DataStartBlock;
using ccsrm::testing::LongLabelTable;
using ccsrm::testing::ParameterBlock;
using ccsrm::testing::WithDeclaredParameterBlocks;
using ::testing::HasSubstr;

bool Contains(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// Same frames, labels, rate, first frame number and samples (NaN where not
// seen in both).
void ExpectSameTrial(const MarkerTable& a, const MarkerTable& b) {
  EXPECT_EQ(a.frames(), b.frames());
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.first_frame_number, b.first_frame_number);
  EXPECT_EQ(a.positions_m.size(), b.positions_m.size());
  EXPECT_TRUE(testing::SameStart(a.positions_m, b.positions_m));
  EXPECT_TRUE(testing::SameStart(a.residual_m, b.residual_m));
}

// The defect seen in the field: the section declares 3 blocks, the header's
// data start (block 8) leaves blocks 2-7 to parameters, and POINT:LABELS
// runs to block 6. Readers that follow the records up to the data read the
// file; the declared count is only a hint, reported in a warning.
TEST(C3dSelfDisagreement, TooFewDeclaredParameterBlocksReadLikeTheCorrectFile) {
  const std::vector<std::uint8_t> correct = EncodeC3d(LongLabelTable(128, 40));
  ASSERT_EQ(ParameterBlock(correct), 2);
  ASSERT_EQ(DataStartBlock(correct), 8);
  const MarkerTable reference = ReadC3dFromMemory(correct, "correct.c3d");
  EXPECT_TRUE(reference.warnings.empty()) << reference.warnings.front();

  const MarkerTable t =
      ReadC3dFromMemory(WithDeclaredParameterBlocks(correct, 3), "three_blocks.c3d");
  ExpectSameTrial(reference, t);
  EXPECT_EQ(t.labels[127], "arm:plate_marker_127");
  EXPECT_EQ(t.position(0, 127), reference.position(0, 127));
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_THAT(t.warnings[0], HasSubstr("the parameter section (byte 514) declares 3 block(s), but "
                                       "its records fill blocks 2-7"));
  EXPECT_THAT(t.warnings[0], HasSubstr("the data starts at block 8"));
  // No block count at all (0) reads the same way.
  const MarkerTable none = ReadC3dFromMemory(WithDeclaredParameterBlocks(correct, 0), "zero.c3d");
  ExpectSameTrial(reference, none);
  EXPECT_TRUE(Contains(none.warnings, "declares 0 block(s)"));
}

TEST(C3dSelfDisagreement, DeclaredBlocksOverlappingTheDataAreReadUpToTheDataStart) {
  const std::vector<std::uint8_t> correct = EncodeC3d(LongLabelTable(128, 40));
  const MarkerTable t = ReadC3dFromMemory(WithDeclaredParameterBlocks(correct, 9), "nine.c3d");
  ExpectSameTrial(ReadC3dFromMemory(correct, "correct.c3d"), t);
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_THAT(t.warnings[0], HasSubstr("declares 9 block(s), to byte 5120, past the data start "
                                       "(block 8, byte 3584)"));
}

TEST(C3dSelfDisagreement, ParametersRunningPastTheDataStartAreStillRefused) {
  const std::vector<std::uint8_t> correct = EncodeC3d(LongLabelTable(128, 40));
  // Header word 9 puts the data at block 4, in the middle of POINT:LABELS.
  std::vector<std::uint8_t> bytes = correct;
  bytes[16] = 4;
  std::string error = testing::InputErrorOf([&] { ReadC3dFromMemory(bytes, "early.c3d"); });
  EXPECT_THAT(error, HasSubstr("early.c3d: byte "));
  EXPECT_THAT(error, HasSubstr("of data of parameter LABELS (dimensions 20x128), but the data "
                               "section starts at byte 1536 (block 4, header word 9)"));
  // POINT:DATA_START alone does the same (header word 9 left at block 8).
  bytes = correct;
  const std::string name = "DATA_START";
  const auto record = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
  ASSERT_NE(record, bytes.end());
  const std::size_t data_at = (record - bytes.begin()) + name.size() + 2 + 2;  // offset, type, dims
  ASSERT_EQ(bytes[data_at], 8);
  bytes[data_at] = 4;
  error = testing::InputErrorOf([&] { ReadC3dFromMemory(bytes, "early.c3d"); });
  EXPECT_THAT(error, HasSubstr("POINT:DATA_START: expected the data section after the parameter "
                               "records, which end at byte "));
  EXPECT_THAT(error, HasSubstr("found block 4 (byte 1536)"));
}

// The same defect in a real vendor file.
TEST(C3dSelfDisagreement, Eb015DeclaringThreeOfItsNineBlocksReadsLikeTheOriginal) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/mocap/c3d/Eb015pi.c3d");
  const std::vector<std::uint8_t> bytes = testing::ReadBytes(path);
  const MarkerTable original = ReadC3dFromMemory(bytes, path);
  const MarkerTable t = ReadC3dFromMemory(WithDeclaredParameterBlocks(bytes, 3), path);
  ExpectSameTrial(original, t);
  EXPECT_EQ(t.warnings.size(), original.warnings.size() + 1);
  EXPECT_TRUE(Contains(t.warnings, "declares 3 block(s), but its records fill blocks 2-"));
}

TEST(MarkerStatistics, LongestGapCountsRunsAtTheEdgesAndWholeAbsence) {
  MarkerTable t;
  t.rate_hz = 100;
  t.Reset(6, {"a", "b", "c"}, false);
  // a: seen in frames 1..4 (gaps of 1 at both ends); b: never seen; c: always.
  for (std::size_t f = 1; f <= 4; ++f) t.set_position(f, 0, Eigen::Vector3d(0, 0, f));
  for (std::size_t f = 0; f < 6; ++f) t.set_position(f, 2, Eigen::Vector3d(1, 0, 0));
  const MarkerStatistics stats = Summarize(t);
  EXPECT_EQ(stats.invalid_points, 2u + 6u);
  EXPECT_NEAR(stats.invalid_fraction, 8.0 / 18.0, 1e-15);
  EXPECT_EQ(stats.longest_gap_frames, 6u);
  EXPECT_EQ(stats.longest_gap_marker, "b");
  EXPECT_EQ(stats.visibility, (std::vector<double>{4.0 / 6.0, 0.0, 1.0}));
}

}  // namespace
}  // namespace ccsrm::mocap
