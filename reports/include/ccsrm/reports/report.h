#pragma once
// Reports of ccsrm's files (SPEC 8): `ccsrm report --in FILE --out DIR`
// writes DIR/index.html (a self-contained page: tables, a short text summary
// and gnuplot figures in DIR/figures/) and DIR/summary.json (every number the
// page shows).
//
// A report reads what the commands wrote and never recomputes a figure they
// already give: a run page shows the run file's stored solver statistics, an
// experiment page the quality figures `ccsrm mocap process` stored under
// /mocap/quality. What a report does compute from the arrays (values at an
// instant, a largest or smallest value) says so in its table's caption.
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/reports/document.h"
#include "ccsrm/reports/figure.h"

namespace ccsrm::reports {

struct ReportOptions {
  // How figures are drawn: the gnuplot program (default "gnuplot" on PATH)
  // and the image format (default PNG).
  PlotOptions plot;
  // Instants [s] at which a run page tabulates joint angles, input tensions,
  // stuck nodes and energy, and draws the tension along each cable. Empty
  // (the default): for a run of the protocol (case 1-4), its end of ramp,
  // mid-hold and end of return that lie within the run, then its last frame
  // (with the middle of the run added when that leaves fewer than two);
  // otherwise the middle and the end of the run. Each instant is shown at the
  // nearest frame. At most 6, each finite.
  std::vector<double> instants_s;

  bool IsValid(std::string* error) const;
};

struct ReportSummary {
  std::string input;   // the file reported on
  std::string output;  // the report folder
  std::string kind;    // "run", "experiment", "fit", "loop", "prediction" or "design"
  std::string title;
  int figures = 0;
  int tables = 0;
  std::vector<std::string> notices;  // what the page says is missing
  double wall_time_s = 0.0;          // time taken to make the report

  // One line; and a few lines with the files written and the notices.
  std::string BriefReport() const;
  std::string FullReport() const;
};

// The page of a simulation run (`source` names it on the page and in
// messages). Uses sim::ParseConfig on run.config_yaml for the arm's segments,
// the arm and protocol in words and, for a run of the protocol (case 1-4),
// the planned motion. It cites the paper's cases and figures only when the
// arm is the paper's (sim::IsPaperArm). Draws nothing: the figures are
// described, WriteReport renders them. Throws InputError for invalid options
// or an inconsistent record (datasets::ValidateRunFile).
Document BuildRunDocument(const datasets::RunFile& run, const std::string& source,
                          const ReportOptions& options);

// The page of an experiment: marker visibility and gaps, the mocap quality
// figures, measured joint angles, inputs. Throws InputError for invalid
// options or an inconsistent record (datasets::ValidateExperimentFile).
Document BuildExperimentDocument(const datasets::ExperimentFile& experiment,
                                 const std::string& source, const ReportOptions& options);

// The page of a fit folder written by `ccsrm identify` (fit.json of schema
// ccsrm-fit/1, and per experiment <name>.angles.csv and <name>.fit.h5):
// measured against fitted angles and the residuals per experiment, the
// parameters with standard errors and 95 % intervals, the correlation
// matrix, singular values and the directions the data do not pin down,
// per-joint errors at the start and fitted, cost per step, the experiments
// and their noise. Every number as fit.json and the angles files give it.
// Throws InputError for invalid options, "<folder>: not a fit folder (no
// fit.json)", a fit.json of another schema, or a missing key or malformed
// file (naming the file and the key or line).
Document BuildFitDocument(const std::string& folder, const ReportOptions& options);

// The page of a loop folder written by `ccsrm loop` (loop.json of schema
// ccsrm-loop/1; declared/ and final/, the fit folders of the declared and
// the final model; holdout/<name>.angles.csv per held-out experiment): the
// error before and after on training and held-out data, overall and per
// joint; the residuals of both models; per round, the residual's
// cross-correlation with each signal, the candidates' evidence, scores,
// refits and the decision; the final parameters with their intervals; what
// remains unexplained. Every number in a table as loop.json gives it.
// Throws InputError for invalid options, "<folder>: not a loop folder (no
// loop.json)", a loop.json of another schema, a missing key or a value of
// the wrong type (naming loop.json and the key), or a broken fit folder or
// angles file. A missing declared/, final/ or held-out file is a notice.
Document BuildLoopDocument(const std::string& folder, const ReportOptions& options);

// The page of a prediction folder written by `ccsrm predict` (pred.json of
// schema ccsrm-prediction/1; per recording <name>.angles.csv and
// <name>.pred.h5): measured against predicted angles and the prediction
// error per recording, the error per joint and axis against the
// measurement noise, the channels above it, the model's parameters and the
// recordings. Every number as pred.json and the angles files give it.
// Throws InputError for invalid options, "<folder>: not a prediction folder
// (no pred.json)", a pred.json of another schema, or a missing key or
// malformed file (naming the file and the key or line).
Document BuildPredictionDocument(const std::string& folder, const ReportOptions& options);

// The page of a design folder written by `ccsrm design` (design.json of
// schema ccsrm-design/1; proposed.inputs.csv when a motion was proposed):
// the candidate plans' predicted relative standard errors side by side,
// which parameter each informs, the proposed motion's planned joint angles,
// cable lengths and speeds, and the errors at the prior box's corners.
// Throws InputError for invalid options, "<folder>: not a design folder (no
// design.json)", a design.json of another schema, or a missing key or
// malformed file (naming the file and the key or line).
Document BuildDesignDocument(const std::string& folder, const ReportOptions& options);

// Renders every figure of `document` with gnuplot into <folder>/figures,
// then writes <folder>/index.html and <folder>/summary.json, all inside a
// temporary folder beside the target that replaces it only when complete
// (common/AtomicOutputDirectory): an existing report is never half
// overwritten. Sets each FigureBlock::file.
// Throws InputError when `folder` exists and is neither empty nor an earlier
// ccsrm report (a summary.json with schema ccsrm-report/1), or is a file, or
// its parent does not exist; PlotError when gnuplot is missing or fails.
void WriteReport(Document* document, const std::string& folder, const ReportOptions& options);

// What `ccsrm report` does: checks the options, that gnuplot is there and
// that the output may be written (as WriteReport; and the input must not lie
// inside it), reads `input` once (a ccsrm-run/1 or ccsrm-dataset/1 file,
// a fit, loop or prediction folder), builds its page and writes it. Throws
// InputError naming the path for a missing input, a folder with neither
// fit.json nor loop.json, or a file of another kind; PlotError as
// WriteReport.
ReportSummary MakeReport(const std::string& input, const std::string& output_folder,
                         const ReportOptions& options);

}  // namespace ccsrm::reports
