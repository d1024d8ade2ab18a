#pragma once
// Tasks on a pool of threads, for every batch of runs in identify/.
#include <cstddef>
#include <functional>

namespace ccsrm::identify::internal {

// Calls task(k) for every k in [0, count) on `threads` threads (the calling
// thread is one of them), then finished(k, n) under a lock, n counting the
// tasks done so far. After the first exception no new task starts; it is
// rethrown once every thread has stopped. Each task must write only its own
// slot, so results do not depend on the number of threads.
void ForEachInParallel(std::size_t count, int threads, const std::function<void(std::size_t)>& task,
                       const std::function<void(std::size_t, std::size_t)>& finished);

}  // namespace ccsrm::identify::internal
