#pragma once
// The joint-angle CSV files the commands write beside their JSON:
// <name>.angles.csv of `ccsrm identify` (measured, fitted, residual) and
// holdout/<name>.angles.csv of `ccsrm loop` (measured, declared, final).
// Comment lines start with '#'; the header is time_s, then for joint
// j = 1..J and axis x, y one column per kind, <kind>_theta<axis><j>_deg;
// an empty cell is a value that was not measured.
#include <string>
#include <vector>

#include "ccsrm/datasets/array.h"

namespace ccsrm::reports::internal {

struct AnglesCsv {
  std::vector<double> time_s;           // strictly increasing
  std::vector<datasets::Array> series;  // per kind, T × J × 2 [deg], NaN where empty
};

// Reads `file` with the columns of `kinds` (e.g. {"measured", "fitted",
// "residual"}). Throws InputError naming the file and the line: a file that
// cannot be read ("<file>: cannot be read (<named_by>)"), a header other
// than the one above, a row with another number of cells, a cell that is not
// a number, times that do not increase, no frames.
AnglesCsv ReadAnglesCsv(const std::string& file, const std::vector<std::string>& kinds,
                        const std::string& named_by);

// <name>.points.csv of `ccsrm identify` and `ccsrm predict` for a recording
// of tracked points: time_s, then per point p, for each kind (measured,
// fitted or predicted, residual) and axis x, y, z, <kind>_<p>_<axis>_mm;
// then, when the recording labels its input patterns, `label`.
struct PointsCsv {
  std::vector<double> time_s;           // strictly increasing
  std::vector<std::string> points;      // names, in column order
  std::vector<datasets::Array> series;  // per kind, T × P × 3 [mm], NaN where empty
  std::vector<std::string> labels;      // per frame; empty without the column
};

// Reads `file` with the columns of `kinds`; throws InputError as
// ReadAnglesCsv does.
PointsCsv ReadPointsCsv(const std::string& file, const std::vector<std::string>& kinds,
                        const std::string& named_by);

}  // namespace ccsrm::reports::internal
