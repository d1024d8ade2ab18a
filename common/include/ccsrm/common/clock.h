#pragma once
#include <string>

namespace ccsrm {
// The current UTC time as ISO 8601, e.g. "2026-11-21T22:48:24Z"; written
// into the `created` attribute of output files.
std::string UtcTimestamp();
}  // namespace ccsrm
