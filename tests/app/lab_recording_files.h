#pragma once
// Issue 27's "a lab's recording, rebuilt", shared by the fast test (case 1,
// clocks) and the slow one (case 2, identify): a generated experiment turned
// into what a lab records — a C3D file of its markers with a trigger pulse
// train on an analog channel, and a 500 Hz log of motor angles (drum radius,
// gear ratio, one motor reversed) on a clock that starts 1.37 s earlier,
// runs 80 ppm fast and stamps its samples with jitter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "run_ccsrm.h"

namespace ccsrm::testing::lab {

namespace fs = std::filesystem;
using Outcome = CommandOutcome;

constexpr double kOffsetS = 1.37;    // the log's time at mocap time 0
constexpr double kDrift = 80e-6;     // the log's clock runs 80 ppm fast
constexpr double kJitterS = 0.1e-3;  // standard deviation of the log's time stamps
constexpr double kLogStepS = 0.002;  // 500 Hz
constexpr double kDrumRadiusM = 0.012;
constexpr double kGearRatio = 19.0;
// The controller raises its sync output at some of its ticks, at irregular
// intervals (a regular train could be paired one pulse off): roughly at these
// mocap times, the first before the markers start (only the log sees it).
// The log stamps the tick (with its jitter); the C3D file's analog channel
// sees the pulse rise over 2 ms (a TTL edge through the A/D's filter).
const std::vector<double> kPulsesNearS = {-0.8, 0.35, 1.1,  2.45, 3.0,  4.2,   5.6,
                                          7.9,  9.35, 11.0, 13.7, 15.1, 17.45, 19.2};
constexpr double kPulseWidthS = 0.02;
constexpr double kRampS = 2e-3;

// The tick (log clock, on its 2 ms grid from 0) nearest each pulse.
inline std::vector<std::size_t> PulseTicks() {
  std::vector<std::size_t> ticks;
  for (double t : kPulsesNearS) {
    ticks.push_back(
        static_cast<std::size_t>(std::lround((kOffsetS + (1 + kDrift) * t) / kLogStepS)));
  }
  return ticks;
}

inline std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

// Non-periodic, slow (below the arm's first bending mode, about 0.9 Hz)
// moves of both segments over 20 s: long enough for the drift (80 ppm shift
// the log by 1.6 ms over 20 s, against 0.1 ms of stamp jitter).
const char* const kProtocol = R"(schema: ccsrm-protocol/1
name: lab-recording
description: slow moves of both segments for the clock alignment test
segments:
  1:
    - move: {to: {theta_y_deg: 4}, duration_s: 2.5}
    - hold: {duration_s: 0.5}
    - move: {to: {theta_x_deg: 3, theta_y_deg: 1}, duration_s: 2}
    - hold: {duration_s: 1}
    - move: {to: {theta_x_deg: -2, theta_y_deg: -3}, duration_s: 4}
    - hold: {duration_s: 2.5}
    - move: {to: {theta_x_deg: 0, theta_y_deg: 0}, duration_s: 3}
    - hold: {duration_s: 4.5}
  2:
    - hold: {duration_s: 0.7}
    - move: {to: {theta_x_deg: -4}, duration_s: 3}
    - hold: {duration_s: 2.3}
    - move: {to: {theta_x_deg: 2, theta_y_deg: 2}, duration_s: 5}
    - hold: {duration_s: 1.5}
    - move: {to: {theta_y_deg: 0, theta_x_deg: 0}, duration_s: 4}
    - hold: {duration_s: 3.5}
)";

// Linear interpolation of column c of an N × C row-major table at t, the end
// values held outside.
inline double At(const std::vector<double>& time, const std::vector<double>& table,
                 std::size_t columns, std::size_t c, double t) {
  if (t <= time.front()) return table[c];
  if (t >= time.back()) return table[(time.size() - 1) * columns + c];
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), t) - time.begin()) - 1;
  const double u = (t - time[k]) / (time[k + 1] - time[k]);
  return (1.0 - u) * table[k * columns + c] + u * table[(k + 1) * columns + c];
}

struct LabFiles {
  fs::path dir;
  ccsrm::datasets::ExperimentFile original;
  std::string c3d, log, map;
  std::string config;  // the experiment's own nominal configuration, as the lab's arm.yaml
};

// Generates an experiment of paper case `paper_case` in `dir` (the first
// `duration_s` of the protocol, 20 s: all of it), then records it "in the
// lab" (the C3D file, the log and its map).
inline LabFiles MakeLabFiles(const fs::path& dir, int paper_case, double duration_s = 20.0) {
  LabFiles f;
  f.dir = dir;
  const fs::path protocol = f.dir / "protocol.yaml";
  std::ofstream(protocol) << kProtocol;
  const std::string exp = (f.dir / "exp.h5").string();
  const Outcome o =
      RunCcsrm("generate --config " + Paper() + " --case " + std::to_string(paper_case) +
               " --protocol " + protocol.string() + " --duration " + std::to_string(duration_s) +
               " --quiet --seed 11 --out " + exp);
  EXPECT_EQ(o.status, 0) << o.err;
  f.original = ccsrm::datasets::ReadExperimentFile(exp);
  const ccsrm::datasets::ExperimentFile& e = f.original;
  // The arm's configuration as the generated experiment states it (case
  // 1's parameters), so that the assembled experiment is the original's
  // twin for identify.
  f.config = (f.dir / "arm.yaml").string();
  std::ofstream(f.config) << e.config_yaml;

  // The C3D file: the markers, and the trigger at 20 analog samples per
  // frame (2 kHz at 100 Hz).
  std::vector<double> rises;  // mocap clock
  for (std::size_t tick : PulseTicks()) {
    rises.push_back((static_cast<double>(tick) * kLogStepS - kOffsetS) / (1.0 + kDrift));
  }
  ccsrm::mocap::C3dRecording c3d;
  c3d.markers = ccsrm::mocap::MarkerTableFromExperiment(e);
  ccsrm::mocap::C3dAnalog& analog = c3d.analog;
  analog.labels = {"force_z", "trigger"};
  analog.units = {"N", "V"};
  analog.samples_per_frame = 20;
  analog.rate_hz = c3d.markers.rate_hz * 20;
  analog.sample_count = c3d.markers.frames() * 20;
  analog.scale = {1.0, 1.0};
  analog.offset = {0.0, 0.0};
  for (std::size_t s = 0; s < analog.sample_count; ++s) {
    const double t = e.mocap_time.values.front() + static_cast<double>(s) / analog.rate_hz;
    double volts = 0.0;
    for (double r : rises) {
      // Edges centred on the tick: the 50 % point, which the threshold
      // (half way) finds, is the moment the controller raised its output.
      volts += 5.0 * (std::clamp((t - r) / kRampS + 0.5, 0.0, 1.0) -
                      std::clamp((t - r - kPulseWidthS) / kRampS + 0.5, 0.0, 1.0));
    }
    analog.values.push_back(2.0 * std::sin(3.0 * t));  // another channel, not the trigger
    analog.values.push_back(volts);
  }
  f.c3d = (f.dir / "rec.c3d").string();
  ccsrm::mocap::WriteC3d(f.c3d, c3d);

  // The log: motor angles in degrees (cable k's motor starts at 10k°;
  // motor 2 is mounted reversed), a sync column, jittered stamps in ms.
  const std::size_t cables = e.input_length_change.shape[1];
  const double t_end = e.mocap_time.values.back();
  std::mt19937 rng(5);
  std::normal_distribution<double> jitter(0.0, kJitterS);
  std::ofstream log(f.dir / "log.csv");
  log << "# lab controller log, motor angles in degrees\nt_ms";
  for (std::size_t c = 0; c < cables; ++c) log << ",motor" << c + 1 << "_deg";
  log << ",sync,bus_voltage\n";
  char line[64];
  const std::vector<std::size_t> ticks = PulseTicks();
  const std::size_t pulse_ticks = static_cast<std::size_t>(std::lround(kPulseWidthS / kLogStepS));
  const double log_end = kOffsetS + (1 + kDrift) * (t_end + 0.5);
  for (std::size_t i = 0; static_cast<double>(i) * kLogStepS <= log_end; ++i) {
    const double t_log = static_cast<double>(i) * kLogStepS;
    const double t_mocap = (t_log - kOffsetS) / (1.0 + kDrift);
    std::snprintf(line, sizeof line, "%.4f", (t_log + jitter(rng)) * 1e3);
    log << line;
    for (std::size_t c = 0; c < cables; ++c) {
      const double length =
          At(e.input_time.values, e.input_length_change.values, cables, c, t_mocap);
      const double sign = c == 1 ? -1.0 : 1.0;
      const double motor_deg =
          10.0 * (c + 1) + sign * length / kDrumRadiusM * kGearRatio * 180.0 / M_PI;
      std::snprintf(line, sizeof line, ",%.6f", motor_deg);
      log << line;
    }
    bool high = false;
    for (std::size_t tick : ticks) high = high || (i >= tick && i < tick + pulse_ticks);
    log << "," << (high ? 1 : 0) << ",24.0\n";
  }
  f.log = (f.dir / "log.csv").string();
  std::ofstream map(f.dir / "map.yaml");
  map << "schema: ccsrm-actuators/1\ntime: {column: t_ms, unit: ms}\n"
         "trigger: {column: sync, threshold: 0.5, polarity: rising}\ncables:\n";
  for (std::size_t c = 0; c < cables; ++c) {
    map << "  - {column: motor" << c + 1
        << "_deg, signal: motor_angle, unit: deg, drum_radius_m: " << kDrumRadiusM
        << ", gear_ratio: " << kGearRatio << ", sign: " << (c == 1 ? -1 : 1) << "}\n";
  }
  f.map = (f.dir / "map.yaml").string();
  return f;
}

}  // namespace ccsrm::testing::lab
