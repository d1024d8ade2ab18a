#pragma once
// Building blocks shared by the run and experiment pages, so that the same
// quantity is drawn and tabulated the same way on every page.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "arm_facts.h"
#include "ccsrm/datasets/array.h"
#include "ccsrm/reports/document.h"
#include "ccsrm/reports/figure.h"

namespace ccsrm::reports::internal {

inline constexpr double kDegPerRad = 57.29577951308232;  // 180 / π

// A moment of a run at which values are tabulated.
struct Instant {
  std::string label;    // e.g. "end of ramp"
  double time_s = 0.0;  // time of the frame shown, s
  std::size_t frame = 0;
};

// The frame whose time is nearest to t (time strictly increasing, not empty).
std::size_t NearestFrame(const std::vector<double>& time, double t);

// Column k of a T × N array, times `scale`.
std::vector<double> ColumnOf(const datasets::Array& array, std::size_t k, double scale = 1.0);
// Component c of item k of a T × N × 2 (or × 3, ...) array, times `scale`.
std::vector<double> ComponentOf(const datasets::Array& array, std::size_t k, std::size_t c,
                                double scale = 1.0);

// Joint angles in degrees against time, one panel per segment, joints as
// coloured lines (joint k of a segment in palette::Indexed(k)), the plan
// (when given, T × J × 2 rad on the same time base) as dashed black lines:
// the layout of the paper's Figs. 16 and 18–21. `component` 0 = θx, 1 = θy.
Figure JointAngleFigure(const std::string& name, const std::vector<double>& time,
                        const datasets::Array& angles, int component,
                        const std::vector<JointGroup>& segments,
                        const std::optional<datasets::Array>& plan);

// Measured against simulated joint angles (fit and prediction pages): one
// panel per segment, joint k of a segment in palette::Indexed(k), its
// measured angle as a thin dashed line and its simulated angle solid on top.
// `measured` and `simulated` are T × J × 2 [deg] on `time`; `simulated_word`
// names the simulated angles in the panel titles ("fitted", "predicted").
Figure MeasuredAgainstSimulatedFigure(const std::string& name, const std::vector<double>& time,
                                      const datasets::Array& measured,
                                      const datasets::Array& simulated, int component,
                                      const std::vector<JointGroup>& segments,
                                      const std::string& simulated_word);

// Tracked points measured against simulated (fit and prediction pages of a
// recording of tracked points): the points' paths seen from above (x
// against y, in the frame they were recorded in), then x, y and z against
// time; point k in palette::Indexed(k), measured dashed, simulated solid.
// `measured` and `simulated` are T × P × 3 [mm] on `time`.
Figure TrackedPointsFigure(const std::string& name, const std::vector<double>& time,
                           const std::vector<std::string>& points, const datasets::Array& measured,
                           const datasets::Array& simulated, const std::string& simulated_word);

// The same paths seen from above, one small panel per input pattern (the
// frames of each label of `labels`, in the order the labels first appear;
// a label that recurs later is the same pattern), titled with the label
// and its RMS error (the points' Euclidean distance, simulated against
// measured [mm]); at most kPatternPanels panels a figure, so a recording of
// many patterns gives several figures, `name`_1, `name`_2, ...
inline constexpr std::size_t kPatternPanels = 24;
std::vector<Figure> TrackedPointsByPatternFigures(const std::string& name,
                                                  const std::vector<std::string>& labels,
                                                  const std::vector<std::string>& points,
                                                  const datasets::Array& measured,
                                                  const datasets::Array& simulated);

// Appends TrackedPointsByPatternFigures' figures to `section` with their
// titles and caption (`simulated_word`: "fitted", "predicted").
void AddPatternFigures(std::vector<Figure> figures, const std::string& simulated_word,
                       Section* section);

// Residuals (simulated − measured, T × J × 2 [deg]) per segment, θx left
// and θy right.
Figure ResidualsFigure(const std::string& name, const std::vector<double>& time,
                       const datasets::Array& residual, const std::vector<JointGroup>& segments);

// One panel per segment of per-cable values against time (cable k in
// palette::Indexed(k)); `values` is T × C.
Figure CableFigure(const std::string& name, const std::vector<double>& time,
                   const datasets::Array& values, double scale, const Axis& y,
                   const std::vector<JointGroup>& segments, const std::vector<int>& cable_segment,
                   SeriesStyle style);

// The time axis every page uses.
Axis TimeAxis();

// "1–6" style joint lists and small text helpers.
std::string FormatSeconds(double t);

// A key-value table (quantity, value, unit), the shape of every summary
// table: one row per quantity, each with its own number format.
Table KeyValueTable(const std::string& id, const std::string& title, const std::string& caption);
void AddValue(Table* table, const std::string& quantity, double value, const std::string& unit,
              NumberFormat format);
void AddText(Table* table, const std::string& quantity, const std::string& text);

// Text helpers of the fit and loop pages, so a sentence quotes a number as
// its table shows it.
// The text `value` shows as in a table cell of that format.
std::string Show(double value, NumberFormat format);
// "3 iterations", "1 thread".
std::string Plural(double n, const std::string& noun);
// The columns a page's table of recordings begins with: what was fitted or
// predicted (`noun`: "experiment", "recording"), its file, where its
// measured angles came from and how the noise weighting its residuals was
// found; and a row's cells for them.
std::vector<Column> RecordingColumns(const std::string& noun);
std::vector<Cell> RecordingCells(const std::string& noun, const std::string& name,
                                 const std::string& path, bool angles_from_pipeline,
                                 const std::string& noise_source);

// "a", "a and b", "a, b and c".
std::string ListNames(const std::vector<std::string>& names);
// " N" after a value, or nothing for a pure number (units "" or "1").
std::string UnitSuffix(const std::string& units);
// "θx" (c = 0) or "θy".
const char* AxisName(int c);
// "T_p" -> "t_p", "friction.mu_v" -> "friction_mu_v": a JSON column key.
std::string Key(const std::string& text);
// A file stem for a figure: letters, digits, '_' and '-' ("g5 slow" -> "g5_slow").
std::string FigureStem(const std::string& name);

}  // namespace ccsrm::reports::internal
