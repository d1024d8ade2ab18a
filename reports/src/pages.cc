#include "pages.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include "ccsrm/common/error.h"

namespace ccsrm::reports::internal {

std::size_t NearestFrame(const std::vector<double>& time, double t) {
  CCSRM_CHECK(!time.empty());
  const auto after = std::lower_bound(time.begin(), time.end(), t);
  if (after == time.begin()) return 0;
  if (after == time.end()) return time.size() - 1;
  const std::size_t i = static_cast<std::size_t>(after - time.begin());
  return (time[i] - t) < (t - time[i - 1]) ? i : i - 1;
}

std::vector<double> ColumnOf(const datasets::Array& array, std::size_t k, double scale) {
  std::vector<double> out(array.rows());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = array.at(i, k) * scale;
  return out;
}

std::vector<double> ComponentOf(const datasets::Array& array, std::size_t k, std::size_t c,
                                double scale) {
  std::vector<double> out(array.rows());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = array.at(i, k, c) * scale;
  return out;
}

Axis TimeAxis() { return Axis{"time", "s"}; }

std::string FormatSeconds(double t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", t);
  return text;
}

Figure JointAngleFigure(const std::string& name, const std::vector<double>& time,
                        const datasets::Array& angles, int component,
                        const std::vector<JointGroup>& segments,
                        const std::optional<datasets::Array>& plan) {
  Figure figure;
  figure.name = name;
  figure.panel_width_px = 1100;  // the whole width of the page: time detail matters
  const std::size_t c = static_cast<std::size_t>(component);
  for (const JointGroup& group : segments) {
    Panel panel;
    panel.title = group.title;
    panel.x = TimeAxis();
    panel.y = Axis{component == 0 ? "θx" : "θy", "deg"};
    for (int k = 1; k <= group.joints; ++k) {
      const std::size_t j = static_cast<std::size_t>(group.first_joint + k - 2);
      Series s;
      s.label = "joint " + std::to_string(j + 1);
      s.x = time;
      s.y = ComponentOf(angles, j, c, kDegPerRad);
      s.color = palette::Indexed(k);
      panel.series.push_back(std::move(s));
    }
    if (plan) {
      // The paper's protocol plans the same angle for every joint: then one
      // dashed line says it; otherwise one per joint.
      const std::size_t j0 = static_cast<std::size_t>(group.first_joint - 1);
      bool same = true;
      for (std::size_t i = 0; i < plan->rows() && same; ++i) {
        for (int k = 1; k < group.joints; ++k) {
          if (std::abs(plan->at(i, j0 + k, c) - plan->at(i, j0, c)) > 1e-12) same = false;
        }
      }
      for (int k = 0; k < (same ? 1 : group.joints); ++k) {
        Series s;
        s.label = k == 0 ? "plan" : "";
        s.x = time;
        s.y = ComponentOf(*plan, j0 + k, c, kDegPerRad);
        s.color = palette::kPlan;
        s.style = SeriesStyle::kDashed;
        s.line_width = 1.2;
        panel.series.push_back(std::move(s));
      }
    }
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

Figure CableFigure(const std::string& name, const std::vector<double>& time,
                   const datasets::Array& values, double scale, const Axis& y,
                   const std::vector<JointGroup>& segments, const std::vector<int>& cable_segment,
                   SeriesStyle style) {
  Figure figure;
  figure.name = name;
  // Two segments side by side (the page is wide enough), their legends
  // below so the plots keep their width; else stacked.
  const bool side_by_side = segments.size() == 2;
  if (side_by_side) {
    figure.columns = 2;
    figure.panel_width_px = 640;
    figure.panel_height_px = 320;
  } else {
    figure.panel_width_px = 1100;
  }
  for (std::size_t g = 0; g < segments.size(); ++g) {
    Panel panel;
    panel.title =
        segments.size() == 1 ? "Driving cables" : "Cables driving segment " + std::to_string(g + 1);
    panel.x = TimeAxis();
    panel.y = y;
    for (std::size_t k = 0; k < cable_segment.size(); ++k) {
      if (cable_segment[k] != static_cast<int>(g)) continue;
      Series s;
      s.label = "cable " + std::to_string(k + 1);
      s.x = time;
      s.y = ColumnOf(values, k, scale);
      s.color = palette::Indexed(static_cast<int>(k) + 1);
      s.style = style;
      panel.series.push_back(std::move(s));
    }
    if (side_by_side) panel.legend = LegendPlace::kBelow;
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

Table KeyValueTable(const std::string& id, const std::string& title, const std::string& caption) {
  Table table;
  table.id = id;
  table.title = title;
  table.caption = caption;
  table.columns = {{"quantity", "quantity", "", NumberFormat::Significant(4)},
                   {"value", "value", "", NumberFormat::Significant(4)},
                   {"unit", "unit", "", NumberFormat::Significant(4)}};
  return table;
}

void AddValue(Table* table, const std::string& quantity, double value, const std::string& unit,
              NumberFormat format) {
  table->AddRow({Cell::Text(quantity), Cell::Number(value, format), Cell::Text(unit)});
}

void AddText(Table* table, const std::string& quantity, const std::string& text) {
  table->AddRow({Cell::Text(quantity), Cell::Text(text), Cell::Text("")});
}

std::string Show(double value, NumberFormat format) {
  return FormatCell(Cell::Number(value, format), Column{});
}

std::string Plural(double n, const std::string& noun) {
  return Show(n, NumberFormat::Integer()) + " " + noun + (n == 1.0 ? "" : "s");
}

std::vector<Column> RecordingColumns(const std::string& noun) {
  const NumberFormat text = NumberFormat::Fixed(4);  // the format of a text column is not used
  return {{noun, noun, "", text},
          {"file", "file", "", text},
          {"angles", "measured angles", "", text},
          {"noise_source", "noise from", "", text}};
}

std::vector<Cell> RecordingCells(const std::string& noun, const std::string& name,
                                 const std::string& path, bool angles_from_pipeline,
                                 const std::string& noise_source) {
  return {Cell::Text(name), Cell::Text(path),
          Cell::Text(angles_from_pipeline ? "from the mocap pipeline" : "stored in the " + noun),
          Cell::Text(noise_source)};
}

std::string ListNames(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  }
  return out;
}

std::string UnitSuffix(const std::string& units) {
  return units.empty() || units == "1" ? "" : " " + units;
}

const char* AxisName(int c) { return c == 0 ? "θx" : "θy"; }

std::string Key(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out.empty() ? "x" : out;
}

std::string FigureStem(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
  return out;
}

Figure MeasuredAgainstSimulatedFigure(const std::string& name, const std::vector<double>& time,
                                      const datasets::Array& measured,
                                      const datasets::Array& simulated, int c,
                                      const std::vector<JointGroup>& segments,
                                      const std::string& simulated_word) {
  Figure figure;
  figure.name = name;
  figure.panel_width_px = 1100;
  figure.panel_height_px = 300;
  const std::size_t axis = static_cast<std::size_t>(c);
  for (const JointGroup& group : segments) {
    Panel panel;
    panel.title = group.title + ": solid " + simulated_word + ", dashed measured";
    panel.x = TimeAxis();
    panel.y = Axis{AxisName(c), "deg"};
    for (int k = 1; k <= group.joints; ++k) {
      const std::size_t j = static_cast<std::size_t>(group.first_joint + k - 2);
      Series m{"", time, ComponentOf(measured, j, axis), palette::Indexed(k), SeriesStyle::kDashed};
      m.line_width = 1.2;
      panel.series.push_back(std::move(m));
    }
    for (int k = 1; k <= group.joints; ++k) {
      const std::size_t j = static_cast<std::size_t>(group.first_joint + k - 2);
      panel.series.push_back(Series{"joint " + std::to_string(j + 1), time,
                                    ComponentOf(simulated, j, axis), palette::Indexed(k)});
    }
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

Figure TrackedPointsFigure(const std::string& name, const std::vector<double>& time,
                           const std::vector<std::string>& points, const datasets::Array& measured,
                           const datasets::Array& simulated, const std::string& simulated_word) {
  Figure figure;
  figure.name = name;
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 360;
  const auto add = [&](Panel* panel, std::size_t p, const std::vector<double>& x_measured,
                       const std::vector<double>& y_measured,
                       const std::vector<double>& x_simulated,
                       const std::vector<double>& y_simulated) {
    const int k = static_cast<int>(p) + 1;
    Series m{"", x_measured, y_measured, palette::Indexed(k), SeriesStyle::kDashed};
    m.line_width = 1.0;
    panel->series.push_back(std::move(m));
    panel->series.push_back(
        Series{points[p] + " " + simulated_word, x_simulated, y_simulated, palette::Indexed(k)});
  };
  Panel top;
  top.title = "seen from above: solid " + simulated_word + ", dashed measured";
  top.x = Axis{"x", "mm"};
  top.y = Axis{"y", "mm"};
  for (std::size_t p = 0; p < points.size(); ++p) {
    add(&top, p, ComponentOf(measured, p, 0), ComponentOf(measured, p, 1),
        ComponentOf(simulated, p, 0), ComponentOf(simulated, p, 1));
  }
  figure.panels.push_back(std::move(top));
  for (std::size_t c = 0; c < 3; ++c) {
    Panel panel;
    const std::string axis(1, static_cast<char>('x' + c));
    panel.title = axis + " against time";
    panel.x = TimeAxis();
    panel.y = Axis{axis, "mm"};
    for (std::size_t p = 0; p < points.size(); ++p) {
      add(&panel, p, time, ComponentOf(measured, p, c), time, ComponentOf(simulated, p, c));
    }
    figure.panels.push_back(std::move(panel));
  }
  return figure;
}

std::vector<Figure> TrackedPointsByPatternFigures(const std::string& name,
                                                  const std::vector<std::string>& labels,
                                                  const std::vector<std::string>& points,
                                                  const datasets::Array& measured,
                                                  const datasets::Array& simulated) {
  // The frames of each pattern, in the order the patterns first appear.
  std::vector<std::string> patterns;
  std::map<std::string, std::vector<std::size_t>> frames;
  for (std::size_t f = 0; f < labels.size(); ++f) {
    if (frames.count(labels[f]) == 0) patterns.push_back(labels[f]);
    frames[labels[f]].push_back(f);
  }
  std::vector<Figure> figures;
  for (std::size_t k = 0; k < patterns.size(); ++k) {
    if (k % kPatternPanels == 0) {
      Figure figure;
      figure.name = name + "_" + std::to_string(figures.size() + 1);
      figure.columns = 4;
      figure.panel_width_px = 380;
      figure.panel_height_px = 280;
      figures.push_back(std::move(figure));
    }
    Panel panel;
    panel.x = Axis{"x", "mm"};
    panel.y = Axis{"y", "mm"};
    panel.legend = LegendPlace::kNone;
    double squared = 0.0;
    std::size_t counted = 0;
    for (std::size_t p = 0; p < points.size(); ++p) {
      std::vector<double> xm, ym, xs, ys;
      for (std::size_t f : frames[patterns[k]]) {
        xm.push_back(measured.at(f, p, 0));
        ym.push_back(measured.at(f, p, 1));
        xs.push_back(simulated.at(f, p, 0));
        ys.push_back(simulated.at(f, p, 1));
        double d2 = 0.0;
        for (std::size_t a = 0; a < 3; ++a) {
          const double d = simulated.at(f, p, a) - measured.at(f, p, a);
          d2 += d * d;
        }
        if (std::isfinite(d2)) {
          squared += d2;
          ++counted;
        }
      }
      // A pattern of one or two poses (a hold) as markers: a line of one
      // point draws nothing.
      const bool few = xm.size() < 3;
      const std::string color = palette::Indexed(static_cast<int>(p) + 1);
      Series m{"", std::move(xm), std::move(ym), color,
               few ? SeriesStyle::kPoints : SeriesStyle::kDashed};
      m.line_width = 1.0;
      m.point_size = 1.5;
      panel.series.push_back(std::move(m));
      Series f{"", std::move(xs), std::move(ys), color,
               few ? SeriesStyle::kLinePoints : SeriesStyle::kLine};
      f.point_size = 1.5;
      panel.series.push_back(std::move(f));
    }
    char rms[48];
    std::snprintf(rms, sizeof(rms), " (%.1f mm)",
                  counted > 0 ? std::sqrt(squared / static_cast<double>(counted)) : NAN);
    panel.title = patterns[k] + rms;
    figures.back().panels.push_back(std::move(panel));
  }
  return figures;
}

void AddPatternFigures(std::vector<Figure> figures, const std::string& simulated_word,
                       Section* section) {
  for (std::size_t k = 0; k < figures.size(); ++k) {
    const std::string part = figures.size() > 1 ? " (" + std::to_string(k + 1) + " of " +
                                                      std::to_string(figures.size()) + ")"
                                                : "";
    section->blocks.push_back(FigureBlock{
        std::move(figures[k]), "Tracked points by input pattern" + part,
        "Each pattern's frames (the recording's input labels) seen from above, titled with the "
        "pattern's RMS error. Dashed: measured; solid: " +
            simulated_word + " (a pattern of one or two poses: markers measured, markers " +
            "joined by a line " + simulated_word + ").",
        ""});
  }
}

Figure ResidualsFigure(const std::string& name, const std::vector<double>& time,
                       const datasets::Array& residual, const std::vector<JointGroup>& segments) {
  Figure figure;
  figure.name = name;
  figure.columns = 2;
  figure.panel_width_px = 640;
  figure.panel_height_px = 300;
  for (const JointGroup& group : segments) {
    for (int c = 0; c < 2; ++c) {
      Panel panel;
      panel.title = group.title + ": " + AxisName(c);
      panel.x = TimeAxis();
      panel.y = Axis{std::string("residual ") + AxisName(c), "deg"};
      for (int k = 1; k <= group.joints; ++k) {
        const std::size_t j = static_cast<std::size_t>(group.first_joint + k - 2);
        Series s{"joint " + std::to_string(j + 1), time,
                 ComponentOf(residual, j, static_cast<std::size_t>(c)), palette::Indexed(k)};
        s.line_width = 1.2;
        panel.series.push_back(std::move(s));
      }
      figure.panels.push_back(std::move(panel));
    }
  }
  return figure;
}

}  // namespace ccsrm::reports::internal
