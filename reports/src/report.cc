#include "ccsrm/reports/report.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <variant>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/clock.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/output_policy.h"
#include "ccsrm/datasets/inspect.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "design_folder.h"
#include "fit_folder.h"
#include "loop_folder.h"
#include "prediction_folder.h"

namespace ccsrm::reports {
namespace {

namespace fs = std::filesystem;

// "report/" and "report" name the same folder.
fs::path FolderPath(const std::string& folder) {
  fs::path path = fs::path(folder).lexically_normal();
  if (!path.has_filename() && path.has_parent_path()) path = path.parent_path();
  return path;
}

// The report folder under the one output policy (common/output_policy.h):
// an existing folder is replaced only when it is empty or an earlier report,
// and never when it is or holds the input.
void CheckOutputFolder(const std::string& folder, const std::string& input) {
  const OutputKind report{std::string("ccsrm report folder (summary.json, ") + kReportSchema + ")",
                          /*folder=*/true, [](const std::string& path) {
                            std::ifstream in(fs::path(path) / "summary.json");
                            const nlohmann::json json =
                                nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
                            return json.is_object() && json.value("schema", "") == kReportSchema;
                          }};
  CheckOutputPath(folder, "--out", report, {input});
}

std::string Count(int n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.flush();
  if (!out) ThrowInputError(path.string(), "", "cannot write");
}

}  // namespace

bool ReportOptions::IsValid(std::string* error) const {
  if (!plot.IsValid(error)) return false;
  if (instants_s.size() > 6) {
    if (error) *error = "at most 6 instants";
    return false;
  }
  for (double t : instants_s) {
    if (!std::isfinite(t)) {
      if (error) *error = "instants must be finite times in s";
      return false;
    }
  }
  return true;
}

std::string ReportSummary::BriefReport() const {
  return "report of " + kind + " " + input + " in " + output + "/ (" + Count(figures, "figure") +
         ", " + Count(tables, "table") +
         (notices.empty() ? "" : ", " + Count(static_cast<int>(notices.size()), "notice")) + ")";
}

std::string ReportSummary::FullReport() const {
  std::ostringstream out;
  char seconds[32];
  std::snprintf(seconds, sizeof(seconds), "%.2f", wall_time_s);
  out << "report: " << title << "\n"
      << "  input:    " << input << " (" << kind << ")\n"
      << "  page:     " << (fs::path(output) / "index.html").string() << "\n"
      << "  numbers:  " << (fs::path(output) / "summary.json").string() << " ("
      << Count(tables, "table") << ")\n"
      << "  figures:  " << figures << " in " << (fs::path(output) / "figures").string() << "\n"
      << "  time:     " << seconds << " s\n";
  for (const std::string& notice : notices) out << "  note: " << notice << "\n";
  return out.str();
}

void WriteReport(Document* document, const std::string& folder, const ReportOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  CheckOutputFolder(folder, "");
  FindGnuplot(options.plot);
  if (document->created.empty()) document->created = UtcTimestamp();

  AtomicOutputDirectory out(folder);
  const fs::path figures = fs::path(out.temp_path()) / "figures";
  fs::create_directory(figures);
  std::set<std::string> names;
  for (Section& section : document->sections) {
    for (Block& block : section.blocks) {
      auto* figure = std::get_if<FigureBlock>(&block);
      if (figure == nullptr) continue;
      CCSRM_CHECK(names.insert(figure->figure.name).second);  // one file per figure
      figure->file = "figures/" + RenderFigure(figure->figure, figures.string(), options.plot);
    }
  }
  WriteFile(fs::path(out.temp_path()) / "index.html", ToHtml(*document));
  WriteFile(fs::path(out.temp_path()) / "summary.json", ToJson(*document).dump(2) + "\n");
  out.Commit();
}

ReportSummary MakeReport(const std::string& input, const std::string& output_folder,
                         const ReportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) ThrowInputError("report options", "", why);
  std::error_code ec;
  if (!fs::exists(input, ec)) ThrowInputError(input, "", "no such file");
  const bool folder = fs::is_directory(input, ec);
  const std::string name = fs::path(input).filename().string();
  if (!folder &&
      (name == "fit.json" || name == "loop.json" || name == "pred.json" || name == "design.json")) {
    const fs::path parent = fs::path(input).parent_path();
    ThrowInputError(input, "",
                    std::string(name == "fit.json"    ? "a fit"
                                : name == "loop.json" ? "a loop"
                                : name == "pred.json" ? "a prediction"
                                                      : "a design") +
                        " is reported from its folder: ccsrm report --in " +
                        (parent.empty() ? std::string(".") : parent.string()));
  }
  // A loop folder holds fit folders but no fit.json of its own.
  const bool loop = folder && internal::LooksLikeLoopFolder(input);
  const bool prediction = folder && !loop && internal::LooksLikePredictionFolder(input);
  const bool design = folder && !loop && !prediction && internal::LooksLikeDesignFolder(input);
  if (folder && !loop && !prediction && !design && !internal::LooksLikeFitFolder(input)) {
    ThrowInputError(input, "",
                    "not a fit, loop, prediction or design folder (no fit.json, loop.json, "
                    "pred.json or design.json); expected a ccsrm-run/1 or ccsrm-dataset/1 file, "
                    "or a folder written by ccsrm identify, ccsrm loop, ccsrm predict or ccsrm "
                    "design");
  }
  CheckOutputFolder(output_folder, input);
  Document document;
  if (folder) {
    FindGnuplot(options.plot);
    document = loop         ? BuildLoopDocument(input, options)
               : prediction ? BuildPredictionDocument(input, options)
               : design     ? BuildDesignDocument(input, options)
                            : BuildFitDocument(input, options);
  } else {
    const datasets::AnyFile file = sim_io::ReadCheckedFile(input);
    FindGnuplot(options.plot);
    document =
        std::holds_alternative<datasets::RunFile>(file)
            ? BuildRunDocument(std::get<datasets::RunFile>(file), input, options)
            : BuildExperimentDocument(std::get<datasets::ExperimentFile>(file), input, options);
  }
  WriteReport(&document, output_folder, options);

  ReportSummary summary;
  summary.input = input;
  summary.output = FolderPath(output_folder).string();
  summary.kind = document.kind;
  summary.title = document.title;
  summary.figures = static_cast<int>(document.figures().size());
  summary.tables = static_cast<int>(document.tables().size());
  summary.notices = document.notices();
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace ccsrm::reports
