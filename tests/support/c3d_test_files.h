#pragma once
// C3D files built with ccsrm's own writer for the reader tests, and the
// defects some vendors' files carry, applied to their bytes.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::testing {

// `markers` markers with 20-character labels ("arm:plate_marker_007") over
// `frames` frames at 100 Hz: marker m at frame f sits at (f, m, 1) mm, every
// 5th sample of marker 1 is not seen. With 128 markers, POINT:LABELS alone
// holds 2560 bytes, so the parameter section fills blocks 2-7 and the data
// starts at block 8.
inline mocap::MarkerTable LongLabelTable(std::size_t markers, std::size_t frames) {
  mocap::MarkerTable table;
  table.rate_hz = 100.0;
  table.first_frame_number = 1;
  std::vector<std::string> labels;
  for (std::size_t m = 0; m < markers; ++m) {
    char label[32];
    std::snprintf(label, sizeof label, "arm:plate_marker_%03zu", m);
    labels.push_back(label);
  }
  table.Reset(frames, labels, /*with_residual=*/false);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t m = 0; m < markers; ++m) {
      if (m == 1 && f % 5 == 2) continue;
      table.set_position(f, m, Eigen::Vector3d(f, m, 1.0) * 1e-3);
    }
  }
  return table;
}

// First block of the parameter section (header byte 0) and of the data
// (header word 9) of an Intel file.
inline int ParameterBlock(const std::vector<std::uint8_t>& c3d) { return c3d.at(0); }
inline int DataStartBlock(const std::vector<std::uint8_t>& c3d) {
  return c3d.at(16) | (c3d.at(17) << 8);
}

// The same file with another block count in byte 2 of its parameter section
// (the count some writers get wrong; readers should take it as a hint).
inline std::vector<std::uint8_t> WithDeclaredParameterBlocks(std::vector<std::uint8_t> c3d,
                                                             std::uint8_t blocks) {
  c3d.at((ParameterBlock(c3d) - 1) * 512 + 2) = blocks;
  return c3d;
}

}  // namespace ccsrm::testing
