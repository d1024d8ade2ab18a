// The page of a prediction folder (`ccsrm predict`): how well a fitted model
// predicts recordings it was not fitted to. Measured against predicted
// joint angles and the residuals per recording, the errors per joint and
// axis against the measurement noise, the channels that stand above it, and
// the model that was run. Every number is read from pred.json or the angles
// files as ccsrm predict wrote them.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "pages.h"
#include "prediction_folder.h"

namespace ccsrm::reports {
namespace {

using internal::AddText;
using internal::AddValue;
using internal::AxisName;
using internal::FigureStem;
using internal::ListNames;
using internal::Plural;
using internal::PredictionFolder;
using internal::PredictionRecording;
using internal::Show;

const NumberFormat kRms = NumberFormat::Fixed(4);  // deg
const NumberFormat kRatio = NumberFormat::Fixed(2);
const NumberFormat kMm = NumberFormat::Fixed(2);  // tracked points
const NumberFormat kPercent = NumberFormat::Fixed(1);
const NumberFormat kValue = NumberFormat::Significant(6);

std::string ChannelName(const internal::PredictionChannel& c) {
  if (!c.point.empty())
    return "point " + c.point + " " + std::string(1, static_cast<char>('x' + c.axis));
  return "joint " + std::to_string(c.joint) + " " + AxisName(c.axis);
}

// ----------------------------------------------------------------- summary

// Whether some recording measured joint angles, and whether some measured
// tracked points (a prediction may hold either or both).
bool HasAngles(const PredictionFolder& p) {
  return std::any_of(p.recordings.begin(), p.recordings.end(),
                     [](const PredictionRecording& r) { return r.points.empty(); });
}
bool HasPoints(const PredictionFolder& p) {
  return std::any_of(p.recordings.begin(), p.recordings.end(),
                     [](const PredictionRecording& r) { return !r.points.empty(); });
}

Section SummarySection(const PredictionFolder& p) {
  Section section{"summary", "Summary", {}};
  // The answer first: whether the model explains these recordings.
  if (!p.verdict.empty()) {
    std::string verdict = p.verdict;
    verdict[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(verdict[0])));
    section.blocks.push_back(Paragraph{
        verdict + (p.above_noise.empty() ? "." : ". `ccsrm loop` looks for what it lacks."),
        !p.above_noise.empty()});
  }
  std::vector<std::string> names;
  for (const PredictionRecording& r : p.recordings) names.push_back(r.name);
  std::string text =
      "Prediction of " + Plural(static_cast<double>(p.recordings.size()), "recording") + " (" +
      ListNames(names) + ") with the model of " + p.model_source + " (" + p.model_kind +
      (p.free.empty() ? std::string() : "; fitted: " + ListNames(p.free)) +
      "; effects: " + (p.effects.empty() ? "none" : ListNames(p.effects)) + "). ";
  std::string size;
  if (std::isfinite(p.errors.rms_deg)) {
    size = "the RMS error of the joint angles is " + Show(p.errors.rms_deg, kRms) +
           " deg, the largest " + Show(p.errors.max_abs_deg, kRms) + " deg";
  }
  for (const PredictionRecording& r : p.recordings) {
    for (std::size_t k = 0; k < r.points.size(); ++k) {
      size += (size.empty() ? "the RMS error of " : ", of ") + r.name + "'s " + r.points[k] +
              " is " + Show(r.point_rms_mm[k], kMm) + " mm (" +
              Show(r.point_rms_mean_removed_mm[k], kMm) + " mm with the mean offset removed)";
    }
  }
  text +=
      "Each recording was simulated from its own recorded inputs and compared at its own "
      "mocap frames as identification compares: " +
      size +
      ", and the error in units of the measurement noise (identification's weighted "
      "residual) has an RMS of " +
      Show(p.errors.weighted_rms, kRatio) + ": 1 is the noise floor. ";
  const std::string rule = "an RMS error above " + Show(p.above_noise_ratio, kRatio) +
                           " times its noise that chance does not explain (p below " +
                           Show(p.significance, NumberFormat::Significant(2)) + " over the " +
                           Plural(p.channels, "channel") + ")";
  if (p.above_noise.empty()) {
    text += "No joint or axis stands above the noise (" + rule +
            "): the model predicts these recordings to the noise floor.";
  } else {
    std::vector<const internal::PredictionChannel*> worst;
    for (const internal::PredictionChannel& c : p.above_noise) worst.push_back(&c);
    std::sort(worst.begin(), worst.end(), [](const auto* a, const auto* b) {
      return a->rms_deg / a->noise_deg > b->rms_deg / b->noise_deg;
    });
    std::vector<std::string> named;
    for (std::size_t k = 0; k < worst.size() && k < 6; ++k) {
      named.push_back(ChannelName(*worst[k]) + " of " + worst[k]->recording + " (" +
                      Show(worst[k]->rms_deg / worst[k]->noise_deg, NumberFormat::Fixed(1)) +
                      " times its noise)");
    }
    text += Plural(static_cast<double>(p.above_noise.size()), "channel") +
            " stand above the noise (" + rule + "): " + ListNames(named) +
            (worst.size() > 6 ? " and more (table Above the noise). " : ". ") +
            "A pattern across joints or recordings is what the model misses; an isolated "
            "channel may also be one whose measurement noise the joint's twist understates "
            "(the noise model weighs every axis of a joint alike).";
  }
  section.blocks.push_back(Paragraph{text, false});
  if (!p.completed) {
    section.blocks.push_back(Paragraph{"A prediction run did not complete: " + p.message, true});
  }
  for (const PredictionRecording& r : p.recordings) {
    for (const std::string& problem : r.problems)
      section.blocks.push_back(Paragraph{problem, true});
  }
  // Angle rows only where some recording measured angles; a tracked point
  // gets its own rows in mm.
  const bool angles = HasAngles(p);
  const bool points = HasPoints(p);
  Table table = internal::KeyValueTable(
      "prediction", "Prediction",
      std::string("From pred.json. ") +
          (angles ? "RMS and largest error: predicted − measured over every measured frame, "
                    "joint and axis. "
                  : "") +
          (points ? "Tracked points: each point's Euclidean RMS error over its frames, and "
                    "the same with its mean offset removed. "
                  : "") +
          "Weighted RMS: the RMS of (predicted − measured) / noise, the residual identification "
          "minimises; about 1 when the errors are as large as the measurement noise.");
  AddText(&table, "model", p.model_source);
  AddText(&table, "model kind", p.model_kind);
  AddText(&table, "fitted parameters", p.free.empty() ? "–" : ListNames(p.free));
  AddText(&table, "effects", p.effects.empty() ? "none" : ListNames(p.effects));
  if (!p.effects_files.empty()) AddText(&table, "effects from", ListNames(p.effects_files));
  AddValue(&table, "recordings", static_cast<double>(p.recordings.size()), "",
           NumberFormat::Integer());
  if (angles) {
    AddValue(&table, "RMS error", p.errors.rms_deg, "deg", kRms);
    AddValue(&table, "largest error", p.errors.max_abs_deg, "deg", kRms);
  }
  for (const PredictionRecording& r : p.recordings) {
    for (std::size_t k = 0; k < r.points.size() && k < r.point_rms_mm.size(); ++k) {
      const std::string name = (p.recordings.size() > 1 ? r.name + " " : "") + r.points[k];
      AddValue(&table, name + " RMS error", r.point_rms_mm[k], "mm", kMm);
      AddValue(&table, name + " RMS error, mean offset removed", r.point_rms_mean_removed_mm[k],
               "mm", kMm);
    }
  }
  AddValue(&table, "weighted RMS", p.errors.weighted_rms, "", kRatio);
  if (angles) AddValue(&table, "fit percent", p.errors.fit_percent, "%", kPercent);
  AddValue(&table, "channels above the noise", static_cast<double>(p.above_noise.size()), "",
           NumberFormat::Integer());
  AddValue(&table, "simulations", p.simulations, "", NumberFormat::Integer());
  AddValue(&table, "threads", p.threads, "", NumberFormat::Integer());
  AddValue(&table, "wall time", p.wall_time_s, "s", NumberFormat::Fixed(1));
  section.blocks.push_back(std::move(table));
  return section;
}

// ------------------------------------------------ measured against predicted

// A recording of tracked points: their paths measured and predicted, and
// their errors.
Section PointsSection(const PredictionRecording& r, const std::string& stem, bool several) {
  Section section{
      "points-" + stem,
      several ? "Measured and predicted points: " + r.name : "Measured and predicted points",
      {}};
  std::string errors;
  for (std::size_t p = 0; p < r.points.size(); ++p) {
    errors += (p == 0 ? "" : "; ") + r.points[p] + ": RMS " + Show(r.point_rms_mm[p], kMm) +
              " mm, " + Show(r.point_rms_mean_removed_mm[p], kMm) +
              " mm with the mean offset removed";
  }
  const std::string placed =
      r.placement_from == "fit" ? "placed in the capture frame as the fit placed its own recordings"
      : r.placement_from.empty()
          ? "recorded in the arm's frame"
          : "placed in the capture frame by the rigid motion that fits this recording best "
            "(the model gave none: six values fitted to the data compared)";
  section.blocks.push_back(Paragraph{
      "Recording " + r.name + " (" + r.path + "), from " + r.points_file +
          ": the measured tracked points and those the model predicts from the recording's "
          "inputs, " +
          placed + ". " + errors + ".",
      false});
  section.blocks.push_back(FigureBlock{
      internal::TrackedPointsFigure("points_" + stem, r.time_s, r.points, r.measured_mm,
                                    r.predicted_mm, "predicted"),
      "Tracked points: measured and predicted",
      "Top left: the points' paths seen from above (x against y); then x, y and z against "
      "time. Dashed: measured; solid: predicted.",
      ""});
  internal::AddPatternFigures(
      internal::TrackedPointsByPatternFigures("patterns_" + stem, r.labels, r.points, r.measured_mm,
                                              r.predicted_mm),
      "predicted", &section);
  return section;
}

Section RecordingSection(const PredictionRecording& r, std::size_t index, bool several) {
  const std::string stem = FigureStem(several ? r.name + "_" + std::to_string(index + 1) : r.name);
  if (!r.points.empty()) return PointsSection(r, stem, several);
  Section section{
      "angles-" + stem,
      several ? "Measured and predicted angles: " + r.name : "Measured and predicted angles",
      {}};
  section.blocks.push_back(Paragraph{
      "Recording " + r.name + " (" + r.path + "), from " + r.angles_file + ": the measured " +
          (r.angles_from_pipeline ? "angles (reconstructed from the markers by the mocap pipeline)"
                                  : "angles stored in the recording") +
          " and the angles the model predicts from the recording's inputs, at the measured "
          "frames. RMS error " +
          Show(r.errors.rms_deg, kRms) + " deg, largest " + Show(r.errors.max_abs_deg, kRms) +
          " deg, weighted RMS " + Show(r.errors.weighted_rms, kRatio) + ".",
      false});
  for (int c = 0; c < 2; ++c) {
    section.blocks.push_back(FigureBlock{
        internal::MeasuredAgainstSimulatedFigure(
            "angles_" + std::string(c == 0 ? "x_" : "y_") + stem, r.time_s, r.measured_deg,
            r.predicted_deg, c, r.segments, "predicted"),
        std::string(AxisName(c)) + ": measured and predicted",
        std::string(c == 0 ? "Bending angle θx" : "Out-of-plane angle θy") +
            " of every joint, one panel per segment, joints in order from the root. Dashed: "
            "measured; solid: predicted by the model (as compared, i.e. through the "
            "measurement's gaps and recorded filter).",
        ""});
  }
  section.blocks.push_back(FigureBlock{
      internal::ResidualsFigure("residuals_" + stem, r.time_s, r.residual_deg, r.segments),
      "Prediction error over time",
      "Predicted minus measured angle of every joint, θx left, θy right, one row per segment. "
      "Errors that follow the motion rather than scatter around 0 are what the model does not "
      "predict.",
      ""});
  // This recording's own errors: pooled tables hide which recording an
  // error belongs to.
  Table table;
  table.id = "errors_" + stem;
  table.title = "Errors per joint: " + r.name;
  table.caption = "pred.json 'recordings[" + std::to_string(index) +
                  "].errors': RMS and largest |predicted − measured| of this recording, its "
                  "noise per joint, and RMS over noise (about 1 at the noise floor).";
  table.columns = {{"joint", "joint", "", NumberFormat::Integer()},
                   {"rms_x_deg", "RMS θx", "deg", kRms},
                   {"max_x_deg", "largest θx", "deg", kRms},
                   {"rms_y_deg", "RMS θy", "deg", kRms},
                   {"max_y_deg", "largest θy", "deg", kRms},
                   {"noise_deg", "noise", "deg", kRms},
                   {"rms_over_noise_x", "RMS/noise θx", "", kRatio},
                   {"rms_over_noise_y", "RMS/noise θy", "", kRatio}};
  for (const auto& j : r.errors.per_joint) {
    table.AddRow({Cell::Number(j.joint), Cell::Number(j.rms_deg[0]), Cell::Number(j.max_abs_deg[0]),
                  Cell::Number(j.rms_deg[1]), Cell::Number(j.max_abs_deg[1]),
                  Cell::Number(j.noise_deg), Cell::Number(j.rms_over_noise[0]),
                  Cell::Number(j.rms_over_noise[1])});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

// ------------------------------------------------------------------ errors

Figure ErrorFigure(const PredictionFolder& p) {
  Figure figure;
  figure.name = "errors_per_joint";
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  const double joints = static_cast<double>(p.errors.per_joint.size());
  for (int c = 0; c < 2; ++c) {
    const std::size_t axis = static_cast<std::size_t>(c);
    Panel panel;
    panel.title = std::string("Prediction error ") + AxisName(c);
    panel.x = Axis{"joint", "1"};
    panel.x.min = 0.4;
    panel.x.max = joints + 0.6;
    panel.y = Axis{"error", "deg"};
    panel.y.min = 0.0;
    panel.legend = LegendPlace::kBelow;
    for (double j = 1; j <= joints; ++j) {
      panel.x.tics.push_back({j, Show(j, NumberFormat::Integer())});
    }
    Series rms{"RMS", {}, {}, palette::kFitted, SeriesStyle::kBars};
    rms.bar_width = 0.38;
    Series largest{"largest", {}, {}, palette::kStart, SeriesStyle::kBars};
    largest.bar_width = 0.38;
    Series noise{Show(p.above_noise_ratio, kRatio) + " × noise",
                 {},
                 {},
                 palette::kWarning,
                 SeriesStyle::kLinePoints};
    for (const auto& joint : p.errors.per_joint) {
      rms.x.push_back(joint.joint - 0.2);
      rms.y.push_back(joint.rms_deg[axis]);
      largest.x.push_back(joint.joint + 0.2);
      largest.y.push_back(joint.max_abs_deg[axis]);
      noise.x.push_back(joint.joint);
      noise.y.push_back(p.above_noise_ratio * joint.noise_deg);
    }
    panel.series.push_back(std::move(rms));
    panel.series.push_back(std::move(largest));
    panel.series.push_back(std::move(noise));
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

Section ErrorSection(const PredictionFolder& p) {
  // Recordings of tracked points only: no joint was measured, and what is
  // left of the section is the channels above the noise.
  const bool angles = HasAngles(p);
  Section section{"errors", angles ? "Errors per joint" : "Channels above the noise", {}};
  Table table;
  table.id = "errors_per_joint";
  table.title = "Prediction error per joint and axis";
  table.caption =
      "Over every recording (pred.json 'errors'): RMS and largest |predicted − measured|, the "
      "measurement noise of the joint (the standard deviation its residuals are weighted by), "
      "RMS over noise (about 1 at the noise floor), the axis's motion (RMS of the measured "
      "angles about their mean) and fit percent (only on an axis that moves, as on the fit "
      "page). Samples: measured frames per axis.";
  table.columns = {{"joint", "joint", "", NumberFormat::Integer()},
                   {"rms_x_deg", "RMS θx", "deg", kRms},
                   {"max_x_deg", "largest θx", "deg", kRms},
                   {"rms_y_deg", "RMS θy", "deg", kRms},
                   {"max_y_deg", "largest θy", "deg", kRms},
                   {"noise_deg", "noise", "deg", kRms},
                   {"rms_over_noise_x", "RMS/noise θx", "", kRatio},
                   {"rms_over_noise_y", "RMS/noise θy", "", kRatio},
                   {"motion_x_deg", "motion θx", "deg", kRms},
                   {"motion_y_deg", "motion θy", "deg", kRms},
                   {"fit_x_percent", "fit θx", "%", kPercent},
                   {"fit_y_percent", "fit θy", "%", kPercent},
                   {"samples_x", "samples θx", "", NumberFormat::Integer()},
                   {"samples_y", "samples θy", "", NumberFormat::Integer()}};
  for (const auto& j :
       angles ? p.errors.per_joint : std::vector<internal::PredictionErrors::Joint>{}) {
    table.AddRow({Cell::Number(j.joint), Cell::Number(j.rms_deg[0]), Cell::Number(j.max_abs_deg[0]),
                  Cell::Number(j.rms_deg[1]), Cell::Number(j.max_abs_deg[1]),
                  Cell::Number(j.noise_deg), Cell::Number(j.rms_over_noise[0]),
                  Cell::Number(j.rms_over_noise[1]), Cell::Number(j.motion_rms_deg[0]),
                  Cell::Number(j.motion_rms_deg[1]), Cell::Number(j.fit_percent[0]),
                  Cell::Number(j.fit_percent[1]), Cell::Number(j.samples[0]),
                  Cell::Number(j.samples[1])});
  }
  if (angles)
    section.blocks.push_back(FigureBlock{
        ErrorFigure(p), "Error against the noise, per joint",
        "RMS (blue) and largest (grey) prediction error of θx (left) and θy (right) per joint over "
        "every recording; red: " +
            Show(p.above_noise_ratio, kRatio) +
            " times the joint's measurement noise. A blue bar above the red mark is a channel the "
            "model does not predict to the noise floor.",
        ""});
  if (angles) section.blocks.push_back(std::move(table));

  Table above;
  above.id = "above_noise";
  above.title = "Above the noise";
  above.caption =
      "pred.json 'above_noise': every recording, joint and axis whose RMS error exceeds " +
      Show(p.above_noise_ratio, kRatio) +
      " times its noise (the loop's threshold for an unexplained channel) and whose weighted "
      "residual is not noise by chance: Σ r² N_eff / N as a chi-square of N_eff degrees of "
      "freedom (N_eff: the frames' worth of independent samples, after the measurement's "
      "filter), its p-value below the significance over the channels.";
  above.columns = {{"recording", "recording", "", kRms},
                   {"channel", "channel", "", kRms},
                   {"unit", "unit", "", kRms},
                   {"rms", "RMS", "", kRms},
                   {"noise", "noise", "", kRms},
                   {"ratio", "RMS/noise", "", kRatio},
                   {"effective_samples", "N_eff", "", NumberFormat::Fixed(1)},
                   {"p_value", "p-value", "", NumberFormat::Significant(2)}};
  for (const internal::PredictionChannel& c : p.above_noise) {
    above.AddRow({Cell::Text(c.recording), Cell::Text(ChannelName(c)),
                  Cell::Text(c.point.empty() ? "deg" : "mm"), Cell::Number(c.rms_deg),
                  Cell::Number(c.noise_deg), Cell::Number(c.rms_deg / c.noise_deg),
                  Cell::Number(c.effective_samples), Cell::Number(c.p_value)});
  }
  if (!above.rows.empty()) section.blocks.push_back(std::move(above));
  return section;
}

// ------------------------------------------------------- model, recordings

Section ModelSection(const PredictionFolder& p) {
  Section section{"model", "Model", {}};
  section.blocks.push_back(Paragraph{
      "The parameter values the prediction ran with, from " + p.model_source +
          ", set over each recording's nominal configuration" +
          (p.effects_files.empty() ? std::string()
                                   : "; effects switched on from " + ListNames(p.effects_files)) +
          ". An effect's parameters are named <effect>.<parameter>.",
      false});
  Table table;
  table.id = "parameters";
  table.title = "Parameters";
  table.caption = "pred.json 'model.values'; fitted: a free parameter of the fit.";
  table.columns = {{"parameter", "parameter", "", kValue},
                   {"value", "value", "", kValue},
                   {"fitted", "fitted", "", kValue}};
  const std::set<std::string> free(p.free.begin(), p.free.end());
  for (const auto& [name, value] : p.values) {
    table.AddRow(
        {Cell::Text(name), Cell::Number(value), Cell::Text(free.count(name) != 0 ? "fitted" : "")});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

Section RecordingsSection(const PredictionFolder& p) {
  Section section{"recordings", "Recordings", {}};
  Table table;
  table.id = "recordings";
  table.title = "Recordings";
  table.caption =
      "pred.json 'recordings': the file predicted, where its measured angles came from, how its "
      "noise was found, its errors and the status of its predicted run (the run and angles "
      "files in this folder).";
  table.columns = internal::RecordingColumns("recording");
  table.columns.insert(table.columns.end(), {{"rms_deg", "RMS", "deg", kRms},
                                             {"max_deg", "largest", "deg", kRms},
                                             {"weighted_rms", "weighted RMS", "", kRatio},
                                             {"run", "predicted run", "", kRms}});
  for (const PredictionRecording& r : p.recordings) {
    std::vector<Cell> row = internal::RecordingCells("recording", r.name, r.path,
                                                     r.angles_from_pipeline, r.noise_source);
    row.insert(row.end(), {Cell::Number(r.errors.rms_deg), Cell::Number(r.errors.max_abs_deg),
                           Cell::Number(r.errors.weighted_rms), Cell::Text(r.run_status)});
    table.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));
  return section;
}

}  // namespace

Document BuildPredictionDocument(const std::string& folder, const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  const PredictionFolder p = internal::ReadPredictionFolder(folder);
  Document document;
  document.kind = "prediction";
  document.title = "Prediction — " + p.model_source;
  document.source = folder;
  document.ccsrm_version = kVersion;
  document.sections.push_back(SummarySection(p));
  const bool several = p.recordings.size() > 1;
  for (std::size_t e = 0; e < p.recordings.size(); ++e) {
    document.sections.push_back(RecordingSection(p.recordings[e], e, several));
  }
  document.sections.push_back(ErrorSection(p));
  document.sections.push_back(ModelSection(p));
  document.sections.push_back(RecordingsSection(p));
  return document;
}

}  // namespace ccsrm::reports
