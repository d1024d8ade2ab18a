#pragma once
// A record of the runs a command has done, kept in its output folder, so
// that a command killed part-way (`ccsrm loop --resume`, docs/cluster.md)
// can run again from its start and take every run it had done from the
// record instead of simulating it. The command is deterministic, so it asks
// for the same runs in the same order and gets the same results, to the bit;
// only the runs in flight at the kill are simulated again.
//
// The file is appended to once per batch and flushed to disk; a record cut
// short by a kill fails its length or checksum and is dropped with whatever
// follows it. Runs that keep their trajectories are not recorded (they are
// run again).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/identify/simulation_backend.h"

namespace ccsrm::identify {

class RunJournal {
 public:
  // Opens `path`. With `resume`, the runs recorded there are replayed first;
  // without, the file is started empty. Throws InputError naming the file
  // when it cannot be written.
  RunJournal(const std::string& path, bool resume);
  ~RunJournal();
  RunJournal(const RunJournal&) = delete;
  RunJournal& operator=(const RunJournal&) = delete;

  const std::string& path() const { return path_; }
  std::int64_t recorded() const;   // runs in the file when it was opened
  std::int64_t replayed() const;   // of those, taken instead of simulated so far
  std::int64_t simulated() const;  // runs simulated since it was opened

  // Internal to the backend below.
  struct Impl;

 private:
  std::string path_;
  std::unique_ptr<Impl> impl_;
  friend class JournaledBackend;
};

// `inner` with the journal: a batch's runs come from the journal while it
// has them, in order, and the rest from `inner` (then recorded). `set` tells
// the experiment sets of one command apart (loop: training 0, held out 1).
// Throws InputError when a recorded run differs from the one asked for:
// the journal is of another command line.
std::shared_ptr<SimulationBackend> WithJournal(std::shared_ptr<SimulationBackend> inner,
                                               std::shared_ptr<RunJournal> journal, int set);

}  // namespace ccsrm::identify
