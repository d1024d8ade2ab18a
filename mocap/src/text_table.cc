#include "text_table.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "ccsrm/common/error.h"

namespace ccsrm::mocap::internal {
namespace {

const std::string kEmpty;

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string Trim(std::string_view s, bool trim_tabs) {
  auto is_space = [trim_tabs](char c) { return c == ' ' || (trim_tabs && c == '\t'); };
  std::size_t begin = 0;
  std::size_t end = s.size();
  while (begin < end && is_space(s[begin])) ++begin;
  while (end > begin && is_space(s[end - 1])) --end;
  return std::string(s.substr(begin, end - begin));
}

std::vector<std::string> SplitCells(std::string_view line, char delimiter) {
  std::vector<std::string> cells;
  const bool trim_tabs = delimiter != '\t';
  std::size_t i = 0;
  while (true) {
    std::string cell;
    // Skip leading spaces to see whether the cell is quoted.
    std::size_t j = i;
    while (j < line.size() && (line[j] == ' ' || (trim_tabs && line[j] == '\t'))) ++j;
    if (j < line.size() && line[j] == '"') {
      ++j;
      while (j < line.size()) {
        if (line[j] == '"') {
          if (j + 1 < line.size() && line[j + 1] == '"') {
            cell += '"';
            j += 2;
            continue;
          }
          ++j;
          break;
        }
        cell += line[j++];
      }
      // Anything between the closing quote and the delimiter is kept.
      const std::size_t end = line.find(delimiter, j);
      cell += Trim(line.substr(j, end == std::string_view::npos ? end : end - j), trim_tabs);
      cells.push_back(cell);
      if (end == std::string_view::npos) break;
      i = end + 1;
      continue;
    }
    const std::size_t end = line.find(delimiter, i);
    cells.push_back(Trim(line.substr(i, end == std::string_view::npos ? end : end - i), trim_tabs));
    if (end == std::string_view::npos) break;
    i = end + 1;
  }
  return cells;
}

}  // namespace

const std::string& TextRow::cell(std::size_t column) const {
  return column < cells.size() ? cells[column] : kEmpty;
}

bool TextRow::blank() const {
  for (const std::string& c : cells) {
    if (!c.empty()) return false;
  }
  return true;
}

std::vector<TextRow> SplitRows(std::string_view text, char delimiter) {
  if (text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::vector<TextRow> rows;
  std::size_t line = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    std::size_t end = text.find_first_of("\r\n", i);
    if (end == std::string_view::npos) end = text.size();
    rows.push_back(TextRow{line, SplitCells(text.substr(i, end - i), delimiter)});
    ++line;
    i = end;
    if (i < text.size() && text[i] == '\r') {
      ++i;
      if (i < text.size() && text[i] == '\n') ++i;  // "\r\n" is one line end
    } else if (i < text.size()) {
      ++i;  // "\n"
    }
  }
  return rows;
}

char GuessDelimiter(std::string_view first_line) {
  const std::size_t end = first_line.find_first_of("\r\n");
  return first_line.substr(0, end).find('\t') != std::string_view::npos ? '\t' : ',';
}

std::optional<double> ParseNumber(std::string_view cell) {
  if (!cell.empty() && cell.front() == '+') {
    cell.remove_prefix(1);
    if (!cell.empty() && (cell.front() == '+' || cell.front() == '-')) return std::nullopt;
  }
  if (cell.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<double> MetresPerLengthUnit(std::string_view unit, std::string* short_name) {
  const std::string u = Lower(unit);
  auto found = [short_name](const char* name, double metres) {
    if (short_name != nullptr) *short_name = name;
    return std::optional<double>(metres);
  };
  if (u == "mm" || u == "millimeters" || u == "millimetres") return found("mm", 1e-3);
  if (u == "cm" || u == "centimeters" || u == "centimetres") return found("cm", 1e-2);
  if (u == "m" || u == "meters" || u == "metres") return found("m", 1.0);
  return std::nullopt;
}

void FailAtLine(const std::string& file, std::size_t line, const std::string& what) {
  ThrowInputError(file, "line " + std::to_string(line), what);
}

void FailAtCell(const std::string& file, std::size_t line, std::size_t column,
                const std::string& what) {
  ThrowInputError(file, "line " + std::to_string(line) + ", column " + std::to_string(column + 1),
                  what);
}

std::string Quoted(const std::string& cell) {
  if (cell.size() <= 40) return "'" + cell + "'";
  return "'" + cell.substr(0, 37) + "...'";
}

std::string FormatNumber(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

double NumberCell(const std::string& file, const TextRow& row, std::size_t column,
                  const std::string& what) {
  const std::optional<double> value = ParseNumber(row.cell(column));
  if (!value) {
    FailAtCell(file, row.line, column,
               "expected a number (" + what + "), found " + Quoted(row.cell(column)));
  }
  return *value;
}

std::int64_t IntegerCell(const std::string& file, const TextRow& row, std::size_t column,
                         const std::string& what) {
  std::string_view cell = row.cell(column);
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (cell.empty() || error != std::errc() || end != cell.data() + cell.size()) {
    FailAtCell(file, row.line, column,
               "expected an integer (" + what + "), found " + Quoted(row.cell(column)));
  }
  return value;
}

std::optional<double> CoordinateCell(const std::string& file, const TextRow& row,
                                     std::size_t column) {
  const std::string& cell = row.cell(column);
  if (cell.empty() || Lower(cell) == "nan") return std::nullopt;
  const std::optional<double> value = ParseNumber(cell);
  if (!value) {
    FailAtCell(file, row.line, column,
               "expected a coordinate (a number, or empty when not seen), found " + Quoted(cell));
  }
  return value;
}

std::optional<Eigen::Vector3d> PointCells(const std::string& file, const TextRow& row,
                                          std::size_t cx, std::size_t cy, std::size_t cz,
                                          std::size_t* partial) {
  const std::optional<double> x = CoordinateCell(file, row, cx);
  const std::optional<double> y = CoordinateCell(file, row, cy);
  const std::optional<double> z = CoordinateCell(file, row, cz);
  if (x && y && z) return Eigen::Vector3d(*x, *y, *z);
  if (x || y || z) ++*partial;
  return std::nullopt;
}

std::string PartialPointsWarning(std::size_t partial) {
  if (partial == 0) return std::string();
  return std::to_string(partial) +
         " point(s) had only some of their X/Y/Z cells filled; they were read as not seen";
}

}  // namespace ccsrm::mocap::internal
