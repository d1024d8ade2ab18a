#include "angles_table.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include <Eigen/Geometry>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/sim_io/run_file.h"

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

void WriteRecordingOutputs(const Experiment& x, const std::string& name,
                           const sim::SimulationResult& run, const sim::ArmParameters& parameters,
                           const Eigen::MatrixXd& simulated_rad, const std::string& kind,
                           const std::string& stem, const std::string& run_suffix,
                           const std::string& tmp_dir, const std::string& directory,
                           nlohmann::json* entry, std::vector<std::string>* written) {
  namespace fs = std::filesystem;
  constexpr double kDeg = 180.0 / M_PI;
  const fs::path tmp(tmp_dir);
  (*entry)["run_file"] = stem + run_suffix;
  (*entry)["angles_file"] = stem + ".angles.csv";
  if (run.trajectory.size() > 0) {
    sim::Config config = x.config;
    config.parameters = parameters;
    sim_io::RunFileInfo info;
    info.config_yaml = sim::ToYaml(config);
    const datasets::RunFile file = sim_io::ToRunFile(*x.model, run, info);
    datasets::WriteRunFile((tmp / (stem + run_suffix)).string(), file);
    written->push_back((fs::path(directory) / (stem + run_suffix)).string());
  } else {
    (*entry)["run_file"] = nullptr;
  }
  if (!x.tracked_points.empty()) {
    // Tracked points only: their coordinates, in mm, in the frame they were
    // recorded in (the run placed there).
    (*entry)["angles_file"] = nullptr;
    (*entry)["points_file"] = stem + ".points.csv";
    WriteTextFileAtomically((tmp / (stem + ".points.csv")).string(),
                            PointsCsvText(x, simulated_rad, name, kind));
    written->push_back((fs::path(directory) / (stem + ".points.csv")).string());
    return;
  }
  const auto measured = [&x](Eigen::Index f, Eigen::Index c) { return x.measured(f, c) * kDeg; };
  const auto simulated = [&simulated_rad](Eigen::Index f, Eigen::Index c) {
    return simulated_rad.rows() > f ? simulated_rad(f, c) * kDeg : NAN;
  };
  const std::string csv = AnglesCsvText(
      name + ": measured and " + kind + " joint angles [deg] at the measured frames; residual = " +
          kind + " - measured; empty where not measured",
      x.frame_time_s, x.joints,
      {{"measured", measured}, {kind, simulated}, {"residual", [&](Eigen::Index f, Eigen::Index c) {
                                                     return simulated(f, c) - measured(f, c);
                                                   }}});
  WriteTextFileAtomically((tmp / (stem + ".angles.csv")).string(), csv);
  written->push_back((fs::path(directory) / (stem + ".angles.csv")).string());
}

namespace {

nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json ErrorsJson(const std::vector<TrackedPoint>& points, const TrackedPointErrors& e) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t p = 0; p < e.rms_mm.size(); ++p) {
    const Eigen::Vector3d& mean = e.mean_offset_mm[p];
    out.push_back({{"point", points[p].name},
                   {"rms_mm", Number(e.rms_mm[p])},
                   {"rms_mean_offset_removed_mm", Number(e.rms_mean_removed_mm[p])},
                   {"mean_offset_mm", {Number(mean.x()), Number(mean.y()), Number(mean.z())}},
                   {"frames", e.frames[p]}});
  }
  return out;
}

std::string Mm(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), std::isfinite(value) ? "%.3f" : "-", value);
  return text;
}

}  // namespace

std::string TrackedPointsText(const std::vector<TrackedPoint>& points,
                              const TrackedPointErrors* start, const TrackedPointErrors& errors,
                              const RigidPlacement* placement, bool placement_given) {
  std::string out;
  char line[256];
  for (std::size_t p = 0; p < errors.rms_mm.size(); ++p) {
    const std::string from =
        start != nullptr && p < start->rms_mm.size() ? Mm(start->rms_mm[p]) + " -> " : "";
    std::snprintf(line, sizeof(line),
                  "    %s: RMS %s%s mm (mean offset removed: %s mm), %zu frames\n",
                  points[p].name.c_str(), from.c_str(), Mm(errors.rms_mm[p]).c_str(),
                  Mm(errors.rms_mean_removed_mm[p]).c_str(), errors.frames[p]);
    out += line;
  }
  if (placement != nullptr) {
    const Eigen::AngleAxisd r(placement->R_CW);
    const Eigen::Vector3d offset_mm = placement->p_CW_m * 1e3;
    std::snprintf(line, sizeof(line),
                  "    capture frame placed %s: %.3f deg about (%.3f, %.3f, %.3f), offset (%.2f, "
                  "%.2f, %.2f) mm\n",
                  placement_given ? "as the fit placed its own recordings"
                                  : "by the best rigid motion to this recording",
                  r.angle() * 180.0 / M_PI, r.axis().x(), r.axis().y(), r.axis().z(), offset_mm.x(),
                  offset_mm.y(), offset_mm.z());
    out += line;
  }
  return out;
}

nlohmann::json TrackedPointsJson(const std::vector<TrackedPoint>& points,
                                 const TrackedPointErrors* start, const TrackedPointErrors& errors,
                                 const RigidPlacement* placement, bool placement_given) {
  nlohmann::json out = {{"errors", ErrorsJson(points, errors)}};
  if (start != nullptr) out["start_errors"] = ErrorsJson(points, *start);
  out["capture_placement"] = nullptr;
  if (placement != nullptr) {
    const Eigen::AngleAxisd r(placement->R_CW);
    out["capture_placement"] = {
        {"from", placement_given ? "fit" : "this recording"},
        {"rotation_deg", r.angle() * 180.0 / M_PI},
        {"rotation_axis", {r.axis().x(), r.axis().y(), r.axis().z()}},
        {"offset_mm",
         {placement->p_CW_m.x() * 1e3, placement->p_CW_m.y() * 1e3, placement->p_CW_m.z() * 1e3}}};
  }
  return out;
}

namespace {

// A free text (an input pattern's label) as one cell: its separators and
// line breaks as spaces.
std::string CsvCellText(std::string text) {
  for (char& c : text) {
    if (c == ',' || c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

}  // namespace

std::string PointsCsvText(const Experiment& x, const Eigen::MatrixXd& simulated,
                          const std::string& name, const std::string& kind) {
  std::ostringstream csv;
  csv << "# " << name << ": measured and " << kind
      << " tracked points [mm] at the measured frames, in the frame they were recorded in; "
         "residual = "
      << kind << " - measured; empty where not measured"
      << (x.frame_labels.empty() ? "" : "; label: the input pattern of the frame") << "\n";
  csv << "time_s";
  for (const TrackedPoint& point : x.tracked_points) {
    for (const char* what : {"measured", kind.c_str(), "residual"}) {
      for (const char* axis : {"x", "y", "z"})
        csv << "," << what << "_" << point.name << "_" << axis << "_mm";
    }
  }
  const bool labelled = !x.frame_labels.empty();
  if (labelled) csv << ",label";
  csv << "\n";
  char value[64];
  const Eigen::Index first = 2 * x.joints;
  for (std::size_t f = 0; f < x.frame_time_s.size(); ++f) {
    const Eigen::Index row = static_cast<Eigen::Index>(f);
    std::snprintf(value, sizeof(value), "%.6f", x.frame_time_s[f]);
    csv << value;
    for (std::size_t p = 0; p < x.tracked_points.size(); ++p) {
      const Eigen::Index c = first + 3 * static_cast<Eigen::Index>(p);
      for (int what = 0; what < 3; ++what) {
        for (Eigen::Index a = 0; a < 3; ++a) {
          const double m = x.measured(row, c + a);
          const double s = simulated.rows() > row ? simulated(row, c + a) : NAN;
          const double v = (what == 0 ? m : what == 1 ? s : s - m) * 1e3;
          if (std::isfinite(v)) {
            std::snprintf(value, sizeof(value), ",%.4f", v);
            csv << value;
          } else {
            csv << ",";
          }
        }
      }
    }
    if (labelled) csv << "," << CsvCellText(x.frame_labels[f]);
    csv << "\n";
  }
  return csv.str();
}

}  // namespace ccsrm::identify::internal
