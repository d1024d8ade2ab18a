// The page of a loop folder (`ccsrm loop`): what the loop found and how the
// error changed, the residuals of the declared and the final model side by
// side (training and held out), per round the residual diagnostics and the
// candidates with their scores, refits and decisions, the final model's
// parameters, and what the final model still does not explain. Every number
// in a table is loop.json's; the figures draw the angles files of declared/,
// final/ and holdout/.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <tuple>

#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "loop_folder.h"
#include "pages.h"

namespace ccsrm::reports {
namespace {

using internal::AddText;
using internal::AddValue;
using internal::AxisName;
using internal::FigureStem;
using internal::JointGroup;
using internal::ListNames;
using internal::LoopCandidate;
using internal::LoopDeclaredCorrection;
using internal::LoopDiagnostics;
using internal::LoopDiscoveredMoment;
using internal::LoopErrors;
using internal::LoopEstimate;
using internal::LoopFolder;
using internal::LoopRound;
using internal::LoopSignal;
using internal::Plural;
using internal::Show;
using internal::UnitSuffix;

// Number formats, one per quantity, as `ccsrm loop` prints them.
const NumberFormat kRms = NumberFormat::Fixed(4);             // deg, or mm of tracked points
const NumberFormat kScore = NumberFormat::Fixed(1);           // score, ΔBIC
const NumberFormat kP = NumberFormat::Significant(2);         // p-value
const NumberFormat kValue = NumberFormat::Significant(4);     // parameters
const NumberFormat kStdError = NumberFormat::Significant(3);  // standard errors
const NumberFormat kSignal = NumberFormat::Significant(3);    // correlations and bands
const NumberFormat kCount = NumberFormat::Integer();

const char* YesNo(bool b) { return b ? "yes" : "no"; }

// A loop over tracked points (loop.json 'unit' mm): its channels are the
// points' coordinates, not joint axes.
bool OverPoints(const LoopFolder& loop) { return loop.unit == "mm"; }

// The column naming a channel's joint, or of a loop over tracked points its
// point; and its cell.
Column ChannelColumn(const LoopFolder& loop) {
  return OverPoints(loop) ? Column{"point", "point", "", kCount}
                          : Column{"joint", "joint", "", kCount};
}
Cell ChannelCell(int joint, const std::string& point) {
  return point.empty() ? Cell::Number(joint) : Cell::Text(point);
}

// A channel's axis: θx, θy of a joint; x, y, z of a tracked point.
std::string ChannelAxis(const std::string& point, int axis) {
  return point.empty() ? AxisName(axis) : std::string(1, "xyz"[axis]);
}

// The channels' word: "joint axis" or "point coordinate", plural with an s.
std::string ChannelWord(const LoopFolder& loop, bool plural) {
  return OverPoints(loop) ? (plural ? "point coordinates" : "point coordinate")
                          : (plural ? "joint axes" : "joint axis");
}

std::string Names(const std::vector<std::string>& names, const std::string& none) {
  return names.empty() ? none : ListNames(names);
}

// ------------------------------------------------------------- summary

Table LoopTable(const LoopFolder& loop) {
  Table table = internal::KeyValueTable(
      "loop", "Loop",
      OverPoints(loop)
          ? "From loop.json. RMS errors: the tracked points' Euclidean distance from the measured "
            "ones over every measured frame of the training (or held-out) experiments; the noise "
            "floor is the training experiments' noise of a point's coordinate: an RMS error near "
            "√3 times it leaves nothing to explain."
          : "From loop.json. RMS errors over every measured frame, joint and axis of the training "
            "(or held-out) experiments; the noise floor is the RMS of the training experiments' "
            "per-joint measurement noise: an RMS error near it leaves nothing to explain.");
  const std::string& unit = loop.unit;
  AddText(&table, "declared free parameters", Names(loop.declared_free, "none"));
  AddText(&table, "effects added", Names(loop.added_effects, "none"));
  std::vector<std::string> taken_back;
  for (const LoopRound& round : loop.rounds) {
    for (const internal::LoopBackwardCheck& b : round.backward) {
      if (b.taken_back) taken_back.push_back(b.name);
    }
  }
  if (!taken_back.empty()) AddText(&table, "taken back (backward step)", ListNames(taken_back));
  AddValue(&table, "rounds", static_cast<double>(loop.rounds.size()), "", kCount);
  AddValue(&table, "training RMS before", loop.rms_before_deg, unit, kRms);
  AddValue(&table, "training RMS after", loop.rms_after_deg, unit, kRms);
  AddValue(&table, "held-out RMS before", loop.holdout_rms_before_deg, unit, kRms);
  AddValue(&table, "held-out RMS after", loop.holdout_rms_after_deg, unit, kRms);
  AddValue(&table, "noise floor", loop.noise_floor_deg, unit, kRms);
  AddText(&table, "declared fit", loop.declared_fit.termination);
  AddValue(&table, "declared fit iterations", loop.declared_fit.iterations, "", kCount);
  AddText(&table, "final fit", loop.final_fit.termination);
  AddValue(&table, "final fit iterations", loop.final_fit.iterations, "", kCount);
  AddValue(&table, "simulations", loop.simulations, "", kCount);
  AddValue(&table, "wall time", loop.wall_time_s, "s", NumberFormat::Fixed(0));
  AddValue(&table, "threads", loop.threads, "", kCount);
  return table;
}

Table DataTable(const LoopFolder& loop) {
  Table table;
  table.id = "data";
  table.title = "Experiments";
  table.caption =
      "loop.json 'data': the training experiments are fitted; the held-out ones are only "
      "simulated, to test each candidate on data its fit has not seen.";
  table.columns = {{"experiment", "experiment", "", kCount},
                   {"role", "role", "", kCount},
                   {"file", "file", "", kCount}};
  for (const LoopFolder::Data& d : loop.data) {
    table.AddRow(
        {Cell::Text(d.name), Cell::Text(d.holdout ? "held out" : "training"), Cell::Text(d.path)});
  }
  return table;
}

// "[lo, hi]", or "not identifiable" when the interval is unknown.
std::string IntervalText(double lower, double upper) {
  return std::isfinite(lower) ? "[" + Show(lower, kValue) + ", " + Show(upper, kValue) + "]"
                              : "not identifiable";
}

// The declared values the loop corrected: the difference of calibrated.yaml
// from the declared configuration.
Table DeclaredCorrectionTable(const LoopFolder& loop) {
  Table table;
  table.id = "declared_corrections";
  table.title = "Declared values corrected (calibrated.yaml)";
  table.caption =
      "loop.json 'declared_corrections': values of the configuration the data say are off, "
      "and the corrected configuration's values (calibrated.yaml in the loop folder). "
      "Relative error: (corrected - declared) / declared, with its 95 % interval. Values the "
      "data cannot tell apart from it are listed: it stands for their combination.";
  // Six digits: a correction of a tenth of a per cent must show.
  const NumberFormat kConfig = NumberFormat::Significant(6);
  table.columns = {
      {"value", "configuration key", "", kCount}, {"declared", "declared", "", kConfig},
      {"corrected", "corrected", "", kConfig},    {"relative", "relative error", "", kValue},
      {"ci", "95 % interval", "", kCount},        {"alike", "indistinguishable from", "", kCount}};
  for (const LoopDeclaredCorrection& d : loop.declared_corrections) {
    const std::string ci = IntervalText(d.relative_ci95[0], d.relative_ci95[1]);
    table.AddRow({Cell::Text(d.config_key), Cell::Number(d.declared), Cell::Number(d.corrected),
                  Cell::Number(d.relative), Cell::Text(ci),
                  Cell::Text(Names(d.indistinguishable, "-"))});
  }
  return table;
}

// The terms the loop found in the data: one row per term of each moment.
Table DiscoveredTermsTable(const LoopFolder& loop) {
  Table table;
  table.id = "discovered_terms";
  table.title = "Terms found in the data (joint_moment)";
  table.caption =
      "loop.json 'discovered_terms': the moment the final model adds at every joint of a "
      "segment about one axis, M = sum of coefficient x term, in the joint's own angle θ [rad] "
      "and rate θ̇ [rad/s], the bending rate its inputs command θ̇_in [rad/s] and time t [s]; "
      "chosen by sparse regression on the residual and refitted "
      "in the simulator (docs/loop.md). Coefficients with their 95 % intervals.";
  table.columns = {{"joints", "joints", "", kCount},    {"axis", "axis", "", kCount},
                   {"term", "term", "", kCount},        {"value", "coefficient", "", kValue},
                   {"ci", "95 % interval", "", kCount}, {"units", "units", "", kCount}};
  for (const LoopDiscoveredMoment& m : loop.discovered_terms) {
    const std::string joints = Show(m.joints[0], kCount) + "-" + Show(m.joints[1], kCount) +
                               " (segment " + std::to_string(m.segment) + ")";
    for (const LoopDiscoveredMoment::Term& t : m.terms) {
      const LoopEstimate& e = t.estimate;
      const std::string ci = IntervalText(e.ci95_lower, e.ci95_upper);
      table.AddRow({Cell::Text(joints), Cell::Text("θ" + m.axis), Cell::Text(t.formula),
                    Cell::Number(e.value), Cell::Text(ci), Cell::Text(t.units)});
    }
  }
  return table;
}

// The answer, before how it was found (issue 44): what the loop added, with
// its fitted values and intervals, the error before and after against the
// noise, and whether the final model explains the data.
Paragraph AnswerParagraph(const LoopFolder& loop) {
  std::string text;
  if (loop.added_effects.empty() && loop.declared_corrections.empty() &&
      loop.discovered_terms.empty()) {
    text = "Answer: nothing added; the declared model is kept.";
  } else {
    std::vector<std::string> found;
    for (const std::string& effect : loop.added_effects) {
      std::vector<std::string> values;
      for (const LoopEstimate& e : loop.parameters) {
        if (e.name.rfind(effect + ".", 0) != 0) continue;
        values.push_back(e.name + " = " + Show(e.value, kValue) +
                         (std::isfinite(e.ci95_lower) ? " [" + Show(e.ci95_lower, kValue) + ", " +
                                                            Show(e.ci95_upper, kValue) + "]"
                                                      : std::string()) +
                         (e.units.empty() || e.units == "1" ? "" : " " + e.units));
      }
      found.push_back(values.empty() ? effect : effect + ": " + ListNames(values));
    }
    for (const LoopDeclaredCorrection& d : loop.declared_corrections) {
      found.push_back("the declared " + d.config_key + " corrected from " +
                      Show(d.declared, kValue) + " to " + Show(d.corrected, kValue));
    }
    if (!loop.discovered_terms.empty()) found.push_back("terms found in the data (table below)");
    text = "Answer: added " + ListNames(found) + ".";
  }
  const std::string unit = " " + loop.unit;
  text += " Training RMS error " + Show(loop.rms_before_deg, kRms) + unit + " declared, " +
          Show(loop.rms_after_deg, kRms) + unit + " final";
  if (std::isfinite(loop.holdout_rms_before_deg) && std::isfinite(loop.holdout_rms_after_deg)) {
    text += "; held out " + Show(loop.holdout_rms_before_deg, kRms) + unit + " declared, " +
            Show(loop.holdout_rms_after_deg, kRms) + unit + " final";
  }
  text += "; the noise floor is " + Show(loop.noise_floor_deg, kRms) + unit +
          (OverPoints(loop) ? " per coordinate." : ".");
  bool misfit = false;
  if (loop.final_model && loop.final_model->adequacy_known) {
    std::string verdict = loop.final_model->verdict;
    if (!verdict.empty()) {
      verdict[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(verdict[0])));
    }
    misfit = !loop.final_model->adequate;
    text +=
        " " + verdict +
        (misfit ? "; what the loop could not explain is under \"What remains unexplained\"." : ".");
  }
  return Paragraph{text, misfit};
}

Section SummarySection(const LoopFolder& loop) {
  Section section{"summary", "Summary", {}};
  section.blocks.push_back(AnswerParagraph(loop));
  std::vector<std::string> training, holdout;
  for (const LoopFolder::Data& d : loop.data) (d.holdout ? holdout : training).push_back(d.name);
  std::string text =
      "ccsrm loop fitted the declared model (free: " + Names(loop.declared_free, "none") + ") to " +
      Plural(static_cast<double>(training.size()), "training experiment") + " (" +
      ListNames(training) + ")";
  if (!holdout.empty()) text += ", held out " + ListNames(holdout);
  text += ", and tried the candidate effects in " +
          Plural(static_cast<double>(loop.rounds.size()), "round") + ". The training RMS error " +
          (OverPoints(loop) ? "of the tracked points " : "") + "went from " +
          Show(loop.rms_before_deg, kRms) + " " + loop.unit + " with the declared model to " +
          Show(loop.rms_after_deg, kRms) + " " + loop.unit + " with the final one";
  if (std::isfinite(loop.holdout_rms_before_deg) && std::isfinite(loop.holdout_rms_after_deg)) {
    text += ", the held-out error from " + Show(loop.holdout_rms_before_deg, kRms) + " to " +
            Show(loop.holdout_rms_after_deg, kRms) + " " + loop.unit;
  }
  text += "; the measurement noise floor is " + Show(loop.noise_floor_deg, kRms) + " " + loop.unit +
          (OverPoints(loop) ? " per coordinate." : ".");
  section.blocks.push_back(Paragraph{text, false});
  section.blocks.push_back(Paragraph{"Conclusion: " + loop.conclusion, false});
  if (loop.declared_fit.termination == "failed") {
    section.blocks.push_back(
        Paragraph{"The declared model's fit failed: no candidate was tried.", true});
  }
  for (const std::string& problem : loop.problems) {
    section.blocks.push_back(Paragraph{problem, true});
  }
  section.blocks.push_back(Paragraph{
      "The fits of the declared and the final model have pages of their own: ccsrm report --in " +
          (std::filesystem::path(loop.folder) / "declared").string() + " (or final).",
      false});
  section.blocks.push_back(LoopTable(loop));
  for (const LoopRound& round : loop.rounds) {
    for (const internal::LoopBackwardCheck& b : round.backward) {
      if (b.taken_back) {
        section.blocks.push_back(Paragraph{
            "Backward step, round " + std::to_string(round.index) + ": " + b.reason + ".", false});
      }
    }
  }
  if (!loop.declared_corrections.empty()) {
    for (const LoopDeclaredCorrection& d : loop.declared_corrections) {
      section.blocks.push_back(Paragraph{"Declared value: " + d.sentence + ".", false});
    }
    section.blocks.push_back(DeclaredCorrectionTable(loop));
  }
  if (!loop.discovered_terms.empty()) {
    for (const LoopDiscoveredMoment& m : loop.discovered_terms) {
      section.blocks.push_back(Paragraph{"Term found in the data: " + m.formula + ".", false});
    }
    section.blocks.push_back(DiscoveredTermsTable(loop));
  }
  section.blocks.push_back(DataTable(loop));
  return section;
}

// -------------------------------------------------------------- errors

// RMS error per joint before (grey) and after (blue): θx left, θy right;
// training in the first row, held out in the second when there is one.
Figure ErrorFigure(const LoopFolder& loop) {
  Figure figure;
  figure.name = "errors_per_joint";
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  struct Set {
    std::string title;
    const LoopErrors* before;
    const LoopErrors* after;
  };
  std::vector<Set> sets = {{"training", &loop.before, &loop.after}};
  if (loop.holdout_before && loop.holdout_after) {
    sets.push_back({"held out", &*loop.holdout_before, &*loop.holdout_after});
  }
  for (const Set& set : sets) {
    const double joints = static_cast<double>(set.before->joint_rms_deg.size());
    for (int c = 0; c < 2; ++c) {
      Panel panel;
      panel.title = "RMS error " + std::string(AxisName(c)) + ", " + set.title;
      panel.x = Axis{"joint", "1"};
      panel.x.min = 0.4;
      panel.x.max = joints + 0.6;
      panel.y = Axis{"RMS error", "deg"};
      panel.y.min = 0.0;
      panel.legend = LegendPlace::kBelow;
      for (double j = 1; j <= joints; ++j) panel.x.tics.push_back({j, Show(j, kCount)});
      const std::pair<const LoopErrors*, const std::string*> bars[] = {
          {set.before, &palette::kStart}, {set.after, &palette::kFitted}};
      for (int s = 0; s < 2; ++s) {
        Series series;
        series.label = s == 0 ? "declared model" : "final model";
        series.color = *bars[s].second;
        series.style = SeriesStyle::kBars;
        series.bar_width = 0.38;
        const auto& rms = bars[s].first->joint_rms_deg;
        for (std::size_t j = 0; j < rms.size(); ++j) {
          series.x.push_back(static_cast<double>(j + 1) + (s == 0 ? -0.2 : 0.2));
          series.y.push_back(rms[j][static_cast<std::size_t>(c)]);
        }
        panel.series.push_back(std::move(series));
      }
      figure.panels.push_back(std::move(panel));
    }
  }
  return figure;
}

// Per training experiment and tracked point, from declared/ and final/:
// the RMS error and the same with the mean offset removed (the publishing
// project's metric on the recorded robot).
Table PointErrorTable(const LoopFolder& loop) {
  Table table;
  table.id = "errors_per_point";
  table.title = "RMS error per tracked point";
  table.caption =
      "declared/ and final/ fit.json 'tracked_points' of the training experiments: the Euclidean "
      "RMS distance of the fitted point from the measured one, and the same after removing the "
      "mean offset.";
  table.columns = {{"experiment", "experiment", "", kRms},
                   {"point", "point", "", kRms},
                   {"before_mm", "declared model", "mm", kRms},
                   {"after_mm", "final model", "mm", kRms},
                   {"before_mean_removed_mm", "declared, mean removed", "mm", kRms},
                   {"after_mean_removed_mm", "final, mean removed", "mm", kRms}};
  if (!loop.declared || !loop.final_model) return table;
  for (const internal::FitExperiment& before : loop.declared->experiments) {
    for (const internal::FitExperiment& after : loop.final_model->experiments) {
      if (after.name != before.name || after.points != before.points) continue;
      for (std::size_t p = 0; p < before.points.size(); ++p) {
        const auto at = [p](const std::vector<double>& v) {
          return p < v.size() ? Cell::Number(v[p]) : Cell::Missing();
        };
        table.AddRow({Cell::Text(before.name), Cell::Text(before.points[p]),
                      at(before.point_rms_mm), at(after.point_rms_mm),
                      at(before.point_rms_mean_removed_mm), at(after.point_rms_mean_removed_mm)});
      }
    }
  }
  return table;
}

Section ErrorSection(const LoopFolder& loop) {
  Section section{"errors", "Error before and after", {}};
  const bool held = loop.holdout_before && loop.holdout_after;
  Table overall;
  overall.id = "errors";
  overall.title = "RMS error";
  overall.caption =
      "loop.json 'rms_before_deg', 'rms_after_deg' and their held-out twins: the declared "
      "model's fit (before) against the final model's (after)" +
      std::string(OverPoints(loop) ? ", in mm (loop.json 'unit')." : ".");
  overall.columns = {{"data", "data", "", kRms},
                     {"before_" + loop.unit, "declared model", loop.unit, kRms},
                     {"after_" + loop.unit, "final model", loop.unit, kRms}};
  overall.AddRow({Cell::Text("training"), Cell::Number(loop.rms_before_deg),
                  Cell::Number(loop.rms_after_deg)});
  if (std::isfinite(loop.holdout_rms_before_deg) || std::isfinite(loop.holdout_rms_after_deg)) {
    overall.AddRow({Cell::Text("held out"), Cell::Number(loop.holdout_rms_before_deg),
                    Cell::Number(loop.holdout_rms_after_deg)});
  }
  if (OverPoints(loop)) {
    section.blocks.push_back(std::move(overall));
    section.blocks.push_back(PointErrorTable(loop));
    return section;
  }
  Table per_joint;
  per_joint.id = "errors_per_joint";
  per_joint.title = "RMS error per joint";
  per_joint.caption =
      "loop.json 'before' and 'after' (and 'holdout_before', 'holdout_after'): per joint and "
      "axis over every experiment of the set.";
  per_joint.columns = {{"joint", "joint", "", kCount},
                       {"training_x_before_deg", "training θx before", "deg", kRms},
                       {"training_x_after_deg", "training θx after", "deg", kRms},
                       {"training_y_before_deg", "training θy before", "deg", kRms},
                       {"training_y_after_deg", "training θy after", "deg", kRms}};
  if (held) {
    per_joint.columns.push_back({"holdout_x_before_deg", "held-out θx before", "deg", kRms});
    per_joint.columns.push_back({"holdout_x_after_deg", "held-out θx after", "deg", kRms});
    per_joint.columns.push_back({"holdout_y_before_deg", "held-out θy before", "deg", kRms});
    per_joint.columns.push_back({"holdout_y_after_deg", "held-out θy after", "deg", kRms});
  }
  // A set with fewer joints than another shows – for the joints it lacks.
  const auto rms = [](const LoopErrors& e, std::size_t j, std::size_t c) {
    return j < e.joint_rms_deg.size() ? Cell::Number(e.joint_rms_deg[j][c]) : Cell::Missing();
  };
  std::size_t joints = std::max(loop.before.joint_rms_deg.size(), loop.after.joint_rms_deg.size());
  if (held) joints = std::max(joints, loop.holdout_before->joint_rms_deg.size());
  for (std::size_t j = 0; j < joints; ++j) {
    std::vector<Cell> row = {Cell::Number(static_cast<double>(j + 1)), rms(loop.before, j, 0),
                             rms(loop.after, j, 0), rms(loop.before, j, 1), rms(loop.after, j, 1)};
    if (held) {
      for (std::size_t c = 0; c < 2; ++c) {
        row.push_back(rms(*loop.holdout_before, j, c));
        row.push_back(rms(*loop.holdout_after, j, c));
      }
    }
    per_joint.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(overall));
  section.blocks.push_back(FigureBlock{
      ErrorFigure(loop), "Before and after, per joint",
      std::string("RMS error of θx (left) and θy (right) per joint: grey with the declared "
                  "model, blue with the final one; training data") +
          (held ? " (top) and held-out data (bottom)." : "."),
      ""});
  section.blocks.push_back(std::move(per_joint));
  return section;
}

// ----------------------------------------------------------- residuals

// Residuals of one axis, one row per segment: the declared model left and
// the final model right, on the same y range so the two can be compared.
// `before` and `after` are T × J × 2 residuals [deg] at `time_before` and
// `time_after`.
Figure PairedResidualFigure(const std::string& name) {
  Figure figure;
  figure.name = name;
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 280;
  return figure;
}

// One row of a residual figure, `title`: the series of components 0..n-1 of
// index `which` (a joint's axis, a point's coordinate), from `before` (the
// declared model, left) and `after` (the final model, right), on the same y
// range. `component(k)` gives series k's index and axis into the arrays, its
// label and its colour index.
void AddResidualRow(
    const std::string& title, const Axis& y, std::size_t n,
    const std::function<std::tuple<std::size_t, std::size_t, std::string, int>(std::size_t)>&
        component,
    const std::vector<double>& time_before, const datasets::Array& before,
    const std::vector<double>& time_after, const datasets::Array& after, Figure* figure) {
  double top = 0.0;
  const std::pair<const std::vector<double>*, const datasets::Array*> sides[] = {
      {&time_before, &before}, {&time_after, &after}};
  std::vector<Panel> pair;
  for (int s = 0; s < 2; ++s) {
    Panel panel;
    panel.title = title + ": " + (s == 0 ? "declared model" : "final model");
    panel.x = internal::TimeAxis();
    panel.y = y;
    for (std::size_t k = 0; k < n; ++k) {
      const auto [index, axis, label, colour] = component(k);
      Series series{label, *sides[s].first, internal::ComponentOf(*sides[s].second, index, axis),
                    palette::Indexed(colour)};
      series.line_width = 1.2;
      for (double v : series.y) {
        if (std::isfinite(v)) top = std::max(top, std::abs(v));
      }
      panel.series.push_back(std::move(series));
    }
    pair.push_back(std::move(panel));
  }
  if (top > 0.0) {
    for (Panel& panel : pair) {
      panel.y.min = -1.05 * top;
      panel.y.max = 1.05 * top;
    }
  }
  for (Panel& panel : pair) figure->panels.push_back(std::move(panel));
}

Figure ResidualFigure(const std::string& name, const std::vector<JointGroup>& segments, int c,
                      const std::vector<double>& time_before, const datasets::Array& before,
                      const std::vector<double>& time_after, const datasets::Array& after) {
  Figure figure = PairedResidualFigure(name);
  const std::size_t axis = static_cast<std::size_t>(c);
  for (const JointGroup& group : segments) {
    AddResidualRow(
        group.title, Axis{std::string("residual ") + AxisName(c), "deg"},
        static_cast<std::size_t>(group.joints),
        [&](std::size_t k) {
          const std::size_t j = static_cast<std::size_t>(group.first_joint - 1) + k;
          return std::tuple{j, axis, "joint " + std::to_string(j + 1), static_cast<int>(k) + 1};
        },
        time_before, before, time_after, after, &figure);
  }
  return figure;
}

// Residuals of tracked points (T × P × 3 [mm]), one row per coordinate x,
// y, z: the declared model left and the final model right, each point in
// its colour.
Figure PointResidualFigure(const std::string& name, const std::vector<std::string>& points,
                           const std::vector<double>& time_before, const datasets::Array& before,
                           const std::vector<double>& time_after, const datasets::Array& after) {
  Figure figure = PairedResidualFigure(name);
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string axis(1, "xyz"[a]);
    AddResidualRow(
        "Coordinate " + axis, Axis{"residual " + axis, "mm"}, points.size(),
        [&](std::size_t p) {
          return std::tuple{p, a, points[p], static_cast<int>(p) + 1};
        },
        time_before, before, time_after, after, &figure);
  }
  return figure;
}

// model − measured of a held-out experiment, T × J × 2 [deg].
datasets::Array Difference(const datasets::Array& model, const datasets::Array& measured) {
  datasets::Array out = model;
  for (std::size_t i = 0; i < out.values.size(); ++i) out.values[i] -= measured.values[i];
  return out;
}

// The arm's segments, from a fitted run in declared/ or final/: the
// held-out angles files carry no configuration.
const std::vector<JointGroup>* SegmentsOf(const LoopFolder& loop) {
  for (const auto* fit : {&loop.declared, &loop.final_model}) {
    if (*fit && !(*fit)->experiments.empty()) return &(*fit)->experiments.front().segments;
  }
  return nullptr;
}

Section TrainingResidualSection(const LoopFolder& loop) {
  Section section{"residuals", "Residuals before and after (training)", {}};
  if (!loop.declared || !loop.final_model) {
    section.blocks.push_back(Paragraph{
        "Without both fit folders (declared/ and final/) there is nothing to compare here.",
        false});
    return section;
  }
  section.blocks.push_back(Paragraph{
      OverPoints(loop)
          ? "Residual (fitted − measured) of every tracked point over time, from declared/ and "
            "final/ <experiment>.points.csv: left with the declared model's fitted parameters, "
            "right with the final model's. A residual that follows the motion rather than "
            "scattering around 0 is what a model misses."
          : "Residual (fitted − measured) of every joint over time, from declared/ and final/ "
            "<experiment>.angles.csv: left with the declared model's fitted parameters, right "
            "with the final model's. A residual that follows the motion rather than scattering "
            "around 0 is what a model misses.",
      false});
  const bool several = loop.declared->experiments.size() > 1;
  for (std::size_t e = 0; e < loop.declared->experiments.size(); ++e) {
    const internal::FitExperiment& before = loop.declared->experiments[e];
    const internal::FitExperiment* after = nullptr;
    for (const internal::FitExperiment& x : loop.final_model->experiments) {
      if (x.name == before.name) after = &x;
    }
    if (!before.points.empty()) {
      if (after == nullptr || after->points != before.points) {
        section.blocks.push_back(
            Paragraph{"final/ has no experiment " + before.name +
                          " with the tracked points of declared/: its residuals are not shown.",
                      true});
        continue;
      }
      const std::string stem =
          FigureStem(several ? before.name + "_" + std::to_string(e + 1) : before.name);
      section.blocks.push_back(FigureBlock{
          PointResidualFigure("residual_points_" + stem, before.points, before.time_s,
                              before.residual_mm, after->time_s, after->residual_mm),
          "Tracked points' residual: " + before.name,
          "Experiment " + before.name +
              ": fitted minus measured position of each tracked point, one row per coordinate "
              "(in the frame the points were recorded in); the declared model left, the final "
              "model right, on the same scale.",
          ""});
      continue;
    }
    if (after == nullptr || after->residual_deg.shape[1] != before.residual_deg.shape[1]) {
      section.blocks.push_back(
          Paragraph{"final/ has no experiment " + before.name +
                        " with the joints of declared/: its residuals are not shown.",
                    true});
      continue;
    }
    const std::string stem =
        FigureStem(several ? before.name + "_" + std::to_string(e + 1) : before.name);
    for (int c = 0; c < 2; ++c) {
      section.blocks.push_back(FigureBlock{
          ResidualFigure(std::string("residual_") + (c == 0 ? "x_" : "y_") + stem, before.segments,
                         c, before.time_s, before.residual_deg, after->time_s, after->residual_deg),
          std::string(AxisName(c)) + " residual: " + before.name,
          "Experiment " + before.name + ", " + AxisName(c) +
              ": fitted minus measured angle, one row per segment, joints in order from the root "
              "(colours as on the run page); the declared model left, the final model right, on "
              "the same scale.",
          ""});
    }
  }
  for (const auto* fit : {&*loop.declared, &*loop.final_model}) {
    for (const internal::FitExperiment& x : fit->experiments) {
      for (const std::string& problem : x.problems) {
        section.blocks.push_back(Paragraph{fit->folder + ": " + problem, true});
      }
    }
  }
  return section;
}

Section HoldoutResidualSection(const LoopFolder& loop) {
  Section section{"holdout", "Residuals before and after (held out)", {}};
  section.blocks.push_back(Paragraph{
      OverPoints(loop)
          ? "Residual (simulated − measured) of the held-out experiments' tracked points, from "
            "holdout/<experiment>.declared.points.csv and .final.points.csv: left the declared "
            "model's run, right the final model's. Neither fit saw these data."
          : "Residual (simulated − measured) of the held-out experiments, from holdout/"
            "<experiment>.angles.csv: left the declared model's run, right the final model's. "
            "Neither fit saw these data.",
      false});
  const std::vector<JointGroup>* known = SegmentsOf(loop);
  const bool several = loop.holdout.size() > 1;
  for (std::size_t e = 0; e < loop.holdout.size(); ++e) {
    const internal::LoopHoldout& h = loop.holdout[e];
    if (!h.points.empty()) {
      const std::string stem = FigureStem(several ? h.name + "_" + std::to_string(e + 1) : h.name);
      section.blocks.push_back(FigureBlock{
          PointResidualFigure("holdout_residual_points_" + stem, h.points, h.time_s,
                              h.declared_residual_mm, h.time_s, h.final_residual_mm),
          "Tracked points' residual: " + h.name + " (held out)",
          "Held-out experiment " + h.name + " (" + h.path +
              "): simulated minus measured position of each tracked point, one row per "
              "coordinate; the declared model left, the final model right, on the same scale.",
          ""});
      continue;
    }
    const std::size_t joints = h.measured_deg.shape[1];
    std::vector<JointGroup> segments;
    int covered = 0;
    if (known) {
      for (const JointGroup& g : *known) covered += g.joints;
    }
    // The fit folders' segments, when they describe the same arm.
    if (known && covered == static_cast<int>(joints)) {
      segments = *known;
    } else {
      segments = {{"All joints (1–" + std::to_string(joints) + ")", 1, static_cast<int>(joints)}};
    }
    const std::string stem = FigureStem(several ? h.name + "_" + std::to_string(e + 1) : h.name);
    const datasets::Array before = Difference(h.declared_deg, h.measured_deg);
    const datasets::Array after = Difference(h.final_deg, h.measured_deg);
    for (int c = 0; c < 2; ++c) {
      section.blocks.push_back(FigureBlock{
          ResidualFigure(std::string("holdout_residual_") + (c == 0 ? "x_" : "y_") + stem, segments,
                         c, h.time_s, before, h.time_s, after),
          std::string(AxisName(c)) + " residual: " + h.name + " (held out)",
          "Held-out experiment " + h.name + " (" + h.path + "), " + AxisName(c) +
              ": simulated minus measured angle, one row per segment; the declared model left, "
              "the final model right, on the same scale.",
          ""});
    }
  }
  return section;
}

// -------------------------------------------------------------- rounds

// Pooled cross-correlation of the residual with each plotted signal against
// the lag, with the 95 % band of "no relation" dashed.
Figure CrossCorrelationFigure(const std::string& name, const LoopDiagnostics& d) {
  Figure figure;
  figure.name = name;
  figure.columns = 3;
  figure.panel_width_px = 420;
  figure.panel_height_px = 250;
  for (const auto& [signal, curve] : d.cross_correlation) {
    const LoopSignal* pooled = nullptr;
    for (const LoopSignal& s : d.pooled) {
      if (s.signal == signal) pooled = &s;
    }
    const bool significant = pooled && pooled->significant;
    Panel panel;
    panel.title = signal + (significant ? " (outside the band)" : "");
    panel.x = Axis{"lag", "s"};
    panel.y = Axis{"correlation", "1"};
    panel.legend = LegendPlace::kNone;
    // Five labelled lags: gnuplot's own tics crowd a third of the page.
    const double reach = std::max(std::abs(d.lags_s.front()), std::abs(d.lags_s.back()));
    for (double f : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
      panel.x.tics.push_back({f * reach, Show(f * reach, NumberFormat::Significant(3))});
    }
    Series series{signal, d.lags_s, curve, significant ? palette::kWarning : palette::kNeutral,
                  SeriesStyle::kLinePoints};
    series.point_size = 0.4;
    panel.series.push_back(std::move(series));
    if (pooled && std::isfinite(pooled->band) && !d.lags_s.empty()) {
      const double x0 = d.lags_s.front(), x1 = d.lags_s.back();
      for (double sign : {1.0, -1.0}) {
        Series band{"",
                    {x0, x1},
                    {sign * pooled->band, sign * pooled->band},
                    palette::kStart,
                    SeriesStyle::kDashed};
        band.line_width = 1.0;
        panel.series.push_back(std::move(band));
      }
    }
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

// The figure of `d`'s cross-correlations, or a line saying there are none
// (a loop whose declared fit failed diagnosed nothing).
Block CrossCorrelationBlock(const std::string& name, const LoopDiagnostics& d,
                            const std::string& title, const std::string& caption) {
  if (d.cross_correlation.empty() || d.lags_s.empty()) {
    return Paragraph{title + ": loop.json holds no cross-correlations to plot.", false};
  }
  return FigureBlock{CrossCorrelationFigure(name, d), title, caption, ""};
}

Table SignalTable(const std::string& id, const std::string& title, const LoopDiagnostics& d,
                  const std::string& source) {
  Table table;
  table.id = id;
  table.title = title;
  table.caption =
      source +
      ": each signal's correlation with the residual pooled over every channel (joint axis or "
      "tracked point coordinate; for constant, hysteresis and lag the normalised statistic of "
      "diagnostics.h), and the 95 % band of no relation from the effective number of "
      "independent samples.";
  table.columns = {{"signal", "signal", "", kSignal},
                   {"value", "value", "", kSignal},
                   {"band", "95 % band", "", kSignal},
                   {"outside_band", "outside the band", "", kSignal}};
  for (const LoopSignal& s : d.pooled) {
    table.AddRow({Cell::Text(s.signal), Cell::Number(s.value), Cell::Number(s.band),
                  Cell::Text(YesNo(s.significant))});
  }
  return table;
}

Table ExperimentLagTable(const std::string& id, const LoopDiagnostics& d, const std::string& source,
                         const std::string& unit) {
  Table table;
  table.id = id;
  table.title = "Residual per experiment";
  table.caption = source +
                  ": RMS residual, the shift of the simulated motion that best matches the "
                  "measured one (positive: the arm moves later than simulated) and the share of "
                  "the residual's mean square that shift removes.";
  table.columns = {{"experiment", "experiment", "", kRms},
                   {"rms_deg", "RMS", unit, kRms},
                   {"lag_s", "lag", "s", NumberFormat::Fixed(3)},
                   {"lag_explained", "explained by the lag", "", kSignal}};
  for (const LoopDiagnostics::Experiment& e : d.experiments) {
    table.AddRow({Cell::Text(e.name), Cell::Number(e.rms_deg), Cell::Number(e.lag_s),
                  Cell::Number(e.lag_explained)});
  }
  return table;
}

Table CandidateTable(const std::string& id, const LoopRound& round, const std::string& unit) {
  Table table;
  table.id = id;
  table.title = "Candidates";
  table.caption =
      "loop.json 'candidates', best score first. Score: the effective chi-square the "
      "linearised candidate removes (score test), p its p-value. The significant best few are "
      "refitted: ΔBIC of the refit (> 10 needed), training and held-out RMS after it. Accepted "
      "only when ΔBIC, the held-out gain and the size of the effect all pass (reason).";
  table.columns = {{"candidate", "candidate", "", kScore},
                   {"parameters", "size parameters", "", kScore, true},
                   {"score", "score", "", kScore},
                   {"p_value", "p", "", kP},
                   {"significant", "significant", "", kScore},
                   {"refitted", "refitted", "", kScore},
                   {"delta_bic", "ΔBIC", "", kScore},
                   {"rms_deg", "RMS", unit, kRms},
                   {"holdout_rms_deg", "held-out RMS", unit, kRms},
                   {"holdout_improved", "held-out gain", "", kScore},
                   {"size_significant", "size ≠ 0", "", kScore},
                   {"accepted", "accepted", "", kScore},
                   {"reason", "reason", "", kScore, true}};
  for (const LoopCandidate& c : round.candidates) {
    const auto refit = [&c](Cell cell) { return c.refitted ? cell : Cell::Missing(); };
    std::string parameters;
    for (const std::string& p : c.parameters) parameters += (parameters.empty() ? "" : ", ") + p;
    table.AddRow({Cell::Text(c.name), Cell::Text(parameters), Cell::Number(c.score),
                  Cell::Number(c.p_value), Cell::Text(YesNo(c.significant)),
                  Cell::Text(YesNo(c.refitted)), refit(Cell::Number(c.delta_bic)),
                  refit(Cell::Number(c.rms_deg)), refit(Cell::Number(c.holdout_rms_deg)),
                  refit(Cell::Text(YesNo(c.holdout_improved))),
                  refit(Cell::Text(YesNo(c.size_significant))), Cell::Text(YesNo(c.accepted)),
                  Cell::Text(c.reason)});
  }
  return table;
}

// The backward step of a round (issue 28): each earlier addition checked
// in the fit after the round's winner, and whether it was taken back.
Table BackwardTable(const std::string& id, const LoopRound& round, const std::string& unit) {
  Table table;
  table.id = id;
  table.title = "Backward step";
  table.caption =
      "loop.json 'backward': after the round's winner was added, every earlier addition is "
      "checked in the new fit. Size ≠ 0: an interval of its parameters excludes 0, or setting "
      "them to 0 raises the effective chi-square (Δχ² at 0) beyond its 95 % quantile. One whose "
      "size is indistinguishable from 0 is refitted away; it is taken back when the ΔBIC of "
      "keeping it is 10 or less (docs/loop.md). At most one per round.";
  table.columns = {{"addition", "addition", "", kScore},
                   {"parameters", "parameters", "", kScore, true},
                   {"size_significant", "size ≠ 0", "", kScore},
                   {"delta_chi2_zeroed", "Δχ² at 0", "", kScore},
                   {"refitted", "refitted without", "", kScore},
                   {"delta_bic_keep", "ΔBIC of keeping", "", kScore},
                   {"rms_deg_without", "RMS without", unit, kRms},
                   {"holdout_rms_deg_without", "held-out RMS without", unit, kRms},
                   {"taken_back", "taken back", "", kScore},
                   {"reason", "reason", "", kScore, true}};
  for (const internal::LoopBackwardCheck& b : round.backward) {
    table.AddRow({Cell::Text(b.name), Cell::Text(ListNames(b.parameters)),
                  Cell::Text(YesNo(b.size_significant)), Cell::Number(b.delta_chi2_zeroed),
                  Cell::Text(YesNo(b.refitted)), Cell::Number(b.delta_bic_keep),
                  Cell::Number(b.rms_deg_without), Cell::Number(b.holdout_rms_deg_without),
                  Cell::Text(YesNo(b.taken_back)), Cell::Text(b.reason)});
  }
  return table;
}

// Each candidate's size parameters: the score test's linear estimate and,
// when refitted, the refit's estimate with its interval.
Table EstimateTable(const std::string& id, const LoopRound& round) {
  Table table;
  table.id = id;
  table.title = "Size parameters of the candidates";
  table.caption =
      "loop.json 'linearised' (the score test's linear estimate at the round's fitted point) and "
      "'estimates' (the refit's, with standard error and 95 % interval) of each candidate's "
      "size parameters.";
  table.columns = {{"candidate", "candidate", "", kValue},
                   {"parameter", "parameter", "", kValue},
                   {"unit", "unit", "", kValue},
                   {"linearised", "linearised", "", kValue},
                   {"estimate", "refitted", "", kValue},
                   {"std_error", "standard error", "", kStdError},
                   {"ci95_lower", "95 % interval from", "", kValue},
                   {"ci95_upper", "95 % interval to", "", kValue},
                   {"identifiable", "identifiable", "", kValue}};
  for (const LoopCandidate& c : round.candidates) {
    for (const std::string& name : c.parameters) {
      double linear = internal::kUnknown;
      for (const auto& [n, v] : c.linearised) {
        if (n == name) linear = v;
      }
      const LoopEstimate* e = nullptr;
      for (const LoopEstimate& x : c.estimates) {
        if (x.name == name) e = &x;
      }
      table.AddRow({Cell::Text(c.name), Cell::Text(name), Cell::Text(e ? e->units : ""),
                    Cell::Number(linear), e ? Cell::Number(e->value) : Cell::Missing(),
                    e ? Cell::Number(e->std_error) : Cell::Missing(),
                    e ? Cell::Number(e->ci95_lower) : Cell::Missing(),
                    e ? Cell::Number(e->ci95_upper) : Cell::Missing(),
                    e ? Cell::Text(YesNo(e->identifiable)) : Cell::Missing()});
    }
  }
  return table;
}

// The signals of each candidate's fingerprint, as found in the residual.
Table EvidenceTable(const std::string& id, const LoopRound& round) {
  Table table;
  table.id = id;
  table.title = "Evidence for each candidate";
  table.caption =
      "loop.json candidates' 'evidence': the signals an effect of that kind leaves in the "
      "residual (its fingerprint, docs/model-notes.md), with their pooled value and band. "
      "Shown beside the scores; the decision rests on the score test and the refit.";
  table.columns = {{"candidate", "candidate", "", kSignal},
                   {"signal", "signal", "", kSignal},
                   {"value", "value", "", kSignal},
                   {"band", "95 % band", "", kSignal},
                   {"outside_band", "outside the band", "", kSignal}};
  for (const LoopCandidate& c : round.candidates) {
    for (const LoopSignal& s : c.evidence) {
      table.AddRow({Cell::Text(c.name), Cell::Text(s.signal), Cell::Number(s.value),
                    Cell::Number(s.band), Cell::Text(YesNo(s.significant))});
    }
  }
  return table;
}

Section RoundSection(const LoopRound& round, const std::string& unit) {
  const std::string k = std::to_string(round.index);
  Section section{"round-" + k, "Round " + k, {}};
  std::string text = "Round " + k + " started from the model with " +
                     (round.effects_on.empty() ? std::string("no effect added (the declared model)")
                                               : ListNames(round.effects_on) + " on") +
                     ": training RMS " + Show(round.rms_deg, kRms) + " " + unit;
  if (std::isfinite(round.holdout_rms_deg)) {
    text += ", held out " + Show(round.holdout_rms_deg, kRms) + " " + unit;
  }
  text += ". " + Plural(static_cast<double>(round.candidates.size()), "candidate") +
          " scored. Decision: " + round.decision;
  section.blocks.push_back(Paragraph{text, false});
  section.blocks.push_back(CandidateTable("round_" + k + "_candidates", round, unit));
  if (!round.backward.empty()) {
    section.blocks.push_back(BackwardTable("round_" + k + "_backward", round, unit));
  }
  section.blocks.push_back(EstimateTable("round_" + k + "_estimates", round));
  section.blocks.push_back(CrossCorrelationBlock(
      "cross_correlation_round_" + k, round.evidence, "Residual against the signals, round " + k,
      "Cross-correlation of the residual of the round's starting model (simulated − measured) "
      "with each signal of the simulated motion, pooled over every channel, against the "
      "shift of the signal (loop.json 'cross_correlation' at 'lags_s'). Dashed: the 95 % band "
      "of no relation at lag 0; red: the signal's pooled correlation lies outside it."));
  section.blocks.push_back(SignalTable("round_" + k + "_signals", "Signals in the residual",
                                       round.evidence,
                                       "loop.json 'evidence.pooled' of round " + k));
  section.blocks.push_back(EvidenceTable("round_" + k + "_evidence", round));
  section.blocks.push_back(ExperimentLagTable("round_" + k + "_experiments", round.evidence,
                                              "loop.json 'evidence.experiments' of round " + k,
                                              unit));
  return section;
}

// ---------------------------------------------------------- parameters

Section ParameterSection(const LoopFolder& loop) {
  Section section{"parameters", "Parameters of the final model", {}};
  Table table;
  table.id = "parameters";
  table.title = "Fitted parameters";
  table.caption =
      "loop.json 'parameters': the final model's free parameters, the declared ones and those "
      "of each effect added (named <effect>.<parameter>), with standard errors and 95 % "
      "intervals of the final fit. A parameter the data cannot pin down has no interval.";
  table.columns = {{"parameter", "parameter", "", kValue},
                   {"from", "from", "", kValue},
                   {"unit", "unit", "", kValue},
                   {"estimate", "estimate", "", kValue},
                   {"std_error", "standard error", "", kStdError},
                   {"ci95_lower", "95 % interval from", "", kValue},
                   {"ci95_upper", "95 % interval to", "", kValue},
                   {"identifiable", "identifiable", "", kValue}};
  std::string sentences;
  for (const LoopEstimate& p : loop.parameters) {
    // An effect's parameters are named <effect>.<parameter>.
    std::string from = "declared model";
    for (const std::string& effect : loop.added_effects) {
      if (p.name.rfind(effect + ".", 0) == 0) from = effect;
    }
    table.AddRow({Cell::Text(p.name), Cell::Text(from), Cell::Text(p.units), Cell::Number(p.value),
                  p.identifiable ? Cell::Number(p.std_error) : Cell::Text("not identifiable"),
                  Cell::Number(p.ci95_lower), Cell::Number(p.ci95_upper),
                  Cell::Text(YesNo(p.identifiable))});
    if (from == "declared model") continue;
    const std::string unit = UnitSuffix(p.units);
    sentences += (sentences.empty() ? "" : " ") + p.name + " = " + Show(p.value, kValue) + unit;
    sentences += p.identifiable && std::isfinite(p.ci95_lower)
                     ? " (95 % interval " + Show(p.ci95_lower, kValue) + " to " +
                           Show(p.ci95_upper, kValue) + unit + ")."
                     : " (not identifiable from these data).";
  }
  if (!sentences.empty()) {
    section.blocks.push_back(Paragraph{"The effects added, as fitted: " + sentences, false});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

// --------------------------------------------------------- unexplained

Table UnexplainedTable(const LoopFolder& loop) {
  Table table;
  table.id = "unexplained";
  table.title = OverPoints(loop) ? "Point coordinates the final model does not explain"
                                 : "Joint axes the final model does not explain";
  table.caption =
      "loop.json 'unexplained': every experiment and channel whose residual stands above its "
      "measurement noise by the rule of the final model's verdict (RMS beyond the loop's ratio, "
      "LoopOptions::unexplained_noise_ratio, 1.5 by default, and beyond chance), largest ratio "
      "first, with the phase of the protocol where it is largest. RMS and noise here weigh each "
      "frame by its noise (a recording's ends count less); the fit's tables give them raw.";
  const std::string& unit = loop.unit;
  table.columns = {{"experiment", "experiment", "", kRms},
                   ChannelColumn(loop),
                   {"axis", "axis", "", kRms},
                   {"rms_deg", "RMS", unit, kRms},
                   {"noise_deg", "noise", unit, kRms},
                   {"worst_phase", "worst phase", "", kRms},
                   {"worst_phase_rms_deg", "RMS in it", unit, kRms}};
  for (const internal::LoopUnexplained& u : loop.unexplained) {
    table.AddRow({Cell::Text(u.experiment), ChannelCell(u.joint, u.point),
                  Cell::Text(ChannelAxis(u.point, u.axis)), Cell::Number(u.rms_deg),
                  Cell::Number(u.noise_deg), Cell::Text(u.worst_phase),
                  Cell::Number(u.worst_phase_rms_deg)});
  }
  return table;
}

// The final residual per experiment, joint and axis: how far above the
// noise, how white, drift and hysteresis.
Table ChannelTable(const LoopFolder& loop) {
  const LoopDiagnostics& d = loop.final_evidence;
  const std::string& unit = loop.unit;
  Table table;
  table.id = "final_channels";
  table.title = OverPoints(loop) ? "Final residual per tracked point and coordinate"
                                 : "Final residual per joint and axis";
  table.caption =
      "loop.json 'final_evidence.channels' (residual simulated − measured of the final model): "
      "RMS, mean and the experiment's noise; the share of autocorrelation lags outside the "
      "white-noise band (about 0.05 for white noise) and the autocorrelation time [frames]; the "
      "mean slope during holds and the loop area against the angle (of a tracked point: its "
      "coordinate).";
  table.columns = {{"experiment", "experiment", "", kRms},
                   ChannelColumn(loop),
                   {"axis", "axis", "", kRms},
                   {"samples", "samples", "", kCount},
                   {"rms_deg", "RMS", unit, kRms},
                   {"mean_deg", "mean", unit, kRms},
                   {"noise_deg", "noise", unit, kRms},
                   {"lags_outside_band", "lags outside band", "", NumberFormat::Fixed(2)},
                   {"autocorrelation_time", "autocorrelation time", "", NumberFormat::Fixed(1)},
                   {"effective_samples", "effective samples", "", kCount},
                   {"hold_drift_degps", "hold drift", unit + "/s", NumberFormat::Significant(3)},
                   {"hysteresis_deg2", "hysteresis", unit + "²", NumberFormat::Significant(3)}};
  for (const LoopDiagnostics::Channel& c : d.channels) {
    table.AddRow({Cell::Text(c.experiment), ChannelCell(c.joint, c.point),
                  Cell::Text(ChannelAxis(c.point, c.axis)), Cell::Number(c.samples),
                  Cell::Number(c.rms_deg), Cell::Number(c.mean_deg), Cell::Number(c.noise_deg),
                  Cell::Number(c.lags_outside_band), Cell::Number(c.autocorrelation_time),
                  Cell::Number(c.effective_samples), Cell::Number(c.hold_drift_degps),
                  Cell::Number(c.hysteresis_deg2)});
  }
  return table;
}

// The phases the worst-phase column names, per experiment.
Table PhaseTable(const LoopDiagnostics& d) {
  Table table;
  table.id = "phases";
  table.title = "Protocol phases";
  table.caption =
      "loop.json 'final_evidence.experiments[].phases': the stretches of each experiment where "
      "the inputs move (motion) or stand still (hold), in experiment time.";
  table.columns = {{"experiment", "experiment", "", kRms},
                   {"phase", "phase", "", kRms},
                   {"start_s", "from", "s", NumberFormat::Fixed(2)},
                   {"end_s", "to", "s", NumberFormat::Fixed(2)}};
  for (const LoopDiagnostics::Experiment& e : d.experiments) {
    for (const LoopDiagnostics::Phase& p : e.phases) {
      table.AddRow(
          {Cell::Text(e.name), Cell::Text(p.name), Cell::Number(p.start_s), Cell::Number(p.end_s)});
    }
  }
  return table;
}

Section UnexplainedSection(const LoopFolder& loop) {
  Section section{"unexplained", "What remains unexplained", {}};
  const std::size_t n = loop.unexplained.size();
  section.blocks.push_back(Paragraph{
      "Conclusion: " + loop.conclusion + " " +
          (n == 0
               ? "No " + ChannelWord(loop, false) + " keeps a residual above its noise threshold."
               : Show(static_cast<double>(n), kCount) + " " + ChannelWord(loop, n != 1) +
                     (n == 1 ? " keeps" : " keep") +
                     " a residual above its noise threshold (table below); the signals the "
                     "residual still follows point to what the effect library lacks."),
      false});
  section.blocks.push_back(UnexplainedTable(loop));
  section.blocks.push_back(PhaseTable(loop.final_evidence));
  section.blocks.push_back(CrossCorrelationBlock(
      "cross_correlation_final", loop.final_evidence,
      "Residual of the final model against the signals",
      "As in the rounds, for the final model's residual (loop.json 'final_evidence'). Dashed: "
      "the 95 % band of no relation; red: outside it."));
  section.blocks.push_back(SignalTable("final_signals", "Signals in the final residual",
                                       loop.final_evidence, "loop.json 'final_evidence.pooled'"));
  section.blocks.push_back(ExperimentLagTable("final_experiments", loop.final_evidence,
                                              "loop.json 'final_evidence.experiments'", loop.unit));
  section.blocks.push_back(ChannelTable(loop));
  return section;
}

}  // namespace

Document BuildLoopDocument(const std::string& folder, const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  const LoopFolder loop = internal::ReadLoopFolder(folder);
  Document document;
  document.kind = "loop";
  document.title = "Closing the loop — " + (loop.added_effects.empty()
                                                ? std::string("no effect added")
                                                : "added " + ListNames(loop.added_effects));
  document.source = folder;
  document.ccsrm_version = kVersion;
  document.sections.push_back(SummarySection(loop));
  document.sections.push_back(ErrorSection(loop));
  document.sections.push_back(TrainingResidualSection(loop));
  if (!loop.holdout.empty()) document.sections.push_back(HoldoutResidualSection(loop));
  for (const LoopRound& round : loop.rounds) {
    document.sections.push_back(RoundSection(round, loop.unit));
  }
  document.sections.push_back(ParameterSection(loop));
  document.sections.push_back(UnexplainedSection(loop));
  return document;
}

}  // namespace ccsrm::reports
