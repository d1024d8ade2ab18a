// The fit page built from a small fit folder whose every number is known
// (fit_fixture.h: fit.json, the angles file and a fitted run file in the
// layout of identify/src/fit_output.cc), so the tables can be checked value
// by value; and the one-line errors for folders that are not fit folders.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/reports/report.h"
#include "fit_fixture.h"
#include "report_test_util.h"
#include "run_ccsrm.h"

namespace ccsrm::reports {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

using testing::FittedX;
using testing::KnownAnglesCsv;
using testing::KnownFitJson;
using testing::MeasuredX;

fs::path WriteFitFolder(const std::string& name, const json& fit) {
  const fs::path dir = ccsrm::testing::ScratchDirectory("fit_page_" + name) / "fit";
  testing::WriteKnownFitFolder(dir, fit, KnownAnglesCsv());
  return dir;
}

json RowOf(const json& summary, const std::string& table, const std::string& key,
           const json& first) {
  for (const json& row : summary["tables"][table]["rows"]) {
    if (row[key] == first) return row;
  }
  ADD_FAILURE() << "table " << table << " has no row " << first;
  return json();
}

TEST(FitPage, KnownFitShowsItsNumbers) {
  const fs::path dir = WriteFitFolder("known", KnownFitJson());
  const Document document = BuildFitDocument(dir.string(), ReportOptions());
  const json summary = ToJson(document);
  EXPECT_EQ(summary["kind"], "fit");
  EXPECT_TRUE(summary["notices"].empty()) << summary["notices"];

  const json tp = RowOf(summary, "parameters", "parameter", "T_p");
  EXPECT_EQ(tp["unit"], "N");
  EXPECT_EQ(tp["start"], 50.0);
  EXPECT_EQ(tp["estimate"], 65.29);
  EXPECT_EQ(tp["std_error"], 0.372);
  EXPECT_EQ(tp["ci95_lower"], 64.56);
  EXPECT_EQ(tp["ci95_upper"], 66.03);
  EXPECT_EQ(tp["upper_bound"], 500.0);
  EXPECT_EQ(tp["status"], "identifiable");
  const json clc = RowOf(summary, "parameters", "parameter", "c_lc");
  EXPECT_EQ(clc["estimate"], 0.6125);
  EXPECT_EQ(clc["std_error"], "not identifiable");
  EXPECT_TRUE(clc["ci95_lower"].is_null());
  EXPECT_EQ(clc["status"], "not identifiable");
  EXPECT_EQ(RowOf(summary, "fixed_parameters", "parameter", "mu")["value"], 0.0);

  const json r = RowOf(summary, "correlation", "parameter", "T_p");
  EXPECT_EQ(r["t_p"], 1.0);
  EXPECT_TRUE(r["c_lc"].is_null());
  const json sv = RowOf(summary, "singular_values", "k", 2);
  EXPECT_EQ(sv["singular_value"], 0.5142);
  EXPECT_EQ(sv["direction"], "1.00 c_lc");
  EXPECT_EQ(sv["relative_std_error"], 13.8);
  EXPECT_TRUE(RowOf(summary, "singular_values", "k", 1)["direction"].is_null());

  const json joint3 = RowOf(summary, "errors_per_joint", "joint", 3);
  EXPECT_EQ(joint3["rms_x_start_deg"], 0.06);
  EXPECT_EQ(joint3["rms_x_fitted_deg"], 0.03);
  EXPECT_EQ(joint3["rms_y_fitted_deg"], 0.006);
  EXPECT_EQ(joint3["fit_x_fitted_percent"], 97.0);
  EXPECT_EQ(joint3["motion_x_deg"], 0.7071);
  // θy barely moves: no fit percent (never a negative one without reason),
  // its RMS error against its motion in degrees instead.
  EXPECT_TRUE(joint3["fit_y_start_percent"].is_null());
  EXPECT_TRUE(joint3["fit_y_fitted_percent"].is_null());
  EXPECT_EQ(joint3["motion_y_deg"], 0.009);
  EXPECT_EQ(joint3["samples_x"], 5);
  const auto& errors = document.sections[document.sections.size() - 3];
  ASSERT_EQ(errors.id, "errors");
  const FigureBlock& bars = std::get<FigureBlock>(errors.blocks[0]);
  EXPECT_EQ(bars.figure.panels[2].title, "Fit percent θx");
  EXPECT_EQ(bars.figure.panels[3].title, "RMS error against motion θy");
  EXPECT_THAT(bars.caption, HasSubstr("θy barely moves at any joint"));
  const Table& per_joint = std::get<Table>(errors.blocks[1]);
  EXPECT_THAT(per_joint.caption, HasSubstr("given only for an axis that moves"));
  EXPECT_THAT(per_joint.caption, HasSubstr("below 0 worse than that mean"));

  auto fit = [&](const std::string& quantity) {
    return RowOf(summary, "fit", "quantity", quantity)["value"];
  };
  EXPECT_EQ(fit("iterations"), 11);
  EXPECT_EQ(fit("RMS error at start"), 0.0827);
  EXPECT_EQ(fit("RMS error fitted"), 0.0312);
  EXPECT_EQ(fit("fit percent fitted"), 98.2);
  EXPECT_EQ(fit("residual variance"), 0.942);
  EXPECT_EQ(fit("cost fitted"), 6203.17);
  EXPECT_EQ(RowOf(summary, "cost_history", "step", 1)["cost"], 6245.83);

  const json g4 = RowOf(summary, "experiments", "experiment", "g4");
  EXPECT_EQ(g4["angles"], "from the mocap pipeline");
  EXPECT_EQ(g4["noise_source"], "joint twist scatter");
  EXPECT_EQ(g4["rms_fitted_deg"], 0.0312);
  EXPECT_EQ(RowOf(summary, "noise", "joint", 12)["noise_deg_g4"], 0.041);

  // The text a lab reader reads first says what happened, in the tables' numbers.
  const Paragraph& headline = std::get<Paragraph>(document.sections[0].blocks[0]);
  EXPECT_THAT(headline.text, HasSubstr("converged after 11 iterations"));
  EXPECT_THAT(headline.text, HasSubstr("from 0.0827 deg at the start values to 0.0312 deg"));
  const Paragraph& estimates = std::get<Paragraph>(document.sections[0].blocks[1]);
  EXPECT_THAT(estimates.text, HasSubstr("T_p = 65.29 N (standard error 0.372 N, 95 % interval "
                                        "64.56 to 66.03 N"));
  EXPECT_THAT(estimates.text, HasSubstr("c_lc could not be determined"));
  EXPECT_THAT(estimates.text, HasSubstr("1.00 c_lc"));

  // Two segments, from the fitted run's configuration: two panels per
  // angle figure; measured (dashed) and fitted (solid) of joint 7 are the
  // angles file's.
  const std::vector<const FigureBlock*> figures = document.figures();
  ASSERT_FALSE(figures.empty());
  const Figure& theta_x = figures[0]->figure;
  EXPECT_EQ(theta_x.name, "angles_x_g4");
  ASSERT_EQ(theta_x.panels.size(), 2u);
  const Series& measured7 = theta_x.panels[1].series[0];
  const Series& fitted7 = theta_x.panels[1].series[6];
  EXPECT_EQ(fitted7.label, "joint 7");
  EXPECT_EQ(measured7.style, SeriesStyle::kDashed);
  EXPECT_EQ(measured7.color, fitted7.color);
  EXPECT_DOUBLE_EQ(measured7.y[3], MeasuredX(3, 6));
  EXPECT_DOUBLE_EQ(fitted7.y[3], FittedX(3, 6));
  const Figure& theta_y = figures[1]->figure;
  EXPECT_TRUE(std::isnan(theta_y.panels[0].series[0].y[1]));  // not measured
}

TEST(FitPage, ReportAgreesWithItsJsonAndReferencesItsFiles) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = WriteFitFolder("written", KnownFitJson());
  const fs::path out = dir.parent_path() / "report";
  fs::remove_all(out);  // an earlier run's page, perhaps of an older ccsrm
  const ReportSummary summary = MakeReport(dir.string(), out.string(), ReportOptions());
  EXPECT_EQ(summary.kind, "fit");
  const std::string html = ReadTextFile((out / "index.html").string());
  const json report = json::parse(ReadTextFile((out / "summary.json").string()));
  EXPECT_GT(testing::ExpectTablesMatchJson(html, report), 150);
  int files = 0;
  for (const std::string& ref : testing::HtmlReferences(html)) {
    if (ref.rfind("#", 0) == 0) continue;
    EXPECT_TRUE(fs::is_regular_file(out / ref)) << ref;
    ++files;
  }
  EXPECT_EQ(files, 1 + summary.figures);  // summary.json and every figure
  // The heat map's cells: the correlation of T_p with itself, and a grey
  // cell for the unidentifiable c_lc.
  const std::string dat = ReadTextFile((out / "figures" / "correlation.dat").string());
  EXPECT_THAT(dat, HasSubstr("1 2 1 1\n"));
  EXPECT_THAT(dat, HasSubstr("2 1 0 0\n"));
}

TEST(FitPage, AFitWithoutItsRunFileShowsAllJointsInOnePanelAndSaysWhy) {
  json fit = KnownFitJson();
  fit["experiments"][0]["run_file"] = nullptr;
  fit["experiments"][0]["run"]["status"] = "failed";
  fit["experiments"][0]["run"]["message"] = "diverged at t = 1 s";
  fit["converged"] = false;
  fit["termination"] = "no_convergence";
  const fs::path dir = WriteFitFolder("norun", fit);
  const Document document = BuildFitDocument(dir.string(), ReportOptions());
  const std::vector<std::string> notices = document.notices();
  ASSERT_EQ(notices.size(), 3u);
  EXPECT_THAT(notices[0], HasSubstr("did not converge"));
  EXPECT_THAT(notices[1], HasSubstr("diverged at t = 1 s"));
  EXPECT_THAT(notices[2], HasSubstr("one panel"));
  EXPECT_EQ(document.figures()[0]->figure.panels.size(), 1u);
}

TEST(FitPage, SeveralExperimentsGetASectionAndANoiseColumnEach) {
  json fit = KnownFitJson();
  json second = fit["experiments"][0];
  second["name"] = "g5 slow";  // not a file stem: its figures get one
  second["angles_from_pipeline"] = false;
  second["noise_source"] = "given";
  for (json& noise : second["noise_deg"]) noise = 0.05;
  fit["experiments"].push_back(second);
  const Document document = BuildFitDocument(WriteFitFolder("two", fit).string(), ReportOptions());
  const json summary = ToJson(document);
  EXPECT_EQ(summary["sections"][1]["id"], "angles-g4_1");
  EXPECT_EQ(summary["sections"][2]["id"], "angles-g5_slow_2");
  std::vector<std::string> names;
  for (const FigureBlock* figure : document.figures()) names.push_back(figure->figure.name);
  EXPECT_THAT(names, ::testing::IsSupersetOf({"angles_x_g4_1", "residuals_g4_1",
                                              "angles_y_g5_slow_2", "residuals_g5_slow_2"}));
  EXPECT_EQ(RowOf(summary, "experiments", "experiment", "g5 slow")["angles"],
            "stored in the experiment");
  const json joint1 = RowOf(summary, "noise", "joint", 1);
  EXPECT_EQ(joint1["noise_deg_g4"], 0.03);
  EXPECT_EQ(joint1["noise_deg_g5_slow"], 0.05);
}

std::string ErrorOf(const fs::path& dir) {
  try {
    BuildFitDocument(dir.string(), ReportOptions());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FitPage, BadFitFoldersAreNamedInOneLine) {
  const fs::path empty = ccsrm::testing::ScratchDirectory("fit_page_empty");
  EXPECT_EQ(ErrorOf(empty), empty.string() + ": not a fit folder (no fit.json)");

  json wrong = KnownFitJson();
  wrong["schema"] = "ccsrm-loop/1";
  EXPECT_THAT(ErrorOf(WriteFitFolder("schema", wrong)),
              HasSubstr("fit.json: key 'schema': is \"ccsrm-loop/1\", expected \"ccsrm-fit/1\""));
  json missing = KnownFitJson();
  missing["parameters"]["T_p"].erase("ci95");
  EXPECT_THAT(ErrorOf(WriteFitFolder("missing", missing)),
              HasSubstr("fit.json: key 'parameters.T_p.ci95': missing"));
  json type = KnownFitJson();
  type["errors"]["per_joint"][2]["rms_deg"][1] = "small";
  EXPECT_THAT(ErrorOf(WriteFitFolder("type", type)),
              HasSubstr("key 'errors.per_joint[2].rms_deg[1]': expected a number or null"));
  json outside = KnownFitJson();
  outside["experiments"][0]["angles_file"] = "../g4.angles.csv";
  EXPECT_THAT(ErrorOf(WriteFitFolder("outside", outside)),
              HasSubstr("expected a file name in the fit folder"));

  const fs::path not_json = WriteFitFolder("notjson", KnownFitJson());
  WriteTextFileAtomically((not_json / "fit.json").string(), "{\"schema\": ");
  EXPECT_EQ(ErrorOf(not_json), (not_json / "fit.json").string() + ": not valid JSON");

  const fs::path header = WriteFitFolder("header", KnownFitJson());
  std::string csv = KnownAnglesCsv();
  csv.replace(csv.find("fitted_thetay2"), 14, "fitted_thetaz2");
  WriteTextFileAtomically((header / "g4.angles.csv").string(), csv);
  EXPECT_THAT(ErrorOf(header),
              HasSubstr("g4.angles.csv: line 2: column 12 is 'fitted_thetaz2_deg', "
                        "expected 'fitted_thetay2_deg'"));

  const fs::path cell = WriteFitFolder("cell", KnownFitJson());
  csv = KnownAnglesCsv();
  csv.replace(csv.rfind("\n", csv.size() - 2) + 1, 8, "0.04000x");
  WriteTextFileAtomically((cell / "g4.angles.csv").string(), csv);
  EXPECT_THAT(ErrorOf(cell), HasSubstr("g4.angles.csv: line 7: column 1 ('time_s'): '0.04000x' "
                                       "is not a number"));

  const fs::path gone = WriteFitFolder("gone", KnownFitJson());
  fs::remove(gone / "g4.angles.csv");
  EXPECT_THAT(ErrorOf(gone), HasSubstr("g4.angles.csv: cannot be read"));
}

}  // namespace
}  // namespace ccsrm::reports
