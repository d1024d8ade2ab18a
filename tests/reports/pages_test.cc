// The run and experiment pages built from small records whose every number
// is known, so the tables can be checked value by value (no gnuplot needed:
// building a page only describes its figures).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/reports/report.h"
#include "ccsrm/sim/protocol.h"

namespace ccsrm::reports {
namespace {
using ::testing::HasSubstr;

constexpr double kDeg = 180.0 / M_PI;

// A value as a table shows it with 3 significant digits, or 3 decimals.
double Sig3(double x) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", x);
  return std::stod(text);
}
double Fixed3(double x) { return std::round(x * 1000) / 1000; }

std::string PaperYaml() {
  return ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
}

// The paper arm (12 joints, 6 cables), by default over 0..2 s in 5 frames
// (`frames` frames `dt` apart). Joint j
// (0-based) has θx = 0.01 (j + 1) i rad and θy = -0.001 (j + 1) i rad in
// frame i; cable k has input tension 100 + k + i N; cable 3's stuck count
// goes 0, 2, 5, 5, 1 (and repeats).
// With `config_yaml` and `cables` given, another arm of 12 joints.
datasets::RunFile KnownRun(const std::string& case_name, std::size_t frames = 5, double dt = 0.5,
                           const std::string& config_yaml = PaperYaml(), std::size_t cables = 6) {
  const std::size_t t = frames, j = 12, c = cables;
  datasets::RunFile run;
  run.case_name = case_name;
  run.config_yaml = config_yaml;
  run.created = "2026-01-02T03:04:05Z";
  run.wall_time_s = 0.8;
  run.steps = 1234;
  run.rejected_steps = 5;
  run.rhs_evaluations = 9876;
  run.time = datasets::Array({t});
  run.joint_angles = datasets::Array({t, j, 2});
  run.joint_rates = datasets::Array({t, j, 2});
  run.link_pose = datasets::Array({t, j, 7});
  run.input_tension = datasets::Array({t, c});
  run.input_length_change = datasets::Array({t, c});
  run.stuck_nodes = datasets::Array({t, c});
  run.constraint_violation = datasets::Array({t});
  run.energy = datasets::Array({t, 3});
  for (std::size_t i = 0; i < t; ++i) {
    run.time.at(i) = dt * i;
    for (std::size_t q = 0; q < j; ++q) {
      run.joint_angles.at(i, q, 0) = 0.01 * (q + 1) * i;
      run.joint_angles.at(i, q, 1) = -0.001 * (q + 1) * i;
    }
    for (std::size_t k = 0; k < c; ++k) run.input_tension.at(i, k) = 100.0 + k + i;
    run.constraint_violation.at(i) = i == 3 ? 3.2e-9 : 1e-10 * i;
    run.energy.at(i, 0) = 0.001 * i;
    run.energy.at(i, 1) = 2.5;
    run.energy.at(i, 2) = 0.01 * i;
  }
  const double stuck3[] = {0, 2, 5, 5, 1};
  for (std::size_t i = 0; i < t; ++i) run.stuck_nodes.at(i, 2) = stuck3[i % 5];
  for (std::size_t k = 0; k < c; ++k) {
    run.cables.push_back(
        {datasets::Array({t, 14}, 100.0), datasets::Array({t, 13}), datasets::Array({t, 13})});
  }
  return run;
}

// The JSON row whose first column shows `first`.
nlohmann::json Row(const nlohmann::json& summary, const std::string& table, const std::string& key,
                   const nlohmann::json& first) {
  for (const nlohmann::json& row : summary["tables"][table]["rows"]) {
    if (row[key] == first) return row;
  }
  ADD_FAILURE() << "table " << table << " has no row " << first;
  return nlohmann::json();
}

TEST(RunPage, KnownRunShowsItsStoredNumbers) {
  const Document document = BuildRunDocument(KnownRun("2"), "known.h5", ReportOptions());
  const nlohmann::json json = ToJson(document);
  EXPECT_EQ(json["kind"], "run");
  EXPECT_EQ(json["title"], "Simulation run — paper case 2");
  EXPECT_TRUE(json["notices"].empty()) << json["notices"];
  // Solver statistics exactly as stored; the real-time factor 2 s / 0.8 s.
  auto solver = [&](const std::string& quantity) {
    return Row(json, "solver", "quantity", quantity)["value"];
  };
  EXPECT_EQ(solver("wall time"), 0.8);
  EXPECT_EQ(solver("real-time factor"), 2.5);
  EXPECT_EQ(solver("accepted steps"), 1234);
  EXPECT_EQ(solver("rejected steps"), 5);
  EXPECT_EQ(solver("right-hand-side evaluations"), 9876);
  EXPECT_EQ(solver("largest constraint violation ‖Φ‖"), 3.2e-9);
  EXPECT_EQ(Row(json, "run", "quantity", "case")["value"], "2 (friction on all cables)");
  EXPECT_EQ(Row(json, "run", "quantity", "planned amplitude")["value"], 6.0);

  // The run is shorter than the 20 s ramp: the middle and the end of it.
  const nlohmann::json& instants = json["tables"]["instants"]["rows"];
  ASSERT_EQ(instants.size(), 2u);
  EXPECT_EQ(instants[0]["instant"], "mid-run");
  EXPECT_EQ(instants[0]["time_s"], 1.0);
  EXPECT_EQ(instants[1]["instant"], "end of run");
  EXPECT_EQ(instants[1]["frame"], 4);

  // Joint 7 at the end: 0.28 rad; the plan row: 6° · quintic(2 s / 20 s).
  const nlohmann::json joint7 = Row(json, "theta_x_at_instants", "joint", 7);
  EXPECT_EQ(joint7["segment"], 2);
  EXPECT_EQ(joint7["theta_x_deg_end_of_run"], Fixed3(0.28 * kDeg));
  const nlohmann::json plan = Row(json, "theta_x_at_instants", "joint", "plan");
  EXPECT_EQ(plan["theta_x_deg_end_of_run"], Fixed3(6.0 * sim::QuinticBlend(0.1)));
  EXPECT_EQ(Row(json, "theta_y_at_instants", "joint", 1)["theta_y_deg_mid_run"],
            Sig3(-0.002 * kDeg));

  const nlohmann::json cable2 = Row(json, "input_tension", "cable", 2);
  EXPECT_EQ(cable2["segment"], 1);
  EXPECT_EQ(cable2["min_n"], 101.0);
  EXPECT_EQ(cable2["max_n"], 105.0);
  EXPECT_EQ(cable2["tension_n_mid_run"], 103.0);
  EXPECT_EQ(Row(json, "input_tension", "cable", 5)["segment"], 2);
  const nlohmann::json cable3 = Row(json, "stuck_nodes", "cable", 3);
  EXPECT_EQ(cable3["hole_nodes"], 13);
  EXPECT_EQ(cable3["stuck_mid_run"], 5);
  EXPECT_EQ(cable3["stuck_end_of_run"], 1);
  EXPECT_EQ(cable3["max_stuck"], 5);
  EXPECT_EQ(Row(json, "energy_at_instants", "instant", "end of run")["dissipated_j"], 0.04);

  // Figures: one panel per segment, plan dashed, axes with units.
  std::vector<std::string> names;
  for (const FigureBlock* figure : document.figures()) names.push_back(figure->figure.name);
  EXPECT_THAT(names, ::testing::ElementsAre("theta_x", "theta_y", "input_tension", "input_length",
                                            "stuck_nodes", "cable_tension", "diagnostics"));
  const Figure& theta = document.figures()[0]->figure;
  ASSERT_EQ(theta.panels.size(), 2u);
  EXPECT_EQ(theta.panels[1].title, "Segment 2 (joints 7–12)");
  EXPECT_EQ(theta.panels[0].series.size(), 7u);  // six joints and the plan
  EXPECT_EQ(theta.panels[0].series.back().style, SeriesStyle::kDashed);
  for (const FigureBlock* figure : document.figures()) {
    std::string why;
    EXPECT_TRUE(figure->figure.IsValid(&why)) << why;
  }
}

// Issue 32: "Simulation run — paper case 2" and captions citing the paper's
// figures on a user's arm. A run of the protocol on another arm is named by
// its case and its arm as configured, with its plan, and no paper word.
TEST(RunPage, AnotherArmIsNamedAsConfiguredWithoutThePapersWords) {
  const std::string three_segment =
      ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  const Document document =
      BuildRunDocument(KnownRun("1", 5, 0.5, three_segment, 9), "arm3.h5", ReportOptions());
  const nlohmann::json json = ToJson(document);
  EXPECT_EQ(json["title"],
            "Simulation run — case 1 (no friction), 3 segments of 4, 4 and 4 links (12 joints), 9 "
            "driving cables");
  EXPECT_EQ(Row(json, "run", "quantity", "case")["value"], "1 (no friction)");
  EXPECT_EQ(Row(json, "run", "quantity", "arm")["value"],
            "3 segments of 4, 4 and 4 links (12 joints), 9 driving cables");
  EXPECT_EQ(Row(json, "run", "quantity", "protocol")["value"],
            "θx of every joint 0 → 8° along a quintic over 20 s, held 4 s, back over 20 s, at "
            "rest 4 s; θy planned 0");
  // The protocol's plan on any arm: 8° · quintic(2 s / 20 s) at the end.
  EXPECT_EQ(Row(json, "theta_x_at_instants", "joint", "plan")["theta_x_deg_end_of_run"],
            Fixed3(8.0 * sim::QuinticBlend(0.1)));
  EXPECT_EQ(Row(json, "input_tension", "cable", 9)["segment"], 3);
  const std::string html = ToHtml(document);
  for (const char* word : {"paper", "Paper", "Fig."}) {
    EXPECT_EQ(html.find(word), std::string::npos) << word << " on the page of another arm";
  }
  EXPECT_THAT(html, HasSubstr("Case 1 (no friction) on the configured arm (3 segments"));

  // The paper's arm in a paper case: its case and figures by name.
  const std::string paper = ToHtml(BuildRunDocument(KnownRun("2"), "known.h5", ReportOptions()));
  EXPECT_THAT(paper, HasSubstr("Paper case 2 (friction on all cables) on the paper's arm"));
  EXPECT_THAT(paper, HasSubstr("the paper's Fig. 22"));
  EXPECT_THAT(paper, HasSubstr("the layout of the paper's Figs. 16 and 18–21"));
  // The paper's arm with one hole moved is the user's: no paper words.
  std::string moved = PaperYaml();
  moved.replace(moved.find("hole_angle_deg: 300.0"), 21, "hole_angle_deg: 290.0");
  const std::string edited =
      ToHtml(BuildRunDocument(KnownRun("2", 5, 0.5, moved), "moved.h5", ReportOptions()));
  EXPECT_EQ(edited.find("paper"), std::string::npos);
  EXPECT_THAT(edited, HasSubstr("Case 2 (friction on all cables) on the configured arm"));
}

TEST(RunPage, PaperInstantsWithinAFullRun) {
  // 0 .. 48 s at 1.5 s: end of ramp 20 s, mid-hold 22 s, end of return
  // 44 s, end of run 48 s, each at its nearest frame.
  const nlohmann::json json =
      ToJson(BuildRunDocument(KnownRun("3", 33, 1.5), "full.h5", ReportOptions()));
  const nlohmann::json& instants = json["tables"]["instants"]["rows"];
  ASSERT_EQ(instants.size(), 4u);
  EXPECT_EQ(instants[0]["instant"], "end of ramp");
  EXPECT_EQ(instants[0]["time_s"], 19.5);
  EXPECT_EQ(instants[1]["instant"], "mid-hold");
  EXPECT_EQ(instants[1]["time_s"], 22.5);
  EXPECT_EQ(instants[2]["instant"], "end of return");
  EXPECT_EQ(instants[2]["time_s"], 43.5);
  EXPECT_EQ(instants[3]["instant"], "end of run");
  EXPECT_EQ(instants[3]["time_s"], 48.0);
  // Instants that fall on one frame are shown once.
  const nlohmann::json coarse =
      ToJson(BuildRunDocument(KnownRun("3", 5, 12.0), "coarse.h5", ReportOptions()));
  EXPECT_EQ(coarse["tables"]["instants"]["rows"].size(), 2u);  // 24 s and 48 s
}

TEST(RunPage, CustomCaseOmitsThePlanAndSaysSo) {
  ReportOptions options;
  options.instants_s = {0.5};
  const Document document = BuildRunDocument(KnownRun("custom"), "custom.h5", options);
  const nlohmann::json json = ToJson(document);
  ASSERT_EQ(json["notices"].size(), 1u);
  EXPECT_THAT(json["notices"][0].get<std::string>(), HasSubstr("planned motion is not drawn"));
  EXPECT_EQ(json["tables"]["theta_x_at_instants"]["rows"].size(), 12u);  // no plan row
  EXPECT_EQ(json["tables"]["instants"]["rows"][0]["instant"], "t = 0.5 s");
  EXPECT_EQ(document.figures()[0]->figure.panels[0].series.size(), 6u);
}

TEST(RunPage, RecordedProtocolIsPlannedAgainWithItsErrorInBothAxes) {
  // A run of any case that recorded its protocol (protocol_yaml, issue 25)
  // is planned again from it: the plan is drawn and the error to it in θx
  // and θy gets a figure each.
  datasets::RunFile run = KnownRun("custom");
  run.protocol_yaml =
      ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/protocols/two-axis.yaml");
  ReportOptions options;
  options.instants_s = {1.0};
  const Document document = BuildRunDocument(run, "two-axis.h5", options);
  const nlohmann::json json = ToJson(document);
  EXPECT_TRUE(json["notices"].empty()) << json["notices"];
  std::vector<std::string> names;
  for (const FigureBlock* f : document.figures()) names.push_back(f->figure.name);
  EXPECT_THAT(names, ::testing::IsSupersetOf({"plan_error_theta_x", "plan_error_theta_y"}));
  // 12 joints and a plan row for each: the segments are planned apart.
  EXPECT_EQ(json["tables"]["theta_x_at_instants"]["rows"].size(), 24u);
  // The protocol in words, from the recorded file rather than the configuration.
  EXPECT_THAT(json.dump(), HasSubstr("segment 1 move, hold, sine, hold, move, hold"));
}

TEST(RunPage, UnreadableConfigurationStillGivesAPage) {
  datasets::RunFile run = KnownRun("1");
  run.config_yaml = "arm: [not a configuration";
  const Document document = BuildRunDocument(run, "odd.h5", ReportOptions());
  const nlohmann::json json = ToJson(document);
  ASSERT_EQ(json["notices"].size(), 1u);
  EXPECT_THAT(json["notices"][0].get<std::string>(), HasSubstr("odd.h5: attribute 'config_yaml'"));
  const Figure& theta = document.figures()[0]->figure;
  ASSERT_EQ(theta.panels.size(), 1u);
  EXPECT_EQ(theta.panels[0].title, "All joints 1–12");
}

TEST(RunPage, DivergedRunIsFlagged) {
  datasets::RunFile run = KnownRun("2");
  run.status = datasets::RunStatus::kDiverged;
  run.status_message = "constraint violation 3.2e-3 above bound 1e-3 at t = 1.99 s";
  const nlohmann::json json = ToJson(BuildRunDocument(run, "bad.h5", ReportOptions()));
  ASSERT_EQ(json["notices"].size(), 1u);
  EXPECT_THAT(json["notices"][0].get<std::string>(), HasSubstr("diverged"));
  EXPECT_EQ(Row(json, "run", "quantity", "status")["value"], "diverged");
}

TEST(ReportOptions, AreChecked) {
  ReportOptions options;
  std::string why;
  EXPECT_TRUE(options.IsValid(&why));
  options.instants_s = {1, 2, 3, 4, 5, 6, 7};
  EXPECT_FALSE(options.IsValid(&why));
  options.instants_s = {NAN};
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_THROW(BuildRunDocument(KnownRun("1"), "x.h5", options), InputError);
}

// Two markers on link1 and a ground marker over 4 frames, processed: the
// quality figures as `ccsrm mocap process` stores them.
datasets::ExperimentFile KnownExperiment() {
  const double nan = NAN;
  datasets::ExperimentFile e;
  e.name = "known";
  e.source = datasets::ExperimentSource::kGenerated;
  e.config_yaml = PaperYaml();
  e.input_time = datasets::Array({2});
  e.input_time.values = {0.0, 1.0};
  e.input_length_change = datasets::Array({2, 6});
  e.mocap_time = datasets::Array({4});
  e.mocap_time.values = {0.0, 0.01, 0.02, 0.03};
  e.marker_names = {"B0_A", "L01_A", "L01_B"};
  e.mocap_markers = datasets::Array({4, 3, 3}, 0.1);
  for (std::size_t k = 0; k < 3; ++k) e.mocap_markers.at(1, 2, k) = nan;  // L01_B lost once
  e.rigid_bodies = {{"base", {"B0_A"}, datasets::Array({1, 3})},
                    {"link1", {"L01_A", "L01_B"}, datasets::Array({2, 3})}};
  auto put = [&](const std::string& name, std::vector<double> values, const std::string& units) {
    datasets::Array a({values.size()});
    a.values = std::move(values);
    e.mocap_quality[name] = a;
    e.mocap_quality_units[name] = units;
  };
  put("marker_visibility", {1.0, 1.0, 0.75}, "1");
  put("marker_gaps_before_fill", {0, 0, 1}, "1");
  put("marker_gaps_after_fill", {0, 0, 0}, "1");
  put("marker_longest_gap_before_fill", {0, 0, 1}, "frames");
  put("marker_longest_gap_after_fill", {0, 0, 0}, "frames");
  put("marker_spline_filled_frames", {0, 0, 1}, "frames");
  put("marker_rigid_filled_frames", {0, 0, 0}, "frames");
  put("marker_fit_rms", {nan, 0.00021, 0.00019}, "m");
  put("body_fit_rms", {nan, 0.0002}, "m");
  put("body_frames_lost", {0, 0}, "frames");
  put("body_whole_loss_frames", {0, 0}, "frames");
  put("joint_frames_lost", std::vector<double>(12, 0.0), "frames");
  put("joint_max_abs_twist", std::vector<double>(12, 0.001), "rad");
  put("ground_fit_rms", {0.00005}, "m");
  e.measured_joint_angles = datasets::Array({4, 12, 2}, 0.01);
  return e;
}

TEST(ExperimentPage, ShowsTheStoredQualityFigures) {
  const Document document =
      BuildExperimentDocument(KnownExperiment(), "known_exp.h5", ReportOptions());
  const nlohmann::json json = ToJson(document);
  EXPECT_EQ(json["kind"], "experiment");
  EXPECT_TRUE(json["notices"].empty()) << json["notices"];
  const nlohmann::json marker = Row(json, "markers", "marker", "L01_B");
  EXPECT_EQ(marker["body"], "link1");
  EXPECT_EQ(marker["visibility_percent"], 75.0);
  EXPECT_EQ(marker["longest_gap_before_fill"], 1);
  EXPECT_EQ(marker["fit_rms_mm"], 0.19);
  EXPECT_TRUE(Row(json, "markers", "marker", "B0_A")["fit_rms_mm"].is_null());
  EXPECT_EQ(Row(json, "bodies", "body", "link1")["fit_rms_mm"], 0.2);
  EXPECT_EQ(Row(json, "joints", "joint", 12)["max_abs_twist_deg"], Fixed3(0.001 * kDeg));
  EXPECT_EQ(Row(json, "world_frame", "quantity", "ground fit RMS")["value"], 0.05);
  EXPECT_EQ(Row(json, "measured_range", "joint", 1)["theta_x_max_deg"], Fixed3(0.01 * kDeg));
  // The gap timeline draws L01_B's lost frame as one bar, half a frame wide
  // on each side.
  const Figure& gaps = document.figures()[0]->figure;
  EXPECT_EQ(gaps.name, "marker_gaps");
  ASSERT_EQ(gaps.panels[0].series[0].y, std::vector<double>{3.0});
  EXPECT_NEAR(gaps.panels[0].series[0].x[0], 0.005, 1e-12);
  EXPECT_NEAR(gaps.panels[0].series[0].x[1], 0.015, 1e-12);
}

TEST(ExperimentPage, AQualityFigureOfTheWrongUnitsIsLeftOutWithANotice) {
  datasets::ExperimentFile e = KnownExperiment();
  e.mocap_quality_units["marker_fit_rms"] = "mm";
  const nlohmann::json json = ToJson(BuildExperimentDocument(e, "odd_exp.h5", ReportOptions()));
  ASSERT_EQ(json["notices"].size(), 1u);
  EXPECT_THAT(json["notices"][0].get<std::string>(), HasSubstr("marker_fit_rms"));
  EXPECT_TRUE(Row(json, "markers", "marker", "L01_A")["fit_rms_mm"].is_null());
}

TEST(ExperimentPage, UnprocessedExperimentSaysWhatToRun) {
  datasets::ExperimentFile e = KnownExperiment();
  e.mocap_quality.clear();
  e.mocap_quality_units.clear();
  e.measured_joint_angles.reset();
  const Document document = BuildExperimentDocument(e, "raw.h5", ReportOptions());
  const nlohmann::json json = ToJson(document);
  ASSERT_EQ(json["notices"].size(), 1u);
  EXPECT_THAT(json["notices"][0].get<std::string>(), HasSubstr("ccsrm mocap process --in raw.h5"));
  EXPECT_FALSE(json["tables"].contains("markers"));
  EXPECT_EQ(document.figures().size(), 2u);  // gap timeline and inputs
}

}  // namespace
}  // namespace ccsrm::reports
