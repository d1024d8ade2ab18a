#include "ccsrm/sim/recorded_inputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm::sim {
namespace {

// time, time_s, time_ms; cable3, cable3_m, cable3_mm (any other unit is
// named in the message).
const std::regex kTimeColumn("time(_([A-Za-z]+))?");
const std::regex kCableColumn("cable([0-9]+)(_([A-Za-z]+))?");

std::string Trim(const std::string& s) {
  const std::size_t first = s.find_first_not_of(" \t\r\"");
  if (first == std::string::npos) return "";
  const std::size_t last = s.find_last_not_of(" \t\r\"");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> Split(const std::string& line, char delimiter) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, delimiter)) fields.push_back(Trim(field));
  if (!line.empty() && line.back() == delimiter) fields.push_back("");
  return fields;
}

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

// Where sample i is in the record, for messages: its line, or its index.
std::string SampleWhere(const RecordedInputs& r, Eigen::Index i, const std::string& column) {
  if (!r.lines.empty()) return "line " + std::to_string(r.lines[i]) + ", column '" + column + "'";
  return column + ", sample " + std::to_string(i);
}

}  // namespace

bool RecordedInputOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(max_gap_s > 0.0)) return fail("max_gap_s must be > 0");
  if (!(regular_step_tolerance >= 0.0)) return fail("regular_step_tolerance must be >= 0");
  if (!(resample_step_s >= 0.0) || !std::isfinite(resample_step_s))
    return fail("resample_step_s must be >= 0");
  if (!(max_cable_speed_mps > 0.0)) return fail("max_cable_speed_mps must be > 0");
  if (!time_unit.empty() && time_unit != "s" && time_unit != "ms")
    return fail("time unit must be s or ms");
  if (!length_unit.empty() && length_unit != "m" && length_unit != "mm")
    return fail("length unit must be m or mm");
  return true;
}

RecordedInputs ParseInputTable(const std::string& text, const std::string& source_name,
                               const RecordedInputOptions& options) {
  RecordedInputs record;
  record.source_name = source_name;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  std::vector<std::string> header;
  int header_line = 0;
  char delimiter = ',';
  int time_column = -1;
  double time_scale = 1.0;
  std::map<int, std::pair<int, double>> cables;  // cable number -> (column, scale to m)
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    if (header.empty()) {
      delimiter = line.find('\t') != std::string::npos ? '\t' : ',';
      header = Split(line, delimiter);
      header_line = line_number;
      for (std::size_t c = 0; c < header.size(); ++c) {
        const std::string& name = header[c];
        const std::string where = "line " + std::to_string(line_number) + ", column '" + name + "'";
        std::smatch match;
        if (std::regex_match(name, match, kTimeColumn)) {
          std::string unit = match[2].matched ? match[2].str() : options.time_unit;
          if (unit != "s" && unit != "ms") {
            ThrowInputError(source_name, where,
                            unit.empty() ? "the time column needs its unit: time_s or time_ms "
                                           "(or the time-unit option)"
                                         : "unit '" + unit + "' is not s or ms");
          }
          if (time_column >= 0) ThrowInputError(source_name, where, "a second time column");
          time_column = static_cast<int>(c);
          time_scale = unit == "ms" ? 1e-3 : 1.0;
          continue;
        }
        if (!std::regex_match(name, match, kCableColumn)) continue;  // another column
        const int number = std::stoi(match[1].str());
        std::string unit = match[3].matched ? match[3].str() : options.length_unit;
        if (unit != "m" && unit != "mm") {
          ThrowInputError(source_name, where,
                          unit.empty()
                              ? "a cable column needs its unit: cable" + std::to_string(number) +
                                    "_m or _mm (or the length-unit option)"
                              : "unit '" + unit + "' is not m or mm");
        }
        if (number < 1 || cables.count(number) != 0) {
          ThrowInputError(source_name, where,
                          number < 1 ? "cables are numbered from 1"
                                     : "a second column for cable " + std::to_string(number));
        }
        cables[number] = {static_cast<int>(c), unit == "mm" ? 1e-3 : 1.0};
      }
      const std::string where = "line " + std::to_string(line_number);
      if (time_column < 0) {
        ThrowInputError(source_name, where, "the header names no time column (time_s or time_ms)");
      }
      if (cables.empty()) {
        ThrowInputError(source_name, where,
                        "the header names no cable column (cable1_m or cable1_mm, ...)");
      }
      int expected = 1;
      for (const auto& [number, column] : cables) {
        if (number != expected) {
          ThrowInputError(source_name, where,
                          "no column for cable " + std::to_string(expected) + " (found cable " +
                              std::to_string(number) + ")");
        }
        ++expected;
      }
      continue;
    }
    const std::vector<std::string> fields = Split(line, delimiter);
    if (fields.size() < header.size()) {
      ThrowInputError(source_name, "line " + std::to_string(line_number),
                      "has " + std::to_string(fields.size()) + " fields, the header (line " +
                          std::to_string(header_line) + ") " + std::to_string(header.size()));
    }
    std::vector<double> row;
    auto read = [&](int column, double scale) {
      double value = 0.0;
      const std::string& field = fields[column];
      const std::string where =
          "line " + std::to_string(line_number) + ", column '" + header[column] + "'";
      if (field.empty()) ThrowInputError(source_name, where, "missing value");
      const std::string problem = ParseNumberText(field, &value);
      if (!problem.empty()) ThrowInputError(source_name, where, "'" + field + "' " + problem);
      row.push_back(value * scale);
    };
    read(time_column, time_scale);
    for (const auto& [number, column] : cables) read(column.first, column.second);
    rows.push_back(std::move(row));
    record.lines.push_back(line_number);
  }
  if (header.empty()) ThrowInputError(source_name, "", "empty: expected a header line and samples");
  record.time_name = header[time_column];
  for (const auto& [number, column] : cables) record.cable_names.push_back(header[column.first]);
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  record.time_s.resize(n);
  record.length_change_m.resize(n, static_cast<Eigen::Index>(cables.size()));
  for (Eigen::Index i = 0; i < n; ++i) {
    record.time_s[i] = rows[i][0];
    for (Eigen::Index c = 0; c < record.length_change_m.cols(); ++c)
      record.length_change_m(i, c) = rows[i][c + 1];
  }
  return record;
}

CableInputs MakeRecordedCableInputs(const RecordedInputs& r, int num_cables,
                                    const RecordedInputOptions& options, std::string* note) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("recorded inputs", "options", error);
  const Eigen::Index n = r.time_s.size();
  const Eigen::Index cables = r.length_change_m.cols();
  CCSRM_CHECK(r.length_change_m.rows() == n);
  if (cables != num_cables) {
    ThrowInputError(r.source_name, "",
                    "has " + std::to_string(cables) + " cable column" + (cables == 1 ? "" : "s") +
                        ", the arm has " + std::to_string(num_cables) + " driving cables");
  }
  if (n < 2) {
    ThrowInputError(
        r.source_name, r.time_name,
        "has " + std::to_string(n) + " sample" + (n == 1 ? "" : "s") + ", at least 2 are needed");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(r.time_s[i])) {
      ThrowInputError(r.source_name, SampleWhere(r, i, r.time_name), "is not a finite number");
    }
    for (Eigen::Index c = 0; c < cables; ++c) {
      if (!std::isfinite(r.length_change_m(i, c))) {
        ThrowInputError(r.source_name, SampleWhere(r, i, r.cable_names[c]),
                        "is not a finite number (NaN or infinite)");
      }
    }
    if (i == 0) continue;
    const double step = r.time_s[i] - r.time_s[i - 1];
    if (!(step > 0.0)) {
      ThrowInputError(r.source_name, SampleWhere(r, i, r.time_name),
                      "time " + Number(r.time_s[i]) + " s does not increase (previous " +
                          Number(r.time_s[i - 1]) + " s)");
    }
    if (!options.settled_poses &&
        step > options.max_gap_s * (1.0 + 1e-9)) {  // a gap at the limit in ms rounds above it
      ThrowInputError(r.source_name, SampleWhere(r, i, r.time_name),
                      "a gap of " + Number(step) + " s after " + Number(r.time_s[i - 1]) +
                          " s, longer than the " + Number(options.max_gap_s) +
                          " s allowed (max gap option)");
    }
  }
  if (options.settled_poses) {
    if (note != nullptr) {
      *note = std::to_string(n) + " settled poses from " + Number(r.time_s[0]) + " to " +
              Number(r.time_s[n - 1]) + " s, used as recorded, straight lines between them";
    }
    return CableInputs(r.time_s, r.length_change_m, CableInputs::Interpolation::kLinear);
  }
  std::vector<double> steps(n - 1);
  for (Eigen::Index i = 1; i < n; ++i) steps[i - 1] = r.time_s[i] - r.time_s[i - 1];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  bool regular = true;
  for (double s : steps)
    regular = regular && std::abs(s - median) <= options.regular_step_tolerance * median;
  if (regular && options.resample_step_s == 0.0) {
    if (note != nullptr) {
      *note = std::to_string(n) + " samples every " + Number(median) + " s from " +
              Number(r.time_s[0]) + " to " + Number(r.time_s[n - 1]) + " s, used as recorded";
    }
    return CableInputs(r.time_s, r.length_change_m);
  }
  // Linear resampling onto a regular grid: between two samples the length
  // stays between their values (a spline through jittered stamps can swing
  // beyond them).
  const double step = options.resample_step_s > 0.0 ? options.resample_step_s : median;
  const double t0 = r.time_s[0], t1 = r.time_s[n - 1];
  const Eigen::Index m = static_cast<Eigen::Index>(std::floor((t1 - t0) / step + 1e-9)) + 1;
  const bool ends_on_grid = std::abs(t0 + (m - 1) * step - t1) <= 1e-9 * step;
  const Eigen::Index total = ends_on_grid ? m : m + 1;
  Eigen::VectorXd time(total);
  Eigen::MatrixXd length(total, cables);
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < total; ++i) {
    const double t = i + 1 == total ? t1 : t0 + i * step;
    while (k + 2 < n && r.time_s[k + 1] <= t) ++k;
    const double u = std::clamp((t - r.time_s[k]) / (r.time_s[k + 1] - r.time_s[k]), 0.0, 1.0);
    time[i] = t;
    length.row(i) = (1.0 - u) * r.length_change_m.row(k) + u * r.length_change_m.row(k + 1);
  }
  if (note != nullptr) {
    *note = std::to_string(n) + " samples from " + Number(t0) + " to " + Number(t1) + " s" +
            (regular ? "" : " at irregular steps (median " + Number(median) + " s)") +
            ", resampled linearly every " + Number(step) + " s";
  }
  return CableInputs(std::move(time), std::move(length));
}

double CableRouteLengthM(const ArmModel& model, int cable) {
  const int anchor_link = model.cables().at(cable).nodes.back().link;
  double length = 0.0;
  for (int l = 1; l <= anchor_link; ++l) length += model.link(l).length_m;
  return length;
}

void CheckRecordedInputsOnArm(const RecordedInputs& r, const ArmModel& model,
                              const RecordedInputOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("recorded inputs", "options", error);
  const Eigen::Index n = r.time_s.size();
  const Eigen::Index cables = std::min<Eigen::Index>(r.length_change_m.cols(), model.num_cables());
  for (Eigen::Index c = 0; c < cables; ++c) {
    const std::string& name = r.cable_names.at(c);
    const double route = CableRouteLengthM(model, static_cast<int>(c));
    for (Eigen::Index i = 0; i < n; ++i) {
      const double length = r.length_change_m(i, c);
      if (std::abs(length) > route) {
        ThrowInputError(r.source_name, SampleWhere(r, i, name),
                        (length > 0.0 ? "pulls cable " + std::to_string(c + 1) + " in by "
                                      : "pays cable " + std::to_string(c + 1) + " out by ") +
                            Number(std::abs(length)) + " m at t = " + Number(r.time_s[i]) +
                            " s, more than the " + Number(route) +
                            " m of arm it runs through: a length unit wrong (mm read as m?)");
      }
      if (i == 0) continue;
      const double speed =
          std::abs(length - r.length_change_m(i - 1, c)) / (r.time_s[i] - r.time_s[i - 1]);
      if (speed > options.max_cable_speed_mps) {
        ThrowInputError(r.source_name, SampleWhere(r, i, name),
                        "cable " + std::to_string(c + 1) + " moves at " + Number(speed) +
                            " m/s after t = " + Number(r.time_s[i - 1]) + " s, beyond the " +
                            Number(options.max_cable_speed_mps) +
                            " m/s any actuator of such an arm reaches: a length unit or a "
                            "corrupt sample");
      }
    }
  }
}

}  // namespace ccsrm::sim
