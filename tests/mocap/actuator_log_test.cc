// Actuator logs and their maps (ccsrm-actuators/1): units, motor angles
// through drum and gear, reversed signs, encoder counts that wrap, and one
// line naming file, line and column (or key) for every bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/actuator_log.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::InputErrorOf;

constexpr double kPi = 3.14159265358979323846;

const char* const kMap = R"(schema: ccsrm-actuators/1
time: {column: t_ms, unit: ms}
trigger: {column: sync, threshold: 0.5, polarity: rising}
cables:
  - {column: len1, signal: length_change, unit: mm}
  - {column: motor2, signal: motor_angle, unit: deg, drum_radius_m: 0.01, gear_ratio: 4, sign: -1}
  - {column: enc3, signal: motor_angle, unit: counts, counts_per_turn: 1000, wrap_counts: 4096,
     drum_radius_m: 0.02}
)";

ActuatorMap Map() { return ParseActuatorMap(kMap, "map.yaml"); }

TEST(ActuatorMap, ParsesEveryField) {
  const ActuatorMap map = Map();
  EXPECT_EQ(map.time_column, "t_ms");
  EXPECT_EQ(map.time_unit, "ms");
  ASSERT_TRUE(map.trigger.has_value());
  EXPECT_EQ(map.trigger->column, "sync");
  ASSERT_EQ(map.cables.size(), 3u);
  EXPECT_EQ(map.cables[1].signal, CableSignal::kMotorAngle);
  EXPECT_EQ(map.cables[1].sign, -1);
  EXPECT_DOUBLE_EQ(map.cables[1].gear_ratio, 4.0);
  EXPECT_DOUBLE_EQ(map.cables[2].wrap_counts, 4096.0);
  EXPECT_DOUBLE_EQ(map.max_gap_s, 0.1);  // the documented default
}

// Length = sign × r × (angle − first angle) / gear; counts unwrap.
TEST(ActuatorLog, ConvertsUnitsAnglesAndWrappedCounts) {
  // The encoder runs up through its 4096 wrap: 4000 → 4090 → 84 (= 4180) → 174.
  const std::string log =
      "# controller log\n"
      "t_ms,len1,motor2,enc3,sync,ignored\n"
      "0,0.5,10,4000,0,x\n"
      "2,1.5,100,4090,0,x\n"
      "4,2.5,190,84,1,x\n"
      "6,3.5,280,174,1,x\n";
  const ActuatorLog a = ParseActuatorLog(log, "log.csv", Map(), "map.yaml");
  ASSERT_EQ(a.time_s.size(), 4);
  EXPECT_DOUBLE_EQ(a.time_s[3], 0.006);
  EXPECT_DOUBLE_EQ(a.length_change_m(2, 0), 2.5e-3);  // mm → m, no zeroing for lengths
  // Motor 2: 270° after 3 samples, through a 4:1 gear on a 10 mm drum,
  // reversed: −0.01 × (3π/2) / 4.
  EXPECT_NEAR(a.length_change_m(3, 1), -0.01 * (270.0 * kPi / 180.0) / 4.0, 1e-15);
  EXPECT_DOUBLE_EQ(a.length_change_m(0, 1), 0.0);
  // Encoder: 174 + 4096 − 4000 = 270 counts of 1000 per turn on a 20 mm drum.
  EXPECT_NEAR(a.length_change_m(3, 2), 0.02 * 2.0 * kPi * 270.0 / 1000.0, 1e-15);
  EXPECT_NEAR(a.length_change_m(2, 2), 0.02 * 2.0 * kPi * 180.0 / 1000.0, 1e-15);
  ASSERT_EQ(a.trigger.size(), 4);
  EXPECT_EQ(a.trigger[2], 1.0);
  EXPECT_EQ(a.lines[0], 3u);
}

TEST(ActuatorLog, TabSeparatedLogsRead) {
  const std::string log = "t_ms\tlen1\tmotor2\tenc3\tsync\n0\t0\t0\t0\t0\n1\t1\t1\t1\t0\n";
  const ActuatorLog a = ParseActuatorLog(log, "log.tsv", Map(), "map.yaml");
  EXPECT_EQ(a.time_s.size(), 2);
}

struct BadCase {
  const char* what;
  std::string text;
  std::string expected;  // a part of the one-line message
};

// Issue 47, 13: a 10 Hz log stamped in ms steps exactly the 0.1 s allowed;
// 100 ms is 0.10000000000000001 s, which must not read as a longer gap.
TEST(ActuatorLog, AGapOfExactlyTheLimitInMillisecondsIsAllowed) {
  const std::string text = "t_ms,len1,motor2,enc3,sync\n0,0,0,0,0\n100,1,0,0,0\n200,2,0,0,0\n";
  const ActuatorLog log = ParseActuatorLog(text, "log.csv", Map(), "map.yaml");
  EXPECT_EQ(log.time_s.size(), 3);
  // A trailing empty cell (a delimiter at the end of a row) is no extra column.
  EXPECT_EQ(ParseActuatorLog("t_ms,len1,motor2,enc3,sync\n0,0,0,0,0,\n100,1,0,0,0,\n", "log.csv",
                             Map(), "map.yaml")
                .time_s.size(),
            2);
}

TEST(ActuatorLog, BadLogsAreOneLineNamingLineAndColumn) {
  const std::string header = "t_ms,len1,motor2,enc3,sync\n";
  const BadCase cases[] = {
      {"time goes back", header + "0,0,0,0,0\n2,0,0,0,0\n1,0,0,0,0\n",
       "log.csv: line 4, column 't_ms': time 0.001 s does not increase (previous 0.002 s, line 3)"},
      {"NaN", header + "0,0,0,0,0\n2,nan,0,0,0\n",
       "log.csv: line 3, column 'len1': 'nan' is not a finite number"},
      {"a gap", header + "0,0,0,0,0\n500,0,0,0,0\n",
       "log.csv: line 3, column 't_ms': a gap of 0.5 s after 0 s, longer than the 0.1 s allowed "
       "(map.yaml, key 'max_gap_s')"},
      {"unknown column", "t_ms,len1,motor2,enc4,sync\n0,0,0,0,0\n",
       "log.csv: line 1: no column 'enc3' (named by map.yaml, key 'cables[2].column')"},
      {"missing value", header + "0,0,,0,0\n", "log.csv: line 2, column 'motor2': missing value"},
      {"text", header + "0,0,abc,0,0\n", "log.csv: line 2, column 'motor2': expected a number"},
      {"one sample", header + "0,0,0,0,0\n", "at least 2 are needed"},
      {"empty", "# nothing\n", "log.csv: empty"},
      // Found by the fuzzer: a byte order mark before a comment made the
      // comment the header line, then no row was left (an internal check).
      {"BOM and a comment", "\xEF\xBB\xBF# controller log", "log.csv: empty"},
      // Issue 47, 7: a mapped column twice, a row wider than the header.
      {"a column twice", "t_ms,len1,motor2,enc3,sync,len1\n0,0,0,0,0,0\n",
       "log.csv: line 1: column 'len1' (named by map.yaml, key 'cables[0].column') appears twice, "
       "as columns 2 and 6"},
      {"a wide row", header + "0,0,0,0,0\n1,0,0,0,0,9\n",
       "log.csv: line 3: has 6 cells, the header (line 1) names 5 columns"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string error =
        InputErrorOf([&] { ParseActuatorLog(c.text, "log.csv", Map(), "map.yaml"); });
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(ActuatorMap, BadMapsAreOneLineNamingTheKey) {
  const std::string head = "schema: ccsrm-actuators/1\ntime: {column: t, unit: s}\n";
  const BadCase cases[] = {
      {"schema", "schema: ccsrm-actuators/2\ntime: {column: t, unit: s}\ncables: []\n",
       "key 'schema': expected ccsrm-actuators/1"},
      {"unknown key",
       head + "cables:\n  - {column: a, signal: length_change, unit: m, radius: 1}\n",
       "key 'cables[0].radius': unknown key"},
      {"no drum", head + "cables:\n  - {column: a, signal: motor_angle, unit: deg}\n",
       "key 'cables[0].drum_radius_m': missing"},
      {"negative drum",
       head + "cables:\n  - {column: a, signal: motor_angle, unit: deg, drum_radius_m: -1}\n",
       "key 'cables[0].drum_radius_m': expected a number > 0"},
      {"sign", head + "cables:\n  - {column: a, signal: length_change, unit: m, sign: 2}\n",
       "key 'cables[0].sign': expected 1 or -1"},
      {"unit", head + "cables:\n  - {column: a, signal: length_change, unit: deg}\n",
       "key 'cables[0].unit': expected one of m, mm"},
      {"counts without counts_per_turn",
       head + "cables:\n  - {column: a, signal: motor_angle, unit: counts, drum_radius_m: 1}\n",
       "key 'cables[0].counts_per_turn': missing"},
      {"a column twice", head + "cables:\n  - {column: t, signal: length_change, unit: m}\n",
       "key 'cables[0].column': column 't' is already time.column"},
      {"no cables", head, "key 'cables': missing"},
      {"time unit", "schema: ccsrm-actuators/1\ntime: {column: t, unit: h}\ncables: []\n",
       "key 'time.unit': expected one of ms, s, us"},
      {"NaN gap",
       head + "max_gap_s: .nan\ncables:\n  - {column: a, signal: length_change, unit: m}\n",
       "not a finite number"},
      {"syntax", "schema: [\n", "YAML syntax error"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string error = InputErrorOf([&] { ParseActuatorMap(c.text, "map.yaml"); });
    EXPECT_NE(error.find("map.yaml"), std::string::npos) << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace ccsrm::mocap
