// The page of a fit folder (`ccsrm identify`): what was fitted and how well,
// measured against fitted joint angles and the residuals per experiment,
// the parameter table with standard errors and 95 % intervals, the
// correlation matrix, the singular values with the directions the data do
// not pin down, per-joint errors before and after, cost per step and the
// experiments with their noise. Every number is read from fit.json or the
// angles files as ccsrm identify wrote them.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "fit_folder.h"
#include "pages.h"

namespace ccsrm::reports {
namespace {

using internal::AddText;
using internal::AddValue;
using internal::AxisName;
using internal::FigureStem;
using internal::FitErrors;
using internal::FitExperiment;
using internal::FitFolder;
using internal::FitParameter;
using internal::Key;
using internal::ListNames;
using internal::Plural;
using internal::Show;
using internal::UnitSuffix;

// Number formats, one per quantity, shared by tables and text.
const NumberFormat kValue = NumberFormat::Significant(4);     // parameters
const NumberFormat kStdError = NumberFormat::Significant(3);  // standard errors
const NumberFormat kRms = NumberFormat::Fixed(4);             // deg
const NumberFormat kPercent = NumberFormat::Fixed(1);         // fit percent
const NumberFormat kCorrelation = NumberFormat::Fixed(2);     // as on the heat map
const NumberFormat kSingular = NumberFormat::Significant(4);
const NumberFormat kCost = NumberFormat::Significant(6);

// ---------------------------------------------------------------- summary

Table FitTable(const FitFolder& fit) {
  Table table = internal::KeyValueTable(
      "fit", "Fit",
      "From fit.json. Cost: ½ Σ r² with each residual r = (fitted − measured) / noise. Residual "
      "variance: 2 cost / (N − p), 1 when the residuals are as large as the measurement noise. "
      "Effective samples: N corrected for the autocorrelation of the residuals (used for the "
      "standard errors). Fit percent: 100 (1 − ‖fitted − measured‖ / ‖measured − its mean‖) "
      "over every measured series of an axis that moves (Errors per joint says which).");
  AddText(&table, "free parameters", ListNames(fit.free));
  AddText(&table, "termination", fit.termination);
  AddText(&table, "message", fit.message);
  AddValue(&table, "iterations", fit.iterations, "", NumberFormat::Integer());
  AddValue(&table, "simulations", fit.simulations, "", NumberFormat::Integer());
  AddValue(&table, "threads", fit.threads, "", NumberFormat::Integer());
  AddValue(&table, "wall time", fit.wall_time_s, "s", NumberFormat::Fixed(1));
  AddValue(&table, "experiments", static_cast<double>(fit.experiments.size()), "",
           NumberFormat::Integer());
  AddValue(&table, "residuals N", fit.residuals, "", NumberFormat::Integer());
  AddValue(&table, "effective samples", fit.effective_samples, "", NumberFormat::Integer());
  AddValue(&table, "residual variance", fit.residual_variance, "", NumberFormat::Significant(3));
  AddValue(&table, "cost at start", fit.cost_history.empty() ? NAN : fit.cost_history.front(), "",
           kCost);
  AddValue(&table, "cost fitted", fit.cost_history.empty() ? NAN : fit.cost_history.back(), "",
           kCost);
  AddValue(&table, "RMS error at start", fit.rms_deg_start, "deg", kRms);
  AddValue(&table, "RMS error fitted", fit.rms_deg, "deg", kRms);
  AddValue(&table, "fit percent at start", fit.start_errors.fit_percent, "%", kPercent);
  AddValue(&table, "fit percent fitted", fit.fit_percent, "%", kPercent);
  return table;
}

// The sentence about one free parameter.
std::string ParameterSentence(const FitParameter& p, const FitFolder& fit) {
  const std::string unit = UnitSuffix(p.units);
  std::string text = p.name + " = " + Show(p.value, kValue) + unit;
  if (!p.identifiable) {
    text = p.name + " could not be determined from these data (it ended at " +
           Show(p.value, kValue) + unit + ", from a start of " + Show(p.start, kValue) + unit + ")";
    for (const internal::FitDirection& d : fit.unidentifiable) {
      for (const auto& component : d.components) {
        if (component.first == p.name) {
          text += "; the data do not pin down the direction " + d.combination;
          break;
        }
      }
    }
    return text + ".";
  }
  text += " (standard error " + Show(p.std_error, kStdError) + unit;
  if (std::isfinite(p.ci95_lower)) {
    text += ", 95 % interval " + Show(p.ci95_lower, kValue) + " to " + Show(p.ci95_upper, kValue) +
            unit;
  }
  text += "; start " + Show(p.start, kValue) + unit + ")";
  if (fit.adequacy_known && !fit.adequate && std::isfinite(p.ci95_misfit_lower)) {
    text += ", or " + Show(p.ci95_misfit_lower, kValue) + " to " +
            Show(p.ci95_misfit_upper, kValue) + unit +
            " with the interval widened by the misfit (× " +
            Show(fit.misfit_scale, NumberFormat::Fixed(2)) + ")";
  }
  if (p.at_bound) {
    text += ", at a bound of its range [" + Show(p.lower, kValue) + ", " + Show(p.upper, kValue) +
            "]" + unit + ", where its interval is not symmetric";
  }
  return text + ".";
}

Section SummarySection(const FitFolder& fit) {
  Section section{"summary", "Summary", {}};
  // The answer first: whether the model explains the data at all, before
  // any number that assumes it does.
  if (fit.adequacy_known) {
    std::string verdict = fit.verdict;
    if (!verdict.empty())
      verdict[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(verdict[0])));
    section.blocks.push_back(Paragraph{
        verdict + (fit.adequate ? "."
                                : ". The estimates and intervals below are those of the "
                                  "model as declared; each parameter also gives its interval "
                                  "widened by the misfit, which allows for the misfit's size "
                                  "but not for a bias: an effect the model lacks can move an "
                                  "estimate beyond both. `ccsrm loop` looks for what the model "
                                  "lacks: quote no value before it is found."),
        !fit.adequate});
  }
  // Parameters the angles jump with: their intervals mean nothing.
  std::string rough;
  for (const FitParameter& p : fit.parameters) {
    if (p.free && p.derivative_step_disagreement > 0.05) {
      rough += (rough.empty() ? "" : ", ") + p.name + " (" +
               Show(100.0 * p.derivative_step_disagreement, NumberFormat::Significant(3)) + " %)";
    }
  }
  if (!rough.empty()) {
    section.blocks.push_back(Paragraph{
        "The derivatives are NOT smooth in " + rough +
            ": at the final point they differ by that much between the fit's finite-difference "
            "step and a third of it (more than 5 %). The angles jump with these parameters here "
            "(a breakaway that happens or not, a stick-slip cycle that gains or loses a slip), "
            "and their estimates and intervals are not to be trusted from these data.",
        true});
  }
  Table table = FitTable(fit);
  std::vector<std::string> names;
  for (const FitExperiment& e : fit.experiments) names.push_back(e.name);
  std::string text = "Fit of " + ListNames(fit.free) + " to " +
                     Plural(static_cast<double>(fit.experiments.size()), "experiment") + " (" +
                     ListNames(names) + "): ";
  text += fit.converged ? "converged" : "did not converge (" + fit.termination + ")";
  text += " after " + Plural(fit.iterations, "iteration") + " (" +
          Plural(fit.simulations, "simulation") + ", " +
          Show(fit.wall_time_s, NumberFormat::Fixed(1)) + " s on " + Plural(fit.threads, "thread") +
          "). ";
  if (std::isfinite(fit.rms_deg)) {
    text += "The RMS error of the joint angles went from " + Show(fit.rms_deg_start, kRms) +
            " deg at the start values to " + Show(fit.rms_deg, kRms) +
            " deg, and the fitted angles reproduce " + Show(fit.fit_percent, kPercent) +
            " % of the measured motion (fit percent over the axes that move; " +
            Show(fit.start_errors.fit_percent, kPercent) + " % at the start). ";
  }
  for (const FitExperiment& e : fit.experiments) {
    for (std::size_t p = 0; p < e.points.size(); ++p) {
      text += "The RMS error of " + e.name + "'s " + e.points[p] + " went from " +
              Show(e.point_start_rms_mm[p], NumberFormat::Fixed(2)) +
              " mm at the start values to " + Show(e.point_rms_mm[p], NumberFormat::Fixed(2)) +
              " mm (" + Show(e.point_rms_mean_removed_mm[p], NumberFormat::Fixed(2)) +
              " mm with the mean offset removed). ";
    }
  }
  text += "Residual variance " + Show(fit.residual_variance, NumberFormat::Significant(3)) +
          ": 1 means the remaining differences are as large as the measurement noise; much more "
          "than 1 means the model misses part of the motion.";
  section.blocks.push_back(Paragraph{text, false});
  std::string parameters;
  for (const FitParameter& p : fit.parameters) {
    if (p.free) parameters += (parameters.empty() ? "" : " ") + ParameterSentence(p, fit);
  }
  section.blocks.push_back(Paragraph{parameters, false});
  if (!fit.converged) {
    section.blocks.push_back(Paragraph{"The fit did not converge (" + fit.termination + ": " +
                                           fit.message +
                                           "): the estimates are where it stopped, not a minimum.",
                                       true});
  }
  for (const FitExperiment& e : fit.experiments) {
    if (e.run_status != "completed") {
      section.blocks.push_back(Paragraph{"The fitted run of experiment " + e.name + " did not " +
                                             "complete (" + e.run_message + ").",
                                         true});
    }
    for (const std::string& problem : e.problems) {
      section.blocks.push_back(Paragraph{problem, true});
    }
  }
  section.blocks.push_back(std::move(table));
  return section;
}

// ------------------------------------------------- measured against fitted

// An experiment of tracked points: their paths measured and fitted.
Section ExperimentPointsSection(const FitExperiment& e, const std::string& stem, bool several) {
  Section section{"points-" + stem,
                  several ? "Measured and fitted points: " + e.name : "Measured and fitted points",
                  {}};
  std::string errors;
  for (std::size_t p = 0; p < e.points.size(); ++p) {
    errors += (p == 0 ? "" : "; ") + e.points[p] + ": RMS " +
              Show(e.point_start_rms_mm[p], NumberFormat::Fixed(3)) + " mm at the start, " +
              Show(e.point_rms_mm[p], NumberFormat::Fixed(3)) + " mm fitted (" +
              Show(e.point_rms_mean_removed_mm[p], NumberFormat::Fixed(3)) +
              " mm with the mean offset removed)";
  }
  section.blocks.push_back(Paragraph{"Experiment " + e.name + " (" + e.path + "), from " +
                                         e.points_file +
                                         ": the measured tracked points and the fitted run's, "
                                         "placed in the frame they were recorded in. " +
                                         errors + ".",
                                     false});
  section.blocks.push_back(FigureBlock{
      internal::TrackedPointsFigure("points_" + stem, e.time_s, e.points, e.measured_mm,
                                    e.fitted_mm, "fitted"),
      "Tracked points: measured and fitted",
      "Top left: the points' paths seen from above (x against y); then x, y and z against "
      "time. Dashed: measured; solid: the fitted model's.",
      ""});
  internal::AddPatternFigures(
      internal::TrackedPointsByPatternFigures("patterns_" + stem, e.labels, e.points, e.measured_mm,
                                              e.fitted_mm),
      "fitted", &section);
  return section;
}

Section ExperimentAnglesSection(const FitExperiment& e, std::size_t index, bool several) {
  const std::string stem = FigureStem(several ? e.name + "_" + std::to_string(index + 1) : e.name);
  if (!e.points.empty()) return ExperimentPointsSection(e, stem, several);
  Section section{"angles-" + stem,
                  several ? "Measured and fitted angles: " + e.name : "Measured and fitted angles",
                  {}};
  section.blocks.push_back(Paragraph{
      "Experiment " + e.name + " (" + e.path + "), from " + e.angles_file + ": the measured " +
          (e.angles_from_pipeline ? "angles (reconstructed from the markers by the mocap pipeline)"
                                  : "angles stored in the experiment") +
          " and the angles of the run with the fitted parameters, at the measured frames.",
      false});
  for (int c = 0; c < 2; ++c) {
    section.blocks.push_back(FigureBlock{
        internal::MeasuredAgainstSimulatedFigure(
            "angles_" + std::string(c == 0 ? "x_" : "y_") + stem, e.time_s, e.measured_deg,
            e.fitted_deg, c, e.segments, "fitted"),
        std::string(AxisName(c)) + ": measured and fitted",
        std::string(c == 0 ? "Bending angle θx" : "Out-of-plane angle θy") +
            " of every joint, one panel per segment, joints in order from the root (colours as "
            "on the run page). Dashed: measured; solid: simulated with the fitted parameters (as "
            "compared in the fit, i.e. through the measurement's gaps and recorded filter).",
        ""});
  }
  section.blocks.push_back(FigureBlock{
      internal::ResidualsFigure("residuals_" + stem, e.time_s, e.residual_deg, e.segments),
      "Residuals over time",
      "Fitted minus measured angle of every joint (the residual of the fit before it is divided "
      "by the noise), θx left, θy right, one row per segment. Residuals that follow the motion "
      "rather than scatter around 0 are what the model does not explain.",
      ""});
  return section;
}

// ------------------------------------------------------------- parameters

Section ParameterSection(const FitFolder& fit) {
  Section section{"parameters", "Parameters", {}};
  Table table;
  table.id = "parameters";
  table.title = "Free parameters";
  table.caption =
      "From fit.json. Standard errors from the covariance of the fit (scaled by the residual "
      "variance and the effective samples); 95 % interval from Student's t. A parameter the data "
      "cannot pin down has no standard error or interval (see Identifiability). Bounds: the "
      "range the fit was allowed.";
  table.columns = {{"parameter", "parameter", "", kValue},
                   {"unit", "unit", "", kValue},
                   {"start", "start", "", kValue},
                   {"estimate", "estimate", "", kValue},
                   {"std_error", "standard error", "", kStdError},
                   {"ci95_lower", "95 % interval from", "", kValue},
                   {"ci95_upper", "95 % interval to", "", kValue},
                   {"lower_bound", "lower bound", "", kValue},
                   {"upper_bound", "upper bound", "", kValue},
                   {"status", "status", "", kValue}};
  Table fixed = internal::KeyValueTable("fixed_parameters", "Fixed parameters",
                                        "Held at these values during the fit (fit.json).");
  fixed.columns[0].key = "parameter";
  fixed.columns[0].header = "parameter";
  for (const FitParameter& p : fit.parameters) {
    if (!p.free) {
      AddValue(&fixed, p.name, p.value, p.units, kValue);
      continue;
    }
    const std::string status = !p.identifiable ? "not identifiable"
                               : p.at_bound    ? "at a bound"
                                               : "identifiable";
    table.AddRow({Cell::Text(p.name), Cell::Text(p.units), Cell::Number(p.start),
                  Cell::Number(p.value),
                  p.identifiable ? Cell::Number(p.std_error) : Cell::Text("not identifiable"),
                  Cell::Number(p.ci95_lower), Cell::Number(p.ci95_upper), Cell::Number(p.lower),
                  Cell::Number(p.upper), Cell::Text(status)});
  }
  section.blocks.push_back(std::move(table));
  if (!fixed.rows.empty()) section.blocks.push_back(std::move(fixed));
  return section;
}

// --------------------------------------------------------- identifiability

Figure CorrelationFigure(const FitFolder& fit) {
  const std::size_t n = fit.free.size();
  Figure figure;
  figure.name = "correlation";
  figure.panel_width_px = static_cast<int>(std::max<std::size_t>(460, 300 + 70 * n));
  figure.panel_height_px = static_cast<int>(std::max<std::size_t>(300, 140 + 60 * n));
  Panel panel;
  panel.title = "Correlation of the estimates";
  panel.x = Axis{"parameter", "1"};
  panel.y = Axis{"parameter", "1"};
  panel.x.min = panel.y.min = 0.5;
  panel.x.max = panel.y.max = static_cast<double>(n) + 0.5;
  Axis color{"correlation", "1"};
  color.min = -1.0;
  color.max = 1.0;
  panel.color = color;
  panel.legend = LegendPlace::kNone;
  Series cells;
  cells.style = SeriesStyle::kCells;
  cells.cell_decimals = kCorrelation.digits;
  for (std::size_t i = 0; i < n; ++i) {
    // Row i from the top, as the table reads.
    const double y = static_cast<double>(n - i);
    panel.x.tics.push_back({static_cast<double>(i + 1), fit.free[i]});
    panel.y.tics.push_back({y, fit.free[i]});
    for (std::size_t j = 0; j < n; ++j) {
      cells.x.push_back(static_cast<double>(j + 1));
      cells.y.push_back(y);
      cells.z.push_back(fit.correlation[i][j]);
    }
  }
  panel.series.push_back(std::move(cells));
  figure.panels.push_back(std::move(panel));
  return figure;
}

Figure SingularValueFigure(const FitFolder& fit, const std::vector<bool>& pinned) {
  Figure figure;
  figure.name = "singular_values";
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  Panel panel;
  panel.title = "Singular values of the scaled Jacobian";
  panel.x = Axis{"direction k", "1"};
  panel.y = Axis{"singular value σk", "1"};
  panel.y.log_scale = true;
  panel.x.min = 0.5;
  panel.x.max = static_cast<double>(fit.singular_values.size()) + 0.5;
  panel.legend = LegendPlace::kBelow;
  Series good{"pinned down by the data", {}, {}, palette::kFitted, SeriesStyle::kPoints};
  Series bad{"not pinned down", {}, {}, palette::kWarning, SeriesStyle::kPoints};
  good.point_size = bad.point_size = 1.8;  // a handful of values: each must stand out
  for (std::size_t k = 0; k < fit.singular_values.size(); ++k) {
    Series& s = pinned[k] ? good : bad;
    s.x.push_back(static_cast<double>(k + 1));
    s.y.push_back(fit.singular_values[k]);
    panel.x.tics.push_back({static_cast<double>(k + 1), "σ" + std::to_string(k + 1)});
  }
  panel.series.push_back(std::move(good));
  panel.series.push_back(std::move(bad));
  figure.panels.push_back(std::move(panel));
  return figure;
}

Section IdentifiabilitySection(const FitFolder& fit) {
  Section section{"identifiability", "Correlations and identifiability", {}};
  const std::size_t n = fit.free.size();
  Table correlation;
  correlation.id = "correlation";
  correlation.title = "Correlation matrix";
  correlation.caption =
      "Correlation of the estimates (fit.json 'correlation'); – where a parameter is not "
      "identifiable. Near ±1: the data trade one parameter against the other.";
  correlation.columns = {{"parameter", "parameter", "", kCorrelation}};
  std::set<std::string> keys = {"parameter"};
  for (const std::string& name : fit.free) {
    std::string key = Key(name);
    while (!keys.insert(key).second) key += "_";
    correlation.columns.push_back({key, name, "", kCorrelation});
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<Cell> row = {Cell::Text(fit.free[i])};
    for (std::size_t j = 0; j < n; ++j) row.push_back(Cell::Number(fit.correlation[i][j]));
    correlation.AddRow(std::move(row));
  }

  // Each unidentifiable direction belongs to the singular value it was
  // written with (the same number in fit.json).
  std::vector<const internal::FitDirection*> direction(fit.singular_values.size(), nullptr);
  std::vector<bool> pinned(fit.singular_values.size(), true);
  std::vector<std::string> unmatched;
  for (const internal::FitDirection& d : fit.unidentifiable) {
    bool found = false;
    for (std::size_t k = 0; k < fit.singular_values.size() && !found; ++k) {
      if (direction[k] == nullptr && fit.singular_values[k] == d.singular_value) {
        direction[k] = &d;
        pinned[k] = false;
        found = true;
      }
    }
    if (!found) unmatched.push_back(d.combination);
  }
  Table singular;
  singular.id = "singular_values";
  singular.title = "Singular values and the directions not pinned down";
  singular.caption =
      "Singular values of the Jacobian in the scaled parameters (fit.json 'singular_values'), "
      "largest first. A direction is not pinned down when the standard error along it, relative "
      "to the parameters' scales, is too large ('unidentifiable'); its combination names the "
      "parameters that move together along it.";
  singular.columns = {
      {"k", "k", "", NumberFormat::Integer()},
      {"singular_value", "singular value", "", kSingular},
      {"direction", "direction not pinned down", "", kSingular},
      {"relative_std_error", "relative standard error", "", NumberFormat::Significant(3)}};
  for (std::size_t k = 0; k < fit.singular_values.size(); ++k) {
    const internal::FitDirection* d = direction[k];
    singular.AddRow({Cell::Number(static_cast<double>(k + 1)), Cell::Number(fit.singular_values[k]),
                     d ? Cell::Text(d->combination) : Cell::Missing(),
                     d ? Cell::Number(d->relative_std_error) : Cell::Missing()});
  }

  std::string text;
  if (fit.unidentifiable.empty()) {
    text =
        "Every free parameter is identifiable from these data: no direction of the "
        "parameters leaves the fit unchanged within the noise.";
  } else {
    text = "The data do not pin down " +
           std::string(fit.unidentifiable.size() == 1 ? "one direction" : "these directions") +
           " of the parameters: ";
    for (std::size_t i = 0; i < fit.unidentifiable.size(); ++i) {
      const internal::FitDirection& d = fit.unidentifiable[i];
      text += (i ? "; " : "") + d.combination + " (singular value " +
              Show(d.singular_value, kSingular) + ")";
    }
    text +=
        ". Moving the parameters along such a direction changes the simulated angles by less "
        "than the noise, so an experiment that excites them more is needed to determine them.";
  }
  section.blocks.push_back(Paragraph{text, false});
  for (const std::string& combination : unmatched) {
    section.blocks.push_back(Paragraph{"fit.json names the unidentifiable direction " +
                                           combination +
                                           " with a singular value not among singular_values.",
                                       true});
  }
  section.blocks.push_back(FigureBlock{
      CorrelationFigure(fit), "Correlation matrix",
      "Correlation between the estimates of the free parameters: red positive, blue negative, "
      "white none; grey cells have no correlation (a parameter that is not identifiable).",
      ""});
  section.blocks.push_back(FigureBlock{
      SingularValueFigure(fit, pinned), "Singular values",
      "Singular values of the Jacobian in the scaled parameters, log scale. A small value is a "
      "direction the data barely see; red: the directions reported as not pinned down.",
      ""});
  section.blocks.push_back(std::move(correlation));
  section.blocks.push_back(std::move(singular));
  return section;
}

// ------------------------------------------------------------------ errors

// True when some joint has a fit percent on axis `c`: the arm moves about
// it (identify::ChannelErrors).
bool AxisHasFitPercent(const FitErrors& errors, int c) {
  for (const FitErrors::Joint& joint : errors.per_joint) {
    if (std::isfinite(joint.fit_percent[static_cast<std::size_t>(c)])) return true;
  }
  return false;
}

Figure ErrorFigure(const FitFolder& fit) {
  Figure figure;
  figure.name = "errors_per_joint";
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  const double joints = static_cast<double>(fit.errors.per_joint.size());
  for (int quantity = 0; quantity < 2; ++quantity) {
    for (int c = 0; c < 2; ++c) {
      const std::size_t axis = static_cast<std::size_t>(c);
      // An axis with no fit percent anywhere (θy of an arm bent in its
      // plane): its errors against its own motion instead, in degrees.
      const bool against_motion = quantity == 1 && !AxisHasFitPercent(fit.errors, c);
      Panel panel;
      panel.title = quantity == 0    ? std::string("RMS error ") + AxisName(c)
                    : against_motion ? std::string("RMS error against motion ") + AxisName(c)
                                     : std::string("Fit percent ") + AxisName(c);
      panel.x = Axis{"joint", "1"};
      panel.x.min = 0.4;
      panel.x.max = joints + 0.6;
      panel.y = quantity == 1 && !against_motion ? Axis{"fit", "%"} : Axis{"RMS", "deg"};
      if (quantity == 0 || against_motion) panel.y.min = 0.0;
      panel.legend = LegendPlace::kBelow;
      for (double j = 1; j <= joints; ++j)
        panel.x.tics.push_back({j, Show(j, NumberFormat::Integer())});
      if (against_motion) {
        Series motion;
        motion.label = "motion";  // the caption says what it is
        motion.color = palette::kStart;
        motion.style = SeriesStyle::kBars;
        motion.bar_width = 0.38;
        Series error;
        error.label = "fitted";
        error.color = palette::kFitted;
        error.style = SeriesStyle::kBars;
        error.bar_width = 0.38;
        for (const FitErrors::Joint& joint : fit.errors.per_joint) {
          motion.x.push_back(joint.joint - 0.2);
          motion.y.push_back(joint.motion_rms_deg[axis]);
          error.x.push_back(joint.joint + 0.2);
          error.y.push_back(joint.rms_deg[axis]);
        }
        panel.series.push_back(std::move(motion));
        panel.series.push_back(std::move(error));
        figure.panels.push_back(std::move(panel));
        continue;
      }
      const std::pair<const FitErrors*, const std::string*> sets[] = {
          {&fit.start_errors, &palette::kStart}, {&fit.errors, &palette::kFitted}};
      for (int s = 0; s < 2; ++s) {
        Series bars;
        bars.label = s == 0 ? "at the start values" : "fitted";
        bars.color = *sets[s].second;
        bars.style = SeriesStyle::kBars;
        bars.bar_width = 0.38;
        for (const FitErrors::Joint& joint : sets[s].first->per_joint) {
          bars.x.push_back(joint.joint + (s == 0 ? -0.2 : 0.2));
          bars.y.push_back(quantity == 0 ? joint.rms_deg[axis] : joint.fit_percent[axis]);
        }
        panel.series.push_back(std::move(bars));
      }
      figure.panels.push_back(std::move(panel));
    }
  }
  return figure;
}

Section ErrorSection(const FitFolder& fit) {
  Section section{"errors", "Errors per joint", {}};
  Table table;
  table.id = "errors_per_joint";
  table.title = "RMS error, motion and fit percent per joint";
  table.caption =
      "Over every experiment (fit.json 'start_errors' and 'errors'): at the start values and "
      "with the fitted parameters. Motion: the RMS of the measured angles about their mean, what "
      "an error is to be read against. Fit percent, 100 (1 − RMS error / motion), is 100 % for a "
      "perfect fit, 0 % no better than the series' mean and below 0 worse than that mean. It is "
      "given only for an axis that moves: its motion at least a tenth of the joint's larger "
      "axis motion and three times the joint's measurement noise. An axis that barely moves (θy "
      "of a joint bent in its plane) has '–': there the ratio measures noise and by-products, "
      "and its RMS error is to be read against its motion in degrees. Samples: measured frames "
      "per axis.";
  table.columns = {{"joint", "joint", "", NumberFormat::Integer()},
                   {"rms_x_start_deg", "RMS θx start", "deg", kRms},
                   {"rms_x_fitted_deg", "RMS θx fitted", "deg", kRms},
                   {"motion_x_deg", "motion θx", "deg", kRms},
                   {"rms_y_start_deg", "RMS θy start", "deg", kRms},
                   {"rms_y_fitted_deg", "RMS θy fitted", "deg", kRms},
                   {"motion_y_deg", "motion θy", "deg", kRms},
                   {"fit_x_start_percent", "fit θx start", "%", kPercent},
                   {"fit_x_fitted_percent", "fit θx fitted", "%", kPercent},
                   {"fit_y_start_percent", "fit θy start", "%", kPercent},
                   {"fit_y_fitted_percent", "fit θy fitted", "%", kPercent},
                   {"samples_x", "samples θx", "", NumberFormat::Integer()},
                   {"samples_y", "samples θy", "", NumberFormat::Integer()}};
  for (std::size_t j = 0; j < fit.errors.per_joint.size(); ++j) {
    const FitErrors::Joint& a = fit.start_errors.per_joint[j];
    const FitErrors::Joint& b = fit.errors.per_joint[j];
    table.AddRow({Cell::Number(b.joint), Cell::Number(a.rms_deg[0]), Cell::Number(b.rms_deg[0]),
                  Cell::Number(b.motion_rms_deg[0]), Cell::Number(a.rms_deg[1]),
                  Cell::Number(b.rms_deg[1]), Cell::Number(b.motion_rms_deg[1]),
                  Cell::Number(a.fit_percent[0]), Cell::Number(b.fit_percent[0]),
                  Cell::Number(a.fit_percent[1]), Cell::Number(b.fit_percent[1]),
                  Cell::Number(b.samples[0]), Cell::Number(b.samples[1])});
  }
  std::string caption =
      "RMS error (top) and fit percent (bottom) of θx (left) and θy (right) per joint over every "
      "experiment: grey at the start values, blue with the fitted parameters. The fit-percent axes "
      "span the data, not 0 to 100 %.";
  for (int c = 0; c < 2; ++c) {
    if (!AxisHasFitPercent(fit.errors, c)) {
      caption += std::string(" ") + AxisName(c) +
                 " barely moves at any joint, so its bottom panel shows, in degrees, its motion "
                 "(grey: the RMS of the measured angles about their mean) against the fitted RMS "
                 "error (blue) instead of a fit percent.";
    }
  }
  section.blocks.push_back(
      FigureBlock{ErrorFigure(fit), "Before and after, per joint", caption, ""});
  section.blocks.push_back(std::move(table));
  return section;
}

// ------------------------------------------------------------ convergence

Section ConvergenceSection(const FitFolder& fit) {
  Section section{"convergence", "Convergence", {}};
  Figure figure;
  figure.name = "cost";
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  Panel panel;
  panel.title = "Cost per accepted step";
  panel.x = Axis{"accepted step (0 = start)", "1"};
  panel.y = Axis{"cost ½ Σ r²", "1"};
  panel.y.log_scale = true;
  panel.x.min = -0.5;
  panel.x.max = static_cast<double>(fit.cost_history.size()) - 0.5;
  panel.legend = LegendPlace::kNone;
  Table table;
  table.id = "cost_history";
  table.title = "Cost per accepted step";
  table.caption =
      "fit.json 'cost_history': the cost at the start and after each accepted step of "
      "the Levenberg–Marquardt minimiser (rejected trial steps are counted in the "
      "iterations but not listed).";
  table.columns = {{"step", "accepted step", "", NumberFormat::Integer()},
                   {"cost", "cost", "", kCost}};
  Series cost{"cost", {}, {}, palette::kFitted, SeriesStyle::kLinePoints};
  for (std::size_t i = 0; i < fit.cost_history.size(); ++i) {
    cost.x.push_back(static_cast<double>(i));
    cost.y.push_back(fit.cost_history[i]);
    table.AddRow({Cell::Number(static_cast<double>(i)), Cell::Number(fit.cost_history[i])});
  }
  panel.series.push_back(std::move(cost));
  figure.panels.push_back(std::move(panel));
  section.blocks.push_back(Paragraph{
      "Termination: " + fit.termination + " — " + fit.message + ". " +
          Plural(fit.iterations, "iteration") + ", " +
          Plural(static_cast<double>(fit.cost_history.size()) - 1.0, "accepted step") + ".",
      false});
  section.blocks.push_back(FigureBlock{
      std::move(figure), "Cost per accepted step",
      "The cost ½ Σ r² (residuals in units of the measurement noise) at the start (0) and after "
      "each accepted step, log scale.",
      ""});
  section.blocks.push_back(std::move(table));
  return section;
}

// ------------------------------------------------------------ experiments

Section ExperimentSection(const FitFolder& fit) {
  Section section{"experiments", "Experiments", {}};
  Table table;
  table.id = "experiments";
  table.title = "Experiments";
  table.caption =
      "fit.json 'experiments': the file fitted, where its measured angles came from, how the "
      "noise that weights its residuals was found, its errors at the start and fitted, and the "
      "status of its run with the fitted parameters (the run and angles files in this folder).";
  table.columns = internal::RecordingColumns("experiment");
  table.columns.insert(table.columns.end(), {{"rms_start_deg", "RMS start", "deg", kRms},
                                             {"rms_fitted_deg", "RMS fitted", "deg", kRms},
                                             {"fit_start_percent", "fit start", "%", kPercent},
                                             {"fit_fitted_percent", "fit fitted", "%", kPercent},
                                             {"fitted_run", "fitted run", "", kRms}});
  Table noise;
  noise.id = "noise";
  noise.title = "Measurement noise per joint";
  noise.caption =
      "fit.json 'noise_deg': the standard deviation each joint's residuals are divided by.";
  noise.columns = {{"joint", "joint", "", NumberFormat::Integer()}};
  std::set<std::string> keys = {"joint"};
  for (const FitExperiment& e : fit.experiments) {
    std::vector<Cell> row = internal::RecordingCells("experiment", e.name, e.path,
                                                     e.angles_from_pipeline, e.noise_source);
    row.insert(row.end(), {Cell::Number(e.start.rms_deg), Cell::Number(e.fitted.rms_deg),
                           Cell::Number(e.start.fit_percent), Cell::Number(e.fitted.fit_percent),
                           Cell::Text(e.run_status)});
    table.AddRow(std::move(row));
    std::string key = "noise_deg_" + Key(e.name);
    while (!keys.insert(key).second) key += "_";
    noise.columns.push_back({key, e.name, "deg", NumberFormat::Fixed(4)});
  }
  std::size_t joints = 0;
  for (const FitExperiment& e : fit.experiments) joints = std::max(joints, e.noise_deg.size());
  for (std::size_t j = 0; j < joints; ++j) {
    std::vector<Cell> row = {Cell::Number(static_cast<double>(j + 1))};
    for (const FitExperiment& e : fit.experiments) {
      row.push_back(j < e.noise_deg.size() ? Cell::Number(e.noise_deg[j]) : Cell::Missing());
    }
    noise.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));
  section.blocks.push_back(std::move(noise));
  return section;
}

}  // namespace

Document BuildFitDocument(const std::string& folder, const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  const FitFolder fit = internal::ReadFitFolder(folder);
  Document document;
  document.kind = "fit";
  document.title = "Identification — " + ListNames(fit.free);
  document.source = folder;
  document.ccsrm_version = kVersion;
  document.sections.push_back(SummarySection(fit));
  const bool several = fit.experiments.size() > 1;
  for (std::size_t e = 0; e < fit.experiments.size(); ++e) {
    document.sections.push_back(ExperimentAnglesSection(fit.experiments[e], e, several));
  }
  document.sections.push_back(ParameterSection(fit));
  document.sections.push_back(IdentifiabilitySection(fit));
  // Experiments of tracked points only: no joint was measured.
  if (std::isfinite(fit.errors.rms_deg)) document.sections.push_back(ErrorSection(fit));
  document.sections.push_back(ConvergenceSection(fit));
  document.sections.push_back(ExperimentSection(fit));
  return document;
}

}  // namespace ccsrm::reports
