// A lab's pose log and the tendon map identified from it (issue 46): on a
// synthetic robot whose map, signs, zeros and directions are known, and on
// the tendon-driven robot's own pulls (../shared/data/tdcr/, skipped
// without it).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/actuator_log.h"
#include "ccsrm/mocap/pose_log.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "mocap_test_util.h"
#include "shared_data.h"

namespace ccsrm::mocap {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;

// A three-segment robot pulled one tendon at a time, as tendon_pull.csv
// does: the active actuator ramps from slack past its engagement to a peak
// and back, the others stay paid out; the tip moves towards the tendon by
// `gain` per unit beyond the engagement (proximal segments more), with
// 0.3 mm of noise. Tendon k of segment s sits at azimuth offset[s] + 120 k;
// it is driven by column `column[tendon]`, reading `sign` × its pull.
struct Robot {
  std::vector<int> column = {4, 3, 8, 5, 2, 7, 6, 1, 0};  // tendon -> column
  std::vector<int> sign = {1, 1, 1, 1, -1, 1, 1, 1, 1};
  std::vector<double> engagement = {-0.2, -0.45, -0.7, -0.4, -0.6, -0.3, -0.8, -0.75, -0.8};
  std::vector<double> offset_deg = {-175.0, -147.0, -118.0};
  std::vector<double> gain = {25.0, 22.0, 18.0};
};

std::string PullLog(const Robot& robot) {
  std::ostringstream csv;
  csv << "timestamp,pattern_label";
  for (int c = 0; c < 9; ++c) csv << ",servo_" << c << "_mm";
  csv << ",tip_x,tip_y,tip_z\n";
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  double t = 1000.0;
  for (int k = 0; k < 9; ++k) {
    const int s = k / 3;
    const double az = (robot.offset_deg[s] + 120.0 * (k % 3)) * kPi / 180.0;
    std::vector<double> pull;
    for (double p = -1.5; p <= 3.0 + 1e-9; p += 0.5) pull.push_back(p);
    for (double p = 2.5; p >= -1.0 - 1e-9; p -= 0.5) pull.push_back(p);
    for (const double p : pull) {
      const double travel = robot.gain[s] * std::max(0.0, p - robot.engagement[k]);
      std::vector<double> reading(9, -10.0);  // the others paid out, slack
      for (int other = 0; other < 9; ++other) {
        if (robot.sign[other] < 0) reading[robot.column[other]] = 10.0;
      }
      reading[robot.column[k]] = robot.sign[k] * p;
      csv << t << ",rep1_tendon" << k << "_pull";
      for (const double v : reading) csv << "," << v;
      csv << "," << travel * std::cos(az) + noise(rng) << "," << travel * std::sin(az) + noise(rng)
          << "," << 188.0 - 0.003 * travel * travel << "\n";
      t += 0.57;
    }
    csv << t << ",rep1_tendon" << k << "_pull_hold";  // one row: not a pull
    for (int c = 0; c < 9; ++c) csv << ",-10";
    csv << ",0,0,188\n";
    t += 10.0;
  }
  return csv.str();
}

TEST(TendonMap, RecoversWhichActuatorDrivesWhichTendonWithItsSignAndZero) {
  const Robot robot;
  const PoseLog log = ParsePoseLog(PullLog(robot), "pulls.csv");
  ASSERT_EQ(log.actuator_columns.size(), 9u);
  const TendonMap map = IdentifyTendonMap(log);
  std::printf("%s", map.Report().c_str());
  ASSERT_EQ(map.tendons.size(), 9u);
  for (int k = 0; k < 9; ++k) {
    const TendonPull& t = map.tendons[static_cast<std::size_t>(k)];
    EXPECT_EQ(t.column, "servo_" + std::to_string(robot.column[k]) + "_mm") << k;
    EXPECT_EQ(t.segment, k / 3 + 1) << k;
    EXPECT_EQ(t.index, k % 3) << k;
    EXPECT_EQ(t.sign, robot.sign[k]) << k;
    // The rows are 0.5 apart in the pull and the noise 0.3 mm against a
    // gain of 18-25 mm per unit: the hinge is placed to a few hundredths.
    EXPECT_NEAR(t.engagement, robot.sign[k] * robot.engagement[k], 0.05) << k;
    EXPECT_NEAR(t.tip_per_unit, robot.gain[k / 3], 0.5) << k;
    const double az = robot.offset_deg[k / 3] + 120.0 * (k % 3);
    EXPECT_NEAR(std::remainder(t.azimuth_deg - az, 360.0), 0.0, 2.0) << k;
  }
  EXPECT_EQ(map.labels_naming, 9);
  EXPECT_EQ(map.labels_agreeing, 9);
  EXPECT_LT(map.spacing_rms_deg, 2.0);
  const std::string yaml = map.ToYaml("pulls.csv");
  EXPECT_THAT(yaml, HasSubstr("schema: ccsrm-tendon-map/1"));
  EXPECT_THAT(yaml, HasSubstr("column: \"servo_2_mm\", sign: -1"));
}

TEST(TendonMap, WritesTheActuatorsMapThatReadsEachTendonFromItsEngagement) {
  // As a ccsrm-actuators/1 map, cable k = tendon k: read through it, every
  // cable's pulled-in length is the tendon's true pull beyond its true
  // engagement, whatever column drives it and which way it counts (to the
  // engagement's accuracy, 0.05 of a unit as above).
  const Robot robot;
  const std::string text = PullLog(robot);
  const PoseLog log = ParsePoseLog(text, "pulls.csv");
  const TendonMap map = IdentifyTendonMap(log);
  ActuatorMap actuators =
      ParseActuatorMap(map.ActuatorMapYaml("pulls.csv", "timestamp", "mm"), "actuators.yaml");
  ASSERT_EQ(actuators.cables.size(), 9u);
  EXPECT_EQ(actuators.time_column, "timestamp");
  actuators.max_gap_s = 20.0;  // settled poses with unrecorded transitions, not a stream
  const ActuatorLog read = ParseActuatorLog(text, "pulls.csv", actuators, "actuators.yaml");
  ASSERT_EQ(read.length_change_m.rows(), static_cast<Eigen::Index>(log.time_s.size()));
  for (int k = 0; k < 9; ++k) {
    const std::string column = "servo_" + std::to_string(robot.column[k]) + "_mm";
    EXPECT_EQ(actuators.cables[static_cast<std::size_t>(k)].column, column) << k;
    int c = 0;
    while (log.actuator_columns[static_cast<std::size_t>(c)] != column) ++c;
    for (Eigen::Index i = 0; i < read.length_change_m.rows(); ++i) {
      const double pull_mm = robot.sign[k] * log.actuators(i, c) - robot.engagement[k];
      EXPECT_NEAR(read.length_change_m(i, k), 1e-3 * pull_mm, 0.05e-3) << k << " row " << i;
    }
  }
}

TEST(ActuatorMap, AZeroIsALengthsOwn) {
  const std::string motor =
      "schema: ccsrm-actuators/1\ntime: {column: t, unit: s}\ncables:\n"
      "  - {column: m1, signal: motor_angle, unit: deg, drum_radius_m: 0.01, zero: 3}\n";
  try {
    ParseActuatorMap(motor, "a.yaml");
    ADD_FAILURE() << "a motor angle's zero accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("a.yaml: line 4, key 'cables[0].zero': only for signal: "
                                    "length_change"));
  }
}

std::string ErrorOf(const std::string& text) {
  try {
    IdentifyTendonMap(ParsePoseLog(text, "log.csv"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// A pull not released within its pattern (the log goes on to the next
// without the return) still gives its direction, from where it started.
TEST(TendonMap, APullNotReleasedStillGivesItsDirection) {
  const Robot robot;
  std::string text = PullLog(robot);
  // Tendon 4's pattern cut at its peak: the rows of its ramp back dropped.
  std::istringstream in(text);
  std::ostringstream cut;
  std::string line;
  int tendon4_rows = 0;
  while (std::getline(in, line)) {
    if (line.find("rep1_tendon4_pull,") != std::string::npos && ++tendon4_rows > 10) continue;
    cut << line << "\n";
  }
  const TendonMap map = IdentifyTendonMap(ParsePoseLog(cut.str(), "cut.csv"));
  ASSERT_EQ(map.tendons.size(), 9u);
  EXPECT_EQ(map.labels_agreeing, 9);
  EXPECT_NEAR(std::remainder(map.tendons[4].azimuth_deg - (-147.0 + 120.0), 360.0), 0.0, 2.0);
}

TEST(TendonMap, BadLogsAreNamedInOneLine) {
  EXPECT_EQ(ErrorOf(""), "log.csv: empty: expected a header line and rows");
  EXPECT_EQ(ErrorOf("timestamp,pattern_label,servo_1_mm,tip_x,tip_y\n1,a,0,0,0\n"),
            "log.csv: line 1: no column 'tip_z' (the tracked point) in the header");
  EXPECT_EQ(ErrorOf("timestamp,pattern_label,motor,tip_x,tip_y,tip_z\n1,a,0,0,0,0\n"),
            "log.csv: line 1: no actuator column (none whose name starts with 'servo_')");
  EXPECT_THAT(ErrorOf("timestamp,pattern_label,servo_1_mm,tip_x,tip_y,tip_z\n1,a,0,0,0,0\n"
                      "2,a,x,0,0,0\n"),
              HasSubstr("log.csv: line 3, column 3"));
  EXPECT_THAT(ErrorOf("timestamp,pattern_label,servo_1_mm,tip_x,tip_y,tip_z\n2,a,0,0,0,0\n"
                      "1,a,0,0,0,0\n"),
              HasSubstr("log.csv: line 3, column 'timestamp': time 1.000000 does not increase"));
  // Two patterns, one tendon per segment expected 3 at a time.
  std::string text = PullLog(Robot());
  text = text.substr(0, text.find("rep1_tendon2_pull"));
  text = text.substr(0, text.rfind('\n') + 1);
  EXPECT_THAT(ErrorOf(text), HasSubstr("2 pull pattern(s) of at least 5 rows: expected a "
                                       "multiple of 3 tendons per segment"));
}

// The robot's own pulls (../shared/data/tdcr/ftdcr_v4/tendon_pull.csv):
// the map its labels name, every reading growing as its tendon is pulled
// in (the shared README's "negative = pulled in" does not hold for these
// columns: docs/tdcr-recordings.md), engaging within a millimetre below the
// zero, in the directions the publishing project's configuration gives.
TEST(TendonMap, IdentifiesTheTendonDrivenRobotsMapFromItsPulls) {
  CCSRM_SHARED_FILE_OR_SKIP(path, "data/tdcr/ftdcr_v4/tendon_pull.csv");
  const TendonMap map = IdentifyTendonMap(ReadPoseLog(path));
  std::printf("%s", map.Report().c_str());
  ASSERT_EQ(map.tendons.size(), 9u);
  EXPECT_EQ(map.labels_agreeing, 9);
  // generation_config.json: seg_offsets + k·120° + tendon_angle_deltas, as
  // capture-frame azimuths [deg]; the return edge is the same estimate.
  const std::vector<double> config = {-174.7, -47.8, 56.7, -138.7, -33.8, 92.2, -125.2, 3.9, 128.9};
  for (std::size_t k = 0; k < 9; ++k) {
    const TendonPull& t = map.tendons[k];
    EXPECT_EQ(t.sign, 1) << t.column;
    EXPECT_GT(t.engagement, -1.0) << t.column;
    EXPECT_LT(t.engagement, 0.3) << t.column;
    EXPECT_NEAR(std::remainder(t.azimuth_deg - config[k], 360.0), 0.0, 1.0) << t.column;
  }
  // Under position control a proximal tendon moves the tip most.
  EXPECT_GT(map.tendons[0].tip_per_unit + map.tendons[1].tip_per_unit,
            map.tendons[6].tip_per_unit + map.tendons[7].tip_per_unit);
}

// --- A pose log made an experiment (dataset import-pose-log) -------------------

std::string RobotConfigPath() { return std::string(CCSRM_SOURCE_DIR) + "/configs/ftdcr_v4.yaml"; }

// The synthetic robot's pulls and the map identified from them, on disk.
struct PullFiles {
  std::filesystem::path dir;
  std::string log, map;
  PoseLog poses;
};

PullFiles WritePullFiles(const std::string& name) {
  PullFiles f;
  f.dir = testing::FreshTempDir(name);
  const std::string text = PullLog(Robot());
  f.log = (f.dir / "pulls.csv").string();
  f.map = (f.dir / "actuators.yaml").string();
  testing::WriteFile(f.log, text);
  f.poses = ParsePoseLog(text, f.log);
  testing::WriteFile(f.map, IdentifyTendonMap(f.poses).ActuatorMapYaml(f.log, "timestamp", "mm"));
  return f;
}

// The import of rows first..last of those files onto the robot's arm.
PoseLogImportRequest ImportRequest(const PullFiles& f, std::size_t first, std::size_t last) {
  PoseLogImportRequest request;
  request.log = f.log;
  request.actuator_map = f.map;
  request.config = RobotConfigPath();
  request.first_row = first;
  request.last_row = last;
  return request;
}

TEST(PoseLogImport, MakesSettledPosesOfATrackedTipFromTheLogThroughItsMap) {
  const Robot robot;
  const PullFiles f = WritePullFiles("pose_log_import");
  PoseLogImportRequest request = ImportRequest(f, 3, 40);
  request.tip_from_link_end_m = Eigen::Vector3d(0.0, 0.0, 8e-3);
  const ImportedPoseLog imported = ImportPoseLog(request);
  std::printf("%s", imported.report.c_str());
  const datasets::ExperimentFile& e = imported.experiment;
  ASSERT_EQ(e.input_time.size(), 38u);
  EXPECT_EQ(e.motion, datasets::RecordedMotion::kSettledPoses);
  EXPECT_EQ(e.marker_frame, datasets::MarkerFrame::kCapture);
  EXPECT_EQ(e.source, datasets::ExperimentSource::kRecorded);
  EXPECT_EQ(e.name, "pulls");
  ASSERT_EQ(e.input_labels.size(), 38u);
  EXPECT_EQ(e.input_labels[0], f.poses.labels[2]);
  ASSERT_EQ(e.input_length_change.shape, (std::vector<std::size_t>{38, 9}));
  for (std::size_t i = 0; i < 38; ++i) {
    const Eigen::Index row = static_cast<Eigen::Index>(i + 2);
    // Time from the first imported row, as logged.
    EXPECT_DOUBLE_EQ(e.input_time.values[i], f.poses.time_s[i + 2] - f.poses.time_s[2]);
    EXPECT_EQ(e.mocap_time.values[i], e.input_time.values[i]);
    // Cable k is tendon k: its true pull beyond its true engagement (the
    // engagement's accuracy, 0.05 mm, as above), in metres.
    for (int k = 0; k < 9; ++k) {
      int c = 0;
      const std::string column = "servo_" + std::to_string(robot.column[k]) + "_mm";
      while (f.poses.actuator_columns[static_cast<std::size_t>(c)] != column) ++c;
      const double pull_mm = robot.sign[k] * f.poses.actuators(row, c) - robot.engagement[k];
      EXPECT_NEAR(e.input_length_change.values[i * 9 + k], 1e-3 * pull_mm, 0.05e-3) << k;
    }
    for (int x = 0; x < 3; ++x) {
      EXPECT_DOUBLE_EQ(e.mocap_markers.values[i * 3 + x], 1e-3 * f.poses.tip(row, x));
    }
  }
  // The tip marker: on the last of the 30 links, 8 mm beyond the centre of
  // its distal end (the link is 6.4 mm long: z' = 3.2 + 8 mm).
  ASSERT_EQ(e.rigid_bodies.size(), 1u);
  EXPECT_EQ(e.rigid_bodies[0].name, "link30");
  EXPECT_EQ(e.marker_names, (std::vector<std::string>{"tip"}));
  EXPECT_NEAR(e.rigid_bodies[0].local_position.values[2], 11.2e-3, 1e-12);

  // Through the file and the door every experiment comes through.
  const std::string out = (f.dir / "pulls.h5").string();
  datasets::WriteExperimentFile(out, e);
  const datasets::ExperimentFile back = datasets::ReadExperimentFile(out);
  EXPECT_TRUE(sim_io::CheckExperimentAgainstConfig(back, out).has_value());
  EXPECT_EQ(back.input_labels, e.input_labels);
  EXPECT_EQ(back.motion, datasets::RecordedMotion::kSettledPoses);
}

TEST(PoseLogImport, BadRequestsAreNamedInOneLine) {
  const PullFiles f = WritePullFiles("pose_log_import_bad");
  PoseLogImportRequest request = ImportRequest(f, 30, 400);
  const std::size_t rows = f.poses.time_s.size();
  EXPECT_EQ(testing::InputErrorOf([&] { ImportPoseLog(request); }),
            f.log + ": rows: 30 to 400 selected, the log has " + std::to_string(rows) +
                " rows: at least 2 rows within them are needed");
  // The paper's arm has 6 driving cables, the map 9.
  request.first_row = request.last_row = 0;
  request.config = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
  EXPECT_EQ(
      testing::InputErrorOf([&] { ImportPoseLog(request); }),
      f.map + ": cables: maps 9 cable(s), the arm (" + request.config + ") has 6 driving cables");
  // Tip columns declared metres: the tip 188 m away is beyond any capture
  // volume, refused when the experiment is checked.
  request.config = RobotConfigPath();
  request.tip_unit = "m";
  const ImportedPoseLog imported = ImportPoseLog(request);
  EXPECT_THAT(testing::InputErrorOf(
                  [&] { sim_io::CheckExperimentAgainstConfig(imported.experiment, f.log); }),
              HasSubstr("beyond any capture volume"));
}

// The robot's training log after its pulls (rows 135 on: the first 134 are
// tendon_pull.csv, docs/tdcr-recordings.md), through the map identified
// from its pulls: at rest every tendon is within a millimetre of taut and
// the tip 188 mm up the capture frame's z; the largest pulls are those the
// file documents (up to 9.6 mm beyond the reading's zero).
TEST(PoseLogImport, ImportsTheTendonDrivenRobotsTrainingPoses) {
  CCSRM_SHARED_FILE_OR_SKIP(pulls, "data/tdcr/ftdcr_v4/tendon_pull.csv");
  CCSRM_SHARED_FILE_OR_SKIP(train, "data/tdcr/ftdcr_v4/train.csv");
  const std::filesystem::path dir = testing::FreshTempDir("pose_log_import_robot");
  PoseLogImportRequest request;
  request.log = train;
  request.actuator_map = (dir / "actuators.yaml").string();
  request.config = RobotConfigPath();
  request.first_row = 135;
  testing::WriteFile(
      request.actuator_map,
      IdentifyTendonMap(ReadPoseLog(pulls)).ActuatorMapYaml(pulls, "timestamp", "mm"));
  const ImportedPoseLog imported = ImportPoseLog(request);
  std::printf("%s", imported.report.c_str());
  const datasets::ExperimentFile& e = imported.experiment;
  ASSERT_EQ(e.input_time.size(), 1620u - 134u);
  EXPECT_EQ(e.input_labels.front().rfind("rep1_seg1", 0), 0u) << e.input_labels.front();
  for (int k = 0; k < 9; ++k) {
    EXPECT_NEAR(e.input_length_change.values[static_cast<std::size_t>(k)], 0.0, 1e-3) << k;
  }
  EXPECT_NEAR(e.mocap_markers.values[2], 0.188, 0.002);
  const auto [low, high] =
      std::minmax_element(e.input_length_change.values.begin(), e.input_length_change.values.end());
  EXPECT_LT(*high, 11e-3);
  EXPECT_GT(*low, -11e-3);
  EXPECT_TRUE(sim_io::CheckExperimentAgainstConfig(e, train).has_value());
}

}  // namespace
}  // namespace ccsrm::mocap
