#include "ccsrm/reports/figure.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ccsrm/common/error.h"

namespace ccsrm::reports {
namespace {

namespace fs = std::filesystem;

bool IsColor(const std::string& c) {
  if (c.size() != 7 || c[0] != '#') return false;
  for (std::size_t i = 1; i < c.size(); ++i) {
    if (!std::isxdigit(static_cast<unsigned char>(c[i]))) return false;
  }
  return true;
}

bool IsFileStem(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') return false;
  }
  return true;
}

// A string literal for a gnuplot script (double quotes, escapes).
std::string Quote(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

// A point gnuplot can draw: finite, and positive on a log axis.
bool Drawable(double x, double y, const Panel& panel) {
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  if (panel.x.log_scale && x <= 0.0) return false;
  if (panel.y.log_scale && y <= 0.0) return false;
  return true;
}

// Writes one series as a data block (x y [width] per line); a run of
// undrawable points becomes one blank line, which breaks the line there.
// Returns false (and writes nothing) when no point is drawable.
bool WriteBlock(const Series& s, const Panel& panel, std::ostream& out) {
  std::ostringstream block;
  bool any = false;
  if (s.style == SeriesStyle::kCells) {
    // x y z valid: a cell without a value keeps its square (grey) and gets
    // z = 0, valid = 0, so gnuplot never meets a NaN it would skip.
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!Drawable(s.x[i], s.y[i], panel)) continue;
      const bool valid = std::isfinite(s.z[i]);
      block << Number(s.x[i]) << ' ' << Number(s.y[i]) << ' ' << Number(valid ? s.z[i] : 0.0) << ' '
            << (valid ? 1 : 0) << '\n';
      any = true;
    }
  } else if (s.style == SeriesStyle::kRanges) {
    for (std::size_t i = 0; i < s.y.size(); ++i) {
      const double x0 = s.x[2 * i], x1 = s.x[2 * i + 1], y = s.y[i];
      if (!Drawable(x0, y, panel) || !Drawable(x1, y, panel)) continue;
      block << Number(x0) << ' ' << Number(x1) << ' ' << Number(y) << '\n';
      any = true;
    }
  } else {
    bool broken = true;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!Drawable(s.x[i], s.y[i], panel)) {
        if (!broken) block << '\n';
        broken = true;
        continue;
      }
      block << Number(s.x[i]) << ' ' << Number(s.y[i]);
      if (s.style == SeriesStyle::kBars) block << ' ' << Number(s.bar_width);
      block << '\n';
      broken = false;
      any = true;
    }
  }
  if (!any) return false;
  out << "# " << s.label << '\n' << block.str() << "\n\n";
  return true;
}

std::string StyleClause(const Series& s) {
  const std::string color = " lc rgb " + Quote(s.color);
  const std::string width = " lw " + Number(s.line_width);
  switch (s.style) {
    case SeriesStyle::kLine:
      return "with lines" + color + width + " dt 1";
    case SeriesStyle::kRanges:
      return "with boxxyerror" + color + " fs solid 1.0 noborder";
    case SeriesStyle::kDashed:
      return "with lines" + color + width + " dt (8,5)";
    case SeriesStyle::kSteps:
      return "with steps" + color + width;
    case SeriesStyle::kPoints:
      return "with points" + color + " pt 7 ps " + Number(s.point_size);
    case SeriesStyle::kLinePoints:
      return "with linespoints" + color + width + " pt 7 ps 0.7";
    case SeriesStyle::kBars:
      return "with boxes" + color + " fs solid 0.85 noborder";
    case SeriesStyle::kCells:
      break;  // three clauses of their own (CellClauses)
  }
  return "with lines";
}

// A heat map: every cell as a grey square, the cells with a value on top in
// the colour of their value (an undefined x skips the others), then the
// values as text.
std::vector<std::string> CellClauses(const Series& s, const std::string& source) {
  const std::string box = "($1-0.5):($1+0.5):($2-0.5):($2+0.5)";
  const std::string style = " with boxxyerror fs solid 1.0 border lc rgb \"#ffffff\"";
  const std::string label = "sprintf(\"%." + std::to_string(s.cell_decimals) + "f\", $3)";
  return {source + " using 1:2:" + box + style + " lc rgb \"#d9d9d9\" notitle",
          source + " using ($4 > 0 ? $1 : 1/0):2:" + box + ":3" + style + " fc palette" +
              (s.label.empty() ? " notitle" : " title " + Quote(s.label)),
          source + " using 1:2:($4 > 0 ? " + label +
              " : \"–\") with labels tc rgb \"#222222\" notitle"};
}

void WriteAxis(const char* name, const Axis& axis, std::ostream& gp) {
  gp << "set " << name << "label " << Quote(axis.Title()) << '\n';
  gp << "set " << name << "range [" << (axis.min ? Number(*axis.min) : "*") << ':'
     << (axis.max ? Number(*axis.max) : "*") << "]\n";
  if (axis.log_scale) {
    // No minor tics: over ten decades they merge into a solid bar.
    gp << "set logscale " << name << " 10\nset format " << name << " \"%.0e\"\nset m" << name
       << "tics 1\n";
  } else {
    gp << "unset logscale " << name << "\nset format " << name << " \"%g\"\nset m" << name
       << "tics default\n";
  }
  if (axis.tics.empty()) {
    gp << "set " << name << "tics autofreq norotate\n";
  } else {
    gp << "set " << name << "tics (";
    for (std::size_t i = 0; i < axis.tics.size(); ++i) {
      gp << (i ? ", " : "") << Quote(axis.tics[i].second) << ' ' << Number(axis.tics[i].first);
    }
    gp << ")" << (axis.rotate_tics ? " rotate by 90 right" : " norotate") << '\n';
  }
}

// The script and data of a figure.
void WriteScript(const Figure& figure, const PlotOptions& options, const std::string& image,
                 std::ostream& gp, std::ostream& dat) {
  const int rows = (static_cast<int>(figure.panels.size()) + figure.columns - 1) / figure.columns;
  const int width = figure.panel_width_px * figure.columns;
  const int height = figure.panel_height_px * rows;
  gp << "# " << figure.name << ": written by ccsrm report; run `gnuplot " << figure.name
     << ".gp` in this folder to draw it again.\n";
  if (options.format == ImageFormat::kPng) {
    const double s = options.png_scale;
    gp << "set terminal pngcairo size " << std::lround(width * s) << ',' << std::lround(height * s)
       << " enhanced font \"DejaVu Sans,10\" fontscale " << Number(s) << " linewidth " << Number(s)
       << " background \"#ffffff\"\n";
  } else {
    gp << "set terminal svg size " << width << ',' << height
       << " enhanced font \"DejaVu Sans,10\" background \"#ffffff\"\n";
  }
  gp << "set output " << Quote(image) << '\n';
  // Text is shown as written (marker names hold '_', which enhanced text
  // would turn into subscripts).
  gp << "set termoption noenhanced\n";
  gp << "set datafile separator whitespace\n";
  gp << "set grid back lc rgb \"#d9d9d9\" lw 1 dt 1\n";
  gp << "set border 3 lc rgb \"#555555\"\nset tics nomirror out\n";
  gp << "set style fill solid 0.85 noborder\n";
  // An autoscaled x axis ends at the data (a 48 s run ends at 48 s, not 50).
  gp << "set autoscale xfix\n";
  gp << "set lmargin 11\nset tmargin 2.5\n";
  gp << "set multiplot layout " << rows << ',' << figure.columns << '\n';
  int index = 0;
  for (const Panel& panel : figure.panels) {
    gp << "set title " << Quote(panel.title) << '\n';
    // Tic labels written upwards need room below the axis for themselves
    // and the axis title.
    std::size_t longest_tic = 0;
    if (panel.x.rotate_tics) {
      for (const auto& tic : panel.x.tics) longest_tic = std::max(longest_tic, tic.second.size());
    }
    const double legend_below = panel.legend == LegendPlace::kBelow ? 1.8 : 0.0;
    gp << "set bmargin " << Number(3.5 + legend_below + 0.8 * static_cast<double>(longest_tic))
       << '\n';
    WriteAxis("x", panel.x, gp);
    WriteAxis("y", panel.y, gp);
    switch (panel.legend) {
      case LegendPlace::kRight:
        // A fixed right margin holds the legend, so stacked panels keep
        // aligned time axes whatever their legend's width.
        gp << "set rmargin 20\nset key outside right top vertical Left reverse samplen 2.5\n";
        break;
      case LegendPlace::kBelow:
        gp << "set rmargin 4\nset key below horizontal Left reverse samplen 2.5\n";
        break;
      case LegendPlace::kInside:
        gp << "set rmargin 4\nset key inside right top vertical Left reverse samplen 2.5 "
              "opaque box lc rgb \"#cccccc\"\n";
        break;
      case LegendPlace::kNone:
        gp << "set rmargin 4\nunset key\n";
        break;
    }
    // The colour bar sits right of the plot, with its tics and title.
    if (panel.color) gp << "set rmargin 18\n";
    // Autoscaled y ranges get 5 % of air above and below, so a line at its
    // extreme (a cable stuck at all its holes) is not hidden in the border;
    // a legend inside the panel gets a third of the height above the data.
    gp << "set offsets 0, 0, graph " << (panel.legend == LegendPlace::kInside ? "0.35" : "0.05")
       << ", graph 0.05\n";
    if (panel.color) {
      // Blue–white–red (ColorBrewer RdBu, its lighter ends so black cell
      // labels stay readable), white at the middle of the range.
      gp << "set palette defined (0 \"#4393c3\", 1 \"#ffffff\", 2 \"#d6604d\")\n"
         << "set cbrange [" << Number(*panel.color->min) << ':' << Number(*panel.color->max)
         << "]\nset cblabel " << Quote(panel.color->Title()) << "\nset colorbox\n";
    } else {
      gp << "unset colorbox\n";
    }
    gp << "unset label\n";
    if (!panel.note.empty()) {
      gp << "set label 1 " << Quote(panel.note)
         << " at graph 0.02, graph 0.92 left front tc rgb \"#555555\"\n";
    }
    std::vector<std::string> clauses;
    for (const Series& s : panel.series) {
      if (!WriteBlock(s, panel, dat)) continue;
      // Columns: x y [width] per point; x0 x1 y per bar of a range.
      const std::string source = "'" + figure.name + ".dat' index " + std::to_string(index);
      if (s.style == SeriesStyle::kCells) {
        for (std::string& clause : CellClauses(s, source)) clauses.push_back(std::move(clause));
        ++index;
        continue;
      }
      const char* columns = s.style == SeriesStyle::kBars ? "1:2:3"
                            : s.style == SeriesStyle::kRanges
                                ? "(($1+$2)/2):3:1:2:($3-0.3):($3+0.3)"
                                : "1:2";
      clauses.push_back(source + " using " + columns + " " + StyleClause(s) +
                        (s.label.empty() ? " notitle" : " title " + Quote(s.label)));
      ++index;
    }
    if (clauses.empty()) {
      // Nothing drawable: an empty frame with fixed ranges and a note, so the
      // figure keeps its layout and gnuplot has no autoscale to fail on.
      if (!panel.x.min || !panel.x.max) gp << "set xrange [0:1]\n";
      if (!panel.y.min || !panel.y.max) gp << "set yrange [0:1]\n";
      gp << "unset logscale\n";
      if (panel.note.empty()) {
        gp << "set label 1 \"no data to plot\" at graph 0.5, graph 0.5 center tc rgb "
              "\"#555555\"\n";
      }
      gp << "plot NaN notitle\n";
      continue;
    }
    gp << "plot ";
    for (std::size_t i = 0; i < clauses.size(); ++i) {
      gp << (i ? ", \\\n     " : "") << clauses[i];
    }
    gp << '\n';
  }
  gp << "unset multiplot\n";
}

// Runs `program script` in `folder`; returns its exit status (-1 when it did
// not exit normally) and what it printed.
int RunInFolder(const std::string& program, const std::string& script, const std::string& folder,
                std::string* output) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    return -1;
  }
  if (pid == 0) {
    // The program blocks SIGINT and SIGTERM for its interrupt watcher
    // (common/output_policy.h); gnuplot gets them as usual.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    if (::chdir(folder.c_str()) != 0) ::_exit(126);
    ::execl(program.c_str(), program.c_str(), script.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  std::array<char, 4096> buffer;
  ssize_t n;
  while ((n = ::read(pipe_fds[0], buffer.data(), buffer.size())) > 0) {
    output->append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(pipe_fds[0]);
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The first line of gnuplot's output that looks like an error, else the first
// non-empty line.
std::string ErrorLine(const std::string& output) {
  std::istringstream lines(output);
  std::string line, first;
  while (std::getline(lines, line)) {
    if (line.find_first_not_of(" \t^") == std::string::npos) continue;
    if (first.empty()) first = line;
    if (line.find("line ") != std::string::npos && line.find(':') != std::string::npos) {
      return line;
    }
  }
  return first;
}

}  // namespace

const char* ImageFormatExtension(ImageFormat format) {
  return format == ImageFormat::kPng ? "png" : "svg";
}

std::string Axis::Title() const { return unit == "1" ? label : label + " [" + unit + "]"; }

bool Figure::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = "figure '" + name + "': " + why;
    return false;
  };
  if (!IsFileStem(name)) return fail("name must be letters, digits, '_' or '-'");
  if (panels.empty()) return fail("has no panel");
  if (columns < 1) return fail("columns must be >= 1");
  if (panel_width_px < 100 || panel_height_px < 100) return fail("panels must be >= 100 px");
  for (const Panel& panel : panels) {
    for (const Axis* axis : {&panel.x, &panel.y, panel.color ? &*panel.color : &panel.y}) {
      if (axis->label.empty() || axis->unit.empty()) {
        return fail("panel '" + panel.title + "': every axis needs a label and a unit");
      }
    }
    for (const Series& s : panel.series) {
      const bool ranges = s.style == SeriesStyle::kRanges;
      if ((ranges && s.x.size() != 2 * s.y.size()) || (!ranges && s.x.size() != s.y.size())) {
        return fail("series '" + s.label + "': x and y lengths disagree");
      }
      if (!IsColor(s.color)) return fail("series '" + s.label + "': colour must be #rrggbb");
      if (!(s.line_width > 0.0) || !(s.bar_width > 0.0) || !(s.point_size > 0.0)) {
        return fail("series '" + s.label + "': widths must be > 0");
      }
      if (s.style == SeriesStyle::kCells) {
        if (s.z.size() != s.x.size()) return fail("series '" + s.label + "': needs a z per cell");
        if (!panel.color || !panel.color->min || !panel.color->max ||
            !(*panel.color->min < *panel.color->max)) {
          return fail("panel '" + panel.title + "': cells need a colour scale with min < max");
        }
        if (s.cell_decimals < 0 || s.cell_decimals > 6) {
          return fail("series '" + s.label + "': cell_decimals must be in [0, 6]");
        }
      }
    }
  }
  return true;
}

bool PlotOptions::IsValid(std::string* error) const {
  if (gnuplot.empty()) {
    if (error) *error = "gnuplot: empty program name";
    return false;
  }
  if (!(png_scale >= 0.5 && png_scale <= 4.0)) {
    if (error) *error = "png_scale must be in [0.5, 4]";
    return false;
  }
  return true;
}

std::string FindGnuplot(const PlotOptions& options) {
  const std::string& name = options.gnuplot;
  if (name.find('/') != std::string::npos) {
    if (::access(name.c_str(), X_OK) == 0 && !fs::is_directory(name)) return name;
  } else if (const char* path = std::getenv("PATH")) {
    std::istringstream dirs(path);
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
      if (dir.empty()) continue;
      const std::string candidate = dir + "/" + name;
      if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) {
        return candidate;
      }
    }
  }
  throw PlotError("gnuplot not found ('" + name +
                  "' on PATH): reports draw their figures with gnuplot; install the Debian "
                  "package gnuplot-nox");
}

std::string RenderFigure(const Figure& figure, const std::string& folder,
                         const PlotOptions& options) {
  std::string why;
  CCSRM_CHECK(figure.IsValid(&why));
  CCSRM_CHECK(options.IsValid(&why));
  const std::string program = FindGnuplot(options);
  const std::string image = figure.name + "." + ImageFormatExtension(options.format);
  const std::string script = figure.name + ".gp";
  {
    std::ofstream gp(fs::path(folder) / script);
    std::ofstream dat(fs::path(folder) / (figure.name + ".dat"));
    WriteScript(figure, options, image, gp, dat);
    gp.flush();
    dat.flush();
    if (!gp || !dat) {
      ThrowInputError((fs::path(folder) / script).string(), "", "cannot write figure files");
    }
  }
  std::string output;
  const int status = RunInFolder(program, script, folder, &output);
  if (status != 0) {
    throw PlotError(
        "figure '" + figure.name + "': gnuplot (" + program + ") " +
        (status < 0 ? std::string("did not run") : "exited with status " + std::to_string(status)) +
        (output.empty() ? "" : ": " + ErrorLine(output)));
  }
  std::error_code ec;
  if (fs::file_size(fs::path(folder) / image, ec) == 0 || ec) {
    throw PlotError("figure '" + figure.name + "': gnuplot wrote no image");
  }
  return image;
}

namespace palette {
const std::string& Indexed(int k) {
  static const std::array<std::string, 10> colors = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                                     "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                                     "#bcbd22", "#17becf"};
  const int i = ((k - 1) % 10 + 10) % 10;
  return colors[static_cast<std::size_t>(i)];
}

const std::string& Instant(int k) {
  static const std::array<std::string, 8> colors = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a",
                                                    "#66a61e", "#e6ab02", "#a6761d", "#666666"};
  const int i = ((k - 1) % 8 + 8) % 8;
  return colors[static_cast<std::size_t>(i)];
}
}  // namespace palette

}  // namespace ccsrm::reports
