#pragma once
// Private: line and cell splitting for the delimited text marker formats, with
// error messages that name the file, the line and the column (both 1-based).
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ccsrm::mocap::internal {

// One line of the file split into trimmed cells.
struct TextRow {
  std::size_t line = 0;  // 1-based line number
  std::vector<std::string> cells;

  // The cell at `column` (0-based), or "" beyond the end of the row.
  const std::string& cell(std::size_t column) const;
  // True when every cell is empty (a blank line, or only delimiters).
  bool blank() const;
};

// Splits text into rows. Lines end at "\n", "\r\n" or "\r"; a UTF-8 byte-order
// mark is dropped. Cells are separated by `delimiter`, trimmed of spaces (and
// tabs when the delimiter is not a tab); a cell in double quotes may contain
// the delimiter and "" for a quote.
std::vector<TextRow> SplitRows(std::string_view text, char delimiter);

// The delimiter of a line: tab if it holds a tab, else comma.
char GuessDelimiter(std::string_view first_line);

// Parses a whole cell as a finite number (a leading '+' is accepted).
std::optional<double> ParseNumber(std::string_view cell);

// Metres per unit for "mm", "cm", "m" and the spelled-out names Motive uses
// ("Millimeters", "Centimeters", "Meters", also "metres"); case-insensitive.
// The short name ("mm", "cm", "m") goes to *short_name when not null.
std::optional<double> MetresPerLengthUnit(std::string_view unit, std::string* short_name);

// Error helpers: "<file>: line L[, column C]: <what>".
[[noreturn]] void FailAtLine(const std::string& file, std::size_t line, const std::string& what);
[[noreturn]] void FailAtCell(const std::string& file, std::size_t line, std::size_t column,
                             const std::string& what);

// Cell readers that throw with the position of the cell. `what` names the
// value expected ("the frame rate", "the frame number").
double NumberCell(const std::string& file, const TextRow& row, std::size_t column,
                  const std::string& what);
std::int64_t IntegerCell(const std::string& file, const TextRow& row, std::size_t column,
                         const std::string& what);
// A coordinate: empty (or "NaN") = not seen → nullopt; otherwise a finite
// number, else throws.
std::optional<double> CoordinateCell(const std::string& file, const TextRow& row,
                                     std::size_t column);

// A point from the coordinate cells at columns cx, cy, cz: nullopt when not
// seen. A point with some but not all cells empty counts as not seen and
// increments *partial.
std::optional<Eigen::Vector3d> PointCells(const std::string& file, const TextRow& row,
                                          std::size_t cx, std::size_t cy, std::size_t cz,
                                          std::size_t* partial);

// The warning for `partial` incomplete points (empty when partial is 0).
std::string PartialPointsWarning(std::size_t partial);

// Quotes a cell for an error message, shortened to 40 characters.
std::string Quoted(const std::string& cell);

// `value` printed by a printf format of one double ("%.3f"), for messages and
// reports.
std::string FormatNumber(const char* format, double value);

}  // namespace ccsrm::mocap::internal
