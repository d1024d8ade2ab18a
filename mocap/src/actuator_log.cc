#include "ccsrm/mocap/actuator_log.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/recorded_inputs.h"
#include "text_table.h"

namespace ccsrm::mocap {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Line(const YAML::Node& node) { return "line " + std::to_string(node.Mark().line + 1); }

[[noreturn]] void Fail(const std::string& file, const YAML::Node& node, const std::string& key,
                       const std::string& what) {
  ThrowInputError(file, Line(node) + ", key '" + key + "'", what);
}

std::string Join(const std::set<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

void ExpectKeys(const std::string& file, const YAML::Node& map, const std::string& path,
                const std::set<std::string>& allowed) {
  for (const auto& entry : map) {
    const std::string key = entry.first.as<std::string>();
    if (allowed.count(key) == 0) {
      Fail(file, entry.first, path.empty() ? key : path + "." + key,
           "unknown key (expected one of " + Join(allowed) + ")");
    }
  }
}

YAML::Node Require(const std::string& file, const YAML::Node& map, const std::string& path,
                   const std::string& key) {
  const YAML::Node node = map[key];
  if (!node) Fail(file, map, path.empty() ? key : path + "." + key, "missing");
  return node;
}

std::string String(const std::string& file, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar() || node.as<std::string>().empty()) {
    Fail(file, node, key, "expected a non-empty string");
  }
  return node.as<std::string>();
}

std::string OneOf(const std::string& file, const YAML::Node& node, const std::string& key,
                  const std::set<std::string>& allowed) {
  const std::string value = String(file, node, key);
  if (allowed.count(value) == 0) {
    Fail(file, node, key, "expected one of " + Join(allowed) + ", found '" + value + "'");
  }
  return value;
}

double Number(const std::string& file, const YAML::Node& node, const std::string& key) {
  return ReadYamlNumber(node, file, Line(node) + ", key '" + key + "'");
}

double Positive(const std::string& file, const YAML::Node& node, const std::string& key) {
  const double value = Number(file, node, key);
  if (!(value > 0.0)) Fail(file, node, key, "expected a number > 0, found " + node.Scalar());
  return value;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double SecondsPerTimeUnit(const std::string& unit) {
  if (unit == "ms") return 1e-3;
  if (unit == "us") return 1e-6;
  return 1.0;
}

// Radians per logged unit of a motor angle column.
double RadiansPerUnit(const CableColumn& c) {
  if (c.unit == "deg") return kPi / 180.0;
  if (c.unit == "counts") return 2.0 * kPi / c.counts_per_turn;
  return 1.0;
}

std::string Format(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

}  // namespace

ActuatorMap ParseActuatorMap(const std::string& yaml_text, const std::string& file) {
  const YAML::Node root = ParseYamlDocument(yaml_text, file);
  if (!root.IsMap()) {
    ThrowInputError(file, "", "expected a mapping with 'schema', 'time' and 'cables'");
  }
  ExpectKeys(file, root, "", {"schema", "time", "cables", "trigger", "max_gap_s"});
  const YAML::Node schema = Require(file, root, "", "schema");
  if (!schema.IsScalar() || schema.as<std::string>() != kActuatorMapSchema) {
    Fail(file, schema, "schema",
         std::string("expected ") + kActuatorMapSchema + ", found '" +
             (schema.IsScalar() ? schema.as<std::string>() : std::string("a non-string")) + "'");
  }
  ActuatorMap map;
  std::map<std::string, std::string> used;  // column -> the key naming it
  auto claim = [&](const YAML::Node& node, const std::string& key, const std::string& column) {
    const auto [it, fresh] = used.emplace(column, key);
    if (!fresh) Fail(file, node, key, "column '" + column + "' is already " + it->second);
  };

  const YAML::Node time = Require(file, root, "", "time");
  if (!time.IsMap()) Fail(file, time, "time", "expected a mapping with 'column' and 'unit'");
  ExpectKeys(file, time, "time", {"column", "unit"});
  map.time_column = String(file, Require(file, time, "time", "column"), "time.column");
  claim(time["column"], "time.column", map.time_column);
  map.time_unit = OneOf(file, Require(file, time, "time", "unit"), "time.unit", {"s", "ms", "us"});

  if (const YAML::Node gap = root["max_gap_s"]) map.max_gap_s = Positive(file, gap, "max_gap_s");

  if (const YAML::Node trigger = root["trigger"]) {
    if (!trigger.IsMap()) Fail(file, trigger, "trigger", "expected a mapping with 'column'");
    ExpectKeys(file, trigger, "trigger", {"column", "threshold", "polarity"});
    TriggerColumn t;
    t.column = String(file, Require(file, trigger, "trigger", "column"), "trigger.column");
    claim(trigger["column"], "trigger.column", t.column);
    if (const YAML::Node v = trigger["threshold"])
      t.threshold = Number(file, v, "trigger.threshold");
    if (const YAML::Node v = trigger["polarity"]) {
      t.polarity = OneOf(file, v, "trigger.polarity", {"rising", "falling"});
    }
    map.trigger = t;
  }

  const YAML::Node cables = Require(file, root, "", "cables");
  if (!cables.IsSequence() || cables.size() == 0) {
    Fail(file, cables, "cables", "expected a list of cable columns (cable 1 first)");
  }
  for (std::size_t k = 0; k < cables.size(); ++k) {
    const YAML::Node node = cables[k];
    const std::string path = "cables[" + std::to_string(k) + "]";
    if (!node.IsMap()) Fail(file, node, path, "expected a mapping with 'column' and 'signal'");
    ExpectKeys(file, node, path,
               {"column", "signal", "unit", "drum_radius_m", "gear_ratio", "sign",
                "counts_per_turn", "wrap_counts", "zero"});
    CableColumn c;
    c.column = String(file, Require(file, node, path, "column"), path + ".column");
    claim(node["column"], path + ".column", c.column);
    const std::string signal = OneOf(file, Require(file, node, path, "signal"), path + ".signal",
                                     {"length_change", "motor_angle"});
    c.signal = signal == "motor_angle" ? CableSignal::kMotorAngle : CableSignal::kLengthChange;
    const YAML::Node unit = Require(file, node, path, "unit");
    if (c.signal == CableSignal::kLengthChange) {
      c.unit = OneOf(file, unit, path + ".unit", {"m", "mm"});
      for (const char* key : {"drum_radius_m", "gear_ratio", "counts_per_turn", "wrap_counts"}) {
        if (node[key]) {
          Fail(file, node[key], path + "." + key, "only for signal: motor_angle");
        }
      }
      if (const YAML::Node v = node["zero"]) c.zero = Number(file, v, path + ".zero");
    } else {
      // A motor angle's zero is its first logged value.
      if (node["zero"]) Fail(file, node["zero"], path + ".zero", "only for signal: length_change");
      c.unit = OneOf(file, unit, path + ".unit", {"rad", "deg", "counts"});
      c.drum_radius_m =
          Positive(file, Require(file, node, path, "drum_radius_m"), path + ".drum_radius_m");
      if (const YAML::Node v = node["gear_ratio"]) {
        c.gear_ratio = Positive(file, v, path + ".gear_ratio");
      }
      if (c.unit == "counts") {
        c.counts_per_turn =
            Positive(file, Require(file, node, path, "counts_per_turn"), path + ".counts_per_turn");
        if (const YAML::Node v = node["wrap_counts"]) {
          c.wrap_counts = Positive(file, v, path + ".wrap_counts");
          // A counter wraps after a whole number of turns at least (a
          // single-turn absolute encoder: exactly one). Less would take
          // every step between two samples as under half that range.
          if (c.wrap_counts < c.counts_per_turn) {
            Fail(file, v, path + ".wrap_counts",
                 "is " + v.Scalar() + ", less than counts_per_turn (" + Format(c.counts_per_turn) +
                     "): a counter wraps after one motor turn at the earliest");
          }
        }
      } else {
        for (const char* key : {"counts_per_turn", "wrap_counts"}) {
          if (node[key]) Fail(file, node[key], path + "." + key, "only for unit: counts");
        }
      }
    }
    if (const YAML::Node v = node["sign"]) {
      const double sign = Number(file, v, path + ".sign");
      if (sign != 1.0 && sign != -1.0) {
        Fail(file, v, path + ".sign", "expected 1 or -1, found " + v.Scalar());
      }
      c.sign = static_cast<int>(sign);
    }
    map.cables.push_back(c);
  }
  return map;
}

ActuatorMap ReadActuatorMap(const std::string& path) {
  return ParseActuatorMap(ReadTextFile(path), path);
}

ActuatorLog ParseActuatorLog(const std::string& text, const std::string& source_name,
                             const ActuatorMap& map, const std::string& map_file) {
  ActuatorLog log;
  log.source_name = source_name;
  // The header: the first line that is neither blank nor a '#' comment.
  std::size_t header_at = 0;
  std::string header_line;
  // A UTF-8 byte order mark is not part of the first line (SplitRows drops
  // it too): "<BOM># comment" is a comment, not the header.
  const std::size_t bom = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  for (std::size_t begin = bom; begin < text.size();) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') {
      header_line = line;
      break;
    }
    ++header_at;
    begin = end + 1;
  }
  if (header_line.empty()) {
    ThrowInputError(source_name, "", "empty: expected a header line and samples");
  }
  const char delimiter = internal::GuessDelimiter(header_line);
  const std::vector<internal::TextRow> rows = internal::SplitRows(text, delimiter);
  std::size_t r = 0;
  auto skipped = [](const internal::TextRow& row) {
    return row.blank() || (!row.cells.empty() && !row.cells[0].empty() && row.cells[0][0] == '#');
  };
  while (r < rows.size() && skipped(rows[r])) ++r;
  if (r == rows.size()) {
    ThrowInputError(source_name, "", "empty: expected a header line and samples");
  }
  const internal::TextRow& header = rows[r];
  auto column_of = [&](const std::string& name, const std::string& key) {
    for (std::size_t c = 0; c < header.cells.size(); ++c) {
      if (header.cells[c] != name) continue;
      // A mapped column named twice: which one the map means is a guess.
      for (std::size_t other = c + 1; other < header.cells.size(); ++other) {
        if (header.cells[other] == name) {
          ThrowInputError(source_name, "line " + std::to_string(header.line),
                          "column '" + name + "' (named by " + map_file + ", key '" + key +
                              "') appears twice, as columns " + std::to_string(c + 1) + " and " +
                              std::to_string(other + 1));
        }
      }
      return c;
    }
    ThrowInputError(source_name, "line " + std::to_string(header.line),
                    "no column '" + name + "' (named by " + map_file + ", key '" + key +
                        "'); the header has " + std::to_string(header.cells.size()) + " column(s)");
  };
  const std::size_t time_column = column_of(map.time_column, "time.column");
  std::vector<std::size_t> cable_columns;
  for (std::size_t k = 0; k < map.cables.size(); ++k) {
    cable_columns.push_back(
        column_of(map.cables[k].column, "cables[" + std::to_string(k) + "].column"));
    log.cable_columns.push_back(map.cables[k].column);
  }
  // The trigger's column, or npos without one.
  const std::size_t trigger_column =
      map.trigger ? column_of(map.trigger->column, "trigger.column") : std::string::npos;

  auto read = [&](const internal::TextRow& row, std::size_t column) {
    const std::string& cell = row.cell(column);
    const std::string& name = header.cells[column];
    if (cell.empty()) {
      ThrowInputError(source_name, "line " + std::to_string(row.line) + ", column '" + name + "'",
                      "missing value");
    }
    const std::optional<double> value = internal::ParseNumber(cell);
    if (!value) {
      const std::string lower = Lower(cell);
      const bool non_finite =
          lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos;
      ThrowInputError(source_name, "line " + std::to_string(row.line) + ", column '" + name + "'",
                      non_finite ? "'" + cell + "' is not a finite number"
                                 : "expected a number, found " + internal::Quoted(cell));
    }
    return *value;
  };

  const double seconds = SecondsPerTimeUnit(map.time_unit);
  std::vector<double> time;
  std::vector<std::vector<double>> raw(map.cables.size());
  std::vector<double> trigger;
  for (++r; r < rows.size(); ++r) {
    const internal::TextRow& row = rows[r];
    if (skipped(row)) continue;
    // More cells than the header names: a delimiter in a value (a decimal
    // comma) or a row joined from two; any reading of it is a guess.
    std::size_t cells = row.cells.size();
    while (cells > header.cells.size() && row.cells[cells - 1].empty()) --cells;
    if (cells > header.cells.size()) {
      ThrowInputError(source_name, "line " + std::to_string(row.line),
                      "has " + std::to_string(cells) + " cells, the header (line " +
                          std::to_string(header.line) + ") names " +
                          std::to_string(header.cells.size()) + " columns");
    }
    const double t = read(row, time_column) * seconds;
    if (!time.empty()) {
      const std::string where =
          "line " + std::to_string(row.line) + ", column '" + map.time_column + "'";
      if (!(t > time.back())) {
        ThrowInputError(source_name, where,
                        "time " + Format(t) + " s does not increase (previous " +
                            Format(time.back()) + " s, line " + std::to_string(log.lines.back()) +
                            ")");
      }
      // The margin absorbs rounding of the unit's scale (100 ms is
      // 0.10000000000000001 s): a gap exactly at the limit is allowed.
      if (t - time.back() > map.max_gap_s * (1.0 + 1e-9)) {
        ThrowInputError(source_name, where,
                        "a gap of " + Format(t - time.back()) + " s after " + Format(time.back()) +
                            " s, longer than the " + Format(map.max_gap_s) + " s allowed (" +
                            map_file + ", key 'max_gap_s')");
      }
    }
    time.push_back(t);
    for (std::size_t k = 0; k < map.cables.size(); ++k) {
      raw[k].push_back(read(row, cable_columns[k]));
    }
    if (map.trigger) trigger.push_back(read(row, trigger_column));
    log.lines.push_back(row.line);
  }
  const std::size_t n = time.size();
  if (n < 2) {
    ThrowInputError(source_name, map.time_column,
                    "has " + std::to_string(n) + " sample(s), at least 2 are needed");
  }
  log.time_s = Eigen::Map<const Eigen::VectorXd>(time.data(), static_cast<Eigen::Index>(n));
  if (map.trigger) {
    log.trigger = Eigen::Map<const Eigen::VectorXd>(trigger.data(), static_cast<Eigen::Index>(n));
  }
  log.length_change_m.resize(static_cast<Eigen::Index>(n),
                             static_cast<Eigen::Index>(map.cables.size()));
  for (std::size_t k = 0; k < map.cables.size(); ++k) {
    const CableColumn& c = map.cables[k];
    std::vector<double>& v = raw[k];
    if (c.signal == CableSignal::kLengthChange) {
      const double scale = c.sign * (c.unit == "mm" ? 1e-3 : 1.0);
      for (std::size_t i = 0; i < n; ++i) log.length_change_m(i, k) = scale * (v[i] - c.zero);
      continue;
    }
    if (c.unit == "counts" && c.wrap_counts > 0.0) {
      // Unwrap: each step is the shortest one modulo the counter's range.
      double previous_raw = v[0];
      for (std::size_t i = 1; i < n; ++i) {
        const double raw_i = v[i];
        double step = raw_i - previous_raw;
        step -= c.wrap_counts * std::round(step / c.wrap_counts);
        v[i] = v[i - 1] + step;
        previous_raw = raw_i;
      }
    }
    const double metres_per_unit = c.sign * c.drum_radius_m * RadiansPerUnit(c) / c.gear_ratio;
    for (std::size_t i = 0; i < n; ++i) {
      log.length_change_m(i, k) = metres_per_unit * (v[i] - v[0]);
    }
  }
  return log;
}

ActuatorLog ReadActuatorLog(const std::string& path, const ActuatorMap& map,
                            const std::string& map_file) {
  return ParseActuatorLog(ReadTextFile(path), path, map, map_file);
}

void CheckActuatorLogOnArm(const ActuatorLog& log, const ActuatorMap& map,
                           const std::string& map_file, const sim::ArmModel& model,
                           const std::string& config_file, Eigen::Index first, Eigen::Index count) {
  if (log.length_change_m.cols() != model.num_cables()) {
    ThrowInputError(map_file, "cables",
                    "maps " + std::to_string(log.length_change_m.cols()) + " cable(s), the arm (" +
                        config_file + ") has " + std::to_string(model.num_cables()) +
                        " driving cables");
  }
  if (count < 0) count = log.time_s.size() - first;
  sim::RecordedInputs record;
  record.source_name = log.source_name;
  record.time_name = map.time_column;
  record.cable_names = log.cable_columns;
  record.time_s = log.time_s.segment(first, count);
  record.length_change_m = log.length_change_m.middleRows(first, count);
  record.lines.assign(log.lines.begin() + first, log.lines.begin() + first + count);
  sim::CheckRecordedInputsOnArm(record, model);
}

}  // namespace ccsrm::mocap
