#include "angles_csv.h"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "ccsrm/common/error.h"

namespace ccsrm::reports::internal {
namespace {

// One row: comma-separated cells, empty = not measured.
std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream stream(line);
  while (std::getline(stream, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

// The next line that is neither empty nor a comment; false at the end.
bool NextRow(std::istream& in, std::string* line, int* number) {
  while (std::getline(in, *line)) {
    ++*number;
    if (!line->empty() && line->back() == '\r') line->pop_back();
    if (!line->empty() && (*line)[0] != '#') return true;
  }
  return false;
}

std::string ColumnName(const std::string& kind, std::size_t axis, std::size_t joint) {
  return kind + "_theta" + (axis == 0 ? "x" : "y") + std::to_string(joint + 1) + "_deg";
}

}  // namespace

namespace {

// The rows of a table whose header passed `check_header`: time_s first and
// increasing, every cell a number or empty (NaN), but for a last column
// named "label" (text, in `labels`; not in `header` or `rows`).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::vector<std::string> labels;
};

template <typename CheckHeader>
Table ReadTable(const std::string& file, const std::string& named_by, CheckHeader check_header) {
  std::ifstream in(file);
  if (!in) ThrowInputError(file, "", "cannot be read (" + named_by + ")");
  std::string line;
  int number = 0;
  Table table;
  if (NextRow(in, &line, &number)) table.header = SplitCells(line);
  const bool labelled = !table.header.empty() && table.header.back() == "label";
  if (labelled) table.header.pop_back();
  check_header(table.header, "line " + std::to_string(number));
  const std::vector<std::string>& header = table.header;
  std::vector<std::vector<double>>& rows = table.rows;
  while (NextRow(in, &line, &number)) {
    const std::string at = "line " + std::to_string(number);
    std::vector<std::string> cells = SplitCells(line);
    const std::size_t columns = header.size() + (labelled ? 1 : 0);
    if (cells.size() != columns) {
      ThrowInputError(file, at,
                      std::to_string(cells.size()) + " cells, expected " + std::to_string(columns));
    }
    if (labelled) {
      table.labels.push_back(cells.back());
      cells.pop_back();
    }
    std::vector<double> row(cells.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (cells[i].empty() && i > 0) continue;
      char* end = nullptr;
      errno = 0;
      row[i] = std::strtod(cells[i].c_str(), &end);
      if (cells[i].empty() || *end != '\0' || errno != 0) {
        ThrowInputError(file, at,
                        "column " + std::to_string(i + 1) + " ('" + header[i] + "'): '" + cells[i] +
                            "' is not a number");
      }
    }
    if (!rows.empty() && !(row[0] > rows.back()[0]))
      ThrowInputError(file, at, "times must increase");
    rows.push_back(std::move(row));
  }
  if (rows.empty()) ThrowInputError(file, "", "has no frames");
  return table;
}

}  // namespace

AnglesCsv ReadAnglesCsv(const std::string& file, const std::vector<std::string>& kinds,
                        const std::string& named_by) {
  const std::size_t per_joint = 2 * kinds.size();
  const Table table = ReadTable(
      file, named_by, [&](const std::vector<std::string>& header, const std::string& where) {
        if (header.empty() || header[0] != "time_s" || header.size() < 1 + per_joint ||
            (header.size() - 1) % per_joint != 0) {
          std::string expected = "time_s";
          for (const std::string& kind : kinds) expected += "," + ColumnName(kind, 0, 0);
          ThrowInputError(file, where,
                          "expected the header " + expected + ",... (" + std::to_string(per_joint) +
                              " columns per joint)");
        }
        const std::size_t joints = (header.size() - 1) / per_joint;
        for (std::size_t j = 0; j < joints; ++j) {
          for (std::size_t c = 0; c < 2; ++c) {
            for (std::size_t k = 0; k < kinds.size(); ++k) {
              const std::string want = ColumnName(kinds[k], c, j);
              const std::size_t column = 1 + per_joint * j + kinds.size() * c + k;
              if (header[column] != want) {
                ThrowInputError(file, where,
                                "column " + std::to_string(column + 1) + " is '" + header[column] +
                                    "', expected '" + want + "'");
              }
            }
          }
        }
      });
  const std::size_t joints = (table.header.size() - 1) / per_joint;
  AnglesCsv out;
  const std::size_t frames = table.rows.size();
  out.series.assign(kinds.size(), datasets::Array({frames, joints, 2}));
  for (std::size_t f = 0; f < frames; ++f) {
    out.time_s.push_back(table.rows[f][0]);
    for (std::size_t j = 0; j < joints; ++j) {
      for (std::size_t c = 0; c < 2; ++c) {
        for (std::size_t k = 0; k < kinds.size(); ++k) {
          out.series[k].at(f, j, c) = table.rows[f][1 + per_joint * j + kinds.size() * c + k];
        }
      }
    }
  }
  return out;
}

PointsCsv ReadPointsCsv(const std::string& file, const std::vector<std::string>& kinds,
                        const std::string& named_by) {
  const std::size_t per_point = 3 * kinds.size();
  PointsCsv out;
  const Table table = ReadTable(
      file, named_by, [&](const std::vector<std::string>& header, const std::string& where) {
        const std::string suffix = "_x_mm";
        const std::string prefix = kinds.empty() ? "" : kinds[0] + "_";
        if (header.empty() || header[0] != "time_s" || header.size() < 1 + per_point ||
            (header.size() - 1) % per_point != 0) {
          ThrowInputError(file, where,
                          "expected the header time_s," + prefix + "<point>" + suffix + ",... (" +
                              std::to_string(per_point) + " columns per point)");
        }
        for (std::size_t p = 0; p < (header.size() - 1) / per_point; ++p) {
          const std::string& first = header[1 + per_point * p];
          if (first.size() <= prefix.size() + suffix.size() || first.rfind(prefix, 0) != 0 ||
              first.compare(first.size() - suffix.size(), suffix.size(), suffix) != 0) {
            ThrowInputError(file, where,
                            "column " + std::to_string(2 + per_point * p) + " is '" + first +
                                "', expected '" + prefix + "<point>" + suffix + "'");
          }
          const std::string point =
              first.substr(prefix.size(), first.size() - prefix.size() - suffix.size());
          for (std::size_t k = 0; k < kinds.size(); ++k) {
            for (const char* axis : {"x", "y", "z"}) {
              const std::size_t column = 1 + per_point * p + 3 * k + (axis[0] - 'x');
              const std::string want = kinds[k] + "_" + point + "_" + axis + "_mm";
              if (header[column] != want) {
                ThrowInputError(file, where,
                                "column " + std::to_string(column + 1) + " is '" + header[column] +
                                    "', expected '" + want + "'");
              }
            }
          }
          out.points.push_back(point);
        }
      });
  const std::size_t frames = table.rows.size(), points = out.points.size();
  out.labels = table.labels;
  out.series.assign(kinds.size(), datasets::Array({frames, points, 3}));
  for (std::size_t f = 0; f < frames; ++f) {
    out.time_s.push_back(table.rows[f][0]);
    for (std::size_t p = 0; p < points; ++p) {
      for (std::size_t k = 0; k < kinds.size(); ++k) {
        for (std::size_t a = 0; a < 3; ++a)
          out.series[k].at(f, p, a) = table.rows[f][1 + per_point * p + 3 * k + a];
      }
    }
  }
  return out;
}

}  // namespace ccsrm::reports::internal
