#include "ccsrm/mocap/pose_log.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <regex>
#include <sstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "text_table.h"

namespace ccsrm::mocap {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

std::string AtLine(std::size_t line) { return "line " + std::to_string(line); }

// Wraps an angle [deg] into (−180, 180].
double Wrap180(double deg) {
  double a = std::fmod(deg, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

double Correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd da = a.array() - a.mean();
  const Eigen::VectorXd db = b.array() - b.mean();
  const double norm = da.norm() * db.norm();
  return norm > 0.0 ? da.dot(db) / norm : 0.0;
}

// d ≈ d0 + a·max(0, x − x0) with a ≥ 0, x0 on a grid over [min x, max x):
// the hinge with the least squared error. Returns {x0, a, rms}.
struct Hinge {
  double x0 = 0.0, slope = 0.0, rms = std::numeric_limits<double>::infinity();
};
Hinge FitHinge(const std::vector<double>& x, const std::vector<double>& d) {
  Hinge best;
  const double lo = *std::min_element(x.begin(), x.end());
  const double hi = *std::max_element(x.begin(), x.end());
  constexpr int kGrid = 400;
  const double n = static_cast<double>(x.size());
  for (int g = 0; g < kGrid; ++g) {
    const double x0 = lo + (hi - lo) * g / kGrid;
    // Least squares for (d0, a) on the columns 1 and max(0, x − x0).
    double s1 = 0.0, s11 = 0.0, sd = 0.0, s1d = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double h = std::max(0.0, x[i] - x0);
      s1 += h;
      s11 += h * h;
      sd += d[i];
      s1d += h * d[i];
    }
    const double det = n * s11 - s1 * s1;
    if (!(det > 0.0)) continue;
    const double slope = std::max(0.0, (n * s1d - s1 * sd) / det);
    const double d0 = (sd - slope * s1) / n;
    double sse = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = d[i] - d0 - slope * std::max(0.0, x[i] - x0);
      sse += r * r;
    }
    const double rms = std::sqrt(sse / n);
    if (rms < best.rms) best = {x0, slope, rms};
  }
  return best;
}

// The spread of a group's azimuths from evenly spaced: the sum of squared
// deviations of its gaps (around the circle) from 360 / size [deg²].
double SpacingCost(const std::vector<TendonPull>& pulls, const std::vector<std::size_t>& group) {
  std::vector<double> az;
  for (const std::size_t k : group) az.push_back(pulls[k].azimuth_deg);
  std::sort(az.begin(), az.end());
  const double even = 360.0 / static_cast<double>(az.size());
  double cost = 0.0;
  for (std::size_t i = 0; i < az.size(); ++i) {
    const double gap = i + 1 < az.size() ? az[i + 1] - az[i] : az[0] + 360.0 - az[i];
    cost += (gap - even) * (gap - even);
  }
  return cost;
}

// Every partition of `pulls` into groups of `size`; the one of least total
// spacing cost.
std::vector<std::vector<std::size_t>> EvenestGrouping(const std::vector<TendonPull>& pulls,
                                                      std::size_t size, double* best_cost) {
  std::vector<std::vector<std::size_t>> best, current;
  *best_cost = std::numeric_limits<double>::infinity();
  std::vector<bool> used(pulls.size(), false);
  std::function<void(double)> extend = [&](double cost) {
    if (cost >= *best_cost) return;
    const auto first = std::find(used.begin(), used.end(), false);
    if (first == used.end()) {
      *best_cost = cost;
      best = current;
      return;
    }
    // The first free pull opens the next group; choose its companions.
    const std::size_t head = static_cast<std::size_t>(first - used.begin());
    std::vector<std::size_t> group = {head};
    used[head] = true;
    std::function<void(std::size_t)> choose = [&](std::size_t from) {
      if (group.size() == size) {
        current.push_back(group);
        extend(cost + SpacingCost(pulls, group));
        current.pop_back();
        return;
      }
      for (std::size_t k = from; k < pulls.size(); ++k) {
        if (used[k]) continue;
        used[k] = true;
        group.push_back(k);
        choose(k + 1);
        group.pop_back();
        used[k] = false;
      }
    };
    choose(head + 1);
    used[head] = false;
  };
  extend(0.0);
  return best;
}

// One pattern's pull: rows [begin, end) of the log.
TendonPull IdentifyPull(const PoseLog& log, std::size_t begin, std::size_t end,
                        const TendonMapOptions& options) {
  TendonPull pull;
  pull.label = log.labels[begin];
  const int a1 = (options.axis + 1) % 3, a2 = (options.axis + 2) % 3;
  const Eigen::Index n = static_cast<Eigen::Index>(end - begin);
  const Eigen::Index b = static_cast<Eigen::Index>(begin);
  // The tip's travel across the axis from where the pattern starts.
  Eigen::MatrixXd across(n, 2);
  across.col(0) = log.tip.col(a1).segment(b, n).array() - log.tip(b, a1);
  across.col(1) = log.tip.col(a2).segment(b, n).array() - log.tip(b, a2);
  const Eigen::VectorXd travel = across.rowwise().norm();
  // The actuator that follows it best.
  double best = 0.0;
  Eigen::Index column = -1;
  for (Eigen::Index c = 0; c < log.actuators.cols(); ++c) {
    const double r = Correlation(log.actuators.col(c).segment(b, n), travel);
    if (std::abs(r) > std::abs(best)) {
      best = r;
      column = c;
    }
  }
  if (column < 0 || !(travel.maxCoeff() > 0.0)) {
    ThrowInputError(log.source_name, AtLine(log.lines[begin]),
                    "pattern '" + pull.label + "' does not move the tip: not a pull");
  }
  pull.column = log.actuator_columns[static_cast<std::size_t>(column)];
  pull.sign = best >= 0.0 ? 1 : -1;
  // The hinge over the pull up to its peak, in the pulled-in direction.
  const Eigen::VectorXd reading = log.actuators.col(column).segment(b, n) * pull.sign;
  Eigen::Index peak = 0;
  reading.maxCoeff(&peak);
  std::vector<double> x, d;
  for (Eigen::Index i = 0; i <= peak; ++i) {
    x.push_back(reading[i]);
    d.push_back(travel[i]);
  }
  if (x.size() < 3) {
    ThrowInputError(log.source_name, AtLine(log.lines[begin]),
                    "pattern '" + pull.label + "' reaches its largest pull within " +
                        std::to_string(x.size()) + " row(s): too few to find where it engages");
  }
  const Hinge hinge = FitHinge(x, d);
  pull.engagement = hinge.x0 * pull.sign;
  pull.tip_per_unit = hinge.slope;
  pull.fit_rms = hinge.rms;
  // Direction: from the pattern's last row back to its farthest; from its
  // first when it ends near its farthest (a pull not released).
  Eigen::Index far = 0;
  const double farthest = travel.maxCoeff(&far);
  Eigen::Vector2d towards = across.row(far) - across.row(n - 1);
  if (towards.norm() < 0.5 * farthest) towards = across.row(far);
  pull.azimuth_deg = Wrap180(std::atan2(towards.y(), towards.x()) * kDeg);
  static const std::regex kTendon("tendon(\\d+)");
  std::smatch m;
  if (std::regex_search(pull.label, m, kTendon)) pull.labelled = std::stoi(m[1].str());
  return pull;
}

}  // namespace

PoseLog ParsePoseLog(const std::string& text, const std::string& source_name,
                     const PoseLogColumns& columns) {
  PoseLog log;
  log.source_name = source_name;
  const std::size_t newline = text.find('\n');
  const char delimiter = internal::GuessDelimiter(text.substr(0, newline));
  const std::vector<internal::TextRow> rows = internal::SplitRows(text, delimiter);
  const auto skipped = [](const internal::TextRow& row) {
    return row.blank() || (!row.cells.empty() && !row.cells[0].empty() && row.cells[0][0] == '#');
  };
  std::size_t r = 0;
  while (r < rows.size() && skipped(rows[r])) ++r;
  if (r == rows.size()) ThrowInputError(source_name, "", "empty: expected a header line and rows");
  const internal::TextRow& header = rows[r];
  const auto find = [&](const std::string& name) -> std::optional<std::size_t> {
    for (std::size_t c = 0; c < header.cells.size(); ++c)
      if (header.cells[c] == name) return c;
    return std::nullopt;
  };
  const auto require = [&](const std::string& name, const std::string& what) {
    const std::optional<std::size_t> c = find(name);
    if (!c) {
      ThrowInputError(source_name, AtLine(header.line),
                      "no column '" + name + "' (" + what + ") in the header");
    }
    return *c;
  };
  const std::size_t time_column = require(columns.time, "the time");
  const std::optional<std::size_t> label_column =
      columns.label.empty() ? std::nullopt : find(columns.label);
  std::array<std::size_t, 3> tip_columns{};
  for (int k = 0; k < 3; ++k) tip_columns[k] = require(columns.tip[k], "the tracked point");
  std::vector<std::size_t> actuator_columns;
  for (std::size_t c = 0; c < header.cells.size(); ++c) {
    if (header.cells[c].rfind(columns.actuator_prefix, 0) == 0) {
      actuator_columns.push_back(c);
      log.actuator_columns.push_back(header.cells[c]);
    }
  }
  if (actuator_columns.empty()) {
    ThrowInputError(
        source_name, AtLine(header.line),
        "no actuator column (none whose name starts with '" + columns.actuator_prefix + "')");
  }
  std::vector<std::vector<double>> values;
  for (++r; r < rows.size(); ++r) {
    const internal::TextRow& row = rows[r];
    if (skipped(row)) continue;
    const auto number = [&](std::size_t c) {
      return internal::NumberCell(source_name, row, c, "column '" + header.cells[c] + "'");
    };
    const double t = number(time_column);
    if (!log.time_s.empty() && !(t > log.time_s.back())) {
      ThrowInputError(source_name, AtLine(row.line) + ", column '" + columns.time + "'",
                      "time " + std::to_string(t) + " does not increase");
    }
    log.time_s.push_back(t);
    log.lines.push_back(row.line);
    log.labels.push_back(label_column ? row.cell(*label_column) : std::string());
    std::vector<double> v;
    for (const std::size_t c : actuator_columns) v.push_back(number(c));
    for (const std::size_t c : tip_columns) v.push_back(number(c));
    values.push_back(std::move(v));
  }
  if (values.size() < 2) {
    ThrowInputError(source_name, "", "fewer than 2 rows: no poses to compare");
  }
  const Eigen::Index n = static_cast<Eigen::Index>(values.size());
  const Eigen::Index a = static_cast<Eigen::Index>(actuator_columns.size());
  log.actuators.resize(n, a);
  log.tip.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::vector<double>& v = values[static_cast<std::size_t>(i)];
    for (Eigen::Index c = 0; c < a; ++c) log.actuators(i, c) = v[static_cast<std::size_t>(c)];
    for (Eigen::Index k = 0; k < 3; ++k) log.tip(i, k) = v[static_cast<std::size_t>(a + k)];
  }
  return log;
}

PoseLog ReadPoseLog(const std::string& path, const PoseLogColumns& columns) {
  return ParsePoseLog(ReadTextFile(path), path, columns);
}

TendonMap IdentifyTendonMap(const PoseLog& log, const TendonMapOptions& options) {
  if (options.tendons_per_segment < 1 || options.axis < 0 || options.axis > 2 ||
      options.min_rows < 3) {
    ThrowInputError(log.source_name, "",
                    "tendon map options: tendons_per_segment >= 1, axis 0..2 and min_rows >= 3");
  }
  std::vector<TendonPull> pulls;
  for (std::size_t begin = 0; begin < log.labels.size();) {
    std::size_t end = begin;
    while (end < log.labels.size() && log.labels[end] == log.labels[begin]) ++end;
    if (end - begin >= static_cast<std::size_t>(options.min_rows)) {
      pulls.push_back(IdentifyPull(log, begin, end, options));
      for (std::size_t k = 0; k + 1 < pulls.size(); ++k) {
        if (pulls[k].column == pulls.back().column) {
          ThrowInputError(log.source_name, AtLine(log.lines[begin]),
                          "patterns '" + pulls[k].label + "' and '" + pulls.back().label +
                              "' both pull with column '" + pulls.back().column +
                              "': one tendon per pattern, each once");
        }
      }
    }
    begin = end;
  }
  const std::size_t per = static_cast<std::size_t>(options.tendons_per_segment);
  if (pulls.empty() || pulls.size() % per != 0 || pulls.size() > 15) {
    ThrowInputError(log.source_name, "",
                    std::to_string(pulls.size()) + " pull pattern(s) of at least " +
                        std::to_string(options.min_rows) + " rows: expected a multiple of " +
                        std::to_string(per) + " tendons per segment, at most 15");
  }
  double cost = 0.0;
  std::vector<std::vector<std::size_t>> groups = EvenestGrouping(pulls, per, &cost);
  // Proximal first: its tendons move the tip most per unit of pull.
  const auto mean_gain = [&](const std::vector<std::size_t>& g) {
    double sum = 0.0;
    for (const std::size_t k : g) sum += pulls[k].tip_per_unit;
    return sum / static_cast<double>(g.size());
  };
  std::stable_sort(groups.begin(), groups.end(),
                   [&](const auto& x, const auto& y) { return mean_gain(x) > mean_gain(y); });
  TendonMap map;
  map.tendons_per_segment = options.tendons_per_segment;
  map.spacing_rms_deg = std::sqrt(cost / static_cast<double>(pulls.size()));
  for (std::size_t s = 0; s < groups.size(); ++s) {
    std::vector<std::size_t> g = groups[s];
    std::sort(g.begin(), g.end(), [&](std::size_t x, std::size_t y) {
      return pulls[x].azimuth_deg < pulls[y].azimuth_deg;
    });
    for (std::size_t i = 0; i < g.size(); ++i) {
      TendonPull t = pulls[g[i]];
      t.segment = static_cast<int>(s) + 1;
      t.index = static_cast<int>(i);
      if (t.labelled >= 0) {
        ++map.labels_naming;
        map.labels_agreeing += t.labelled == static_cast<int>(s * per + i);
      }
      map.tendons.push_back(t);
    }
  }
  return map;
}

std::string TendonMap::Report() const {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof(line), "  %-7s %-7s %-14s %4s %11s %12s %9s %8s  %s\n", "segment",
                "tendon", "column", "sign", "engagement", "tip per unit", "azimuth", "fit RMS",
                "pattern");
  out << line;
  for (const TendonPull& t : tendons) {
    std::snprintf(line, sizeof(line), "  %-7d %-7d %-14s %+4d %11.3f %12.2f %8.1f° %8.2f  %s\n",
                  t.segment, t.index, t.column.c_str(), t.sign, t.engagement, t.tip_per_unit,
                  t.azimuth_deg, t.fit_rms, t.label.c_str());
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "  segments grouped by the most even spacing of their tendons' directions (RMS "
                "%.1f deg from %g deg apart), proximal first (most tip travel per unit)\n",
                spacing_rms_deg, 360.0 / tendons_per_segment);
  out << line;
  if (labels_naming > 0) {
    out << "  the labels name " << labels_agreeing << " of " << labels_naming
        << " tendons as identified (tendon K = (segment - 1) x " << tendons_per_segment
        << " + index)\n";
  }
  return out.str();
}

std::string TendonMap::ToYaml(const std::string& source) const {
  YAML::Emitter out;
  out << YAML::Comment("Identified by ccsrm dataset tendon-map from " + source);
  out << YAML::BeginMap;
  out << YAML::Key << "schema" << YAML::Value << kTendonMapSchema;
  out << YAML::Key << "tendons_per_segment" << YAML::Value << tendons_per_segment;
  out << YAML::Key << "spacing_rms_deg" << YAML::Value << spacing_rms_deg;
  out << YAML::Key << "tendons" << YAML::Value << YAML::BeginSeq;
  for (const TendonPull& t : tendons) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "segment" << YAML::Value << t.segment;
    out << YAML::Key << "index" << YAML::Value << t.index;
    out << YAML::Key << "column" << YAML::Value << YAML::DoubleQuoted << t.column;
    out << YAML::Key << "sign" << YAML::Value << t.sign;
    out << YAML::Key << "engagement" << YAML::Value << t.engagement;
    out << YAML::Key << "tip_per_unit" << YAML::Value << t.tip_per_unit;
    out << YAML::Key << "azimuth_deg" << YAML::Value << t.azimuth_deg;
    out << YAML::Key << "fit_rms" << YAML::Value << t.fit_rms;
    out << YAML::Key << "pattern" << YAML::Value << YAML::DoubleQuoted << t.label;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string TendonMap::ActuatorMapYaml(const std::string& source, const std::string& time_column,
                                       const std::string& unit) const {
  YAML::Emitter out;
  out << YAML::Comment("The actuators identified by ccsrm dataset tendon-map from " + source +
                       "; cable k: tendon k (segment by segment, by increasing azimuth)");
  out << YAML::BeginMap;
  out << YAML::Key << "schema" << YAML::Value << "ccsrm-actuators/1";
  out << YAML::Key << "time" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "column" << YAML::Value << YAML::DoubleQuoted << time_column;
  out << YAML::Key << "unit" << YAML::Value << "s" << YAML::EndMap;
  out << YAML::Key << "cables" << YAML::Value << YAML::BeginSeq;
  for (const TendonPull& t : tendons) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "column" << YAML::Value << YAML::DoubleQuoted << t.column;
    out << YAML::Key << "signal" << YAML::Value << "length_change";
    out << YAML::Key << "unit" << YAML::Value << unit;
    out << YAML::Key << "sign" << YAML::Value << t.sign;
    out << YAML::Key << "zero" << YAML::Value << t.engagement;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace ccsrm::mocap
