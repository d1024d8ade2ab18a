#pragma once
// GSL's default error handler aborts the program. ccsrm checks its inputs
// before calling GSL and reads GSL's return codes instead, so the handler is
// switched off once for the whole process, never toggled per call: a toggle
// inside a run would race with runs on other threads.

namespace ccsrm {

// Switches GSL's error handler off the first time it is called (thread-safe;
// later calls do nothing). Every module that calls GSL calls this first.
void UseGslErrorCodes();

}  // namespace ccsrm
