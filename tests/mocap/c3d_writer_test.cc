// The C3D writer: round trips through the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "ccsrm/mocap/c3d.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::InputErrorOf;

// Largest coordinate difference over samples valid in both; counts samples
// valid in only one.
double MaxDeviation(const MarkerTable& a, const MarkerTable& b, std::size_t* validity_mismatches) {
  double max = 0;
  *validity_mismatches = 0;
  for (std::size_t f = 0; f < a.frames(); ++f) {
    for (std::size_t m = 0; m < a.markers(); ++m) {
      if (a.is_valid(f, m) != b.is_valid(f, m)) {
        ++*validity_mismatches;
      } else if (a.is_valid(f, m)) {
        max = std::max(max, (a.position(f, m) - b.position(f, m)).cwiseAbs().maxCoeff());
      }
    }
  }
  return max;
}

// A synthetic trial: marker m at frame f sits at (f, m, 1) mm, and every 7th
// sample of marker 0 is missing.
MarkerTable SyntheticTable(std::size_t frames, std::size_t markers) {
  MarkerTable t;
  t.rate_hz = 200.0;
  t.first_frame_number = 5;
  t.format = "synthetic";
  std::vector<std::string> labels;
  for (std::size_t m = 0; m < markers; ++m) labels.push_back("marker_" + std::to_string(m));
  t.Reset(frames, labels, /*with_residual=*/false);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t m = 0; m < markers; ++m) {
      if (m == 0 && f % 7 == 3) continue;
      t.set_position(f, m, Eigen::Vector3d(f % 1000, m, 1.0) * 1e-3);
    }
  }
  return t;
}

// Renames a parameter in an encoded file (same length, so offsets stay).
void RenameParameter(std::vector<std::uint8_t>* bytes, const std::string& from,
                     const std::string& to) {
  ASSERT_EQ(from.size(), to.size());
  const auto it = std::search(bytes->begin(), bytes->end(), from.begin(), from.end());
  ASSERT_NE(it, bytes->end()) << from;
  std::copy(to.begin(), to.end(), it);
}

TEST(C3dWriter, Eb015RoundTripIsIdenticalWithinFloatPrecision) {
  CCSRM_SHARED_FILE_OR_SKIP(vendor_file, "data/mocap/c3d/Eb015pr.c3d");
  const fs::path dir = FreshTempDir("c3d_round_trip");
  const MarkerTable original = ReadC3d(vendor_file);
  const std::string path = (dir / "copy.c3d").string();
  WriteC3d(path, original);
  // Only the finished file is left (the temporary was renamed).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

  const MarkerTable copy = ReadC3d(path);
  EXPECT_EQ(copy.processor, "intel");
  EXPECT_EQ(copy.storage, "float");
  EXPECT_EQ(copy.units_in_file, "mm");
  EXPECT_EQ(copy.labels, original.labels);
  EXPECT_EQ(copy.frames(), original.frames());
  EXPECT_DOUBLE_EQ(copy.rate_hz, original.rate_hz);
  EXPECT_EQ(copy.first_frame_number, original.first_frame_number);
  EXPECT_NEAR(copy.point_scale_m, original.point_scale_m, 1e-12);
  EXPECT_EQ(copy.up_axis, original.up_axis);
  std::size_t mismatches = 0;
  const double deviation = MaxDeviation(original, copy, &mismatches);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_LT(deviation, 1e-7);  // float precision of mm values below 1 m
  EXPECT_EQ(copy.residual_m, original.residual_m);
  EXPECT_EQ(copy.camera_mask, original.camera_mask);
  std::cout << "[ info ] Eb015pr.c3d write/read: max deviation " << deviation * 1e3 << " mm\n";
}

TEST(C3dWriter, IntegerFileRoundTripsThroughFloatStorageInMetres) {
  CCSRM_SHARED_FILE_OR_SKIP(vendor_file, "data/mocap/c3d/sgi_int.c3d");
  const MarkerTable original = ReadC3d(vendor_file);
  C3dWriteOptions options;
  options.units = "m";
  const MarkerTable copy = ReadC3dFromMemory(EncodeC3d(original, options), "memory");
  EXPECT_EQ(copy.units_in_file, "m");
  std::size_t mismatches = 0;
  // Float precision of metre values up to 2 m: one ulp is 1.2e-7 m.
  EXPECT_LT(MaxDeviation(original, copy, &mismatches), 2.5e-7);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(copy.camera_mask, original.camera_mask);
  // The residual steps survive; the step itself is a float in each file.
  for (std::size_t i = 0; i < copy.residual_m.size(); ++i) {
    ASSERT_NEAR(copy.residual_m[i], original.residual_m[i], 1e-6 * original.point_scale_m * 255)
        << i;
  }
}

TEST(C3dWriter, MoreThan255MarkersGoToLabels2AndLabels3) {
  const MarkerTable original = SyntheticTable(3, 600);
  const std::vector<std::uint8_t> bytes = EncodeC3d(original);
  const std::string labels3 = "LABELS3";
  EXPECT_NE(std::search(bytes.begin(), bytes.end(), labels3.begin(), labels3.end()), bytes.end());
  const MarkerTable copy = ReadC3dFromMemory(bytes, "memory");
  EXPECT_EQ(copy.labels, original.labels);
  std::size_t mismatches = 0;
  EXPECT_LT(MaxDeviation(original, copy, &mismatches), 1e-9);
  EXPECT_EQ(mismatches, 0u);
}

TEST(C3dWriter, MoreThan65535FramesAreCountedThroughLongFramesOrTheTrialGroup) {
  const MarkerTable original = SyntheticTable(70001, 2);
  std::vector<std::uint8_t> bytes = EncodeC3d(original);
  {
    const MarkerTable copy = ReadC3dFromMemory(bytes, "long_frames");
    EXPECT_EQ(copy.frames(), 70001u);
    EXPECT_EQ(copy.first_frame_number, 5);
    EXPECT_TRUE(copy.warnings.empty());
    std::size_t mismatches = 0;
    EXPECT_LT(MaxDeviation(original, copy, &mismatches), 1e-9);
    EXPECT_EQ(mismatches, 0u);
  }
  // Without POINT:LONG_FRAMES the reader falls back to TRIAL:ACTUAL_*_FIELD.
  RenameParameter(&bytes, "LONG_FRAMES", "LONG_FRAMEX");
  {
    const MarkerTable copy = ReadC3dFromMemory(bytes, "trial");
    EXPECT_EQ(copy.frames(), 70001u);
    EXPECT_EQ(copy.first_frame_number, 5);
    EXPECT_TRUE(copy.warnings.empty());
  }
  // Without either, the frame count comes from the size of the data section.
  RenameParameter(&bytes, "ACTUAL_END_FIELD", "ACTUAL_END_FIELX");
  {
    const MarkerTable copy = ReadC3dFromMemory(bytes, "file size");
    EXPECT_EQ(copy.frames(), 70001u);
    ASSERT_EQ(copy.warnings.size(), 1u);
    EXPECT_NE(copy.warnings[0].find("65535"), std::string::npos) << copy.warnings[0];
  }
}

TEST(C3dWriter, RejectsAnInconsistentTableAndBadOptions) {
  const fs::path dir = FreshTempDir("c3d_writer_rejects");
  MarkerTable table = SyntheticTable(4, 2);
  table.positions_m.pop_back();
  const std::string path = (dir / "bad.c3d").string();
  EXPECT_NE(InputErrorOf([&] { WriteC3d(path, table); }).find("positions_m"), std::string::npos);
  EXPECT_FALSE(fs::exists(path));

  C3dWriteOptions options;
  options.units = "inch";
  EXPECT_NE(InputErrorOf([&] { EncodeC3d(SyntheticTable(2, 1), options); }).find("units"),
            std::string::npos);

  MarkerTable long_label = SyntheticTable(2, 1);
  long_label.labels[0] = std::string(300, 'x');
  EXPECT_NE(InputErrorOf([&] { EncodeC3d(long_label); }).find("255"), std::string::npos);
}

}  // namespace
}  // namespace ccsrm::mocap
