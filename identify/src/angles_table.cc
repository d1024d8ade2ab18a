#include "angles_table.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace ccsrm::identify::internal {

std::string AnglesCsvText(const std::string& comment, const std::vector<double>& frame_time_s,
                          int joints, const std::vector<AnglesColumn>& columns) {
  std::ostringstream csv;
  csv << "# " << comment << "\n";
  csv << "time_s";
  for (int j = 1; j <= joints; ++j) {
    for (const char* axis : {"x", "y"}) {
      for (const AnglesColumn& column : columns) {
        csv << "," << column.kind << "_theta" << axis << j << "_deg";
      }
    }
  }
  csv << "\n";
  char value[64];
  for (std::size_t f = 0; f < frame_time_s.size(); ++f) {
    std::snprintf(value, sizeof(value), "%.6f", frame_time_s[f]);
    csv << value;
    for (Eigen::Index c = 0; c < 2 * joints; ++c) {
      for (const AnglesColumn& column : columns) {
        const double v = column.value_deg(static_cast<Eigen::Index>(f), c);
        if (std::isfinite(v)) {
          std::snprintf(value, sizeof(value), ",%.6f", v);
          csv << value;
        } else {
          csv << ",";
        }
      }
    }
    csv << "\n";
  }
  return csv.str();
}

std::vector<std::string> OutputStems(const std::vector<std::string>& names) {
  std::vector<std::string> stems;
  std::set<std::string> used;
  for (const std::string& name : names) {
    std::string stem;
    for (char c : name) {
      stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')
                  ? c
                  : '_';
    }
    if (stem.empty()) stem = "experiment";
    std::string unique = stem;
    for (int k = 2; used.count(unique) != 0; ++k) unique = stem + "_" + std::to_string(k);
    used.insert(unique);
    stems.push_back(unique);
  }
  return stems;
}

}  // namespace ccsrm::identify::internal
