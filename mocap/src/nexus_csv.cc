// Vicon Nexus CSV reader: the "Trajectories" block (layout in text_formats.h).
#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/mocap/text_formats.h"
#include "text_table.h"
#include "utf8.h"

namespace ccsrm::mocap {
namespace {

using internal::FailAtCell;
using internal::FailAtLine;
using internal::Quoted;
using internal::TextRow;

bool EqualsIgnoringCase(const std::string& a, const std::string& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

}  // namespace

MarkerTable ReadNexusCsvFromString(const std::string& text, const std::string& name) {
  const std::vector<TextRow> rows = internal::SplitRows(text, ',');
  std::size_t t = 0;
  while (t < rows.size() && !EqualsIgnoringCase(rows[t].cell(0), "Trajectories")) ++t;
  if (t == rows.size()) {
    FailAtLine(name, 1,
               "expected a Vicon Nexus 'Trajectories' block (a line starting with "
               "'Trajectories'), found none");
  }
  const std::size_t header_end = t + 4;  // "Trajectories", rate, names, components
  if (header_end > rows.size()) {
    FailAtLine(name, rows.back().line + 1,
               "expected the rate, marker name and X/Y/Z lines after 'Trajectories' (line " +
                   std::to_string(rows[t].line) + "), the file ends");
  }
  const TextRow& rate_row = rows[t + 1];
  const double rate = internal::NumberCell(name, rate_row, 0, "the frame rate in Hz");
  if (rate <= 0) FailAtCell(name, rate_row.line, 0, "the frame rate must be positive");

  // The component line fixes the marker count: Frame, Sub Frame, X, Y, Z, X, ...
  const TextRow& components = rows[t + 3];
  if (!EqualsIgnoringCase(components.cell(0), "Frame")) {
    FailAtCell(
        name, components.line, 0,
        "expected the line 'Frame,Sub Frame,X,Y,Z,...', found " + Quoted(components.cell(0)));
  }
  std::size_t n = 0;
  while (!components.cell(2 + 3 * n).empty()) {
    const char* axes[] = {"X", "Y", "Z"};
    for (std::size_t a = 0; a < 3; ++a) {
      const std::size_t c = 2 + 3 * n + a;
      if (!EqualsIgnoringCase(components.cell(c), axes[a])) {
        FailAtCell(name, components.line, c,
                   std::string("expected '") + axes[a] + "', found " + Quoted(components.cell(c)));
      }
    }
    ++n;
  }
  const std::size_t columns = 2 + 3 * n;

  const TextRow& names = rows[t + 2];
  std::vector<std::string> labels(n);
  for (std::size_t k = 0; k < n; ++k) {
    labels[k] = internal::AsUtf8(names.cell(2 + 3 * k));
    if (labels[k].empty()) {
      FailAtCell(name, names.line, 2 + 3 * k,
                 "expected the name of marker " + std::to_string(k + 1) + " (subject:marker)");
    }
  }

  // Units line (",,mm,mm,mm,..."), present in current Nexus versions.
  MarkerTable table;
  std::size_t r = header_end;
  std::vector<double> metres_per_unit(n, 1e-3);
  table.units_in_file = "mm";
  if (r < rows.size() && rows[r].cell(0).empty() && !rows[r].blank()) {
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t a = 0; a < 3; ++a) {
        const std::size_t c = 2 + 3 * k + a;
        std::string unit;
        const std::optional<double> metres = internal::MetresPerLengthUnit(rows[r].cell(c), &unit);
        if (!metres) {
          FailAtCell(name, rows[r].line, c,
                     "expected a unit (mm, cm or m), found " + Quoted(rows[r].cell(c)));
        }
        metres_per_unit[k] = *metres;
        if (k == 0) table.units_in_file = unit;
      }
    }
    ++r;
  } else {
    table.warnings.push_back("no units line after the X/Y/Z line; assumed mm");
  }

  // Data rows up to a blank line, the next block (a non-numeric first cell) or
  // the end of the file.
  std::vector<const TextRow*> data;
  for (; r < rows.size(); ++r) {
    const TextRow& row = rows[r];
    if (row.blank()) break;
    if (!internal::ParseNumber(row.cell(0))) {
      if (data.empty()) {
        FailAtCell(name, row.line, 0, "expected a frame number, found " + Quoted(row.cell(0)));
      }
      break;
    }
    if (row.cells.size() < columns) {
      FailAtLine(name, row.line,
                 "expected " + std::to_string(columns) + " columns (Frame, Sub Frame, X/Y/Z of " +
                     std::to_string(n) + " markers), found " + std::to_string(row.cells.size()));
    }
    for (std::size_t c = columns; c < row.cells.size(); ++c) {
      if (!row.cells[c].empty()) {
        FailAtCell(name, row.line, c,
                   "expected " + std::to_string(columns) + " columns, found a value " +
                       Quoted(row.cells[c]) + " beyond them");
      }
    }
    data.push_back(&row);
  }

  table.format = "nexus-csv";
  table.rate_hz = rate;
  table.up_axis = "";
  table.Reset(data.size(), labels, /*with_residual=*/false);
  std::size_t partial = 0;
  for (std::size_t f = 0; f < data.size(); ++f) {
    const TextRow& row = *data[f];
    const std::int64_t frame = internal::IntegerCell(name, row, 0, "Frame");
    if (f == 0) table.first_frame_number = frame;
    internal::IntegerCell(name, row, 1, "Sub Frame");
    for (std::size_t m = 0; m < n; ++m) {
      const std::size_t c = 2 + 3 * m;
      if (const auto p = internal::PointCells(name, row, c, c + 1, c + 2, &partial)) {
        table.set_position(f, m, *p * metres_per_unit[m]);
      }
    }
  }
  if (partial > 0) table.warnings.push_back(internal::PartialPointsWarning(partial));
  return table;
}

MarkerTable ReadNexusCsv(const std::string& path) {
  return ReadNexusCsvFromString(ReadTextFile(path), path);
}

}  // namespace ccsrm::mocap
