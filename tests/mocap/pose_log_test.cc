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
#include "ccsrm/mocap/actuator_log.h"
#include "ccsrm/mocap/pose_log.h"
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

}  // namespace
}  // namespace ccsrm::mocap
