#pragma once
// Stages the jobs (job.h) share.
#include <string>
#include <vector>

#include "ccsrm/identify/job.h"

namespace ccsrm::identify::internal {

// Refuses a file given twice in `files` (by any name) or also in `others`,
// one line naming the file and the option.
void RefuseRepeatedFiles(const std::vector<std::string>& files, const std::string& option,
                         const std::vector<std::string>& others, const std::string& others_option);

// A fitting job's options applied to the fit's: its data given (else
// InputError naming --data), the threads, the iterations and the parameter
// choice (ApplyFitParameters; the free list falls back to `fit`'s own).
void ApplyFitJob(const FitJobOptions& job, IdentificationOptions* fit);

// Says `text` through the job's reporting, when it has a line reporter.
inline void Say(const JobReporting& reporting, const std::string& text) {
  if (reporting.line) reporting.line(text);
}

}  // namespace ccsrm::identify::internal
