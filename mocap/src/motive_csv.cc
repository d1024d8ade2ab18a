// OptiTrack Motive CSV reader (layout in text_formats.h). Example header,
// format 1.23 (columns aligned with the data rows):
//   Format Version,1.23,Take Name,walk,Capture Frame Rate,120.000000,...
//   <blank>
//   ,Type,Rigid Body,...,Rigid Body Marker,...,Marker,Marker,Marker
//   ,Name,Arm,...,Arm:Marker1,...,Unlabeled 1000,Unlabeled 1000,...
//   ,ID,1,...
//   [,Parent,...]                      (format 1.24 and later)
//   ,,Rotation,...,Position,...,Position,Position,Position
//   Frame,Time (Seconds),X,Y,Z,W,...,X,Y,Z
//   0,0.000000,...
#include <algorithm>
#include <map>
#include <string>
#include <utility>
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

constexpr std::size_t kNoColumn = static_cast<std::size_t>(-1);

// The marker columns found in the header.
struct MarkerColumns {
  std::string label;
  std::string key;  // name + ID: what makes a marker unique
  std::size_t column[3] = {kNoColumn, kNoColumn, kNoColumn};
};

}  // namespace

MarkerTable ReadMotiveCsvFromString(const std::string& text, const std::string& name) {
  const std::vector<TextRow> rows = internal::SplitRows(text, ',');
  if (rows.empty() || rows[0].cell(0) != "Format Version") {
    FailAtLine(name, 1,
               "expected the Motive metadata line 'Format Version,...', found " +
                   Quoted(rows.empty() ? std::string() : rows[0].cell(0)));
  }
  std::map<std::string, std::pair<std::string, std::size_t>> metadata;  // key → (value, column)
  for (std::size_t c = 0; c + 1 < rows[0].cells.size(); c += 2) {
    metadata.emplace(rows[0].cells[c], std::make_pair(rows[0].cells[c + 1], c + 1));
  }

  // Header rows up to the "Frame,Time..." row.
  const TextRow* type_row = nullptr;
  const TextRow* name_row = nullptr;
  const TextRow* id_row = nullptr;
  const TextRow* component_row = nullptr;
  std::size_t r = 1;
  for (; r < rows.size() && rows[r].cell(0) != "Frame"; ++r) {
    const TextRow& row = rows[r];
    if (row.blank()) continue;
    const std::string& label = row.cell(0).empty() ? row.cell(1) : row.cell(0);
    if (label == "Type") {
      type_row = &row;
    } else if (label == "Name") {
      name_row = &row;
    } else if (label == "ID") {
      id_row = &row;
    } else if (label == "Parent") {
      // Skeleton hierarchy: not needed for markers.
    } else if (row.cell(0).empty() && row.cell(1).empty()) {
      component_row = &row;
    } else {
      FailAtCell(name, row.line, 0,
                 "expected a Motive header row (Type, Name, ID, Parent, the Rotation/Position "
                 "row or 'Frame,Time,...'), found " +
                     Quoted(row.cell(0).empty() ? row.cell(1) : row.cell(0)));
    }
  }
  if (r == rows.size()) {
    FailAtLine(name, rows.back().line + 1,
               "expected the header row 'Frame,Time (Seconds),X,Y,Z,...', the file ends");
  }
  const TextRow& axis_row = rows[r];
  auto require = [&](const TextRow* row, const char* what) {
    if (row == nullptr) {
      FailAtLine(name, axis_row.line,
                 std::string("missing the ") + what + " row before the 'Frame,Time,...' row");
    }
  };
  require(type_row, "Type");
  require(name_row, "Name");
  require(component_row, "Rotation/Position");

  // Marker position columns, grouped by name and ID in order of appearance.
  std::vector<MarkerColumns> markers;
  for (std::size_t c = 2; c < axis_row.cells.size(); ++c) {
    if (type_row->cell(c) != "Marker" || component_row->cell(c) != "Position") continue;
    const std::string& axis = axis_row.cell(c);
    const int a = axis == "X" ? 0 : axis == "Y" ? 1 : axis == "Z" ? 2 : -1;
    if (a < 0) {
      FailAtCell(name, axis_row.line, c,
                 "expected X, Y or Z for a marker position, found " + Quoted(axis));
    }
    const std::string& label = name_row->cell(c);
    if (label.empty()) FailAtCell(name, name_row->line, c, "expected a marker name");
    const std::string key = label + '\x1f' + (id_row != nullptr ? id_row->cell(c) : std::string());
    auto it = std::find_if(markers.begin(), markers.end(),
                           [&key](const MarkerColumns& m) { return m.key == key; });
    if (it == markers.end()) {
      markers.push_back(MarkerColumns{label, key, {kNoColumn, kNoColumn, kNoColumn}});
      it = markers.end() - 1;
    }
    if (it->column[a] != kNoColumn) {
      FailAtCell(name, axis_row.line, c,
                 "marker " + Quoted(label) + " has a second " + axis + " column");
    }
    it->column[a] = c;
  }
  std::size_t columns = 2;
  std::vector<std::string> labels;
  for (const MarkerColumns& m : markers) {
    for (int a = 0; a < 3; ++a) {
      if (m.column[a] == kNoColumn) {
        FailAtLine(name, axis_row.line,
                   "marker " + Quoted(m.label) + " has no " + "XYZ"[a] + " position column");
      }
      columns = std::max(columns, m.column[a] + 1);
    }
    labels.push_back(internal::AsUtf8(m.label));
  }

  // Rate and units from the metadata line.
  MarkerTable table;
  double rate = 0;
  bool have_rate = false;
  for (const char* key : {"Export Frame Rate", "Capture Frame Rate"}) {
    const auto it = metadata.find(key);
    if (it == metadata.end()) continue;
    const std::optional<double> value = internal::ParseNumber(it->second.first);
    if (!value || *value <= 0) {
      FailAtCell(name, rows[0].line, it->second.second,
                 std::string("expected a positive ") + key + ", found " + Quoted(it->second.first));
    }
    rate = *value;
    have_rate = true;
    break;
  }
  if (!have_rate) {
    FailAtLine(name, rows[0].line, "expected 'Export Frame Rate' or 'Capture Frame Rate'");
  }
  double metres_per_unit = 1.0;
  table.units_in_file = "m";
  if (const auto it = metadata.find("Length Units"); it != metadata.end()) {
    std::string unit;
    const std::optional<double> metres = internal::MetresPerLengthUnit(it->second.first, &unit);
    if (!metres) {
      FailAtCell(name, rows[0].line, it->second.second,
                 "expected Length Units Meters, Centimeters or Millimeters, found " +
                     Quoted(it->second.first));
    }
    metres_per_unit = *metres;
    table.units_in_file = unit;
  } else {
    table.warnings.push_back("no 'Length Units' in the metadata line; assumed Meters");
  }

  // Data rows.
  std::vector<const TextRow*> data;
  for (++r; r < rows.size(); ++r) {
    const TextRow& row = rows[r];
    if (row.blank()) continue;
    if (row.cells.size() < columns) {
      FailAtLine(name, row.line,
                 "expected at least " + std::to_string(columns) + " columns, found " +
                     std::to_string(row.cells.size()));
    }
    data.push_back(&row);
  }

  table.format = "motive-csv";
  table.rate_hz = rate;
  table.up_axis = "y";  // Motive's world frame is Y-up
  table.Reset(data.size(), labels, /*with_residual=*/false);
  std::size_t partial = 0;
  for (std::size_t f = 0; f < data.size(); ++f) {
    const TextRow& row = *data[f];
    const std::int64_t frame = internal::IntegerCell(name, row, 0, "Frame");
    if (f == 0) table.first_frame_number = frame;
    internal::NumberCell(name, row, 1, "Time");
    for (std::size_t m = 0; m < markers.size(); ++m) {
      const std::size_t* c = markers[m].column;
      if (const auto p = internal::PointCells(name, row, c[0], c[1], c[2], &partial)) {
        table.set_position(f, m, *p * metres_per_unit);
      }
    }
  }
  if (partial > 0) table.warnings.push_back(internal::PartialPointsWarning(partial));
  if (const auto it = metadata.find("Total Exported Frames"); it != metadata.end()) {
    const std::optional<double> stated = internal::ParseNumber(it->second.first);
    if (!stated || *stated != static_cast<double>(data.size())) {
      table.warnings.push_back("Total Exported Frames says " + it->second.first +
                               ", the file holds " + std::to_string(data.size()) +
                               " data rows; read the rows");
    }
  }
  return table;
}

MarkerTable ReadMotiveCsv(const std::string& path) {
  return ReadMotiveCsvFromString(ReadTextFile(path), path);
}

}  // namespace ccsrm::mocap
