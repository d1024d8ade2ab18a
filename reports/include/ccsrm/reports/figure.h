#pragma once
// The plotting layer of the reports: a figure is described as data (panels,
// series, axes with units, legend, colours) and drawn by gnuplot. Every page
// goes through RenderFigure, so axes, fonts, legends and colours look the
// same everywhere and no page writes gnuplot commands of its own.
//
// RenderFigure writes three files into a folder: <name>.dat (the data, one
// gnuplot block per series), <name>.gp (the script, which reads the .dat by
// its relative name so it can be re-run with `gnuplot <name>.gp` to restyle
// a figure) and the image <name>.png or <name>.svg.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ccsrm::reports {

enum class ImageFormat { kPng, kSvg };

// "png" / "svg", the image file's extension.
const char* ImageFormatExtension(ImageFormat format);

enum class SeriesStyle {
  kLine,    // solid line; NaN values break it
  kDashed,  // dashed line (planned or reference motion)
  kSteps,   // staircase (counts that change in jumps)
  kPoints,  // markers only
  kLinePoints,
  kBars,    // vertical bars from 0 (per-marker or per-body figures)
  kRanges,  // horizontal bars 0.6 high: x holds start, end pairs (x0, x1, x0, x1,
            // ...) and y one value per bar (timelines of gaps)
  kCells,   // a heat map: unit squares centred at (x, y), filled with the colour
            // of z on the panel's colour scale (Panel::color) and labelled with
            // z to Series::cell_decimals; a non-finite z is a light grey
            // square labelled "–" (a correlation that does not exist)
};

struct Series {
  Series() = default;
  Series(std::string label_in, std::vector<double> x_in, std::vector<double> y_in,
         std::string color_in, SeriesStyle style_in = SeriesStyle::kLine)
      : label(std::move(label_in)),
        x(std::move(x_in)),
        y(std::move(y_in)),
        color(std::move(color_in)),
        style(style_in) {}

  std::string label;  // legend entry; empty: not in the legend
  std::vector<double> x;
  std::vector<double> y;          // same length as x (kRanges: half of it)
  std::string color = "#000000";  // "#rrggbb"
  SeriesStyle style = SeriesStyle::kLine;
  double line_width = 1.5;  // in gnuplot's line-width units
  double bar_width = 0.8;   // kBars: width in x units (categories sit 1 apart)
  double point_size = 0.6;  // kPoints: marker size in gnuplot's units
  std::vector<double> z;    // kCells: the value of each cell (same length as x)
  int cell_decimals = 2;    // kCells: decimals of the cell labels
};

struct Axis {
  Axis() = default;
  Axis(std::string label_in, std::string unit_in)
      : label(std::move(label_in)), unit(std::move(unit_in)) {}

  std::string label;  // what is plotted, e.g. "θx"
  // Unit shown in brackets after the label, e.g. "deg", "N", "s"; "1" for a
  // pure number or a count (then no brackets are shown). Required: every
  // axis says what it measures.
  std::string unit;
  std::optional<double> min;  // unset: gnuplot's automatic range
  std::optional<double> max;
  bool log_scale = false;  // values <= 0 are left out on a log axis
  // Labelled tics (value, text), e.g. marker names; empty: automatic tics.
  std::vector<std::pair<double, std::string>> tics;
  bool rotate_tics = false;  // tic labels at 90 degrees (long category names)

  // "θx [deg]", or the label alone for unit "1".
  std::string Title() const;
};

// Where the legend goes: right of the panel (a fixed margin, so stacked
// panels keep aligned axes), below it, inside its top-right corner, or none.
enum class LegendPlace { kRight, kBelow, kInside, kNone };

struct Panel {
  std::string title;  // above the panel; may be empty
  Axis x;
  Axis y;
  std::vector<Series> series;
  LegendPlace legend = LegendPlace::kRight;
  // Text in the top-left corner of an empty or special panel (e.g. "no data").
  std::string note;
  // The colour scale of kCells series (label, unit, min and max required),
  // drawn as a colour bar right of the panel: a diverging blue–white–red
  // scale, white at the middle of [min, max]. Unset: no colour bar.
  std::optional<Axis> color;
};

struct Figure {
  // File stem: letters, digits, '_' and '-' only (checked by IsValid).
  std::string name;
  std::vector<Panel> panels;  // at least one
  int columns = 1;            // panels fill rows of this many, left to right
  int panel_width_px = 900;   // per panel, before the legend strip
  int panel_height_px = 280;

  // Checks the name, that there is a panel, that every axis has a unit,
  // that every series' x and y agree in length and its colour is #rrggbb,
  // and that kCells series have a z per cell and a panel colour scale with
  // min < max.
  bool IsValid(std::string* error) const;
};

struct PlotOptions {
  // The gnuplot program: a name looked up on PATH, or a path. Default
  // "gnuplot" (Debian package gnuplot-nox).
  std::string gnuplot = "gnuplot";
  // PNG (pngcairo) by default: a fixed-size image whatever the number of
  // points (an SVG of a 48 s run at 100 Hz with a dozen series weighs
  // megabytes); SVG for figures to print or edit.
  ImageFormat format = ImageFormat::kPng;
  // Scale of the PNG raster: 1.5 draws a 900 px wide panel on 1350 pixels so
  // lines and text stay sharp on high-density screens when the page shows it
  // at 900 CSS pixels.
  double png_scale = 1.5;

  bool IsValid(std::string* error) const;
};

// Thrown when gnuplot cannot be run or fails. Not an InputError: the input
// was fine, the machine lacks (or has a broken) gnuplot.
class PlotError : public std::runtime_error {
 public:
  explicit PlotError(const std::string& message) : std::runtime_error(message) {}
};

// The gnuplot executable PlotOptions::gnuplot names (searched on PATH when
// it has no '/'). Throws PlotError "gnuplot not found ... (install the Debian
// package gnuplot-nox)" when there is none.
std::string FindGnuplot(const PlotOptions& options);

// Writes <name>.dat, <name>.gp and the image into `folder` (which must
// exist) and runs gnuplot there. Returns the image's file name (no folder).
// Requires figure.IsValid() and options.IsValid() (checked, aborts).
// Throws PlotError naming the figure when gnuplot is missing, exits with a
// non-zero status (its first error line is quoted) or writes no image.
std::string RenderFigure(const Figure& figure, const std::string& folder,
                         const PlotOptions& options);

// The colours every page uses, so that one thing keeps one colour.
namespace palette {
// Tableau 10, the default of many plotting tools: distinct, colour-blind
// tolerable, readable on white. Joint k of a segment (k = 1..) and cable k
// get entry (k - 1) % 10.
const std::string& Indexed(int k);
inline const std::string kPlan = "#000000";      // planned motion: black dashed
inline const std::string kMeasured = "#333333";  // measured reference
inline const std::string kNeutral = "#4e79a7";   // single-series bar charts
inline const std::string kWarning = "#d62728";   // gaps, losses
// A fit's values at its start (grey) and fitted (the neutral blue), in every
// before/after figure of a fit page.
inline const std::string kStart = "#a0a0a0";
inline const std::string kFitted = "#4e79a7";
// Instants of a run (end of ramp, mid-hold, ...), in time order: Dark2.
const std::string& Instant(int k);
}  // namespace palette

}  // namespace ccsrm::reports
