// The page of a design folder (`ccsrm design`): which planned motions would
// pin the free parameters down, before anything is recorded. The candidates'
// predicted relative standard errors side by side, which parameter each
// motion informs, the proposed motion's planned angles and cable speeds, and
// the worst case over the prior box. Every number is read from design.json
// or proposed.inputs.csv as ccsrm design wrote them.
#include <algorithm>
#include <cmath>
#include <string>

#include "arm_facts.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "design_folder.h"
#include "pages.h"

namespace ccsrm::reports {
namespace {

using internal::AddText;
using internal::AddValue;
using internal::DesignCandidateRow;
using internal::DesignFolder;
using internal::Key;
using internal::ListNames;
using internal::Plural;
using internal::Show;

const NumberFormat kPercent = NumberFormat::Significant(3);

double Percent(double x) { return 100.0 * x; }  // NaN stays NaN: "–"
// identify's kDerivativeStepLimit: a derivative that moves more between
// relative steps r and r/3 is not smooth (the fit page uses the same).
constexpr double kDerivativeLimit = 0.05;

bool Proposed(const DesignCandidateRow& c) { return !c.protocol_yaml.empty(); }

// A plan's name with room to wrap: "a.yaml@x=1,y=2+b.yaml" shows as
// "a.yaml@x=1, y=2 + b.yaml".
std::string Shown(const std::string& name) {
  std::string text;
  for (const char c : name) {
    if (c == '+') {
      text += " + ";
    } else {
      text += c;
      if (c == ',') text += ' ';
    }
  }
  return text;
}

// "0.98 mu_c − 0.21 mu", the shares below 0.2 left out.
std::string Direction(const DesignCandidateRow& c) {
  std::string text;
  for (std::size_t k = 0; k < c.worst_direction.size(); ++k) {
    const auto& [name, component] = c.worst_direction[k];
    if (k > 0 && std::abs(component) < 0.2) break;
    text += (k == 0          ? ""
             : component < 0 ? " − "
                             : " + ") +
            Show(k == 0 ? component : std::abs(component), NumberFormat::Fixed(2)) + " " + name;
  }
  return text;
}

// The best candidate that is a given plan (not proposed), if any.
const DesignCandidateRow* BestGiven(const DesignFolder& d) {
  for (const std::size_t k : d.ranking) {
    if (!Proposed(d.candidates[k]) && d.candidates[k].completed) return &d.candidates[k];
  }
  return nullptr;
}

Section SummarySection(const DesignFolder& d) {
  Section section{"summary", "Summary", {}};
  const DesignCandidateRow& best = d.candidates[d.ranking.front()];
  std::string text =
      Plural(static_cast<double>(d.candidates.size()), "candidate plan") +
      " ranked by the largest relative standard error a fit of " + ListNames(d.free) +
      " to their recordings would report, predicted from the Fisher information of the "
      "identification's residuals at the prior values (noise " +
      Show(d.noise_deg, NumberFormat::Significant(3)) + " deg per angle, N_eff/N " +
      Show(d.effective_sample_fraction, NumberFormat::Significant(3)) + "). ";
  if (best.completed) {
    text += "The best is " + Shown(best.name) + " (" +
            Show(best.duration_s, NumberFormat::Fixed(1)) +
            " s of recording): its least determined parameter, " + best.worst_parameter + ", to " +
            Show(Percent(best.worst_relative_std_error), kPercent) + " %. ";
  }
  const DesignCandidateRow* given = BestGiven(d);
  if (given != nullptr && Proposed(best) && best.completed) {
    text += "The best plan given to compare, " + Shown(given->name) + ", reaches " +
            Show(Percent(given->worst_relative_std_error), kPercent) + " % (" +
            given->worst_parameter + "): the proposed motion's worst error is " +
            Show(given->worst_relative_std_error / best.worst_relative_std_error,
                 NumberFormat::Significant(3)) +
            " times smaller. ";
  }
  if (!d.prior_box.empty()) {
    text += "With the prior box, the plans ranked best at the prior (up to " +
            Show(d.robust_candidates, NumberFormat::Integer()) +
            ") were evaluated at every corner of the box too and are ranked by their worst "
            "case (table Prior box). ";
  }
  text +=
      "These are first-order predictions: a fit of real recordings realises them as far as its "
      "noise is the one assumed (docs/design.md, Validation).";
  section.blocks.push_back(Paragraph{text, false});
  for (const std::size_t k : d.ranking) {
    const DesignCandidateRow& c = d.candidates[k];
    if (c.derivative_step_disagreement.empty()) continue;
    std::string rough, largest;
    double worst = -1.0;
    for (std::size_t i = 0; i < c.derivative_step_disagreement.size() && i < d.free.size(); ++i) {
      const double x = c.derivative_step_disagreement[i];
      if (!(x <= kDerivativeLimit)) {
        rough += (rough.empty() ? "" : ", ") + d.free[i] + " " +
                 (std::isnan(x) ? std::string("(not computed)")
                                : Show(Percent(x), NumberFormat::Significant(3)) + " %");
      } else if (x > worst) {
        worst = x;
        largest = d.free[i] + ", " + Show(Percent(x), NumberFormat::Significant(3)) + " %";
      }
    }
    const std::string checked =
        "Plan " + Shown(c.name) +
        "'s derivatives at the prior were checked as a fit checks its own (relative steps " +
        Show(d.relative_step, NumberFormat::Significant(2)) + " and a third of it): ";
    if (rough.empty()) {
      section.blocks.push_back(
          Paragraph{checked + "smooth (largest disagreement " + largest + ").", false});
    } else {
      section.blocks.push_back(Paragraph{
          checked + "NOT smooth in " + rough +
              " (limit 5 %). The angles jump with the parameters there (as in stick-slip at "
              "static friction well above kinetic: docs/model-notes.md), so a fit of its "
              "recordings would not give its predicted errors; it is ranked last.",
          true});
    }
  }
  for (const DesignCandidateRow& c : d.candidates) {
    if (!c.completed) {
      section.blocks.push_back(
          Paragraph{"Plan " + c.name + " was not evaluated: " + c.message, true});
    }
  }
  Table table = internal::KeyValueTable("design", "Design run", "From design.json.");
  AddText(&table, "free parameters", ListNames(d.free));
  AddValue(&table, "noise per angle", d.noise_deg, "deg", NumberFormat::Significant(3));
  AddValue(&table, "N_eff / N", d.effective_sample_fraction, "", NumberFormat::Significant(3));
  AddValue(&table, "frame rate", d.frame_rate_hz, "Hz", NumberFormat::Significant(4));
  AddValue(&table, "low-pass of the angles (0: none)", d.low_pass_hz, "Hz",
           NumberFormat::Significant(3));
  AddValue(&table, "relative step", d.relative_step, "", NumberFormat::Significant(2));
  AddValue(&table, "candidate plans", static_cast<double>(d.candidates.size()), "",
           NumberFormat::Integer());
  AddValue(&table, "simulations", d.simulations, "", NumberFormat::Integer());
  AddValue(&table, "threads", d.threads, "", NumberFormat::Integer());
  AddValue(&table, "wall time", d.wall_time_s, "s", NumberFormat::Fixed(1));
  section.blocks.push_back(std::move(table));
  return section;
}

Section ErrorsSection(const DesignFolder& d) {
  Section section{"errors", "Predicted errors", {}};
  Table table;
  table.id = "candidates";
  table.title = "Candidate plans, best first";
  table.caption =
      "Predicted standard error of each free parameter relative to its prior value, in %; worst: "
      "the largest of them (the ranking criterion); D and A: the D- and A-criteria of the "
      "relative covariance as standard errors; worst direction: the least informed combination "
      "of the parameters. – : a direction the plan does not inform.";
  table.columns = {{"rank", "rank", "", NumberFormat::Integer()},
                   {"plan", "plan", "", kPercent, true},
                   {"kind", "kind", "", kPercent},
                   {"duration_s", "time", "s", NumberFormat::Fixed(1)}};
  for (const std::string& name : d.free) {
    table.columns.push_back({"rse_" + Key(name), name, "%", kPercent});
  }
  table.columns.push_back({"worst", "worst", "%", kPercent});
  table.columns.push_back({"worst_parameter", "of", "", kPercent});
  table.columns.push_back({"d_criterion", "D", "%", kPercent});
  table.columns.push_back({"a_criterion", "A", "%", kPercent});
  table.columns.push_back({"worst_direction", "worst direction", "", kPercent, true});
  if (!d.prior_box.empty()) {
    table.columns.push_back({"robust_worst", "worst over the box", "%", kPercent});
  }
  for (std::size_t r = 0; r < d.ranking.size(); ++r) {
    const DesignCandidateRow& c = d.candidates[d.ranking[r]];
    std::vector<Cell> row = {Cell::Number(static_cast<double>(r + 1)), Cell::Text(Shown(c.name)),
                             Cell::Text(Proposed(c) ? "proposed" : "given"),
                             Cell::Number(c.duration_s)};
    for (const double x : c.relative_std_error) row.push_back(Cell::Number(Percent(x)));
    row.push_back(Cell::Number(Percent(c.worst_relative_std_error)));
    row.push_back(Cell::Text(c.completed ? c.worst_parameter : "not evaluated"));
    row.push_back(Cell::Number(Percent(c.d_criterion)));
    row.push_back(Cell::Number(Percent(c.a_criterion)));
    row.push_back(Cell::Text(Direction(c)));
    if (!d.prior_box.empty()) {
      row.push_back(c.corners.empty() ? Cell::Missing()
                                      : Cell::Number(Percent(c.robust_worst_relative_std_error)));
    }
    table.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));

  // Side by side: one marker per parameter and plan, on a log scale.
  Figure figure;
  figure.name = "predicted_errors";
  figure.panel_width_px = 1000;
  figure.panel_height_px = 340;
  Panel panel;
  panel.title = "Predicted relative standard errors, plans in rank order";
  panel.x = Axis{"plan (rank)", "1"};
  panel.x.min = 0.5;
  panel.x.max = static_cast<double>(d.ranking.size()) + 0.5;
  for (std::size_t r = 0; r < d.ranking.size(); ++r) {
    panel.x.tics.push_back({static_cast<double>(r + 1), std::to_string(r + 1)});
  }
  panel.y = Axis{"relative standard error", "%"};
  panel.y.log_scale = true;
  for (std::size_t i = 0; i < d.free.size(); ++i) {
    Series s;
    s.label = d.free[i];
    s.color = palette::Indexed(static_cast<int>(i) + 1);
    s.style = SeriesStyle::kLinePoints;
    s.line_width = 1.0;
    for (std::size_t r = 0; r < d.ranking.size(); ++r) {
      s.x.push_back(static_cast<double>(r + 1));
      s.y.push_back(Percent(d.candidates[d.ranking[r]].relative_std_error[i]));
    }
    panel.series.push_back(std::move(s));
  }
  figure.panels.push_back(std::move(panel));
  section.blocks.push_back(FigureBlock{
      std::move(figure), "Predicted errors side by side",
      "Each parameter's predicted relative standard error (log scale) for every plan, in the "
      "order of the table; a plan's worst is its highest marker. Missing: not informed.",
      ""});

  // Which parameter each motion informs: log10 of the relative error.
  Figure cells_figure;
  cells_figure.name = "informs";
  cells_figure.panel_width_px = static_cast<int>(360 + 90 * d.free.size());
  cells_figure.panel_height_px =
      static_cast<int>(std::max<std::size_t>(260, 90 + 34 * d.ranking.size()));
  Panel map;
  map.title = "log10 of the predicted relative standard error [%]";
  map.x = Axis{"parameter", "1"};
  map.y = Axis{"plan (rank)", "1"};
  map.x.min = map.y.min = 0.5;
  map.x.max = static_cast<double>(d.free.size()) + 0.5;
  map.y.max = static_cast<double>(d.ranking.size()) + 0.5;
  Axis color{"log10 error", "1"};
  color.min = -2.0;  // 0.01 %
  color.max = 2.0;   // 100 %
  map.color = color;
  map.legend = LegendPlace::kNone;
  Series cells;
  cells.style = SeriesStyle::kCells;
  cells.cell_decimals = 1;
  for (std::size_t i = 0; i < d.free.size(); ++i) {
    map.x.tics.push_back({static_cast<double>(i + 1), d.free[i]});
  }
  for (std::size_t r = 0; r < d.ranking.size(); ++r) {
    const double y = static_cast<double>(d.ranking.size() - r);  // best at the top
    map.y.tics.push_back({y, std::to_string(r + 1)});
    for (std::size_t i = 0; i < d.free.size(); ++i) {
      cells.x.push_back(static_cast<double>(i + 1));
      cells.y.push_back(y);
      cells.z.push_back(std::log10(Percent(d.candidates[d.ranking[r]].relative_std_error[i])));
    }
  }
  map.series.push_back(std::move(cells));
  cells_figure.panels.push_back(std::move(map));
  section.blocks.push_back(FigureBlock{
      std::move(cells_figure), "Which parameter each motion informs",
      "Per plan (rank, best at the top) and parameter, log10 of its predicted relative standard "
      "error in %: −1 is 0.1 %, 0 is 1 %, 1 is 10 %. Blue: the motion pins the parameter down; "
      "red: it hardly informs it; grey: not at all.",
      ""});
  return section;
}

Section ProposedSection(const DesignFolder& d) {
  Section section{"proposed", "The proposed motion", {}};
  const DesignCandidateRow* proposed = nullptr;
  for (const std::size_t k : d.ranking) {
    if (Proposed(d.candidates[k]) && d.candidates[k].completed) {
      proposed = &d.candidates[k];
      break;
    }
  }
  if (proposed == nullptr) {
    section.blocks.push_back(
        Paragraph{"No motion was proposed (ccsrm design without --propose).", false});
    return section;
  }
  section.blocks.push_back(Paragraph{
      proposed->name + ", written as proposed.yaml (a protocol file for the lab and for ccsrm "
                       "generate --protocol) and planned on the prior arm in proposed.inputs.csv "
                       "(cable input lengths that ccsrm simulate --inputs reads, their speeds, "
                       "and the planned joint angles).",
      false});
  if (!d.proposed) {
    section.blocks.push_back(
        Paragraph{"proposed.inputs.csv is missing: the planned motion cannot be drawn.", true});
    return section;
  }
  const internal::PlannedMotion& m = *d.proposed;
  const std::size_t joints = m.angles_rad.shape[1], cables = m.length_m.shape[1];
  const internal::ArmFacts arm =
      internal::ReadArmFacts(d.config_yaml, "design.json", joints, cables, nullptr);
  for (const std::string& problem : arm.problems)
    section.blocks.push_back(Paragraph{problem, true});
  for (int c = 0; c < 2; ++c) {
    bool moves = false;
    for (std::size_t t = 0; t < m.time_s.size() && !moves; ++t) {
      for (std::size_t j = 0; j < joints; ++j) moves = moves || m.angles_rad.at(t, j, c) != 0.0;
    }
    if (c == 1 && !moves) continue;  // a motion in θx alone: no empty θy panel
    section.blocks.push_back(FigureBlock{
        internal::JointAngleFigure(c == 0 ? "proposed_theta_x" : "proposed_theta_y", m.time_s,
                                   m.angles_rad, c, arm.segments, std::nullopt),
        std::string("Planned ") + internal::AxisName(c),
        std::string("The proposed motion's planned ") + internal::AxisName(c) +
            " of every joint, per segment, from proposed.inputs.csv.",
        ""});
  }
  double fastest = 0.0;
  for (const double v : m.speed_m_s.values) fastest = std::max(fastest, std::abs(v));
  section.blocks.push_back(FigureBlock{
      internal::CableFigure("proposed_cable_speeds", m.time_s, m.speed_m_s, 1e3,
                            Axis{"input speed", "mm/s"}, arm.segments, arm.cable_segment,
                            SeriesStyle::kLine),
      "Cable input speeds",
      "The rate of each driving cable's planned input length (pulled in = positive), from "
      "proposed.inputs.csv; the fastest is " +
          Show(1e3 * fastest, NumberFormat::Fixed(1)) +
          " mm/s, within the protocol's cable speed limit (the checks refuse a faster plan).",
      ""});
  section.blocks.push_back(
      FigureBlock{internal::CableFigure("proposed_cable_lengths", m.time_s, m.length_m, 1e3,
                                        Axis{"input length", "mm"}, arm.segments, arm.cable_segment,
                                        SeriesStyle::kLine),
                  "Cable input lengths", "The planned input length of each driving cable.", ""});
  return section;
}

Section BoxSection(const DesignFolder& d) {
  Section section{"prior-box", "Prior box", {}};
  std::vector<std::string> ranges;
  for (const DesignFolder::Range& r : d.prior_box) {
    ranges.push_back(r.name + " from " + Show(r.lower, NumberFormat::Significant(4)) + " to " +
                     Show(r.upper, NumberFormat::Significant(4)));
  }
  section.blocks.push_back(
      Paragraph{"The truth may lie anywhere in the box " + ListNames(ranges) +
                    ". The plans ranked best at the prior (up to " +
                    Show(d.robust_candidates, NumberFormat::Integer()) +
                    ") were evaluated at each of its corners; a relative error there is "
                    "against the corner's value.",
                false});
  Table table;
  table.id = "corners";
  table.title = "Predicted errors at the corners";
  table.caption =
      "Per plan evaluated at the corners and corner: the box's values there and the "
      "predicted relative standard errors in %.";
  table.columns = {{"plan", "plan", "", kPercent, true}, {"corner", "corner", "", kPercent}};
  for (const std::string& name : d.free) {
    table.columns.push_back({"rse_" + Key(name), name, "%", kPercent});
  }
  table.columns.push_back({"worst", "worst", "%", kPercent});
  table.columns.push_back({"worst_parameter", "of", "", kPercent});
  for (const std::size_t k : d.ranking) {
    const DesignCandidateRow& c = d.candidates[k];
    for (const internal::DesignCorner& corner : c.corners) {
      std::string at;
      for (const auto& [name, value] : corner.values) {
        at += (at.empty() ? "" : ", ") + name + " = " + Show(value, NumberFormat::Significant(4));
      }
      std::vector<Cell> row = {Cell::Text(Shown(c.name)), Cell::Text(at)};
      for (std::size_t i = 0; i < d.free.size(); ++i) {
        row.push_back(i < corner.relative_std_error.size()
                          ? Cell::Number(Percent(corner.relative_std_error[i]))
                          : Cell::Missing());
      }
      row.push_back(Cell::Number(Percent(corner.worst_relative_std_error)));
      row.push_back(Cell::Text(corner.completed ? corner.worst_parameter : corner.message));
      table.AddRow(std::move(row));
    }
  }
  section.blocks.push_back(std::move(table));
  return section;
}

}  // namespace

Document BuildDesignDocument(const std::string& folder, const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  const DesignFolder d = internal::ReadDesignFolder(folder);
  Document document;
  document.kind = "design";
  document.title = "Experiment design — " + ListNames(d.free);
  document.source = folder;
  document.ccsrm_version = kVersion;
  document.sections.push_back(SummarySection(d));
  document.sections.push_back(ErrorsSection(d));
  document.sections.push_back(ProposedSection(d));
  if (!d.prior_box.empty()) document.sections.push_back(BoxSection(d));
  return document;
}

}  // namespace ccsrm::reports
