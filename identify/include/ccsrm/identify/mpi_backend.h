#pragma once
// Simulations spread over the ranks of an MPI job (docs/cluster.md). Under
// `mpirun -n N ccsrm identify|loop ...` every rank runs the same command
// line and loads the same experiments once; then rank 0 runs the command
// (the optimiser, the outputs) and hands its batches of runs out to every
// rank, itself included, while the others only serve runs. A run is a
// function of its request alone, so the results are the thread backend's, to
// the bit, for any N: only where each run happens changes.
//
// A rank that does not return a run within MpiOptions::run_timeout_s of
// getting it (it died, or hangs) ends the job: rank 0 prints one line naming
// the rank and the run and aborts the job with kMpiRankLost, before any
// output of the command is written.
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/simulation_backend.h"

namespace ccsrm::identify {

// Exit status of a job that lost a rank (it died or hung) or whose ranks
// loaded different experiments.
inline constexpr int kMpiRankLost = 7;

struct MpiOptions {
  // Runs at a time on each rank, rank 0 included (`--threads`). Default 1.
  int threads = 1;
  // How long a rank may take over one run before it is taken for dead [s]
  // (`--run-timeout`). Default 1800: ten times the longest single run seen
  // so far (a 60 s recording of the paper's arm with stick-slip events takes
  // minutes on a slow core), so that only a dead or hung rank reaches it.
  double run_timeout_s = 1800.0;

  // False with the reason: threads < 1, a timeout that is not > 0.
  bool IsValid(std::string* error) const;
};

// Whether this build has MPI (libopenmpi-dev was found).
bool MpiCompiled();

// Starts MPI when this process was launched by mpirun or srun (their
// environment says so); otherwise, and in a build without MPI, does nothing.
// Ranks other than 0 then write nothing to stdout or stderr: rank 0 speaks
// for the job. Call first in main.
void StartMpi(int* argc, char*** argv);
// Ends MPI if StartMpi started it, with the command's exit status. Rank 0
// first releases ranks still waiting for work (a command that failed before
// handing any out); a nonzero status of rank 0 ends the job through
// MPI_Abort, so that mpirun reports it in every configuration. Call last in
// main.
void StopMpi(int status);

int MpiRank();   // 0 outside an MPI job
int MpiRanks();  // 1 outside an MPI job

// Collective: every rank calls it with the same experiment sets (the same
// files read the same way). Rank 0 gets one backend per set. Every other rank
// serves rank 0's runs until the last of those backends is destroyed, then
// gets an empty vector: its command is over. Outside an MPI job (one rank):
// thread backends of options.threads. The sets must outlive the backends.
// Throws InputError for invalid options.
std::vector<std::shared_ptr<SimulationBackend>> ShareRuns(
    const std::vector<const std::vector<Experiment>*>& sets, const MpiOptions& options);

}  // namespace ccsrm::identify
