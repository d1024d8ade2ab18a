// The loop page built from a small loop folder whose every number is known:
// loop.json written here in the layout of identify/src/loop_output.cc (two
// rounds: table_tilt accepted, joint_friction refitted and refused,
// backlash not significant), declared/ and final/ as the fit page test's
// fit folder (the declared residual three times the final one), and a
// held-out experiment's angles. Checks the tables value by value against
// loop.json, the figures against the angles files, the page against its
// summary.json, and the one-line errors of broken folders.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/reports/report.h"
#include "fit_fixture.h"
#include "report_test_util.h"
#include "run_ccsrm.h"

namespace ccsrm::reports {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using testing::kJoints;

constexpr std::size_t kHoldoutFrames = 4;

// A diagnostics object (diagnostics.cc's ToJson) whose correlations are
// `scale` times a fixed pattern: every signal pooled, six cross-correlation
// curves at five lags, experiment g4, two channels (one number null, as a
// NaN comes out).
json Diagnostics(double scale) {
  const char* signals[] = {"angle", "constant",   "heading", "hold_drift", "hysteresis",
                           "lag",   "input_rate", "rate",    "rate_sign",  "time"};
  json pooled = json::object();
  for (int s = 0; s < 10; ++s) {
    const double value = scale * 0.1 * (s + 1) * (s % 2 ? -1.0 : 1.0);
    const double band = 0.25;
    pooled[signals[s]] = {
        {"value", value}, {"band", band}, {"significant", std::abs(value) > band}};
  }
  json xc = json::object();
  for (const char* s : {"angle", "heading", "input_rate", "rate", "rate_sign", "time"}) {
    xc[s] = json::array();
    for (int k = -2; k <= 2; ++k) xc[s].push_back(scale * (0.5 - 0.1 * std::abs(k)));
  }
  json channel = {{"experiment", "g4"},
                  {"joint", 1},
                  {"axis", "x"},
                  {"samples", 5},
                  {"rms_deg", scale * 0.1},
                  {"mean_deg", scale * 0.02},
                  {"noise_deg", 0.03},
                  {"autocorrelation", {0.9, 0.7, 0.4}},
                  {"whiteness_band", 0.8765},
                  {"lags_outside_band", 0.5},
                  {"autocorrelation_time", 3.25},
                  {"effective_samples", 1.538},
                  {"hold_drift_degps", scale * 0.001234},
                  {"hysteresis_deg2", scale * 0.0456},
                  {"phase_rms_deg", {scale * 0.12, scale * 0.08}},
                  {"evidence", {{"angle", {{"value", 0.3}, {"band", 0.2}}}}}};
  json channel_y = channel;
  channel_y["axis"] = "y";
  channel_y["hysteresis_deg2"] = nullptr;
  return {{"rms_deg", scale * 0.1},
          {"effective_samples", 812.5},
          {"pooled", pooled},
          {"lags_s", {-0.02, -0.01, 0.0, 0.01, 0.02}},
          {"cross_correlation", xc},
          {"experiments",
           {{{"name", "g4"},
             {"rms_deg", scale * 0.1},
             {"lag_s", 0.01},
             {"lag_explained", 0.125},
             {"phases",
              {{{"name", "motion 1"}, {"start_s", 0.0}, {"end_s", 0.02}},
               {{"name", "hold 1"}, {"start_s", 0.02}, {"end_s", 0.04}}}}}}},
          {"channels", {channel, channel_y}}};
}

// Per joint errors in loop.json's layout: θx scale · 0.01 (j + 1), θy
// scale · 0.002 (j + 1), as the fit fixture's.
json JointErrors(double overall, double scale) {
  json joints = json::array();
  for (std::size_t j = 0; j < kJoints; ++j) {
    joints.push_back(
        {{"joint", j + 1}, {"rms_deg", {scale * 0.01 * (j + 1), scale * 0.002 * (j + 1)}}});
  }
  return {{"rms_deg", overall}, {"joints", joints}};
}

json Estimate(double value, json std_error, json lower, json upper, bool identifiable,
              const std::string& units) {
  return {{"value", value},         {"std_error", std_error},
          {"ci95", {lower, upper}}, {"identifiable", identifiable},
          {"free", true},           {"units", units}};
}

json Backlash() {
  return {{"name", "backlash"},
          {"score", 1.25},
          {"p_value", 0.5353},
          {"significant", false},
          {"parameters", {"backlash.dead_band_rad"}},
          {"linearised", {{"backlash.dead_band_rad", 1e-4}}},
          {"evidence",
           {{{"signal", "hysteresis"}, {"value", 0.012}, {"band", 0.09}, {"significant", false}}}},
          {"refitted", false},
          {"delta_bic", nullptr},
          {"rms_deg", nullptr},
          {"holdout_rms_deg", nullptr},
          {"holdout_improved", false},
          {"size_significant", false},
          {"termination", ""},
          {"estimates", json::object()},
          {"simulations", 0},
          {"accepted", false},
          {"reason", "score test not significant (p 0.54)"}};
}

json KnownLoopJson() {
  json tilt = {
      {"name", "table_tilt"},
      {"score", 812.3456},
      {"p_value", 1.234e-30},
      {"significant", true},
      {"parameters", {"table_tilt.lateral_rad", "table_tilt.longitudinal_rad"}},
      {"linearised",
       {{"table_tilt.lateral_rad", 0.00091234}, {"table_tilt.longitudinal_rad", -1.5e-5}}},
      {"evidence",
       {{{"signal", "constant"}, {"value", 0.61234}, {"band", 0.0812}, {"significant", true}},
        {{"signal", "heading"}, {"value", 0.04321}, {"band", 0.0912}, {"significant", false}}}},
      {"refitted", true},
      {"delta_bic", 640.27},
      {"rms_deg", 0.0412345},
      {"holdout_rms_deg", 0.0523456},
      {"holdout_improved", true},
      {"size_significant", true},
      {"termination", "converged"},
      {"estimates",
       {{"table_tilt.lateral_rad", Estimate(0.000987654, 2.3456e-5, 0.00094, 0.00103, true, "rad")},
        {"table_tilt.longitudinal_rad", Estimate(-1.2e-5, 2.1e-5, -5.3e-5, 2.9e-5, true, "rad")}}},
      {"simulations", 42},
      {"accepted", true},
      {"reason",
       "ΔBIC 640.3 > 10; held-out RMS 0.1212 -> 0.0523 deg (a real gain); its size is "
       "distinguishable from 0"}};
  json friction = {
      {"name", "joint_friction"},
      {"score", 95.25},
      {"p_value", 3.4e-19},
      {"significant", true},
      {"parameters", {"joint_friction.coulomb_nm"}},
      {"linearised", {{"joint_friction.coulomb_nm", 0.0021}}},
      {"evidence",
       {{{"signal", "rate_sign"}, {"value", 0.1234}, {"band", 0.0567}, {"significant", true}}}},
      {"refitted", true},
      {"delta_bic", 4.24},
      {"rms_deg", 0.0901},
      {"holdout_rms_deg", 0.1199},
      {"holdout_improved", false},
      {"size_significant", false},
      {"termination", "converged"},
      {"estimates",
       {{"joint_friction.coulomb_nm", Estimate(0.0019, nullptr, nullptr, nullptr, false, "N m")}}},
      {"simulations", 30},
      {"accepted", false},
      {"reason", "ΔBIC 4.2 <= 10; held-out RMS 0.1212 -> 0.1199 deg (no gain beyond chance)"}};
  json round1 = {{"round", 1},
                 {"effects_on", json::array()},
                 {"rms_deg", 0.0934891},
                 {"holdout_rms_deg", 0.1212345},
                 {"evidence", Diagnostics(1.0)},
                 {"candidates", {tilt, friction, Backlash()}},
                 {"winner", "table_tilt"},
                 {"tie", json::array()},
                 {"decision", "added table_tilt: ΔBIC 640.3, training RMS 0.0935 -> 0.0412 deg."}};
  json round2 = {{"round", 2},
                 {"effects_on", {"table_tilt"}},
                 {"rms_deg", 0.0412345},
                 {"holdout_rms_deg", 0.0523456},
                 {"evidence", Diagnostics(0.5)},
                 {"candidates", {Backlash()}},
                 {"winner", nullptr},
                 {"tie", json::array()},
                 {"decision",
                  "no candidate earns its place: none explains a significant part of the "
                  "residual (score test)."}};
  json parameters = {
      {"mu", Estimate(0.1523, 0.0021, 0.1481, 0.1565, true, "1")},
      {"T_p", Estimate(65.2939046830209, 0.3724, 64.5604, 66.0274, true, "N")},
      {"table_tilt.lateral_rad", Estimate(0.000987654, 2.3456e-5, 0.00094, 0.00103, true, "rad")},
      {"table_tilt.longitudinal_rad", Estimate(-1.2e-5, nullptr, nullptr, nullptr, false, "rad")}};
  return {{"schema", "ccsrm-loop/1"},
          {"data",
           {{{"name", "g4"}, {"path", "data/g4.h5"}, {"role", "training"}},
            {{"name", "h1"}, {"path", "data/h1.h5"}, {"role", "holdout"}}}},
          {"declared_free", {"mu", "T_p"}},
          {"rounds", {round1, round2}},
          {"added_effects", {"table_tilt"}},
          {"parameters", parameters},
          {"rms_before_deg", 0.0934891},
          {"rms_after_deg", 0.0412345},
          {"holdout_rms_before_deg", 0.1212345},
          {"holdout_rms_after_deg", 0.0523456},
          {"before", JointErrors(0.0934891, 3.0)},
          {"after", JointErrors(0.0412345, 1.0)},
          {"holdout_before", JointErrors(0.1212345, 4.0)},
          {"holdout_after", JointErrors(0.0523456, 1.5)},
          {"noise_floor_deg", 0.0301234},
          {"unexplained",
           {{{"experiment", "g4"},
             {"joint", 7},
             {"axis", "x"},
             {"rms_deg", 0.07123},
             {"noise_deg", 0.036},
             {"worst_phase", "motion 2"},
             {"worst_phase_rms_deg", 0.1012}},
            {{"experiment", "g4"},
             {"joint", 12},
             {"axis", "y"},
             {"rms_deg", 0.0551},
             {"noise_deg", 0.0351},
             {"worst_phase", "hold 1"},
             {"worst_phase_rms_deg", 0.0609}}}},
          {"final_evidence", Diagnostics(0.4)},
          {"conclusion",
           "added table_tilt. Unexplained residual remains in 2 joint axes (above 1.5x their "
           "noise); the largest: g4 joint 7 θx 0.0712 deg against 0.0360, worst in motion 2."},
          {"simulations", 512},
          {"wall_time_s", 1234.5},
          {"threads", 2},
          {"declared_fit", {{"termination", "converged"}, {"iterations", 7}, {"simulations", 64}}},
          {"final_fit", {{"termination", "converged"}, {"iterations", 5}, {"simulations", 80}}}};
}

// Held-out h1: measured θx 0.2 i + 0.05 j, the declared model 0.03 above it
// and the final one 0.01 above; θy measured 0 (not in frame 1), declared
// 0.02, final -0.005.
double HoldoutMeasuredX(std::size_t i, std::size_t j) { return 0.2 * i + 0.05 * j; }

std::string HoldoutCsv() {
  std::string csv =
      "# h1: held-out joint angles [deg]: measured, the declared model's and the final model's; "
      "empty where not measured\ntime_s";
  for (std::size_t j = 1; j <= kJoints; ++j) {
    for (const char* axis : {"x", "y"}) {
      for (const char* kind : {"measured", "declared", "final"}) {
        csv += std::string(",") + kind + "_theta" + axis + std::to_string(j) + "_deg";
      }
    }
  }
  csv += "\n";
  char cell[96];
  for (std::size_t i = 0; i < kHoldoutFrames; ++i) {
    std::snprintf(cell, sizeof(cell), "%.6f", 0.01 * i);
    csv += cell;
    for (std::size_t j = 0; j < kJoints; ++j) {
      const double m = HoldoutMeasuredX(i, j);
      std::snprintf(cell, sizeof(cell), ",%.6f,%.6f,%.6f", m, m + 0.03, m + 0.01);
      csv += cell;
      csv += i == 1 ? ",,0.020000,-0.005000" : ",0.000000,0.020000,-0.005000";
    }
    csv += "\n";
  }
  return csv;
}

fs::path WriteLoopFolder(const std::string& name, const json& loop) {
  const fs::path dir = ccsrm::testing::ScratchDirectory("loop_page_" + name) / "loop";
  fs::create_directories(dir / "holdout");
  WriteTextFileAtomically((dir / "loop.json").string(), loop.dump(2));
  testing::WriteKnownFitFolder(dir / "declared", testing::KnownFitJson(),
                               testing::KnownAnglesCsv(3.0));
  testing::WriteKnownFitFolder(dir / "final", testing::KnownFitJson(),
                               testing::KnownAnglesCsv(1.0));
  WriteTextFileAtomically((dir / "holdout" / "h1.angles.csv").string(), HoldoutCsv());
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

json RowWith(const json& summary, const std::string& table, const json& cells) {
  for (const json& row : summary["tables"][table]["rows"]) {
    bool match = true;
    for (const auto& [key, value] : cells.items()) match = match && row[key] == value;
    if (match) return row;
  }
  ADD_FAILURE() << "table " << table << " has no row " << cells;
  return json();
}

const Figure& FigureNamed(const Document& document, const std::string& name) {
  for (const FigureBlock* block : document.figures()) {
    if (block->figure.name == name) return block->figure;
  }
  ADD_FAILURE() << "no figure " << name;
  static const Figure none;
  return none;
}

TEST(LoopPage, KnownLoopShowsItsNumbers) {
  const fs::path dir = WriteLoopFolder("known", KnownLoopJson());
  const Document document = BuildLoopDocument(dir.string(), ReportOptions());
  const json summary = ToJson(document);
  EXPECT_EQ(summary["kind"], "loop");
  EXPECT_EQ(summary["title"], "Closing the loop — added table_tilt");
  EXPECT_TRUE(summary["notices"].empty()) << summary["notices"];

  // Candidates of round 1, as loop.json has them, at the precision ccsrm
  // loop prints.
  const json tilt = RowOf(summary, "round_1_candidates", "candidate", "table_tilt");
  EXPECT_EQ(tilt["parameters"], "table_tilt.lateral_rad, table_tilt.longitudinal_rad");
  EXPECT_EQ(tilt["score"], 812.3);
  EXPECT_EQ(tilt["p_value"], 1.2e-30);
  EXPECT_EQ(tilt["delta_bic"], 640.3);
  EXPECT_EQ(tilt["rms_deg"], 0.0412);
  EXPECT_EQ(tilt["holdout_rms_deg"], 0.0523);
  EXPECT_EQ(tilt["holdout_improved"], "yes");
  EXPECT_EQ(tilt["accepted"], "yes");
  EXPECT_THAT(tilt["reason"].get<std::string>(), HasSubstr("(a real gain)"));
  const json friction = RowOf(summary, "round_1_candidates", "candidate", "joint_friction");
  EXPECT_EQ(friction["delta_bic"], 4.2);
  EXPECT_EQ(friction["size_significant"], "no");
  EXPECT_EQ(friction["accepted"], "no");
  const json backlash = RowOf(summary, "round_1_candidates", "candidate", "backlash");
  EXPECT_EQ(backlash["p_value"], 0.54);
  EXPECT_EQ(backlash["refitted"], "no");
  EXPECT_TRUE(backlash["delta_bic"].is_null());  // not refitted: no ΔBIC, RMS or held-out RMS
  EXPECT_TRUE(backlash["holdout_rms_deg"].is_null());
  EXPECT_TRUE(backlash["holdout_improved"].is_null());
  EXPECT_EQ(summary["tables"]["round_2_candidates"]["rows"].size(), 1u);

  const json lateral =
      RowWith(summary, "round_1_estimates",
              {{"candidate", "table_tilt"}, {"parameter", "table_tilt.lateral_rad"}});
  EXPECT_EQ(lateral["linearised"], 0.0009123);
  EXPECT_EQ(lateral["estimate"], 0.0009877);
  EXPECT_EQ(lateral["std_error"], 2.35e-05);
  EXPECT_EQ(lateral["ci95_upper"], 0.00103);
  const json coulomb =
      RowOf(summary, "round_1_estimates", "parameter", "joint_friction.coulomb_nm");
  EXPECT_EQ(coulomb["identifiable"], "no");
  EXPECT_TRUE(coulomb["std_error"].is_null());
  EXPECT_TRUE(RowOf(summary, "round_1_estimates", "candidate", "backlash")["estimate"].is_null());

  // The diagnostics that pointed to the candidates.
  const json constant =
      RowWith(summary, "round_1_evidence", {{"candidate", "table_tilt"}, {"signal", "constant"}});
  EXPECT_EQ(constant["value"], 0.612);
  EXPECT_EQ(constant["band"], 0.0812);
  EXPECT_EQ(constant["outside_band"], "yes");
  const json heading = RowOf(summary, "round_1_signals", "signal", "heading");
  EXPECT_EQ(heading["value"], 0.3);
  EXPECT_EQ(heading["outside_band"], "yes");
  EXPECT_EQ(RowOf(summary, "round_2_signals", "signal", "angle")["value"], 0.05);
  EXPECT_EQ(RowOf(summary, "round_1_experiments", "experiment", "g4")["lag_s"], 0.01);

  // Errors before and after, training and held out, overall and per joint.
  const json training = RowOf(summary, "errors", "data", "training");
  EXPECT_EQ(training["before_deg"], 0.0935);
  EXPECT_EQ(training["after_deg"], 0.0412);
  EXPECT_EQ(RowOf(summary, "errors", "data", "held out")["after_deg"], 0.0523);
  const json joint3 = RowOf(summary, "errors_per_joint", "joint", 3);
  EXPECT_EQ(joint3["training_x_before_deg"], 0.09);
  EXPECT_EQ(joint3["training_x_after_deg"], 0.03);
  EXPECT_EQ(joint3["training_y_before_deg"], 0.018);
  EXPECT_EQ(joint3["holdout_x_before_deg"], 0.12);
  EXPECT_EQ(joint3["holdout_y_after_deg"], 0.009);

  // The final parameters with their intervals; where each comes from.
  const json tp = RowOf(summary, "parameters", "parameter", "T_p");
  EXPECT_EQ(tp["from"], "declared model");
  EXPECT_EQ(tp["estimate"], 65.29);
  EXPECT_EQ(tp["ci95_lower"], 64.56);
  const json longitudinal =
      RowOf(summary, "parameters", "parameter", "table_tilt.longitudinal_rad");
  EXPECT_EQ(longitudinal["from"], "table_tilt");
  EXPECT_EQ(longitudinal["std_error"], "not identifiable");
  EXPECT_TRUE(longitudinal["ci95_lower"].is_null());

  // What remains.
  const json worst = RowOf(summary, "unexplained", "joint", 7);
  EXPECT_EQ(worst["axis"], "θx");
  EXPECT_EQ(worst["rms_deg"], 0.0712);
  EXPECT_EQ(worst["noise_deg"], 0.036);
  EXPECT_EQ(worst["worst_phase"], "motion 2");
  EXPECT_EQ(RowOf(summary, "unexplained", "joint", 12)["axis"], "θy");
  const json hold = RowOf(summary, "phases", "phase", "hold 1");
  EXPECT_EQ(hold["start_s"], 0.02);
  EXPECT_EQ(hold["end_s"], 0.04);
  const json channel_y = RowOf(summary, "final_channels", "axis", "θy");
  EXPECT_TRUE(channel_y["hysteresis_deg2"].is_null());  // null in loop.json
  EXPECT_EQ(channel_y["rms_deg"], 0.04);
  auto loop = [&](const std::string& quantity) {
    return RowOf(summary, "loop", "quantity", quantity)["value"];
  };
  EXPECT_EQ(loop("effects added"), "table_tilt");
  EXPECT_EQ(loop("noise floor"), 0.0301);
  EXPECT_EQ(loop("simulations"), 512);
  EXPECT_EQ(loop("rounds"), 2);

  // The page opens with the answer (issue 44): what was added, its value
  // and interval, the error before and after.
  const Paragraph& answer = std::get<Paragraph>(document.sections[0].blocks[0]);
  EXPECT_THAT(answer.text, HasSubstr("Answer: added table_tilt: table_tilt.lateral_rad = "
                                     "0.0009877 [0.00094, 0.00103] rad"));
  EXPECT_THAT(answer.text, HasSubstr("0.0935 deg declared, 0.0412 deg final"));
  EXPECT_THAT(answer.text, HasSubstr("held out 0.1212 deg declared, 0.0523 deg final"));
  // The text says what happened, in the tables' numbers.
  const Paragraph& headline = std::get<Paragraph>(document.sections[0].blocks[1]);
  EXPECT_THAT(headline.text, HasSubstr("went from 0.0935 deg with the declared model to 0.0412"));
  EXPECT_THAT(headline.text, HasSubstr("the held-out error from 0.1212 to 0.0523 deg"));
  const Paragraph& conclusion = std::get<Paragraph>(document.sections[0].blocks[2]);
  EXPECT_THAT(conclusion.text, HasSubstr("worst in motion 2"));
  const Paragraph& remains = std::get<Paragraph>(document.sections.back().blocks[0]);
  EXPECT_THAT(remains.text, HasSubstr("2 joint axes keep a residual above its noise threshold"));
  const json round2 = summary["sections"][5];
  EXPECT_EQ(round2["id"], "round-2");

  // Residuals before (declared/) and after (final/): two segments, declared
  // left and final right on one scale; joint 7's are the angles files'.
  const Figure& residual = FigureNamed(document, "residual_x_g4");
  ASSERT_EQ(residual.panels.size(), 4u);
  const Series& before7 = residual.panels[2].series[0];
  const Series& after7 = residual.panels[3].series[0];
  EXPECT_EQ(before7.label, "joint 7");
  EXPECT_NEAR(before7.y[3], testing::FittedX(3, 6, 3.0) - testing::MeasuredX(3, 6), 2e-6);
  EXPECT_NEAR(after7.y[3], testing::FittedX(3, 6, 1.0) - testing::MeasuredX(3, 6), 2e-6);
  EXPECT_EQ(residual.panels[2].y.max, residual.panels[3].y.max);
  // Held out: model − measured of holdout/h1.angles.csv; θy not measured
  // in frame 1.
  const Figure& held = FigureNamed(document, "holdout_residual_x_h1");
  ASSERT_EQ(held.panels.size(), 4u);
  EXPECT_NEAR(held.panels[0].series[2].y[2], 0.03, 2e-6);
  EXPECT_NEAR(held.panels[1].series[2].y[2], 0.01, 2e-6);
  const Figure& held_y = FigureNamed(document, "holdout_residual_y_h1");
  EXPECT_TRUE(std::isnan(held_y.panels[0].series[0].y[1]));
  EXPECT_NEAR(held_y.panels[1].series[0].y[0], -0.005, 2e-6);

  // The cross-correlations of round 1 against the lags, with the band at
  // ±0.25: angle (pooled 0.1) inside it, heading (0.3) outside, in red.
  const Figure& xc = FigureNamed(document, "cross_correlation_round_1");
  ASSERT_EQ(xc.panels.size(), 6u);
  EXPECT_EQ(xc.panels[0].title, "angle");
  EXPECT_EQ(xc.panels[0].series[0].color, palette::kNeutral);
  EXPECT_EQ(xc.panels[1].title, "heading (outside the band)");
  EXPECT_EQ(xc.panels[1].series[0].color, palette::kWarning);
  EXPECT_EQ(xc.panels[1].series[0].x, (std::vector<double>{-0.02, -0.01, 0.0, 0.01, 0.02}));
  EXPECT_DOUBLE_EQ(xc.panels[1].series[0].y[2], 0.5);
  EXPECT_DOUBLE_EQ(xc.panels[1].series[1].y[0], 0.25);
  EXPECT_DOUBLE_EQ(xc.panels[1].series[2].y[1], -0.25);
}

TEST(LoopPage, ReportAgreesWithItsJsonAndReferencesItsFiles) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = WriteLoopFolder("written", KnownLoopJson());
  const fs::path out = dir.parent_path() / "report";
  fs::remove_all(out);  // an earlier run's page, perhaps of an older ccsrm
  const ReportSummary summary = MakeReport(dir.string(), out.string(), ReportOptions());
  EXPECT_EQ(summary.kind, "loop");
  const std::string html = ReadTextFile((out / "index.html").string());
  const json report = json::parse(ReadTextFile((out / "summary.json").string()));
  EXPECT_GT(testing::ExpectTablesMatchJson(html, report), 200);
  int files = 0;
  for (const std::string& ref : testing::HtmlReferences(html)) {
    if (ref.rfind("#", 0) == 0) continue;
    EXPECT_EQ(ref.find("://"), std::string::npos) << "external reference " << ref;
    EXPECT_TRUE(fs::is_regular_file(out / ref)) << ref;
    ++files;
  }
  // summary.json and every figure: the errors, two residual figures each
  // for g4 and h1, a cross-correlation figure per round and the final one.
  EXPECT_EQ(summary.figures, 8);
  EXPECT_EQ(files, 1 + summary.figures);
  // The decision's text is on the page.
  EXPECT_THAT(html, HasSubstr("Decision: added table_tilt: ΔBIC 640.3"));
  // The band is drawn at ±0.25 around the curve of the heading.
  const std::string dat =
      ReadTextFile((out / "figures" / "cross_correlation_round_1.dat").string());
  EXPECT_THAT(dat, HasSubstr("-0.02 0.25\n0.02 0.25"));
}

std::string ErrorOf(const fs::path& dir) {
  try {
    BuildLoopDocument(dir.string(), ReportOptions());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(LoopPage, BrokenLoopFoldersAreNamedInOneLine) {
  const fs::path empty = ccsrm::testing::ScratchDirectory("loop_page_empty");
  EXPECT_EQ(ErrorOf(empty), empty.string() + ": not a loop folder (no loop.json)");

  const fs::path not_json = WriteLoopFolder("notjson", KnownLoopJson());
  WriteTextFileAtomically((not_json / "loop.json").string(), "{\"schema\": \"ccsrm-loop/1\",");
  EXPECT_EQ(ErrorOf(not_json), (not_json / "loop.json").string() + ": not valid JSON");

  json schema = KnownLoopJson();
  schema["schema"] = "ccsrm-fit/1";
  EXPECT_THAT(ErrorOf(WriteLoopFolder("schema", schema)),
              HasSubstr("loop.json: key 'schema': is \"ccsrm-fit/1\", expected \"ccsrm-loop/1\" "
                        "(written by ccsrm loop)"));

  json missing = KnownLoopJson();
  missing["rounds"][0]["candidates"][1].erase("score");
  const fs::path missing_dir = WriteLoopFolder("missing", missing);
  EXPECT_EQ(ErrorOf(missing_dir), (missing_dir / "loop.json").string() +
                                      ": key 'rounds[0].candidates[1].score': missing");

  json type = KnownLoopJson();
  type["before"]["joints"][4]["rms_deg"][1] = "small";
  EXPECT_THAT(ErrorOf(WriteLoopFolder("type", type)),
              HasSubstr("loop.json: key 'before.joints[4].rms_deg[1]': expected a number or null"));

  json diagnostics = KnownLoopJson();
  diagnostics["rounds"][1]["evidence"]["cross_correlation"]["rate"].erase(0);
  EXPECT_THAT(ErrorOf(WriteLoopFolder("curve", diagnostics)),
              HasSubstr("loop.json: key 'rounds[1].evidence.cross_correlation.rate': has 4 values, "
                        "expected one per lag (5)"));

  json axis = KnownLoopJson();
  axis["unexplained"][1]["axis"] = "z";
  EXPECT_THAT(ErrorOf(WriteLoopFolder("axis", axis)),
              HasSubstr("loop.json: key 'unexplained[1].axis': is 'z', expected x or y"));

  json role = KnownLoopJson();
  role["data"][1]["role"] = "test";
  EXPECT_THAT(ErrorOf(WriteLoopFolder("role", role)),
              HasSubstr("loop.json: key 'data[1].role': is 'test', expected training or holdout"));

  json rounds = KnownLoopJson();
  rounds["rounds"][1]["round"] = 1;
  EXPECT_THAT(ErrorOf(WriteLoopFolder("rounds", rounds)),
              HasSubstr("loop.json: key 'rounds[1].round': expected rounds 1, 2, ..."));

  // The files beside loop.json: a held-out angles file with another
  // layout, a broken fit folder.
  const fs::path header = WriteLoopFolder("header", KnownLoopJson());
  std::string csv = HoldoutCsv();
  csv.replace(csv.find("final_thetax1"), 13, "fitted_thetax1");
  WriteTextFileAtomically((header / "holdout" / "h1.angles.csv").string(), csv);
  EXPECT_THAT(ErrorOf(header), HasSubstr("h1.angles.csv: line 2: column 4 is 'fitted_thetax1_deg', "
                                         "expected 'final_thetax1_deg'"));
  const fs::path fit = WriteLoopFolder("fit", KnownLoopJson());
  WriteTextFileAtomically((fit / "final" / "fit.json").string(), "{\"schema\": \"ccsrm-fit/1\"}");
  EXPECT_THAT(ErrorOf(fit), HasSubstr("final/fit.json: key 'converged': missing"));

  // Each message is one line.
  EXPECT_EQ(ErrorOf(missing_dir).find('\n'), std::string::npos);
}

TEST(LoopPage, MissingFitFoldersAndHeldOutFilesAreNotices) {
  const fs::path dir = WriteLoopFolder("partial", KnownLoopJson());
  fs::remove_all(dir / "final");
  fs::remove(dir / "holdout" / "h1.angles.csv");
  const Document document = BuildLoopDocument(dir.string(), ReportOptions());
  const std::vector<std::string> notices = document.notices();
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_THAT(notices[0], HasSubstr("no final/ (the final model's fit folder)"));
  EXPECT_THAT(notices[1], HasSubstr("no holdout/h1.angles.csv"));
  // The tables stay: they are loop.json's. Only the residual figures go.
  const json summary = ToJson(document);
  EXPECT_EQ(RowOf(summary, "errors", "data", "held out")["before_deg"], 0.1212);
  for (const FigureBlock* block : document.figures()) {
    EXPECT_EQ(block->figure.name.find("residual"), std::string::npos) << block->figure.name;
  }
}

TEST(LoopPage, AFinalFitOfAnotherArmIsANoticeNotACrash) {
  const fs::path dir = WriteLoopFolder("other_arm", KnownLoopJson());
  // final/ with the angles of 11 joints: nothing to put beside declared/.
  std::string csv = testing::KnownAnglesCsv(1.0);
  std::string cut;
  std::size_t start = 0;
  while (start < csv.size()) {
    const std::size_t end = csv.find('\n', start);
    std::string line = csv.substr(start, end - start);
    if (line[0] != '#') {
      // Drop the last joint's 6 columns.
      for (int k = 0; k < 6; ++k) line.erase(line.rfind(','));
    }
    cut += line + "\n";
    start = end + 1;
  }
  WriteTextFileAtomically((dir / "final" / "g4.angles.csv").string(), cut);
  json fit = testing::KnownFitJson();
  fit["experiments"][0]["noise_deg"].erase(11);
  fit["experiments"][0]["start"]["per_joint"].erase(11);
  fit["experiments"][0]["fitted"]["per_joint"].erase(11);
  WriteTextFileAtomically((dir / "final" / "fit.json").string(), fit.dump());
  const Document document = BuildLoopDocument(dir.string(), ReportOptions());
  ASSERT_FALSE(document.notices().empty());
  EXPECT_THAT(document.notices()[0], HasSubstr("with the joints of declared/"));
}

TEST(LoopPage, AFailedDeclaredFitGivesAPageThatSaysSo) {
  // What ccsrm loop writes when the declared model's fit fails: no rounds,
  // empty diagnostics, no fit folders, no held-out errors.
  json loop = KnownLoopJson();
  loop["rounds"] = json::array();
  loop["added_effects"] = json::array();
  loop["parameters"] = json::object();
  loop["unexplained"] = json::array();
  loop["holdout_rms_before_deg"] = nullptr;
  loop["holdout_rms_after_deg"] = nullptr;
  loop["holdout_before"] = nullptr;
  loop["holdout_after"] = nullptr;
  loop["declared_fit"]["termination"] = "failed";
  loop["final_evidence"] = {{"rms_deg", 0.0},
                            {"effective_samples", 0.0},
                            {"pooled", json::object()},
                            {"lags_s", json::array()},
                            {"cross_correlation", json::object()},
                            {"experiments", json::array()},
                            {"channels", json::array()}};
  const fs::path dir = WriteLoopFolder("failed", loop);
  fs::remove_all(dir / "declared");
  fs::remove_all(dir / "final");
  fs::remove_all(dir / "holdout");
  const Document document = BuildLoopDocument(dir.string(), ReportOptions());
  EXPECT_EQ(document.title, "Closing the loop — no effect added");
  const std::vector<std::string> notices = document.notices();
  ASSERT_GE(notices.size(), 1u);
  EXPECT_THAT(notices[0], HasSubstr("declared model's fit failed"));
  // Only the errors figure (training bars) is left to draw.
  ASSERT_EQ(document.figures().size(), 1u);
  EXPECT_EQ(document.figures()[0]->figure.panels.size(), 2u);
  const json summary = ToJson(document);
  EXPECT_EQ(summary["tables"]["errors"]["rows"].size(), 1u);  // no held-out row
  EXPECT_FALSE(summary["tables"]["errors_per_joint"]["rows"][0].contains("holdout_x_before_deg"));
}

TEST(LoopPage, CorrectedDeclaredValuesAreShownWithTheirConfigurationDifference) {
  // Issue 28: a declared value the loop corrected, as loop.json writes it.
  json loop = KnownLoopJson();
  loop["declared_corrections"] = json::array(
      {{{"parameter", "declared.segment2.hole_circle_radius"},
        {"config_key", "arm.segments[1].hole_circle_radius_m"},
        {"declared", 0.016},
        {"corrected", 0.0152008},
        {"delta", -0.0007992},
        {"relative", -0.04995},
        {"relative_std_error", 0.00035},
        {"relative_ci95", {-0.05063, -0.04927}},
        {"identifiable", true},
        {"indistinguishable", json::array()},
        {"sentence", "the declared segment 2 hole circle radius (...) is off by -0.0007992 m"}}});
  const fs::path dir = WriteLoopFolder("declared", loop);
  const Document document = BuildLoopDocument(dir.string(), ReportOptions());
  const json summary = ToJson(document);
  ASSERT_TRUE(summary["tables"].contains("declared_corrections"));
  const json& rows = summary["tables"]["declared_corrections"]["rows"];
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["value"], "arm.segments[1].hole_circle_radius_m");
  EXPECT_DOUBLE_EQ(rows[0]["declared"].get<double>(), 0.016);
  EXPECT_DOUBLE_EQ(rows[0]["corrected"].get<double>(), 0.0152008);
  // A loop.json without the key (written before issue 28) has no such table.
  const Document before =
      BuildLoopDocument(WriteLoopFolder("before", KnownLoopJson()).string(), ReportOptions());
  EXPECT_FALSE(ToJson(before)["tables"].contains("declared_corrections"));
}

TEST(LoopPage, AnAdditionTakenBackHasARowAndASentence) {
  // Issue 28: the backward step of round 2 took back round 1's addition, as
  // loop.json writes it.
  json loop = KnownLoopJson();
  const json check = {{"round", 2},
                      {"name", "table_tilt"},
                      {"parameters", {"table_tilt.lateral_rad"}},
                      {"size_significant", false},
                      {"delta_chi2_zeroed", 0.4},
                      {"refitted", true},
                      {"delta_bic_keep", -9.1},
                      {"rms_deg_without", 0.0301},
                      {"holdout_rms_deg_without", 0.0299},
                      {"taken_back", true},
                      {"reason", "took back table_tilt: after x its size is indistinguishable"}};
  loop["rounds"][1]["backward"] = json::array({check});
  loop["rounds"][1]["taken_back"] = check;
  loop["taken_back"] = json::array({check});
  const Document document =
      BuildLoopDocument(WriteLoopFolder("taken_back", loop).string(), ReportOptions());
  const json summary = ToJson(document);
  ASSERT_TRUE(summary["tables"].contains("round_2_backward"));
  const json& rows = summary["tables"]["round_2_backward"]["rows"];
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["addition"], "table_tilt");
  EXPECT_EQ(rows[0]["taken_back"], "yes");
  EXPECT_DOUBLE_EQ(rows[0]["delta_bic_keep"].get<double>(), -9.1);
  EXPECT_FALSE(summary["tables"].contains("round_1_backward"));  // nothing earlier to check
  bool sentence = false;
  for (const Section& section : document.sections) {
    for (const Block& block : section.blocks) {
      if (const auto* p = std::get_if<Paragraph>(&block)) {
        sentence |=
            p->text.find("Backward step, round 2: took back table_tilt") != std::string::npos;
      }
    }
  }
  EXPECT_TRUE(sentence);
  // A loop.json without the key (written before the backward step) has no such table.
  const Document before = BuildLoopDocument(
      WriteLoopFolder("before_backward", KnownLoopJson()).string(), ReportOptions());
  EXPECT_FALSE(ToJson(before)["tables"].contains("round_2_backward"));
}

// Renders the loop page in headless Chromium into
// <build>/report_screenshots/loop.png for a person to look at; checks only
// that an image of some size came out.
TEST(LoopPage, ScreenshotInHeadlessChromium) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  if (!testing::ProgramOnPath("chromium")) GTEST_SKIP() << "chromium not installed";
  const fs::path dir = WriteLoopFolder("shot", KnownLoopJson());
  const fs::path out = dir.parent_path() / "report";
  fs::remove_all(out);  // an earlier run's page, perhaps of an older ccsrm
  MakeReport(dir.string(), out.string(), ReportOptions());
  const fs::path shots = fs::path(CCSRM_BINARY_DIR) / "report_screenshots";
  fs::create_directories(shots);
  const fs::path png = shots / "loop.png";
  fs::remove(png);
  const std::string command =
      "timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars "
      "--force-device-scale-factor=1 --window-size=1400,9000 --screenshot=" +
      png.string() + " file://" + fs::absolute(out / "index.html").string() + " >/dev/null 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  ASSERT_TRUE(fs::exists(png)) << command;
  EXPECT_GT(fs::file_size(png), 50000u);
  std::printf("screenshot: %s\n", png.string().c_str());
}

}  // namespace
}  // namespace ccsrm::reports
