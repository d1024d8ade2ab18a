// libFuzzer target: arbitrary bytes through the C3D reader (points and
// analog channels). The only allowed outcomes are a recording or an
// InputError; a crash, a sanitizer report or any other exception is a bug. A
// recording that was read must also survive the inspect summaries and a
// write/read round trip without error.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ccsrm::mocap;
  const std::vector<std::uint8_t> bytes(data, data + size);
  C3dRecording recording;
  try {
    recording = ReadC3dRecordingFromMemory(bytes, "fuzz.c3d");
  } catch (const ccsrm::InputError&) {
    return 0;
  }
  const MarkerTable& table = recording.markers;
  InspectJson(table).dump();
  InspectText(table);
  InspectAnalogJson(recording.analog).dump();
  InspectAnalogText(recording.analog);
  if (table.frames() * table.markers() > 1000000) return 0;  // keep runs fast
  std::vector<std::uint8_t> rewritten;
  try {
    rewritten = EncodeC3d(recording);
  } catch (const ccsrm::InputError&) {
    return 0;  // a recording the writer refuses (e.g. a rate no float can hold)
  }
  // Must not throw: an InputError escaping here aborts the fuzzer.
  ReadC3dRecordingFromMemory(rewritten, "fuzz-rewritten.c3d");
  return 0;
}
