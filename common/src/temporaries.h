#pragma once
// The temporaries of the AtomicOutputFile and AtomicOutputDirectory objects
// alive in this process, so that an interrupt can remove them
// (RemoveTemporariesOnInterrupt, output_policy.h). Private to common.
#include <string>
#include <vector>

namespace ccsrm::internal {

// Every temporary is named "<target><kTemporaryInfix><pid>-<n>".
inline constexpr const char* kTemporaryInfix = ".tmp-";

void RegisterTemporary(const std::string& path);
void UnregisterTemporary(const std::string& path);

// The registered paths, for the interrupt handler.
std::vector<std::string> RegisteredTemporaries();

}  // namespace ccsrm::internal
