#pragma once
// The joint-angle tables the identify outputs write beside their JSON
// (<name>.angles.csv of a fit, a loop's held-out angles, a prediction), in
// one format that reports/src/angles_csv.h reads: comment lines starting with
// '#', the header time_s then, for joint j = 1..J and axis x, y, one column
// per kind, <kind>_theta<axis><j>_deg; values in degrees with 6 decimals, an
// empty cell where there is no value.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace ccsrm::identify::internal {

struct AnglesColumn {
  std::string kind;  // "measured", "fitted", ...
  // The value [deg] at frame f and column c (2 joint + axis); NaN: empty.
  std::function<double(Eigen::Index f, Eigen::Index c)> value_deg;
};

// The table's text. `comment` is the first line's text after "# ".
std::string AnglesCsvText(const std::string& comment, const std::vector<double>& frame_time_s,
                          int joints, const std::vector<AnglesColumn>& columns);

// Unique, file-safe stems for output files named after experiments:
// letters, digits, '-', '_' and '.' kept, anything else '_'; an empty name
// is "experiment"; a repeated one gets "_2", "_3", ...
std::vector<std::string> OutputStems(const std::vector<std::string>& names);

}  // namespace ccsrm::identify::internal
