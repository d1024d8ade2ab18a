// OpenSim TRC reader (layout in text_formats.h).
#include <map>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/mocap/text_formats.h"
#include "text_table.h"
#include "utf8.h"

namespace ccsrm::mocap {

using internal::FailAtCell;
using internal::FailAtLine;
using internal::Quoted;
using internal::TextRow;

MarkerTable ReadTrcFromString(const std::string& text, const std::string& name) {
  const std::vector<TextRow> rows = internal::SplitRows(text, internal::GuessDelimiter(text));
  // Header: rows 0-4 (lines 1-5).
  if (rows.empty() || rows[0].cell(0) != "PathFileType") {
    FailAtLine(name, 1,
               "expected the TRC header 'PathFileType', found " +
                   Quoted(rows.empty() ? std::string() : rows[0].cell(0)));
  }
  if (rows.size() < 5) {
    FailAtLine(name, rows.size() + 1,
               "expected the 5 TRC header lines (PathFileType, keys, values, marker names, "
               "X/Y/Z labels), the file ends after " +
                   std::to_string(rows.size()));
  }
  const TextRow& keys = rows[1];
  const TextRow& values = rows[2];
  std::map<std::string, std::size_t> column_of;
  for (std::size_t c = 0; c < keys.cells.size(); ++c) {
    if (!keys.cells[c].empty()) column_of.emplace(keys.cells[c], c);
  }
  auto require_key = [&](const std::string& key) {
    const auto it = column_of.find(key);
    if (it == column_of.end()) {
      FailAtLine(name, keys.line,
                 "expected the TRC header keys (DataRate, CameraRate, NumFrames, NumMarkers, "
                 "Units, ...), key '" +
                     key + "' is missing (first cell " + Quoted(keys.cell(0)) + ")");
    }
    return it->second;
  };
  const std::size_t rate_column = require_key("DataRate");
  const std::size_t markers_column = require_key("NumMarkers");
  const std::size_t units_column = require_key("Units");
  const double rate = internal::NumberCell(name, values, rate_column, "DataRate");
  if (rate <= 0) FailAtCell(name, values.line, rate_column, "DataRate must be positive");
  const std::int64_t marker_count =
      internal::IntegerCell(name, values, markers_column, "NumMarkers");
  if (marker_count < 0 || marker_count > 100000) {
    FailAtCell(name, values.line, markers_column, "NumMarkers must be between 0 and 100000");
  }
  const auto n = static_cast<std::size_t>(marker_count);
  std::string units;
  const std::optional<double> metres_per_unit =
      internal::MetresPerLengthUnit(values.cell(units_column), &units);
  if (!metres_per_unit) {
    FailAtCell(name, values.line, units_column,
               "expected Units mm, cm or m, found " + Quoted(values.cell(units_column)));
  }

  // Marker names every third column from column 3 ("Frame#", "Time", name, _, _).
  const TextRow& names = rows[3];
  if (names.cell(0) != "Frame#") {
    FailAtCell(
        name, names.line, 0,
        "expected the marker name line starting with 'Frame#', found " + Quoted(names.cell(0)));
  }
  std::vector<std::string> labels(n);
  for (std::size_t k = 0; k < n; ++k) {
    labels[k] = internal::AsUtf8(names.cell(2 + 3 * k));
    if (labels[k].empty()) {
      FailAtCell(name, names.line, 2 + 3 * k,
                 "expected the name of marker " + std::to_string(k + 1) + " of " +
                     std::to_string(n) + " (NumMarkers)");
    }
  }
  const TextRow& components = rows[4];
  if (n > 0 && components.cell(2).empty()) {
    FailAtCell(name, components.line, 2, "expected the coordinate labels X1 Y1 Z1 ...");
  }

  // Data rows, skipping blank lines.
  const std::size_t columns = 2 + 3 * n;
  std::vector<const TextRow*> data;
  for (std::size_t r = 5; r < rows.size(); ++r) {
    if (rows[r].blank()) continue;
    if (rows[r].cells.size() < columns) {
      FailAtLine(name, rows[r].line,
                 "expected " + std::to_string(columns) + " columns (Frame#, Time, X/Y/Z of " +
                     std::to_string(n) + " markers), found " +
                     std::to_string(rows[r].cells.size()));
    }
    for (std::size_t c = columns; c < rows[r].cells.size(); ++c) {
      if (!rows[r].cells[c].empty()) {
        FailAtCell(name, rows[r].line, c,
                   "expected " + std::to_string(columns) + " columns, found a value " +
                       Quoted(rows[r].cells[c]) + " beyond them");
      }
    }
    data.push_back(&rows[r]);
  }

  MarkerTable table;
  table.format = "trc";
  table.units_in_file = units;
  table.rate_hz = rate;
  table.Reset(data.size(), labels, /*with_residual=*/false);
  std::size_t partial = 0;
  for (std::size_t f = 0; f < data.size(); ++f) {
    const TextRow& row = *data[f];
    const std::int64_t frame = internal::IntegerCell(name, row, 0, "Frame#");
    if (f == 0) table.first_frame_number = frame;
    internal::NumberCell(name, row, 1, "Time");
    for (std::size_t m = 0; m < n; ++m) {
      const std::size_t c = 2 + 3 * m;
      if (const auto p = internal::PointCells(name, row, c, c + 1, c + 2, &partial)) {
        table.set_position(f, m, *p * *metres_per_unit);
      }
    }
  }
  if (partial > 0) table.warnings.push_back(internal::PartialPointsWarning(partial));
  const auto frames_column = column_of.find("NumFrames");
  if (frames_column != column_of.end()) {
    const std::optional<double> stated = internal::ParseNumber(values.cell(frames_column->second));
    if (!stated || *stated != static_cast<double>(data.size())) {
      table.warnings.push_back("NumFrames says " + values.cell(frames_column->second) +
                               ", the file holds " + std::to_string(data.size()) +
                               " data rows; read the rows");
    }
  }
  return table;
}

MarkerTable ReadTrc(const std::string& path) { return ReadTrcFromString(ReadTextFile(path), path); }

}  // namespace ccsrm::mocap
