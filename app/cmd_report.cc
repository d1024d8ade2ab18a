// ccsrm report --in run.h5|exp.h5|fit/|loop/ --out report/: an HTML page
// with gnuplot figures and a JSON summary of a run, an experiment, a fit or
// a loop.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/reports/report.h"
#include "commands.h"

namespace ccsrm::app {

void AddReportCommand(CLI::App& root) {
  CLI::App* cmd = root.add_subcommand(
      "report",
      "Write an HTML report (index.html, figures/, summary.json) of a ccsrm-run/1 or "
      "ccsrm-dataset/1 file, or of a fit folder (ccsrm identify) or a loop folder (ccsrm loop)");
  struct Args {
    std::string in;
    std::string out;
    std::string format = "png";
    reports::ReportOptions options;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--in", a->in,
                  "Run (ccsrm simulate), experiment (ccsrm generate, mocap process), fit "
                  "folder (ccsrm identify) or loop folder (ccsrm loop)")
      ->required();
  cmd->add_option("--out", a->out,
                  "Report folder; an existing one is replaced only if it holds an earlier report "
                  "and nothing else")
      ->required();
  cmd->add_option("--format", a->format, "Figure images: png or svg")
      ->check(CLI::IsMember({"png", "svg"}))
      ->capture_default_str();
  cmd->add_option("--instants", a->options.instants_s,
                  "Times [s] a run page tabulates (default: end of ramp, mid-hold, end of "
                  "return, end of run)")
      ->expected(1, 6);
  cmd->callback([a] {
    a->options.plot.format =
        a->format == "svg" ? reports::ImageFormat::kSvg : reports::ImageFormat::kPng;
    const reports::ReportSummary summary = reports::MakeReport(a->in, a->out, a->options);
    std::printf("%s", summary.FullReport().c_str());
  });
}

}  // namespace ccsrm::app
