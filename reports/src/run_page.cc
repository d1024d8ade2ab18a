// The page of a simulation run (ccsrm-run/1): summary and solver statistics,
// joint angles against the plan, input tensions, slack cables, stick–slip, tension along
// the cables at chosen instants, constraint violation and energy. The page
// names the arm and the protocol as configured; it cites the paper (its
// cases, its Figs. 16, 18–21 and 22) only for a run of one of the paper's
// cases on the paper's arm (PaperWords).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include "arm_facts.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"
#include "ccsrm/reports/report.h"
#include "ccsrm/sim/simulator.h"
#include "pages.h"

namespace ccsrm::reports {
namespace {

using datasets::RunFile;
using internal::AddText;
using internal::AddValue;
using internal::ArmFacts;
using internal::Instant;
using internal::kDegPerRad;

// How a run page speaks. A case number (the file's `case`, 1-4) says which
// cables have friction and that the run followed the configured protocol,
// whose plan can be drawn again; on any arm. It is one of the paper's
// cases, which may be compared with the paper's figures, only on the
// paper's arm, recognised from the stored configuration (sim::IsPaperArm):
// the run file holds the arm it ran, so no flag can disagree with it.
struct Words {
  bool protocol_case = false;  // case 1-4: the protocol's plan applies
  bool paper = false;          // and the arm is the paper's
  std::string case_words;      // "paper case 2 (...)", "case 1 (...)", "case 'custom'"
};

Words WordsFor(const RunFile& run, const ArmFacts& facts) {
  Words w;
  w.protocol_case = internal::CaseNumber(run.case_name) != 0;
  w.paper = w.protocol_case && facts.paper_arm;
  w.case_words = internal::CaseWords(run.case_name, facts.paper_arm);
  return w;
}

std::string Slug(const std::string& label) {
  std::string out;
  for (char c : label) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

// The instants of ReportOptions::instants_s (see there for the default).
std::vector<Instant> ChooseInstants(const std::vector<double>& time, const ArmFacts& facts,
                                    bool protocol_case, const ReportOptions& options) {
  const double first = time.front(), last = time.back();
  std::vector<std::pair<std::string, double>> wanted;
  if (!options.instants_s.empty()) {
    // A time outside the run would be shown at its nearest end, labelled
    // with a time it is not: refused instead. Half a frame either side is
    // still that frame.
    const double half_frame = time.size() > 1 ? 0.5 * (last - first) / (time.size() - 1) : 0.0;
    for (double t : options.instants_s) {
      if (t < first - half_frame || t > last + half_frame) {
        ThrowInputError("--instants", "",
                        internal::FormatSeconds(t) + " s is outside the run (" +
                            internal::FormatSeconds(first) + " to " +
                            internal::FormatSeconds(last) + " s)");
      }
      wanted.push_back({"t = " + internal::FormatSeconds(t) + " s", t});
    }
  } else {
    if (protocol_case && facts.protocol) {
      const internal::ProtocolPhases& p = *facts.protocol;
      const std::pair<std::string, double> phases[] = {
          {"end of ramp", p.ramp_s},
          {"mid-hold", p.ramp_s + 0.5 * p.hold_s},
          {"end of return", p.ramp_s + p.hold_s + p.return_s}};
      for (const auto& phase : phases) {
        if (phase.second >= first && phase.second < last) wanted.push_back(phase);
      }
    }
    if (wanted.size() + 1 < 2) wanted.push_back({"mid-run", first + 0.5 * (last - first)});
    wanted.push_back({"end of run", last});
  }
  std::vector<Instant> instants;
  for (const auto& [label, t] : wanted) {
    const std::size_t frame = internal::NearestFrame(time, t);
    // Two instants on one frame (a run of a frame or two) are shown once.
    const bool repeated = std::any_of(instants.begin(), instants.end(),
                                      [&](const Instant& i) { return i.frame == frame; });
    if (!repeated) instants.push_back({label, time[frame], frame});
  }
  return instants;
}

// "end of ramp (20 s)"; a requested time names itself ("t = 1.5 s").
std::string InstantHeader(const Instant& instant) {
  if (instant.label.rfind("t = ", 0) == 0) return instant.label;
  return instant.label + " (" + internal::FormatSeconds(instant.time_s) + " s)";
}

double MaxOf(const std::vector<double>& values) {
  double m = -INFINITY;
  for (double v : values) {
    if (std::isfinite(v)) m = std::max(m, v);
  }
  return m;
}

double MinOf(const std::vector<double>& values) {
  double m = INFINITY;
  for (double v : values) {
    if (std::isfinite(v)) m = std::min(m, v);
  }
  return m;
}

// The value text of a key-value table's row, as the page shows it.
std::string Shown(const Table& table, const std::string& quantity) {
  for (const auto& row : table.rows) {
    if (row[0].text == quantity) return FormatCell(row[1], table.columns[1]);
  }
  CCSRM_CHECK(false);
}

// θx or θy of every joint at every instant, with the plan's rows on top.
Table JointAnglesAtInstants(const RunFile& run, const ArmFacts& facts,
                            const std::vector<Instant>& instants, int component) {
  const std::string axis = component == 0 ? "θx" : "θy";
  const std::string key = component == 0 ? "theta_x" : "theta_y";
  Table table;
  table.id = key + "_at_instants";
  table.title = axis + " of every joint at the chosen instants";
  table.caption = "Degrees, read from /joint_angles at the frames listed under Instants." +
                  std::string(facts.plan ? " Plan: the planned " + axis +
                                               " at the same frames (the protocol plans the same "
                                               "angle for every joint)."
                                         : "");
  table.columns = {{"joint", "joint", "", NumberFormat::Integer()},
                   {"segment", "segment", "", NumberFormat::Integer()}};
  for (const Instant& instant : instants) {
    // θx to 0.001 deg (the scale of the paper's figures, and well below
    // mocap noise); θy, which stays small, to 3 significant digits so
    // 1e-5 deg does not show as 0.
    table.columns.push_back(
        {key + "_deg_" + Slug(instant.label), InstantHeader(instant), "deg",
         component == 0 ? NumberFormat::Fixed(3) : NumberFormat::Significant(3)});
  }
  const std::size_t joints = run.joint_angles.shape[1];
  const std::size_t c = static_cast<std::size_t>(component);
  if (facts.plan) {
    // One "plan" row when the plan is the same for every joint at these
    // instants, else one per joint.
    bool same = true;
    for (const Instant& instant : instants) {
      for (std::size_t j = 1; j < joints; ++j) {
        if (std::abs(facts.plan->at(instant.frame, j, c) - facts.plan->at(instant.frame, 0, c)) >
            1e-12) {
          same = false;
        }
      }
    }
    for (std::size_t j = 0; j < (same ? 1 : joints); ++j) {
      std::vector<Cell> row = {Cell::Text(same ? "plan" : "plan " + std::to_string(j + 1)),
                               Cell::Missing()};
      for (const Instant& instant : instants) {
        row.push_back(Cell::Number(facts.plan->at(instant.frame, j, c) * kDegPerRad));
      }
      table.AddRow(std::move(row));
    }
  }
  for (std::size_t g = 0; g < facts.segments.size(); ++g) {
    const internal::JointGroup& group = facts.segments[g];
    for (int k = 0; k < group.joints; ++k) {
      const std::size_t j = static_cast<std::size_t>(group.first_joint - 1 + k);
      std::vector<Cell> row = {
          Cell::Number(static_cast<double>(j + 1)),
          facts.segments.size() > 1 ? Cell::Number(static_cast<double>(g + 1)) : Cell::Missing()};
      for (const Instant& instant : instants) {
        row.push_back(Cell::Number(run.joint_angles.at(instant.frame, j, c) * kDegPerRad));
      }
      table.AddRow(std::move(row));
    }
  }
  return table;
}

Section SummarySection(const RunFile& run, const std::string& source, const ArmFacts& facts,
                       const Words& words, const std::vector<Instant>& instants) {
  Section section{"summary", "Summary", {}};
  const double first = run.time.values.front(), last = run.time.values.back();
  const bool completed = run.status == datasets::RunStatus::kCompleted;

  Table about = internal::KeyValueTable("run", "Run",
                                        "Root attributes of the run file and the protocol of its "
                                        "stored configuration.");
  AddText(&about, "file", source);
  const int case_number = internal::CaseNumber(run.case_name);
  AddText(&about, "case",
          case_number != 0 ? run.case_name + " (" + internal::CaseFriction(case_number) + ")"
                           : run.case_name);
  if (!facts.arm_words.empty()) {
    AddText(&about, "arm", (facts.paper_arm ? "the paper's: " : "") + facts.arm_words);
    AddText(&about, "protocol", facts.protocol_words);
  }
  if (facts.protocol) {
    AddValue(&about, "planned amplitude", facts.protocol->amplitude_deg, "deg",
             NumberFormat::Fixed(3));
    AddValue(&about, "protocol ramp", facts.protocol->ramp_s, "s", NumberFormat::Fixed(2));
    AddValue(&about, "protocol hold", facts.protocol->hold_s, "s", NumberFormat::Fixed(2));
    AddValue(&about, "protocol return", facts.protocol->return_s, "s", NumberFormat::Fixed(2));
    AddValue(&about, "protocol rest", facts.protocol->rest_s, "s", NumberFormat::Fixed(2));
  }
  AddValue(&about, "first frame", first, "s", NumberFormat::Fixed(3));
  AddValue(&about, "last frame", last, "s", NumberFormat::Fixed(3));
  AddValue(&about, "frames", static_cast<double>(run.frames()), "", NumberFormat::Integer());
  AddText(&about, "status", datasets::RunStatusName(run.status));
  if (!completed) AddText(&about, "status message", run.status_message);
  AddText(&about, "created", run.created);
  AddText(&about, "ccsrm version", run.ccsrm_version);

  Table solver = internal::KeyValueTable(
      "solver", "Solver",
      "As the simulator stored them in the run file (attributes wall_time_s, steps, "
      "rejected_steps, rhs_evaluations). Real-time factor: simulated time / wall time, as "
      "ccsrm simulate prints it (none for a wall time of 0, e.g. the ground truth of a "
      "generated experiment). Largest constraint violation: the maximum of "
      "/diagnostics/constraint_violation over the frames.");
  const double simulated = last - first;
  AddValue(&solver, "wall time", run.wall_time_s, "s", NumberFormat::Fixed(3));
  AddValue(&solver, "real-time factor", run.wall_time_s > 0.0 ? simulated / run.wall_time_s : NAN,
           "", NumberFormat::Fixed(2));
  AddValue(&solver, "accepted steps", static_cast<double>(run.steps), "", NumberFormat::Integer());
  AddValue(&solver, "rejected steps", static_cast<double>(run.rejected_steps), "",
           NumberFormat::Integer());
  AddValue(&solver, "right-hand-side evaluations", static_cast<double>(run.rhs_evaluations), "",
           NumberFormat::Integer());
  AddValue(&solver, "largest constraint violation ‖Φ‖", MaxOf(run.constraint_violation.values),
           "mixed", NumberFormat::Significant(3));

  // The text summary quotes the tables, so it shows their numbers exactly.
  std::string text = words.case_words;
  text[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  if (!facts.arm_words.empty()) {
    text +=
        words.paper ? " on the paper's arm" : " on the configured arm (" + facts.arm_words + ")";
  }
  if (facts.protocol) text += ", planned amplitude " + Shown(about, "planned amplitude") + " deg";
  text += ": " + Shown(about, "last frame") + " s simulated";
  if (run.wall_time_s > 0.0) {
    text += " in " + Shown(solver, "wall time") + " s of wall time (real-time factor " +
            Shown(solver, "real-time factor") + ")";
  }
  text += ", " + Shown(solver, "accepted steps") + " steps. ";
  text += completed ? "The run completed." : "The run diverged: " + run.status_message + ".";
  section.blocks.push_back(Paragraph{text, false});
  if (!completed) {
    section.blocks.push_back(Paragraph{
        "This run diverged (" + run.status_message + "); the page shows the frames up to then.",
        true});
  }
  if (!words.protocol_case && run.protocol_yaml.empty()) {
    section.blocks.push_back(
        Paragraph{"The run's case is '" + run.case_name +
                      "', not one of the cases 1–4 of the protocol: the planned motion is not "
                      "drawn (only a run of the protocol can be planned again from its "
                      "configuration).",
                  true});
  }
  for (const std::string& problem : facts.problems) {
    section.blocks.push_back(Paragraph{problem, true});
  }
  section.blocks.push_back(std::move(about));
  section.blocks.push_back(std::move(solver));

  Table at;
  at.id = "instants";
  at.title = "Instants";
  at.caption =
      "The moments the tables below quote and the tension along the cables is drawn at, each "
      "shown at the run's frame nearest to it.";
  at.columns = {{"instant", "instant", "", NumberFormat::Integer()},
                {"time_s", "time", "s", NumberFormat::Fixed(3)},
                {"frame", "frame", "", NumberFormat::Integer()}};
  for (const Instant& instant : instants) {
    at.AddRow({Cell::Text(instant.label), Cell::Number(instant.time_s),
               Cell::Number(static_cast<double>(instant.frame))});
  }
  section.blocks.push_back(std::move(at));
  return section;
}

// Simulated minus planned angles, θx and θy, for a run that recorded its
// protocol (protocol_yaml): how closely the arm followed a planned motion
// in both axes, at a scale the angle figures cannot show.
void AddPlanErrorFigures(const RunFile& run, const ArmFacts& facts, Section* section) {
  datasets::Array error = run.joint_angles;
  for (std::size_t i = 0; i < error.values.size(); ++i) error.values[i] -= facts.plan->values[i];
  for (int axis = 0; axis < 2; ++axis) {
    const std::string name = axis == 0 ? "θx" : "θy";
    section->blocks.push_back(FigureBlock{
        internal::JointAngleFigure(axis == 0 ? "plan_error_theta_x" : "plan_error_theta_y",
                                   run.time.values, error, axis, facts.segments, std::nullopt),
        "Error to the plan, " + name,
        "Simulated minus planned " + name +
            " of every joint, one panel per segment; the plan is "
            "the run's own protocol (" +
            facts.protocol_words + ").",
        ""});
  }
}

Section JointAngleSection(const RunFile& run, const ArmFacts& facts, const Words& words,
                          const std::vector<Instant>& instants) {
  Section section{"joint-angles", "Joint angles", {}};
  const std::string plan = facts.plan ? " Dashed black: the planned motion." : "";
  const std::string layout = words.paper ? ": the layout of the paper's Figs. 16 and 18–21." : ".";
  section.blocks.push_back(FigureBlock{
      internal::JointAngleFigure("theta_x", run.time.values, run.joint_angles, 0, facts.segments,
                                 facts.plan),
      "θx against time",
      "Bending angle θx of every universal joint (X–Y Cardan pair of SPEC §2), one panel per "
      "segment, joints in order from the root" +
          layout + plan,
      ""});
  section.blocks.push_back(FigureBlock{
      internal::JointAngleFigure("theta_y", run.time.values, run.joint_angles, 1, facts.segments,
                                 facts.plan),
      "θy against time",
      std::string("Out-of-plane angle θy of every joint") +
          (words.protocol_case && run.protocol_yaml.empty() ? " (the protocol plans 0)" : "") +
          ", same layout and colours." + plan,
      ""});
  if (facts.plan && !run.protocol_yaml.empty()) AddPlanErrorFigures(run, facts, &section);
  section.blocks.push_back(JointAnglesAtInstants(run, facts, instants, 0));
  section.blocks.push_back(JointAnglesAtInstants(run, facts, instants, 1));
  return section;
}

Section InputSection(const RunFile& run, const ArmFacts& facts, const Words& words,
                     const std::vector<Instant>& instants) {
  Section section{"inputs", "Input tensions", {}};
  const std::vector<double>& time = run.time.values;
  section.blocks.push_back(FigureBlock{
      internal::CableFigure("input_tension", time, run.input_tension, 1.0, Axis{"tension", "N"},
                            facts.segments, facts.cable_segment, SeriesStyle::kLine),
      "Input tension against time",
      std::string("Tension of the first element of each driving cable (/input_tension), the force "
                  "the actuator holds") +
          (words.paper ? ": the paper's Fig. 22" : "") +
          ". One panel per segment the cables drive.",
      ""});
  section.blocks.push_back(FigureBlock{
      internal::CableFigure("input_length", time, run.input_length_change, 1000.0,
                            Axis{"pulled-in length", "mm"}, facts.segments, facts.cable_segment,
                            SeriesStyle::kLine),
      "Prescribed inputs",
      "Length of each driving cable pulled in at its input (/input_length_change; positive = "
      "pulled), as prescribed to the simulation.",
      ""});
  Table table;
  table.id = "input_tension";
  table.title = "Input tension of every driving cable";
  table.caption =
      "From /input_tension: the value at each instant, and the smallest and largest over all "
      "frames.";
  table.columns = {{"cable", "cable", "", NumberFormat::Integer()},
                   {"segment", "segment", "", NumberFormat::Integer()}};
  for (const Instant& instant : instants) {
    table.columns.push_back(
        {"tension_n_" + Slug(instant.label), InstantHeader(instant), "N", NumberFormat::Fixed(2)});
  }
  table.columns.push_back({"min_n", "smallest", "N", NumberFormat::Fixed(2)});
  table.columns.push_back({"max_n", "largest", "N", NumberFormat::Fixed(2)});
  for (std::size_t k = 0; k < run.input_tension.shape[1]; ++k) {
    const std::vector<double> tension = internal::ColumnOf(run.input_tension, k);
    std::vector<Cell> row = {Cell::Number(static_cast<double>(k + 1)),
                             Cell::Number(facts.cable_segment[k] + 1.0)};
    for (const Instant& instant : instants) row.push_back(Cell::Number(tension[instant.frame]));
    row.push_back(Cell::Number(MinOf(tension)));
    row.push_back(Cell::Number(MaxOf(tension)));
    table.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));
  return section;
}

// Elements at zero tension per frame and cable: the file's /slack_elements,
// or, in a file written before it, counted from /cables/<k>/tension (where
// a model that let cables push shows them too).
Eigen::MatrixXi SlackElements(const RunFile& run) {
  const std::size_t frames = run.frames(), cables = run.cables.size();
  Eigen::MatrixXi count(frames, cables);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t k = 0; k < cables; ++k) {
      if (run.slack_elements) {
        count(f, k) = static_cast<int>(run.slack_elements->at(f, k));
        continue;
      }
      const datasets::Array& tension = run.cables[k].tension;
      std::vector<double> row(tension.shape[1]);
      for (std::size_t e = 0; e < row.size(); ++e) row[e] = tension.at(f, e);
      count(f, k) = sim::CountSlackElements(row);
    }
  }
  return count;
}

// Which cable went slack, when and for how long (a cable cannot push: its
// elements then carry no tension), with the tension the rest of it kept.
Section SlackSection(const RunFile& run, const ArmFacts& facts) {
  Section section{"slack", "Slack cables", {}};
  const std::vector<sim::SlackInterval> intervals =
      sim::FindSlackIntervals(run.time.values, SlackElements(run));
  if (intervals.empty()) {
    section.blocks.push_back(Paragraph{
        "No driving cable went slack: every element of every cable carried tension in every "
        "frame.",
        false});
    return section;
  }
  std::string cables;
  int previous = 0, distinct = 0;
  for (const sim::SlackInterval& v : intervals) {
    if (v.cable == previous) continue;
    cables += (cables.empty() ? "" : ", ") + std::to_string(v.cable);
    previous = v.cable;
    ++distinct;
  }
  section.blocks.push_back(Paragraph{
      std::string(distinct == 1 ? "Cable " : "Cables ") + cables + " went slack: some of " +
          (distinct == 1 ? "its" : "their") +
          " elements carried no tension (a cable cannot push; "
          "docs/model-notes.md row 27). The arm then follows the remaining cables, not the "
          "plan. A cable is slack where the release at its input outruns what the arm takes up "
          "(friction holding the cable in its holes, or a motion beyond what the pre-tension "
          "allows).",
      true});
  Table table;
  table.id = "slack";
  table.title = "Stretches of time with a slack element";
  table.caption =
      "From /slack_elements (or the element tensions): consecutive frames in which at least one "
      "element of the cable carried no tension; times to the frame spacing. Highest tension: the "
      "largest element tension of the cable over the stretch, what the rest of it still held.";
  table.columns = {{"cable", "cable", "", NumberFormat::Integer()},
                   {"segment", "segment", "", NumberFormat::Integer()},
                   {"start_s", "from", "s", NumberFormat::Fixed(3)},
                   {"end_s", "to", "s", NumberFormat::Fixed(3)},
                   {"duration_s", "for", "s", NumberFormat::Fixed(3)},
                   {"most_elements", "most slack elements", "", NumberFormat::Integer()},
                   {"elements", "of elements", "", NumberFormat::Integer()},
                   {"highest_tension_n", "highest tension", "N", NumberFormat::Fixed(1)}};
  const std::vector<double>& time = run.time.values;
  for (const sim::SlackInterval& v : intervals) {
    const datasets::Array& tension = run.cables[v.cable - 1].tension;
    double highest = 0.0;
    for (std::size_t f = 0; f < time.size(); ++f) {
      if (time[f] < v.start_s || time[f] > v.end_s) continue;
      for (std::size_t e = 0; e < tension.shape[1]; ++e)
        highest = std::max(highest, tension.at(f, e));
    }
    table.AddRow({Cell::Number(v.cable), Cell::Number(facts.cable_segment[v.cable - 1] + 1.0),
                  Cell::Number(v.start_s), Cell::Number(v.end_s), Cell::Number(v.duration_s()),
                  Cell::Number(v.most_elements),
                  Cell::Number(static_cast<double>(tension.shape[1])), Cell::Number(highest)});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

Section StickSlipSection(const RunFile& run, const ArmFacts& facts,
                         const std::vector<Instant>& instants) {
  Section section{"stick-slip", "Stick–slip", {}};
  // Counts start at 0; half a count of air keeps a cable at 0 off the axis.
  Axis stuck_axis{"stuck hole nodes", "1"};
  stuck_axis.min = -0.5;
  section.blocks.push_back(FigureBlock{
      internal::CableFigure("stuck_nodes", run.time.values, run.stuck_nodes, 1.0, stuck_axis,
                            facts.segments, facts.cable_segment, SeriesStyle::kSteps),
      "Stuck hole nodes",
      "Number of hole nodes of each driving cable held by static friction (/stuck_nodes). "
      "Flat stretches at a cable's hole count mean the whole cable sticks.",
      ""});
  Table table;
  table.id = "stuck_nodes";
  table.title = "Stuck hole nodes of every driving cable";
  table.caption =
      "From /stuck_nodes: the count at each instant and the largest over all frames; "
      "hole nodes: the cable's number of holes (columns of /cables/<k>/stuck).";
  table.columns = {{"cable", "cable", "", NumberFormat::Integer()},
                   {"hole_nodes", "hole nodes", "", NumberFormat::Integer()}};
  for (const Instant& instant : instants) {
    table.columns.push_back(
        {"stuck_" + Slug(instant.label), InstantHeader(instant), "", NumberFormat::Integer()});
  }
  table.columns.push_back({"max_stuck", "most stuck", "", NumberFormat::Integer()});
  for (std::size_t k = 0; k < run.stuck_nodes.shape[1]; ++k) {
    const std::vector<double> stuck = internal::ColumnOf(run.stuck_nodes, k);
    std::vector<Cell> row = {Cell::Number(static_cast<double>(k + 1)),
                             Cell::Number(static_cast<double>(run.cables[k].stuck.shape[1]))};
    for (const Instant& instant : instants) row.push_back(Cell::Number(stuck[instant.frame]));
    row.push_back(Cell::Number(MaxOf(stuck)));
    table.AddRow(std::move(row));
  }
  section.blocks.push_back(std::move(table));
  return section;
}

Section CableTensionSection(const RunFile& run, const std::vector<Instant>& instants) {
  Section section{"cable-tension", "Tension along the cables", {}};
  Figure figure;
  figure.name = "cable_tension";
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  for (std::size_t k = 0; k < run.cables.size(); ++k) {
    const datasets::Array& tension = run.cables[k].tension;
    Panel panel;
    panel.title = "Cable " + std::to_string(k + 1);
    panel.x = Axis{"element, from input (1) to anchor", "1"};
    panel.x.min = 0.5;
    panel.x.max = tension.shape[1] + 0.5;
    panel.y = Axis{"tension", "N"};
    for (std::size_t i = 0; i < instants.size(); ++i) {
      Series s;
      s.label = instants[i].label;
      for (std::size_t e = 0; e < tension.shape[1]; ++e) {
        s.x.push_back(static_cast<double>(e + 1));
        s.y.push_back(tension.at(instants[i].frame, e));
      }
      s.color = palette::Instant(static_cast<int>(i) + 1);
      s.style = SeriesStyle::kLinePoints;
      panel.series.push_back(std::move(s));
    }
    // One legend for all six panels (same instants, same colours), inside
    // the first, so every panel keeps the same plot width.
    panel.legend = k == 0 ? LegendPlace::kInside : LegendPlace::kNone;
    figure.panels.push_back(std::move(panel));
  }
  section.blocks.push_back(FigureBlock{
      std::move(figure), "Element tensions at the instants",
      "Tension of every element of each driving cable (/cables/<k>/tension) at the instants of "
      "the summary (colours in the legend of cable 1). Element 1 runs from the input point to "
      "the ground-disk hole, element e ends at hole e. Without friction the tension is the same "
      "all along a cable; friction at the holes makes it change from element to element.",
      ""});
  return section;
}

Section DiagnosticsSection(const RunFile& run, const std::vector<Instant>& instants) {
  Section section{"diagnostics", "Constraint violation and energy", {}};
  const std::vector<double>& time = run.time.values;
  Figure figure;
  figure.name = "diagnostics";
  figure.columns = 2;
  figure.panel_width_px = 620;
  figure.panel_height_px = 260;
  Panel violation;
  violation.title = "Constraint violation ‖Φ‖";
  violation.x = internal::TimeAxis();
  violation.y = Axis{"‖Φ‖", "mixed"};
  violation.y.log_scale = true;
  violation.legend = LegendPlace::kNone;
  violation.series.push_back(
      Series{"‖Φ‖", time, run.constraint_violation.values, palette::kNeutral});
  figure.panels.push_back(std::move(violation));
  // Each energy on its own axis: the elastic energy of the pre-tensioned
  // cables dwarfs the kinetic and dissipated ones.
  const char* names[] = {"Kinetic energy", "Elastic energy", "Dissipated energy"};
  for (std::size_t c = 0; c < 3; ++c) {
    Panel energy;
    energy.title = names[c];
    energy.x = internal::TimeAxis();
    energy.y = Axis{"energy", "J"};
    energy.legend = LegendPlace::kNone;
    energy.series.push_back(Series{names[c], time, internal::ColumnOf(run.energy, c),
                                   palette::Indexed(static_cast<int>(c) + 1)});
    figure.panels.push_back(std::move(energy));
  }
  section.blocks.push_back(FigureBlock{
      std::move(figure), "Against time",
      "Norm of the joint constraints Φ (/diagnostics/constraint_violation; positions in m and "
      "quaternion norms mixed), log scale, zeros left out; and the kinetic, elastic and "
      "dissipated energy (/diagnostics/energy), each on its own scale.",
      ""});
  Table table;
  table.id = "energy_at_instants";
  table.title = "Energy and constraint violation at the instants";
  table.caption = "From /diagnostics/energy and /diagnostics/constraint_violation.";
  table.columns = {{"instant", "instant", "", NumberFormat::Integer()},
                   {"time_s", "time", "s", NumberFormat::Fixed(3)},
                   {"kinetic_j", "kinetic", "J", NumberFormat::Significant(4)},
                   {"elastic_j", "elastic", "J", NumberFormat::Significant(5)},
                   {"dissipated_j", "dissipated", "J", NumberFormat::Significant(4)},
                   {"constraint_violation", "‖Φ‖", "mixed", NumberFormat::Significant(3)}};
  for (const Instant& instant : instants) {
    table.AddRow({Cell::Text(instant.label), Cell::Number(instant.time_s),
                  Cell::Number(run.energy.at(instant.frame, 0)),
                  Cell::Number(run.energy.at(instant.frame, 1)),
                  Cell::Number(run.energy.at(instant.frame, 2)),
                  Cell::Number(run.constraint_violation.at(instant.frame))});
  }
  section.blocks.push_back(std::move(table));
  return section;
}

}  // namespace

Document BuildRunDocument(const RunFile& run, const std::string& source,
                          const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  datasets::ValidateRunFile(run, source);
  const std::vector<double>& time = run.time.values;
  const bool protocol_case = internal::CaseNumber(run.case_name) != 0;
  // A run that recorded its protocol can be planned again whatever its case.
  const bool plannable = protocol_case || !run.protocol_yaml.empty();
  const ArmFacts facts = internal::ReadArmFacts(
      run.config_yaml, source + ": attribute 'config_yaml'", run.joint_angles.shape[1],
      run.input_tension.shape[1], plannable ? &time : nullptr, run.protocol_yaml);
  const Words words = WordsFor(run, facts);
  const std::vector<Instant> instants = ChooseInstants(time, facts, protocol_case, options);

  Document document;
  document.kind = "run";
  // The paper's case by its name; any other run by its case and its arm.
  document.title = words.paper ? "Simulation run — paper case " + run.case_name
                               : "Simulation run — " + words.case_words +
                                     (facts.arm_words.empty() ? "" : ", " + facts.arm_words);
  document.source = source;
  document.ccsrm_version = kVersion;
  document.sections.push_back(SummarySection(run, source, facts, words, instants));
  document.sections.push_back(JointAngleSection(run, facts, words, instants));
  document.sections.push_back(InputSection(run, facts, words, instants));
  document.sections.push_back(SlackSection(run, facts));
  document.sections.push_back(StickSlipSection(run, facts, instants));
  document.sections.push_back(CableTensionSection(run, instants));
  document.sections.push_back(DiagnosticsSection(run, instants));
  return document;
}

}  // namespace ccsrm::reports
