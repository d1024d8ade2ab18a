// libFuzzer target: arbitrary text through the actuator map parser and, with
// a fixed map, through the actuator log parser (ccsrm-actuators/1). The
// only allowed outcomes are a result or an InputError; a crash, a sanitizer
// report or any other exception is a bug. The first byte picks the parser.
#include <cstddef>
#include <cstdint>
#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/actuator_log.h"

namespace {

const char* const kMap = R"(schema: ccsrm-actuators/1
time: {column: t_ms, unit: ms}
trigger: {column: sync}
cables:
  - {column: a, signal: length_change, unit: mm}
  - {column: b, signal: motor_angle, unit: deg, drum_radius_m: 0.01, gear_ratio: 4, sign: -1}
  - {column: c, signal: motor_angle, unit: counts, counts_per_turn: 1000, wrap_counts: 4096,
     drum_radius_m: 0.02}
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ccsrm::mocap;
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  static const ActuatorMap map = ParseActuatorMap(kMap, "fuzz-map.yaml");
  try {
    if (data[0] % 2 == 0) {
      ParseActuatorMap(text, "fuzz.yaml");
    } else {
      ParseActuatorLog(text, "fuzz.csv", map, "fuzz-map.yaml");
    }
  } catch (const ccsrm::InputError&) {
  }
  return 0;
}
