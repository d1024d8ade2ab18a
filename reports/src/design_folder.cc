#include "design_folder.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm::reports::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

DesignCandidateRow ReadCandidate(const JsonReader& in, const json& entry, const std::string& at,
                                 std::size_t free_count) {
  DesignCandidateRow c;
  c.name = in.Text(entry, at, "name");
  c.protocol_yaml = in.Text(entry, at, "protocol_yaml");
  c.experiments = in.Texts(entry, at, "experiments");
  c.duration_s = in.NumberAt(entry, at, "duration_s");
  c.samples = in.NumberAt(entry, at, "samples");
  c.completed = in.Flag(entry, at, "completed");
  c.message = in.Text(entry, at, "message");
  const json& parameters = in.List(entry, at, "parameters");
  if (parameters.size() != free_count) {
    in.Fail(at + ".parameters", "expected one entry per free parameter");
  }
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const std::string p = JsonReader::Index(at + ".parameters", i);
    c.prior.push_back(in.NumberAt(parameters[i], p, "prior"));
    c.std_error.push_back(in.NumberAt(parameters[i], p, "std_error", true));
    c.relative_std_error.push_back(in.NumberAt(parameters[i], p, "relative_std_error", true));
  }
  c.worst_relative_std_error = in.NumberAt(entry, at, "worst_relative_std_error", true);
  c.worst_parameter = in.Text(entry, at, "worst_parameter");
  c.d_criterion = in.NumberAt(entry, at, "d_criterion", true);
  c.a_criterion = in.NumberAt(entry, at, "a_criterion", true);
  c.worst_direction_relative_std_error =
      in.NumberAt(entry, at, "worst_direction_relative_std_error", true);
  const json& direction = in.List(entry, at, "worst_direction");
  for (std::size_t k = 0; k < direction.size(); ++k) {
    const std::string d = JsonReader::Index(at + ".worst_direction", k);
    c.worst_direction.emplace_back(in.Text(direction[k], d, "name"),
                                   in.NumberAt(direction[k], d, "component"));
  }
  if (entry.contains("derivative_step_disagreement") &&
      !entry["derivative_step_disagreement"].is_null()) {
    const json& d = in.List(entry, at, "derivative_step_disagreement");
    if (d.size() != free_count) {
      in.Fail(at + ".derivative_step_disagreement", "expected one entry per free parameter");
    }
    for (std::size_t i = 0; i < d.size(); ++i) {
      c.derivative_step_disagreement.push_back(
          d[i].is_null()
              ? kUnknown
              : in.Number(d[i], JsonReader::Index(at + ".derivative_step_disagreement", i)));
    }
  }
  const json& corners = in.List(entry, at, "corners");
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const std::string d = JsonReader::Index(at + ".corners", k);
    DesignCorner corner;
    for (const auto& [name, value] : in.Object(corners[k], d, "values").items()) {
      corner.values.emplace_back(name, in.Number(value, d + ".values." + name));
    }
    corner.completed = in.Flag(corners[k], d, "completed");
    corner.message = in.Text(corners[k], d, "message");
    corner.relative_std_error = in.Numbers(corners[k], d, "relative_std_error", true);
    corner.worst_relative_std_error = in.NumberAt(corners[k], d, "worst_relative_std_error", true);
    corner.worst_parameter = in.Text(corners[k], d, "worst_parameter");
    c.corners.push_back(std::move(corner));
  }
  c.robust_worst_relative_std_error =
      in.NumberAt(entry, at, "robust_worst_relative_std_error", true);
  c.simulations = in.NumberAt(entry, at, "simulations");
  return c;
}

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream stream(line);
  while (std::getline(stream, cell, ',')) cells.push_back(cell);
  return cells;
}

// proposed.inputs.csv: '#' comments, a header time_s, cable<k>_m,
// speed_cable<k>_m_s, planned_theta{x,y}<j>_deg, then numbers.
PlannedMotion ReadPlannedMotion(const std::string& file) {
  std::ifstream in(file);
  if (!in) ThrowInputError(file, "", "cannot be read");
  PlannedMotion m;
  m.file = file;
  std::string line;
  int number = 0;
  std::vector<std::string> header;
  std::vector<int> kind, index, axis;  // per column: 0 time, 1 length, 2 speed, 3 angle
  std::vector<std::vector<double>> rows;
  int cables = 0, joints = 0;
  const std::regex length("cable([0-9]+)_m"), speed("speed_cable([0-9]+)_m_s"),
      angle("planned_theta([xy])([0-9]+)_deg");
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> cells = SplitCells(line);
    const std::string where = "line " + std::to_string(number);
    if (header.empty()) {
      header = cells;
      for (const std::string& name : header) {
        std::smatch match;
        if (name == "time_s") {
          kind.push_back(0), index.push_back(0), axis.push_back(0);
        } else if (std::regex_match(name, match, length)) {
          kind.push_back(1), index.push_back(std::stoi(match[1].str()) - 1), axis.push_back(0);
          cables = std::max(cables, index.back() + 1);
        } else if (std::regex_match(name, match, speed)) {
          kind.push_back(2), index.push_back(std::stoi(match[1].str()) - 1), axis.push_back(0);
        } else if (std::regex_match(name, match, angle)) {
          kind.push_back(3), index.push_back(std::stoi(match[2].str()) - 1);
          axis.push_back(match[1].str() == "x" ? 0 : 1);
          joints = std::max(joints, index.back() + 1);
        } else {
          ThrowInputError(file, where + ", column '" + name + "'", "not a column of this table");
        }
        if (index.back() < 0) ThrowInputError(file, where, "cables and joints count from 1");
      }
      if (header.empty() || header[0] != "time_s" ||
          header.size() != static_cast<std::size_t>(1 + 2 * cables + 2 * joints)) {
        ThrowInputError(file, where,
                        "expected time_s, cable<k>_m and speed_cable<k>_m_s per cable, "
                        "planned_thetax<j>_deg and planned_thetay<j>_deg per joint");
      }
      continue;
    }
    if (cells.size() != header.size()) {
      ThrowInputError(file, where,
                      "has " + std::to_string(cells.size()) + " cells, the header " +
                          std::to_string(header.size()));
    }
    std::vector<double> row(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string problem = ParseNumberText(cells[c], &row[c]);
      if (!problem.empty()) ThrowInputError(file, where + ", column '" + header[c] + "'", problem);
    }
    if (!m.time_s.empty() && !(row[0] > m.time_s.back())) {
      ThrowInputError(file, where, "time_s does not increase");
    }
    m.time_s.push_back(row[0]);
    rows.push_back(std::move(row));
  }
  if (rows.empty()) ThrowInputError(file, "", "no rows");
  const std::size_t t_count = rows.size(), c_count = static_cast<std::size_t>(cables),
                    j_count = static_cast<std::size_t>(joints);
  m.length_m = datasets::Array({t_count, c_count});
  m.speed_m_s = datasets::Array({t_count, c_count});
  m.angles_rad = datasets::Array({t_count, j_count, 2});
  for (std::size_t t = 0; t < t_count; ++t) {
    for (std::size_t c = 1; c < header.size(); ++c) {
      const std::size_t i = static_cast<std::size_t>(index[c]);
      const double value = rows[t][c];
      if (kind[c] == 1) m.length_m.at(t, i) = value;
      if (kind[c] == 2) m.speed_m_s.at(t, i) = value;
      if (kind[c] == 3) {
        m.angles_rad.at(t, i, static_cast<std::size_t>(axis[c])) = value * M_PI / 180.0;
      }
    }
  }
  return m;
}

}  // namespace

bool LooksLikeDesignFolder(const std::string& folder) {
  std::error_code ec;
  return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "design.json", ec);
}

DesignFolder ReadDesignFolder(const std::string& folder) {
  std::error_code ec;
  const fs::path path = fs::path(folder) / "design.json";
  if (!fs::is_regular_file(path, ec)) {
    ThrowInputError(folder, "", "not a design folder (no design.json)");
  }
  const std::string file = path.string();
  const json root = ReadSchemaFile(file, kDesignSchema, "ccsrm design");
  const JsonReader in(file);
  DesignFolder d;
  d.folder = folder;
  d.free = in.Texts(root, "", "free_parameters");
  d.noise_deg = in.NumberAt(root, "", "noise_deg");
  d.effective_sample_fraction = in.NumberAt(root, "", "effective_sample_fraction");
  d.frame_rate_hz = in.NumberAt(root, "", "frame_rate_hz");
  d.relative_step = in.NumberAt(root, "", "relative_step");
  if (root.contains("low_pass")) {
    d.low_pass_hz = in.NumberAt(in.Object(root, "", "low_pass"), "low_pass", "cutoff_hz");
  }
  const json& box = in.List(root, "", "prior_box");
  for (std::size_t k = 0; k < box.size(); ++k) {
    const std::string at = JsonReader::Index("prior_box", k);
    d.prior_box.push_back({in.Text(box[k], at, "name"), in.NumberAt(box[k], at, "lower"),
                           in.NumberAt(box[k], at, "upper")});
  }
  d.robust_candidates = in.NumberAt(root, "", "robust_candidates");
  d.threads = in.NumberAt(root, "", "threads");
  d.simulations = in.NumberAt(root, "", "simulations");
  d.wall_time_s = in.NumberAt(root, "", "wall_time_s");
  d.config_yaml = in.Text(root, "", "config_yaml");
  const json& candidates = in.List(root, "", "candidates");
  if (candidates.empty()) in.Fail("candidates", "is empty");
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    d.candidates.push_back(
        ReadCandidate(in, candidates[k], JsonReader::Index("candidates", k), d.free.size()));
  }
  const std::vector<double> ranking = in.Numbers(root, "", "ranking");
  std::vector<bool> seen(d.candidates.size(), false);
  for (const double r : ranking) {
    if (!(r >= 0.0) || r >= static_cast<double>(d.candidates.size()) || seen[std::size_t(r)] ||
        r != std::floor(r)) {
      in.Fail("ranking", "expected each candidate's index once");
    }
    seen[static_cast<std::size_t>(r)] = true;
    d.ranking.push_back(static_cast<std::size_t>(r));
  }
  if (d.ranking.size() != d.candidates.size()) in.Fail("ranking", "expected every candidate once");
  const fs::path motion = fs::path(folder) / "proposed.inputs.csv";
  if (fs::is_regular_file(motion, ec)) d.proposed = ReadPlannedMotion(motion.string());
  return d;
}

}  // namespace ccsrm::reports::internal
