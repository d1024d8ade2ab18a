#include "ccsrm/mocap/marker_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <variant>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/text_formats.h"
#include "utf8.h"

namespace ccsrm::mocap {
namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The first non-blank line of a file (at most 4096 bytes are read).
std::string FirstLine(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "", "cannot open for reading");
  std::string head(4096, '\0');
  stream.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(stream.gcount()));
  if (head.rfind("\xEF\xBB\xBF", 0) == 0) head.erase(0, 3);
  std::size_t begin = head.find_first_not_of("\r\n");
  if (begin == std::string::npos) return std::string();
  const std::size_t end = head.find_first_of("\r\n", begin);
  return head.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

std::string FirstCell(const std::string& line) {
  std::string cell = line.substr(0, line.find(','));
  const std::size_t begin = cell.find_first_not_of(" \t\"");
  const std::size_t end = cell.find_last_not_of(" \t\"");
  if (begin == std::string::npos) return std::string();
  cell = cell.substr(begin, end - begin + 1);
  for (char& c : cell) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return cell;
}

std::string FormatNumber(double value, int precision) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
  return buffer;
}

// A table from F × M × 3 positions [m] at the given times.
MarkerTable TableFromArray(const datasets::Array& markers, const std::vector<std::string>& names,
                           const std::vector<double>& time, const std::string& format) {
  MarkerTable table;
  table.Reset(markers.rows(), names, false);
  table.positions_m = markers.values;
  table.format = format;
  table.units_in_file = "m";
  table.rate_hz =
      time.size() >= 2 ? static_cast<double>(time.size() - 1) / (time.back() - time.front()) : 0.0;
  // A sample is seen only when all three coordinates are (the table's rule).
  for (std::size_t i = 0; i + 2 < table.positions_m.size(); i += 3) {
    double* p = &table.positions_m[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      p[0] = p[1] = p[2] = std::nan("");
    }
  }
  return table;
}

}  // namespace

MarkerTable MarkerTableFromExperiment(const datasets::ExperimentFile& experiment) {
  return TableFromArray(experiment.mocap_markers, experiment.marker_names,
                        experiment.mocap_time.values, "ccsrm-dataset");
}

MarkerTable MarkerTableFromRun(const datasets::RunFile& run, const std::string& file) {
  if (!run.markers) ThrowInputError(file, "/markers", "missing: this run has no virtual markers");
  return TableFromArray(*run.markers, run.marker_names, run.time.values, "ccsrm-run");
}

MarkerTable ReadHdf5Markers(const std::string& path) {
  const datasets::AnyFile file = datasets::ReadAnyFile(path);  // read once
  if (const auto* experiment = std::get_if<datasets::ExperimentFile>(&file)) {
    return MarkerTableFromExperiment(*experiment);
  }
  return MarkerTableFromRun(std::get<datasets::RunFile>(file), path);
}

C3dRecording ReadMarkerFileWithAnalog(const std::string& path) {
  if (LowerExtension(path) == ".c3d") return ReadC3dRecording(path);
  return C3dRecording{ReadMarkerFile(path), C3dAnalog()};
}

MarkerTable ReadMarkerFile(const std::string& path) {
  const std::string ext = LowerExtension(path);
  if (ext == ".c3d") return ReadC3d(path);
  if (ext == ".trc") return ReadTrc(path);
  if (ext == ".csv") {
    const std::string first = FirstCell(FirstLine(path));
    if (first == "format version") return ReadMotiveCsv(path);
    if (first == "trajectories" || first == "devices") return ReadNexusCsv(path);
    ThrowInputError(path, "line 1",
                    "unrecognised CSV: expected an OptiTrack Motive export ('Format Version,...') "
                    "or a Vicon Nexus export ('Trajectories' or 'Devices'), found '" +
                        first + "'");
  }
  if (ext == ".h5" || ext == ".hdf5") return ReadHdf5Markers(path);
  ThrowInputError(
      path, "",
      "unknown marker file extension '" + ext + "': expected .c3d, .trc, .csv, .h5 or .hdf5");
}

nlohmann::json InspectJson(const MarkerTable& table) {
  // JSON strings must be UTF-8: a table built by hand (or a warning quoting a
  // file's bytes) may not be.
  const auto utf8 = [](const std::string& s) { return internal::AsUtf8(s); };
  const MarkerStatistics stats = Summarize(table);
  nlohmann::json j;
  j["format"] = utf8(table.format);
  j["frames"] = table.frames();
  j["markers"] = table.markers();
  j["rate_hz"] = table.rate_hz;
  j["first_frame_number"] = table.first_frame_number;
  j["duration_s"] = table.rate_hz > 0 ? static_cast<double>(table.frames()) / table.rate_hz : 0.0;
  nlohmann::json labels = nlohmann::json::array();
  for (const std::string& label : table.labels) labels.push_back(utf8(label));
  j["labels"] = labels;
  j["units_in_file"] = utf8(table.units_in_file);
  j["up_axis"] =
      table.up_axis.empty() ? nlohmann::json(nullptr) : nlohmann::json(utf8(table.up_axis));
  j["invalid_points"] = stats.invalid_points;
  j["invalid_fraction"] = stats.invalid_fraction;
  j["longest_gap_frames"] = stats.longest_gap_frames;
  j["longest_gap_marker"] = utf8(stats.longest_gap_marker);
  nlohmann::json visibility = nlohmann::json::object();
  nlohmann::json first_frame = nlohmann::json::object();
  for (std::size_t m = 0; m < table.markers(); ++m) {
    const std::string label = utf8(table.labels[m]);
    if (visibility.contains(label)) continue;  // a repeated label: the first marker wins
    visibility[label] = stats.visibility[m];
    if (table.frames() > 0 && table.is_valid(0, m)) {
      const Eigen::Vector3d p = table.position(0, m);
      first_frame[label] = {p.x(), p.y(), p.z()};
    } else {
      first_frame[label] = nullptr;
    }
  }
  j["visibility"] = visibility;
  j["first_frame"] = first_frame;
  j["has_residual"] = table.has_residual;
  if (table.format == "c3d") {
    j["processor"] = utf8(table.processor);
    j["storage"] = utf8(table.storage);
    j["point_scale_m"] = table.point_scale_m;
  }
  nlohmann::json warnings = nlohmann::json::array();
  for (const std::string& w : table.warnings) warnings.push_back(utf8(w));
  j["warnings"] = warnings;
  return j;
}

std::string InspectText(const MarkerTable& table) {
  const MarkerStatistics stats = Summarize(table);
  std::ostringstream out;
  out << "format:          " << table.format;
  if (table.format == "c3d") {
    out << " (" << table.processor << ", " << table.storage << " storage, scale "
        << FormatNumber(table.point_scale_m * 1e3, 6) << " mm)";
  }
  out << "\n";
  out << "frames:          " << table.frames() << " at " << FormatNumber(table.rate_hz, 6)
      << " Hz (" << FormatNumber(table.rate_hz > 0 ? table.frames() / table.rate_hz : 0.0, 6)
      << " s), first frame number " << table.first_frame_number << "\n";
  out << "markers:         " << table.markers() << "\n";
  out << "units in file:   " << table.units_in_file
      << (table.up_axis.empty() ? "" : ", up axis " + table.up_axis) << "\n";
  out << "invalid points:  " << stats.invalid_points << " ("
      << FormatNumber(100.0 * stats.invalid_fraction, 4) << " %)\n";
  out << "longest gap:     " << stats.longest_gap_frames << " frames";
  if (stats.longest_gap_frames > 0) {
    out << " (" << stats.longest_gap_marker << ", from frame index "
        << stats.longest_gap_first_frame << ")";
  }
  out << "\n";
  std::size_t width = 5;
  for (const std::string& label : table.labels) width = std::max(width, label.size());
  out << "\n  " << std::string("label") << std::string(width - 5, ' ')
      << "  seen %   first frame x, y, z (m)\n";
  for (std::size_t m = 0; m < table.markers(); ++m) {
    const std::string& label = table.labels[m];
    out << "  " << label << std::string(width - label.size(), ' ') << "  ";
    char seen[16];
    std::snprintf(seen, sizeof(seen), "%6.1f", 100.0 * stats.visibility[m]);
    out << seen << "   ";
    if (table.frames() > 0 && table.is_valid(0, m)) {
      const Eigen::Vector3d p = table.position(0, m);
      char xyz[96];
      std::snprintf(xyz, sizeof(xyz), "%.6f, %.6f, %.6f", p.x(), p.y(), p.z());
      out << xyz;
    } else {
      out << "not seen";
    }
    out << "\n";
  }
  for (const std::string& warning : table.warnings) out << "warning: " << warning << "\n";
  return out.str();
}

namespace {

struct ChannelRange {
  double min = 0.0;
  double max = 0.0;
  std::size_t finite = 0;
  std::size_t non_finite = 0;
};

ChannelRange RangeOf(const C3dAnalog& analog, std::size_t channel) {
  ChannelRange r;
  for (std::size_t s = 0; s < analog.sample_count; ++s) {
    const double v = analog.value(s, channel);
    if (!std::isfinite(v)) {
      ++r.non_finite;
      continue;
    }
    r.min = r.finite == 0 ? v : std::min(r.min, v);
    r.max = r.finite == 0 ? v : std::max(r.max, v);
    ++r.finite;
  }
  return r;
}

}  // namespace

nlohmann::json InspectAnalogJson(const C3dAnalog& analog) {
  const auto utf8 = [](const std::string& s) { return internal::AsUtf8(s); };
  nlohmann::json j;
  j["channels"] = analog.channels();
  j["rate_hz"] = analog.rate_hz;
  j["samples_per_frame"] = analog.samples_per_frame;
  j["samples"] = analog.sample_count;
  j["gen_scale"] = analog.gen_scale;
  j["unsigned_integers"] = analog.unsigned_integers;
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t c = 0; c < analog.channels(); ++c) {
    const ChannelRange r = RangeOf(analog, c);
    nlohmann::json channel;
    channel["label"] = utf8(analog.labels[c]);
    channel["units"] = utf8(analog.units[c]);
    channel["scale"] = analog.scale[c];
    channel["offset"] = analog.offset[c];
    channel["min"] = r.finite > 0 ? nlohmann::json(r.min) : nlohmann::json(nullptr);
    channel["max"] = r.finite > 0 ? nlohmann::json(r.max) : nlohmann::json(nullptr);
    channel["non_finite"] = r.non_finite;
    list.push_back(channel);
  }
  j["list"] = list;
  return j;
}

std::string InspectAnalogText(const C3dAnalog& analog) {
  if (analog.channels() == 0) return std::string();
  std::ostringstream out;
  out << "\nanalog:          " << analog.channels() << " channel(s) at "
      << FormatNumber(analog.rate_hz, 6) << " Hz (" << analog.samples_per_frame << " per frame, "
      << analog.sample_count << " samples), GEN_SCALE " << FormatNumber(analog.gen_scale, 6)
      << (analog.unsigned_integers ? ", unsigned" : "") << "\n";
  std::size_t width = 5;
  for (const std::string& label : analog.labels) width = std::max(width, label.size());
  out << "\n  label" << std::string(width - 5, ' ')
      << "  units      scale         offset    min .. max (scaled)\n";
  for (std::size_t c = 0; c < analog.channels(); ++c) {
    const ChannelRange r = RangeOf(analog, c);
    char line[160];
    std::snprintf(line, sizeof(line), "  %-*s  %-8s  %-12.6g  %-8g  ", static_cast<int>(width),
                  analog.labels[c].c_str(), analog.units[c].c_str(), analog.scale[c],
                  analog.offset[c]);
    out << line;
    if (r.finite > 0) {
      out << FormatNumber(r.min, 6) << " .. " << FormatNumber(r.max, 6);
    } else {
      out << "no finite sample";
    }
    if (r.non_finite > 0) out << " (" << r.non_finite << " not finite)";
    out << "\n";
  }
  return out.str();
}

}  // namespace ccsrm::mocap
