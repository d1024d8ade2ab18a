#pragma once
// A fit folder whose every number is known, in the layout of
// identify/src/fit_output.cc: fit.json of a fit of T_p (identifiable) and
// c_lc (not) with mu fixed, experiment g4 of the paper arm (12 joints, 5
// frames) with its angles file and a fitted run file that carries only the
// configuration. The fit page test checks it value by value; the loop page
// test uses two of them as a loop's declared/ and final/ folders.
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/run_file.h"

namespace ccsrm::reports::testing {

using nlohmann::json;

inline constexpr std::size_t kJoints = 12;  // the paper arm: two segments of 6
inline constexpr std::size_t kFrames = 5;

// The measured θx of joint j (0-based) in frame i, deg; fitted adds
// scale · 0.01 (j + 1); θy is measured only in even frames.
inline double MeasuredX(std::size_t i, std::size_t j) { return 0.5 * i + 0.1 * j; }
inline double FittedX(std::size_t i, std::size_t j, double scale = 1.0) {
  return MeasuredX(i, j) + scale * 0.01 * (j + 1);
}

// θy barely moves (a planar protocol): no fit percent, its motion instead.
inline json Errors(double scale) {
  json joints = json::array();
  for (std::size_t j = 0; j < kJoints; ++j) {
    joints.push_back({{"joint", j + 1},
                      {"rms_deg", {scale * 0.01 * (j + 1), scale * 0.002 * (j + 1)}},
                      {"fit_percent", {100.0 - scale * (j + 1), nullptr}},
                      {"motion_rms_deg", {0.7071067811865476, 0.003 * (j + 1)}},
                      {"samples", {kFrames, 3}}});
  }
  return {{"rms_deg", scale * 0.031164149880225006},
          {"fit_percent", 100.0 - scale * 1.78716750501047},
          {"per_joint", joints},
          {"axes", {"theta_x", "theta_y"}}};
}

// fit.json of a fit of T_p (identifiable) and c_lc (not), with mu fixed.
inline json KnownFitJson() {
  json parameters = {{"T_p",
                      {{"value", 65.2939046830209},
                       {"units", "N"},
                       {"free", true},
                       {"start", 50.0},
                       {"std_error", 0.37239821776687093},
                       {"ci95", {64.56039846616547, 66.02741089987633}},
                       {"identifiable", true},
                       {"bounds", {1.0, 500.0}},
                       {"scale", 50.0},
                       {"at_bound", false}}},
                     {"c_lc",
                      {{"value", 0.6125325149326545},
                       {"units", "N m s/rad"},
                       {"free", true},
                       {"start", 0.05},
                       {"std_error", nullptr},
                       {"ci95", nullptr},
                       {"identifiable", false},
                       {"bounds", {0.0, 10.0}},
                       {"scale", 0.05},
                       {"at_bound", false}}},
                     {"mu", {{"value", 0.0}, {"units", "1"}, {"free", false}, {"start", 0.0}}}};
  json experiment = {{"name", "g4"},
                     {"path", "data/g4.h5"},
                     {"angles_from_pipeline", true},
                     {"noise_deg", json::array()},
                     {"noise_source", "joint twist scatter"},
                     {"start", Errors(2.0)},
                     {"fitted", Errors(1.0)},
                     {"run",
                      {{"status", "completed"},
                       {"message", "completed"},
                       {"wall_time_s", 2.0},
                       {"real_time_factor", 2.75}}},
                     {"run_file", "g4.fit.h5"},
                     {"angles_file", "g4.angles.csv"}};
  for (std::size_t j = 0; j < kJoints; ++j) experiment["noise_deg"].push_back(0.03 + 0.001 * j);
  return {{"schema", "ccsrm-fit/1"},
          {"converged", true},
          {"termination", "converged"},
          {"message", "the last step moved every parameter by less than 0.1 of its std error"},
          {"iterations", 11},
          {"simulations", 33},
          {"threads", 2},
          {"wall_time_s", 64.540907955},
          {"relative_step", 0.01},
          {"free", {"T_p", "c_lc"}},
          {"parameters", parameters},
          {"rms_deg", 0.031164149880225006},
          {"fit_percent", 98.21283249498953},
          {"rms_deg_start", 0.08273468465977663},
          {"errors", Errors(1.0)},
          {"start_errors", Errors(2.0)},
          {"cost_history", {48948.15073811071, 6245.828414384231, 6203.168114212665}},
          {"initial_cost", 48948.15073811071},
          {"final_cost", 6203.168114212665},
          {"residuals", 13172},
          {"effective_samples", 247.2889211724696},
          {"residual_variance", 0.9420148996526447},
          {"covariance_available", true},
          {"covariance_message", ""},
          {"correlation", {{1.0, nullptr}, {nullptr, nullptr}}},
          {"singular_values", {955.7614774152829, 0.5142213050620882}},
          {"unidentifiable",
           {{{"combination", "1.00 c_lc"},
             {"components", {{"c_lc", 0.9999999985701546}}},
             {"singular_value", 0.5142213050620882},
             {"relative_std_error", 13.775340761434506}}}},
          {"experiments", {experiment}}};
}

// θx fitted = measured + residual_scale · 0.01 (j + 1).
inline std::string KnownAnglesCsv(double residual_scale = 1.0) {
  std::string csv = "# g4: measured and fitted joint angles [deg]\ntime_s";
  for (std::size_t j = 1; j <= kJoints; ++j) {
    for (const char* axis : {"x", "y"}) {
      for (const char* kind : {"measured", "fitted", "residual"}) {
        csv += std::string(",") + kind + "_theta" + axis + std::to_string(j) + "_deg";
      }
    }
  }
  csv += "\n";
  char cell[64];
  for (std::size_t i = 0; i < kFrames; ++i) {
    std::snprintf(cell, sizeof(cell), "%.6f", 0.01 * i);
    csv += cell;
    for (std::size_t j = 0; j < kJoints; ++j) {
      const double m = MeasuredX(i, j), f = FittedX(i, j, residual_scale);
      std::snprintf(cell, sizeof(cell), ",%.6f,%.6f,%.6f", m, f, f - m);
      csv += cell;
      if (i % 2 == 0) {
        std::snprintf(cell, sizeof(cell), ",%.6f,%.6f,%.6f", 0.01, 0.0, -0.01);
        csv += cell;
      } else {
        csv += ",,0.000000,";  // θy not measured in this frame
      }
    }
    csv += "\n";
  }
  return csv;
}

// The fitted run: only its configuration (the paper arm's two segments)
// matters to the page.
inline datasets::RunFile FittedRun() {
  const std::size_t t = 2, j = kJoints, c = 6;
  datasets::RunFile run;
  run.case_name = "custom";
  run.config_yaml = ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
  run.time = datasets::Array({t});
  run.time.at(1) = 0.01;
  run.joint_angles = datasets::Array({t, j, 2});
  run.joint_rates = datasets::Array({t, j, 2});
  run.link_pose = datasets::Array({t, j, 7});
  run.input_tension = datasets::Array({t, c});
  run.input_length_change = datasets::Array({t, c});
  run.stuck_nodes = datasets::Array({t, c});
  run.constraint_violation = datasets::Array({t});
  run.energy = datasets::Array({t, 3});
  for (std::size_t k = 0; k < c; ++k) {
    run.cables.push_back(
        {datasets::Array({t, 14}, 100.0), datasets::Array({t, 13}), datasets::Array({t, 13})});
  }
  return run;
}

// Writes fit.json, g4.angles.csv and g4.fit.h5 into `dir` (created).
inline void WriteKnownFitFolder(const std::filesystem::path& dir, const json& fit,
                                const std::string& angles_csv) {
  std::filesystem::create_directories(dir);
  WriteTextFileAtomically((dir / "fit.json").string(), fit.dump(2));
  WriteTextFileAtomically((dir / "g4.angles.csv").string(), angles_csv);
  datasets::WriteRunFile((dir / "g4.fit.h5").string(), FittedRun());
}

}  // namespace ccsrm::reports::testing
