#pragma once
// The one way a backend's request becomes a run.
#include "ccsrm/identify/simulation_backend.h"

namespace ccsrm::identify::internal {

// One run of a backend's request on experiment e (every backend's runs go
// through here, so they agree to the bit whichever backend ran them).
RunResult RunExperiment(const Experiment& e, const identify::RunRequest& request);

}  // namespace ccsrm::identify::internal
