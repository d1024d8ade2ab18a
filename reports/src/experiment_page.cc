// The page of an experiment (ccsrm-dataset/1): what motion capture saw
// (marker visibility and gaps), the quality figures `ccsrm mocap process`
// stored under /mocap/quality, the measured joint angles and the inputs.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>

#include "arm_facts.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "pages.h"

namespace ccsrm::reports {
namespace {

using datasets::ExperimentFile;
using internal::AddText;
using internal::AddValue;
using internal::kDegPerRad;

// The quality figures of `ccsrm mocap process` (datasets/README.md), each
// checked for the expected length and units and converted to the units the
// page shows (m -> mm, rad -> deg). A figure that is absent or does not fit
// is left out with a notice: it is never recomputed here.
class QualityFigures {
 public:
  explicit QualityFigures(const ExperimentFile& experiment) : experiment_(experiment) {}

  bool any() const { return !experiment_.mocap_quality.empty(); }

  std::optional<std::vector<double>> Get(const std::string& name, std::size_t length,
                                         const std::string& units) {
    const auto found = experiment_.mocap_quality.find(name);
    if (found == experiment_.mocap_quality.end()) {
      problems_.push_back("/mocap/quality/" + name + " is missing: not shown.");
      return std::nullopt;
    }
    const datasets::Array& array = found->second;
    const auto unit = experiment_.mocap_quality_units.find(name);
    const std::string stored = unit == experiment_.mocap_quality_units.end() ? "" : unit->second;
    if (array.rank() != 1 || array.rows() != length || stored != units) {
      problems_.push_back("/mocap/quality/" + name + " has shape " +
                          datasets::ShapeToString(array.shape) + " and units '" + stored +
                          "', expected " + std::to_string(length) + " values in '" + units +
                          "': not shown.");
      return std::nullopt;
    }
    const double scale = units == "m" ? 1000.0 : units == "rad" ? kDegPerRad : 1.0;
    std::vector<double> values = array.values;
    for (double& v : values) v *= scale;
    return values;
  }

  const std::vector<std::string>& problems() const { return problems_; }

 private:
  const ExperimentFile& experiment_;
  std::vector<std::string> problems_;
};

// The body each marker belongs to ("" for none).
std::vector<std::string> BodyOfMarker(const ExperimentFile& experiment) {
  std::map<std::string, std::string> body;
  for (const datasets::RigidBody& rb : experiment.rigid_bodies) {
    for (const std::string& marker : rb.marker_names) body[marker] = rb.name;
  }
  std::vector<std::string> out;
  for (const std::string& marker : experiment.marker_names) out.push_back(body[marker]);
  return out;
}

// Categories 1..n labelled with names, for bar charts and timelines.
std::vector<std::pair<double, std::string>> NameTics(const std::vector<std::string>& names) {
  std::vector<std::pair<double, std::string>> tics;
  for (std::size_t i = 0; i < names.size(); ++i) tics.push_back({i + 1.0, names[i]});
  return tics;
}

// When each marker was not seen, drawn from the raw /mocap/markers (NaN
// where not seen): one row per marker, one red bar per gap, each frame
// widened to its own half-intervals so a one-frame gap shows.
Figure GapTimeline(const ExperimentFile& experiment) {
  const std::vector<double>& time = experiment.mocap_time.values;
  const std::size_t frames = time.size(), markers = experiment.marker_names.size();
  auto edge = [&](std::size_t i, int side) {
    if (frames == 1) return time[0] + 0.5 * side;
    if (side < 0)
      return i == 0 ? time[0] - 0.5 * (time[1] - time[0]) : 0.5 * (time[i - 1] + time[i]);
    return i + 1 == frames ? time[i] + 0.5 * (time[i] - time[i - 1])
                           : 0.5 * (time[i] + time[i + 1]);
  };
  Series gaps;
  gaps.label = "not seen";
  gaps.color = palette::kWarning;
  gaps.style = SeriesStyle::kRanges;
  for (std::size_t m = 0; m < markers; ++m) {
    std::size_t i = 0;
    while (i < frames) {
      if (std::isfinite(experiment.mocap_markers.at(i, m, 0))) {
        ++i;
        continue;
      }
      const std::size_t start = i;
      while (i < frames && !std::isfinite(experiment.mocap_markers.at(i, m, 0))) ++i;
      gaps.x.push_back(edge(start, -1));
      gaps.x.push_back(edge(i - 1, +1));
      gaps.y.push_back(static_cast<double>(m + 1));
    }
  }
  Panel panel;
  panel.title = "Frames where each marker was not seen";
  panel.x = internal::TimeAxis();
  panel.x.min = edge(0, -1);
  panel.x.max = edge(frames - 1, +1);
  panel.y = Axis{"marker", "1"};
  panel.y.min = 0.0;
  panel.y.max = markers + 1.0;
  panel.y.tics = NameTics(experiment.marker_names);
  panel.legend = LegendPlace::kNone;
  if (gaps.y.empty()) panel.note = "every marker was seen in every frame";
  panel.series.push_back(std::move(gaps));
  Figure figure;
  figure.name = "marker_gaps";
  figure.panels.push_back(std::move(panel));
  figure.panel_width_px = 1100;
  figure.panel_height_px = std::max(300, static_cast<int>(13 * markers) + 100);
  return figure;
}

Section SummarySection(const ExperimentFile& experiment, const std::string& source,
                       const std::vector<std::string>& problems, bool processed) {
  Section section{"summary", "Summary", {}};
  const std::vector<double>& t = experiment.mocap_time.values;
  Table about = internal::KeyValueTable("experiment", "Experiment",
                                        "Root attributes and sizes of the experiment file.");
  AddText(&about, "file", source);
  AddText(&about, "name", experiment.name);
  AddText(&about, "description", experiment.description);
  AddText(&about, "source", datasets::ExperimentSourceName(experiment.source));
  AddText(&about, "created", experiment.created);
  AddValue(&about, "mocap frames", static_cast<double>(t.size()), "", NumberFormat::Integer());
  AddValue(&about, "first mocap frame", t.front(), "s", NumberFormat::Fixed(3));
  AddValue(&about, "last mocap frame", t.back(), "s", NumberFormat::Fixed(3));
  AddValue(&about, "markers", static_cast<double>(experiment.marker_names.size()), "",
           NumberFormat::Integer());
  AddValue(&about, "rigid bodies", static_cast<double>(experiment.rigid_bodies.size()), "",
           NumberFormat::Integer());
  AddValue(&about, "input samples", static_cast<double>(experiment.input_time.rows()), "",
           NumberFormat::Integer());
  AddValue(&about, "driving cables", static_cast<double>(experiment.input_length_change.shape[1]),
           "", NumberFormat::Integer());
  AddText(&about, "measured joint angles", experiment.measured_joint_angles ? "yes" : "no");
  AddText(&about, "mocap quality figures", experiment.mocap_quality.empty() ? "no" : "yes");
  AddText(&about, "load-cell tensions", experiment.measured_input_tension ? "yes" : "no");

  auto shown = [&](const std::string& quantity) {
    for (const auto& row : about.rows) {
      if (row[0].text == quantity) return FormatCell(row[1], about.columns[1]);
    }
    return std::string();
  };
  std::string text = "Experiment '" + experiment.name + "' (" + shown("source") +
                     "): " + shown("mocap frames") + " motion-capture frames from " +
                     shown("first mocap frame") + " s to " + shown("last mocap frame") + " s of " +
                     shown("markers") + " markers on " + shown("rigid bodies") + " rigid bodies. ";
  text += processed ? "Processed by ccsrm mocap process: joint angles and quality figures below."
                    : "Not processed yet.";
  section.blocks.push_back(Paragraph{text, false});
  if (!processed) {
    section.blocks.push_back(Paragraph{
        "This experiment has no /measured/joint_angles and no /mocap/quality: run `ccsrm mocap "
        "process --in " +
            source +
            " --config <arm.yaml> --out <processed.h5>` and report on its output to see joint "
            "angles and quality figures. Shown here: the raw marker visibility and the inputs.",
        true});
  }
  for (const std::string& problem : problems) section.blocks.push_back(Paragraph{problem, true});
  section.blocks.push_back(std::move(about));
  return section;
}

Section MarkerSection(const ExperimentFile& experiment, QualityFigures* quality) {
  Section section{"markers", "Marker visibility and gaps", {}};
  section.blocks.push_back(FigureBlock{
      GapTimeline(experiment), "When each marker was lost",
      "Red: frames where the marker is NaN in /mocap/markers, i.e. motion capture did not see "
      "it (before any gap filling).",
      ""});
  if (!quality->any()) return section;
  const std::size_t m = experiment.marker_names.size();
  const auto visibility = quality->Get("marker_visibility", m, "1");
  const auto gaps_before = quality->Get("marker_gaps_before_fill", m, "1");
  const auto longest_before = quality->Get("marker_longest_gap_before_fill", m, "frames");
  const auto gaps_after = quality->Get("marker_gaps_after_fill", m, "1");
  const auto longest_after = quality->Get("marker_longest_gap_after_fill", m, "frames");
  const auto spline = quality->Get("marker_spline_filled_frames", m, "frames");
  const auto rigid = quality->Get("marker_rigid_filled_frames", m, "frames");
  const auto fit_rms = quality->Get("marker_fit_rms", m, "m");

  Figure figure;
  figure.name = "marker_quality";
  figure.panel_width_px = 1100;
  figure.panel_height_px = 300;
  std::vector<double> x(m);
  for (std::size_t i = 0; i < m; ++i) x[i] = i + 1.0;
  auto category_axis = [&] {
    Axis axis{"marker", "1"};
    axis.tics = NameTics(experiment.marker_names);
    axis.rotate_tics = true;
    axis.min = 0.4;
    axis.max = m + 0.6;
    return axis;
  };
  if (visibility) {
    Panel panel;
    panel.title = "Visibility";
    panel.x = category_axis();
    panel.y = Axis{"frames seen", "%"};
    panel.y.min = 0.0;
    panel.y.max = 100.0;
    std::vector<double> percent = *visibility;
    for (double& v : percent) v *= 100.0;
    Series s{"seen", x, percent, palette::kNeutral, SeriesStyle::kBars};
    panel.series.push_back(std::move(s));
    panel.legend = LegendPlace::kNone;
    figure.panels.push_back(std::move(panel));
  }
  if (longest_before && longest_after) {
    Panel panel;
    panel.title = "Longest gap";
    panel.x = category_axis();
    panel.y = Axis{"longest gap", "frames"};
    panel.y.min = 0.0;
    std::vector<double> left = x, right = x;
    for (double& v : left) v -= 0.2;
    for (double& v : right) v += 0.2;
    Series before{"before filling", left, *longest_before, palette::Indexed(2), SeriesStyle::kBars};
    before.bar_width = 0.4;
    Series after{"after filling", right, *longest_after, palette::Indexed(1), SeriesStyle::kBars};
    after.bar_width = 0.4;
    panel.series = {std::move(before), std::move(after)};
    panel.legend = LegendPlace::kInside;
    figure.panels.push_back(std::move(panel));
  }
  if (!figure.panels.empty()) {
    section.blocks.push_back(FigureBlock{
        std::move(figure), "Visibility and gaps per marker",
        "From /mocap/quality as ccsrm mocap process wrote it: the share of frames each marker "
        "was seen, and its longest gap before and after filling (spline for short gaps, the "
        "link's other markers for long ones; a whole-link loss stays unfilled).",
        ""});
  }
  Table table;
  table.id = "markers";
  table.title = "Quality figures per marker";
  table.caption =
      "As stored under /mocap/quality (marker_visibility, marker_gaps_*, marker_longest_gap_*, "
      "marker_*_filled_frames, marker_fit_rms); fit RMS in mm; – where there is no value.";
  table.columns = {
      {"marker", "marker", "", NumberFormat::Integer()},
      {"body", "body", "", NumberFormat::Integer()},
      {"visibility_percent", "seen", "%", NumberFormat::Fixed(1)},
      {"gaps_before_fill", "gaps before filling", "", NumberFormat::Integer()},
      {"longest_gap_before_fill", "longest gap before", "frames", NumberFormat::Integer()},
      {"gaps_after_fill", "gaps after filling", "", NumberFormat::Integer()},
      {"longest_gap_after_fill", "longest gap after", "frames", NumberFormat::Integer()},
      {"spline_filled_frames", "filled by spline", "frames", NumberFormat::Integer()},
      {"rigid_filled_frames", "filled from the link", "frames", NumberFormat::Integer()},
      {"fit_rms_mm", "fit RMS", "mm", NumberFormat::Fixed(3)}};
  const std::vector<std::string> body = BodyOfMarker(experiment);
  auto value = [](const std::optional<std::vector<double>>& v, std::size_t i, double scale = 1.0) {
    return v ? Cell::Number((*v)[i] * scale) : Cell::Missing();
  };
  for (std::size_t i = 0; i < m; ++i) {
    table.AddRow({Cell::Text(experiment.marker_names[i]), Cell::Text(body[i]),
                  value(visibility, i, 100.0), value(gaps_before, i), value(longest_before, i),
                  value(gaps_after, i), value(longest_after, i), value(spline, i), value(rigid, i),
                  value(fit_rms, i)});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

Section FitSection(const ExperimentFile& experiment, std::size_t joints, QualityFigures* quality) {
  Section section{"fit", "Rigid-body fits", {}};
  const std::size_t b = experiment.rigid_bodies.size();
  const auto body_rms = quality->Get("body_fit_rms", b, "m");
  const auto body_lost = quality->Get("body_frames_lost", b, "frames");
  const auto body_whole = quality->Get("body_whole_loss_frames", b, "frames");
  const auto joint_lost = quality->Get("joint_frames_lost", joints, "frames");
  const auto joint_twist = quality->Get("joint_max_abs_twist", joints, "rad");
  const auto ground = quality->Get("ground_fit_rms", 1, "m");

  std::vector<std::string> names;
  for (const datasets::RigidBody& rb : experiment.rigid_bodies) names.push_back(rb.name);
  Figure figure;
  figure.name = "fit_quality";
  figure.columns = 2;
  figure.panel_width_px = 650;
  figure.panel_height_px = 320;
  if (body_rms) {
    Panel panel;
    panel.title = "Fit residual per body";
    panel.x = Axis{"body", "1"};
    panel.x.tics = NameTics(names);
    panel.x.rotate_tics = true;
    panel.x.min = 0.4;
    panel.x.max = b + 0.6;
    panel.y = Axis{"RMS fit residual", "mm"};
    panel.y.min = 0.0;
    std::vector<double> x(b);
    for (std::size_t i = 0; i < b; ++i) x[i] = i + 1.0;
    panel.series.push_back(Series{"", x, *body_rms, palette::kNeutral, SeriesStyle::kBars});
    panel.legend = LegendPlace::kNone;
    figure.panels.push_back(std::move(panel));
  }
  if (joint_twist) {
    Panel panel;
    panel.title = "Largest twist per joint";
    panel.x = Axis{"joint", "1"};
    panel.x.min = 0.4;
    panel.x.max = joints + 0.6;
    panel.y = Axis{"max |twist|", "deg"};
    panel.y.min = 0.0;
    std::vector<double> x(joints);
    for (std::size_t i = 0; i < joints; ++i) x[i] = i + 1.0;
    panel.x.tics.clear();
    for (std::size_t i = 0; i < joints; ++i)
      panel.x.tics.push_back({i + 1.0, std::to_string(i + 1)});
    panel.series.push_back(Series{"", x, *joint_twist, palette::kNeutral, SeriesStyle::kBars});
    panel.legend = LegendPlace::kNone;
    figure.panels.push_back(std::move(panel));
  }
  if (!figure.panels.empty()) {
    section.blocks.push_back(FigureBlock{
        std::move(figure), "Fit residuals and twist",
        "Left: RMS residual of each body's least-squares rigid fit over its seen markers "
        "(body_fit_rms). Right: the largest |twist| of each joint (joint_max_abs_twist), the "
        "third Cardan angle a true universal joint keeps at zero.",
        ""});
  }
  Table world = internal::KeyValueTable(
      "world_frame", "World frame",
      "RMS residual of the ground cluster's fit that fixes W (ground_fit_rms; – without a "
      "ground cluster).");
  AddValue(&world, "ground fit RMS", ground ? (*ground)[0] : NAN, "mm", NumberFormat::Fixed(3));
  section.blocks.push_back(std::move(world));

  Table bodies;
  bodies.id = "bodies";
  bodies.title = "Quality figures per body";
  bodies.caption =
      "As stored under /mocap/quality (body_fit_rms, body_frames_lost, "
      "body_whole_loss_frames); fit RMS in mm.";
  bodies.columns = {{"body", "body", "", NumberFormat::Integer()},
                    {"fit_rms_mm", "fit RMS", "mm", NumberFormat::Fixed(3)},
                    {"frames_lost", "frames without a pose", "frames", NumberFormat::Integer()},
                    {"whole_loss_frames", "whole-body losses", "frames", NumberFormat::Integer()}};
  auto value = [](const std::optional<std::vector<double>>& v, std::size_t i) {
    return v ? Cell::Number((*v)[i]) : Cell::Missing();
  };
  for (std::size_t i = 0; i < b; ++i) {
    bodies.AddRow(
        {Cell::Text(names[i]), value(body_rms, i), value(body_lost, i), value(body_whole, i)});
  }
  section.blocks.push_back(std::move(bodies));

  Table joint_table;
  joint_table.id = "joints";
  joint_table.title = "Quality figures per joint";
  joint_table.caption =
      "As stored under /mocap/quality (joint_frames_lost, joint_max_abs_twist); twist in deg.";
  joint_table.columns = {
      {"joint", "joint", "", NumberFormat::Integer()},
      {"frames_lost", "frames without an angle", "frames", NumberFormat::Integer()},
      {"max_abs_twist_deg", "max |twist|", "deg", NumberFormat::Fixed(3)}};
  for (std::size_t j = 0; j < joints; ++j) {
    joint_table.AddRow({Cell::Number(j + 1.0), value(joint_lost, j), value(joint_twist, j)});
  }
  section.blocks.push_back(std::move(joint_table));
  return section;
}

Section MeasuredSection(const ExperimentFile& experiment, const internal::ArmFacts& facts) {
  Section section{"joint-angles", "Measured joint angles", {}};
  const datasets::Array& angles = *experiment.measured_joint_angles;
  const std::vector<double>& time = experiment.mocap_time.values;
  section.blocks.push_back(FigureBlock{
      internal::JointAngleFigure("theta_x", time, angles, 0, facts.segments, std::nullopt),
      "Measured θx against time",
      "θx of every joint from the mocap pipeline (/measured/joint_angles), one panel per "
      "segment, colours as on run pages; gaps where a link was lost.",
      ""});
  section.blocks.push_back(FigureBlock{
      internal::JointAngleFigure("theta_y", time, angles, 1, facts.segments, std::nullopt),
      "Measured θy against time", "θy of every joint, same layout and colours.", ""});
  Table table;
  table.id = "measured_range";
  table.title = "Range of the measured joint angles";
  table.caption =
      "Smallest and largest θx and θy of each joint over the frames that have one "
      "(/measured/joint_angles), in degrees.";
  table.columns = {{"joint", "joint", "", NumberFormat::Integer()},
                   {"theta_x_min_deg", "θx smallest", "deg", NumberFormat::Fixed(3)},
                   {"theta_x_max_deg", "θx largest", "deg", NumberFormat::Fixed(3)},
                   {"theta_y_min_deg", "θy smallest", "deg", NumberFormat::Fixed(3)},
                   {"theta_y_max_deg", "θy largest", "deg", NumberFormat::Fixed(3)}};
  for (std::size_t j = 0; j < angles.shape[1]; ++j) {
    std::vector<Cell> row = {Cell::Number(j + 1.0)};
    for (std::size_t c = 0; c < 2; ++c) {
      const std::vector<double> v = internal::ComponentOf(angles, j, c, kDegPerRad);
      double lo = INFINITY, hi = -INFINITY;
      for (double x : v) {
        if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
      }
      row.push_back(Cell::Number(lo));
      row.push_back(Cell::Number(hi));
    }
    table.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));
  return section;
}

Section InputSection(const ExperimentFile& experiment, const internal::ArmFacts& facts) {
  Section section{"inputs", "Inputs", {}};
  const std::size_t cables = experiment.input_length_change.shape[1];
  if (cables == 0) {
    section.blocks.push_back(Paragraph{
        "The experiment records no driving-cable inputs (/input/length_change has no cables).",
        true});
    return section;
  }
  const std::vector<double>& time = experiment.input_time.values;
  section.blocks.push_back(FigureBlock{
      internal::CableFigure("input_length", time, experiment.input_length_change, 1000.0,
                            Axis{"pulled-in length", "mm"}, facts.segments, facts.cable_segment,
                            SeriesStyle::kLine),
      "Inputs", "Length of each driving cable pulled in at its input (/input/length_change).", ""});
  if (experiment.measured_input_tension) {
    section.blocks.push_back(FigureBlock{
        internal::CableFigure("input_tension", time, *experiment.measured_input_tension, 1.0,
                              Axis{"tension", "N"}, facts.segments, facts.cable_segment,
                              SeriesStyle::kLine),
        "Measured input tensions", "Load-cell tensions (/measured/input_tension).", ""});
  }
  return section;
}

}  // namespace

Document BuildExperimentDocument(const ExperimentFile& experiment, const std::string& source,
                                 const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  datasets::ValidateExperimentFile(experiment, source);
  const bool measured = experiment.measured_joint_angles.has_value();
  const std::size_t joints = measured ? experiment.measured_joint_angles->shape[1] : 0;
  const std::size_t cables = experiment.input_length_change.shape[1];
  // Segments (for joint panels) and cable routing (for input panels) come
  // from the nominal configuration; without measured angles only the cables
  // need it.
  internal::ArmFacts facts;
  if (measured || cables > 0) {
    facts = internal::ReadArmFacts(experiment.config_yaml, source + ": attribute 'config_yaml'",
                                   joints, cables, nullptr);
  }
  QualityFigures quality(experiment);
  const bool processed = measured || quality.any();

  Document document;
  document.kind = "experiment";
  document.title = "Experiment — " + experiment.name;
  document.source = source;
  document.ccsrm_version = kVersion;
  std::vector<Section> sections;
  sections.push_back(MarkerSection(experiment, &quality));
  if (quality.any()) sections.push_back(FitSection(experiment, joints, &quality));
  if (measured) sections.push_back(MeasuredSection(experiment, facts));
  sections.push_back(InputSection(experiment, facts));
  std::vector<std::string> problems = facts.problems;
  problems.insert(problems.end(), quality.problems().begin(), quality.problems().end());
  document.sections.push_back(SummarySection(experiment, source, problems, processed));
  for (Section& section : sections) document.sections.push_back(std::move(section));
  return document;
}

}  // namespace ccsrm::reports
