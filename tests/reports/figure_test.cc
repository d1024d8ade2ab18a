// The plotting layer: what a figure must say (units), what it writes, and
// how gnuplot's absence or failure is reported.
#include "ccsrm/reports/figure.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "ccsrm/common/atomic_file.h"
#include "report_test_util.h"
#include "run_ccsrm.h"

namespace ccsrm::reports {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path FreshDir(const std::string& name) {
  return ccsrm::testing::ScratchDirectory("reports_" + name);
}

Figure TwoPanels() {
  Figure figure;
  figure.name = "two_panels";
  Panel a;
  a.title = "Segment 1";
  a.x = Axis{"time", "s"};
  a.y = Axis{"θx", "deg"};
  a.series.push_back(Series{"joint 1", {0, 1, 2, 3}, {0, 1, NAN, 3}, palette::Indexed(1)});
  a.series.push_back(
      Series{"plan", {0, 1, 2, 3}, {0, 1, 2, 3}, palette::kPlan, SeriesStyle::kDashed});
  Panel b;
  b.title = "Violation";
  b.x = Axis{"time", "s"};
  b.y = Axis{"‖Φ‖", "mixed"};
  b.y.log_scale = true;
  b.series.push_back(Series{"‖Φ‖", {0, 1, 2}, {0.0, 1e-9, 1e-8}, palette::kNeutral});
  figure.panels = {a, b};
  return figure;
}

TEST(Figure, EveryAxisNeedsALabelAndAUnit) {
  Figure figure = TwoPanels();
  std::string why;
  EXPECT_TRUE(figure.IsValid(&why)) << why;
  figure.panels[0].y.unit = "";
  EXPECT_FALSE(figure.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("label and a unit"));
  EXPECT_EQ((Axis{"stuck hole nodes", "1"}.Title()), "stuck hole nodes");
  EXPECT_EQ((Axis{"θx", "deg"}.Title()), "θx [deg]");
}

TEST(Figure, RejectsBadNamesColoursAndLengths) {
  std::string why;
  Figure figure = TwoPanels();
  figure.name = "../escape";
  EXPECT_FALSE(figure.IsValid(&why));
  figure = TwoPanels();
  figure.panels[0].series[0].color = "red";
  EXPECT_FALSE(figure.IsValid(&why));
  figure = TwoPanels();
  figure.panels[0].series[0].y.pop_back();
  EXPECT_FALSE(figure.IsValid(&why));
  figure = TwoPanels();
  figure.panels.clear();
  EXPECT_FALSE(figure.IsValid(&why));
}

TEST(Figure, MissingGnuplotIsSaidClearly) {
  PlotOptions options;
  options.gnuplot = "ccsrm-no-such-gnuplot";
  try {
    FindGnuplot(options);
    FAIL() << "no error";
  } catch (const PlotError& e) {
    EXPECT_THAT(e.what(), HasSubstr("gnuplot not found"));
    EXPECT_THAT(e.what(), HasSubstr("gnuplot-nox"));
  }
  options.gnuplot = "/nonexistent/gnuplot";
  EXPECT_THROW(FindGnuplot(options), PlotError);
}

TEST(Figure, GnuplotFailureNamesTheFigure) {
  const fs::path dir = FreshDir("failure");
  PlotOptions options;
  options.gnuplot = "/bin/false";
  try {
    RenderFigure(TwoPanels(), dir.string(), options);
    FAIL() << "no error";
  } catch (const PlotError& e) {
    EXPECT_THAT(e.what(), HasSubstr("figure 'two_panels'"));
    EXPECT_THAT(e.what(), HasSubstr("exited with status 1"));
  }
}

TEST(Figure, WritesDataScriptAndImage) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = FreshDir("render");
  for (ImageFormat format : {ImageFormat::kPng, ImageFormat::kSvg}) {
    PlotOptions options;
    options.format = format;
    const std::string image = RenderFigure(TwoPanels(), dir.string(), options);
    EXPECT_EQ(image, std::string("two_panels.") + ImageFormatExtension(format));
    EXPECT_GT(fs::file_size(dir / image), 1000u);
  }
  const std::string data = ReadTextFile((dir / "two_panels.dat").string());
  // The NaN breaks joint 1's line (one blank line), blocks are separated by
  // two, and the log axis leaves the zero out.
  EXPECT_THAT(data, HasSubstr("1 1\n\n3 3\n"));
  EXPECT_THAT(data, ::testing::Not(HasSubstr("0 0\n1 1e-09")));
  EXPECT_THAT(data, HasSubstr("1 1e-09\n2 1e-08\n"));
  const std::string script = ReadTextFile((dir / "two_panels.gp").string());
  EXPECT_THAT(script, HasSubstr("set ylabel \"θx [deg]\""));
  EXPECT_THAT(script, HasSubstr("set xlabel \"time [s]\""));
  EXPECT_THAT(script, HasSubstr("'two_panels.dat' index 0"));
  EXPECT_THAT(script, HasSubstr("title \"joint 1\""));
}

TEST(Figure, APanelWithNothingToDrawStillRenders) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = FreshDir("empty");
  Figure figure = TwoPanels();
  figure.name = "empty";
  figure.panels[0].series[0].y.assign(4, NAN);
  figure.panels[0].series[1].y.assign(4, NAN);
  figure.panels[1].series[0].y.assign(3, 0.0);  // nothing positive on a log axis
  EXPECT_EQ(RenderFigure(figure, dir.string(), PlotOptions()), "empty.png");
}

TEST(Figure, BarsRangesAndLabelledTicsRender) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = FreshDir("bars");
  Figure figure;
  figure.name = "bars";
  Panel bars;
  bars.x = Axis{"marker", "1"};
  bars.x.tics = {{1, "L01_A"}, {2, "L01_B"}};
  bars.x.rotate_tics = true;
  bars.y = Axis{"seen", "%"};
  bars.series.push_back(Series{"", {1, 2}, {100, 87.5}, palette::kNeutral, SeriesStyle::kBars});
  Panel ranges;
  ranges.x = Axis{"time", "s"};
  ranges.y = Axis{"marker", "1"};
  ranges.series.push_back(
      Series{"not seen", {0.1, 0.3, 0.5, 0.55}, {1, 2}, palette::kWarning, SeriesStyle::kRanges});
  figure.panels = {bars, ranges};
  EXPECT_EQ(RenderFigure(figure, dir.string(), PlotOptions()), "bars.png");
  EXPECT_THAT(ReadTextFile((dir / "bars.gp").string()), HasSubstr("\"L01_A\" 1"));
}

// A 2 × 2 heat map with one cell without a value (a correlation that does
// not exist).
Figure HeatMap() {
  Figure figure;
  figure.name = "heat";
  Panel panel;
  panel.x = Axis{"parameter", "1"};
  panel.y = Axis{"parameter", "1"};
  Axis color{"correlation", "1"};
  color.min = -1.0;
  color.max = 1.0;
  panel.color = color;
  Series cells;
  cells.style = SeriesStyle::kCells;
  cells.x = {1, 2, 1, 2};
  cells.y = {2, 2, 1, 1};
  cells.z = {1.0, -0.625, -0.625, NAN};
  panel.series.push_back(cells);
  figure.panels = {panel};
  return figure;
}

TEST(Figure, CellsNeedAValueEachAndAColourScale) {
  std::string why;
  Figure figure = HeatMap();
  EXPECT_TRUE(figure.IsValid(&why)) << why;
  figure.panels[0].series[0].z.pop_back();
  EXPECT_FALSE(figure.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("needs a z per cell"));
  figure = HeatMap();
  figure.panels[0].color->max = -1.0;
  EXPECT_FALSE(figure.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("colour scale with min < max"));
  figure = HeatMap();
  figure.panels[0].color->unit = "";
  EXPECT_FALSE(figure.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("label and a unit"));
}

TEST(Figure, HeatMapRendersEveryCellWithItsValue) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = FreshDir("heat");
  EXPECT_EQ(RenderFigure(HeatMap(), dir.string(), PlotOptions()), "heat.png");
  // A cell without a value keeps its place (z 0, flagged 0) so gnuplot
  // draws it grey instead of skipping it.
  EXPECT_THAT(ReadTextFile((dir / "heat.dat").string()),
              HasSubstr("1 2 1 1\n2 2 -0.625 1\n1 1 -0.625 1\n2 1 0 0\n"));
  const std::string script = ReadTextFile((dir / "heat.gp").string());
  EXPECT_THAT(script, HasSubstr("set cbrange [-1:1]"));
  EXPECT_THAT(script, HasSubstr("set cblabel \"correlation\""));
  EXPECT_THAT(script, HasSubstr("fc palette"));
  EXPECT_THAT(script, HasSubstr("sprintf(\"%.2f\", $3)"));
}

}  // namespace
}  // namespace ccsrm::reports
