// libFuzzer target: arbitrary text through the TRC, Nexus CSV and Motive CSV
// readers. The only allowed outcomes are a table or an InputError; a table
// that was read must also survive the inspect summary and a C3D round trip.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/text_formats.h"

namespace {

using ccsrm::mocap::MarkerTable;

void Exercise(MarkerTable (*read)(const std::string&, const std::string&),
              const std::string& text) {
  MarkerTable table;
  try {
    table = read(text, "fuzz.txt");
  } catch (const ccsrm::InputError&) {
    return;
  }
  ccsrm::mocap::InspectJson(table).dump();
  if (table.frames() * table.markers() > 1000000) return;
  std::vector<std::uint8_t> c3d;
  try {
    c3d = ccsrm::mocap::EncodeC3d(table);
  } catch (const ccsrm::InputError&) {
    return;  // e.g. a label longer than 255 characters, a rate no float holds
  }
  ccsrm::mocap::ReadC3dFromMemory(c3d, "fuzz-rewritten.c3d");  // must not throw
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Exercise(&ccsrm::mocap::ReadTrcFromString, text);
  Exercise(&ccsrm::mocap::ReadNexusCsvFromString, text);
  Exercise(&ccsrm::mocap::ReadMotiveCsvFromString, text);
  return 0;
}
