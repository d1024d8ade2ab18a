#include "angles_table.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

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

}  // namespace ccsrm::identify::internal
