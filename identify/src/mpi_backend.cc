#include "ccsrm/identify/mpi_backend.h"
#include "ccsrm/identify/runs.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <numeric>
#include <optional>
#include <thread>

#include "ccsrm/common/error.h"
#include "parallel.h"
#include "run_codec.h"
#include "run_experiment.h"

#ifdef CCSRM_HAVE_MPI
#include <mpi.h>
#include <unistd.h>
#endif

namespace ccsrm::identify {

bool MpiOptions::IsValid(std::string* error) const {
  if (const std::string problem = ThreadCountProblem(threads); !problem.empty()) {
    *error = problem + ", found " + std::to_string(threads);
    return false;
  }
  if (!(run_timeout_s > 0.0)) {
    *error = "run_timeout_s must be > 0";
    return false;
  }
  return true;
}

namespace {

std::vector<std::shared_ptr<SimulationBackend>> ThreadBackends(
    const std::vector<const std::vector<Experiment>*>& sets, int threads) {
  std::vector<std::shared_ptr<SimulationBackend>> out;
  for (const std::vector<Experiment>* set : sets) out.push_back(MakeThreadBackend(set, threads));
  return out;
}

void CheckOptions(const MpiOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) ThrowInputError("MPI runs", "options", error);
}

}  // namespace

#ifndef CCSRM_HAVE_MPI

bool MpiCompiled() { return false; }
void StartMpi(int*, char***) {}
void StopMpi(int) {}
int MpiRank() { return 0; }
int MpiRanks() { return 1; }

std::vector<std::shared_ptr<SimulationBackend>> ShareRuns(
    const std::vector<const std::vector<Experiment>*>& sets, const MpiOptions& options) {
  CheckOptions(options);
  return ThreadBackends(sets, options.threads);
}

#else

namespace {

using internal::GetRequest;
using internal::GetResult;
using internal::Packer;
using internal::PutRequest;
using internal::PutResult;
using internal::Unpacker;
using Clock = std::chrono::steady_clock;

// Message tags. Work and stop go from rank 0 to a server; the rest to rank 0.
enum Tag : int { kReady = 1, kWork = 2, kResults = 3, kStop = 4 };

// Between polls of an idle loop: short against a run (tenths of a second and
// more), long enough that a waiting rank leaves its core to the runs.
constexpr auto kPollInterval = std::chrono::microseconds(200);

bool started = false;
int rank = 0;
int ranks = 1;
bool servers_released = false;  // rank 0: every server was sent kStop

std::vector<char> Receive(int source, int tag, MPI_Status* status = nullptr) {
  MPI_Status st;
  MPI_Probe(source, tag, MPI_COMM_WORLD, &st);
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  std::vector<char> bytes(static_cast<std::size_t>(count));
  MPI_Recv(bytes.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  if (status != nullptr) *status = st;
  return bytes;
}

// Ends the whole job from rank 0 with one line.
[[noreturn]] void EndJob(const std::string& line, int status) {
  std::fflush(stdout);
  std::fprintf(stderr, "ccsrm: %s\n", line.c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, status);
  std::_Exit(status);  // not reached: MPI_Abort ends this process too
}

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g s", s);
  return text;
}

// Test hook (tests/identify/mpi_test.cc): CCSRM_MPI_TEST_LOSE_RANK=
// "rank:runs:exit|hang" makes that server, once it has run `runs` runs, exit
// at once (as a crashed node would) or stop answering (as a hung one).
struct LoseRank {
  int rank = -1;
  long runs = 0;
  bool hang = false;
};

LoseRank ReadLoseRank() {
  LoseRank out;
  const char* text = std::getenv("CCSRM_MPI_TEST_LOSE_RANK");
  if (text == nullptr) return out;
  char mode[16] = {0};
  if (std::sscanf(text, "%d:%ld:%15s", &out.rank, &out.runs, mode) != 3) out.rank = -1;
  out.hang = std::string(mode) == "hang";
  return out;
}

// What every rank shares: the experiment sets, and on rank 0 the servers.
struct Job {
  std::vector<const std::vector<Experiment>*> sets;
  MpiOptions options;
  std::vector<int> server_threads;   // per rank; [0] is rank 0's own
  std::int64_t runs_handed_out = 0;  // numbers the runs of the job for messages
  // For the closing line (the scaling figures of BENCHMARKS.md): from the
  // backends' creation, the time rank 0 spent in batches and outside them.
  Clock::time_point created = Clock::now();
  double batch_s = 0.0;

  ~Job() {
    if (rank != 0) return;
    const double total_s = std::chrono::duration<double>(Clock::now() - created).count();
    std::printf(
        "MPI: %lld runs on %d rank%s in %.2f s of batches (%.3g runs/s); rank 0 on its "
        "own %.2f s\n",
        static_cast<long long>(runs_handed_out), ranks, ranks == 1 ? "" : "s", batch_s,
        batch_s > 0.0 ? static_cast<double>(runs_handed_out) / batch_s : 0.0, total_s - batch_s);
    std::fflush(stdout);
    if (servers_released) return;
    for (int r = 1; r < ranks; ++r) MPI_Send(nullptr, 0, MPI_CHAR, r, kStop, MPI_COMM_WORLD);
    servers_released = true;
  }
};

class MpiBackend final : public SimulationBackend {
 public:
  MpiBackend(std::shared_ptr<Job> job, std::size_t set) : job_(std::move(job)), set_(set) {}

  int parallelism() const override {
    return std::accumulate(job_->server_threads.begin(), job_->server_threads.end(), 0);
  }

  std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                  const RunFinishedCallback& on_finished) override {
    const std::vector<Experiment>& experiments = *job_->sets[set_];
    for (const RunRequest& r : requests) CCSRM_CHECK(r.experiment < experiments.size());
    const std::size_t n = requests.size();
    const Clock::time_point batch_start = Clock::now();
    const std::int64_t first_run = job_->runs_handed_out + 1;
    job_->runs_handed_out += static_cast<std::int64_t>(n);
    std::vector<RunResult> results(n);

    // Longest first, so that the long runs start early and short ones fill
    // the ranks at the end; runs that keep their trajectory stay on rank 0
    // (trajectories are not sent).
    std::vector<std::size_t> shared, own;
    for (std::size_t k = 0; k < n; ++k) (requests[k].keep_trajectory ? own : shared).push_back(k);
    std::stable_sort(shared.begin(), shared.end(), [&](std::size_t a, std::size_t b) {
      return experiments[requests[a].experiment].duration_s() >
             experiments[requests[b].experiment].duration_s();
    });
    std::atomic<std::size_t> next_shared{0}, next_own{0};
    std::atomic<bool> failed{false};
    const auto take_shared = [&]() -> std::optional<std::size_t> {
      if (failed) return std::nullopt;
      const std::size_t i = next_shared++;
      if (i >= shared.size()) return std::nullopt;
      return shared[i];
    };

    // Rank 0's own threads take runs from the same queue.
    std::mutex mutex;  // guards finished_here and error
    std::vector<std::size_t> finished_here;
    std::string error;
    std::atomic<int> working{0};
    const auto work_here = [&] {
      for (;;) {
        std::optional<std::size_t> k;
        if (!failed) {
          const std::size_t i = next_own++;
          if (i < own.size()) k = own[i];
        }
        if (!k) k = take_shared();
        if (!k) break;
        try {
          results[*k] = internal::RunExperiment(experiments[requests[*k].experiment], requests[*k]);
        } catch (const std::exception& e) {
          const std::lock_guard<std::mutex> lock(mutex);
          if (error.empty()) error = e.what();
          failed = true;
          break;
        }
        const std::lock_guard<std::mutex> lock(mutex);
        finished_here.push_back(*k);
      }
      --working;
    };
    const int own_threads = job_->server_threads[0];
    working = own_threads;
    std::vector<std::thread> pool;
    for (int t = 0; t < own_threads; ++t) pool.emplace_back(work_here);

    // The other ranks: one chunk of up to their thread count each at a time.
    struct Out {
      std::vector<std::size_t> runs;
      std::vector<char> message;
      MPI_Request send = MPI_REQUEST_NULL;
      Clock::time_point deadline;
    };
    std::vector<Out> out(static_cast<std::size_t>(ranks));
    std::size_t done = 0;
    const auto finish = [&](std::size_t k) {
      ++done;
      if (on_finished) on_finished(done, n, results[k]);
    };
    for (;;) {
      bool busy = false;
      for (int r = 1; r < ranks; ++r) {
        Out& o = out[static_cast<std::size_t>(r)];
        if (!o.runs.empty()) {
          busy = true;
          continue;
        }
        for (int t = 0; t < job_->server_threads[static_cast<std::size_t>(r)]; ++t) {
          const std::optional<std::size_t> k = take_shared();
          if (!k) break;
          o.runs.push_back(*k);
        }
        Packer packer;
        packer.Put<std::uint64_t>(set_);
        packer.Put<std::uint64_t>(o.runs.size());
        for (const std::size_t k : o.runs) {
          packer.Put<std::uint64_t>(k);
          PutRequest(requests[k], &packer);
        }
        if (o.runs.empty()) continue;
        busy = true;
        o.message = std::move(packer.bytes());
        MPI_Isend(o.message.data(), static_cast<int>(o.message.size()), MPI_CHAR, r, kWork,
                  MPI_COMM_WORLD, &o.send);
        // A chunk holds at most one run per thread of the rank.
        o.deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(job_->options.run_timeout_s));
      }

      bool progressed = false;
      int arrived = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, kResults, MPI_COMM_WORLD, &arrived, &status);
      if (arrived) {
        progressed = true;
        const std::vector<char> bytes = Receive(status.MPI_SOURCE, kResults);
        Out& o = out[static_cast<std::size_t>(status.MPI_SOURCE)];
        MPI_Wait(&o.send, MPI_STATUS_IGNORE);
        Unpacker in(bytes);
        for (std::size_t i = 0; i < o.runs.size(); ++i) {
          const auto k = in.Get<std::uint64_t>();
          CCSRM_CHECK(k == o.runs[i]);
          if (in.Get<std::uint8_t>() == 0) {
            const std::string what = in.GetString();
            const std::lock_guard<std::mutex> lock(mutex);
            if (error.empty()) error = what;
            failed = true;
            continue;
          }
          results[k] = GetResult(&in);
          finish(k);
        }
        o.runs.clear();
      }
      std::vector<std::size_t> finished;
      {
        const std::lock_guard<std::mutex> lock(mutex);
        finished.swap(finished_here);
      }
      for (const std::size_t k : finished) finish(k);
      progressed = progressed || !finished.empty();

      const Clock::time_point now = Clock::now();
      for (int r = 1; r < ranks; ++r) {
        const Out& o = out[static_cast<std::size_t>(r)];
        if (o.runs.empty() || now < o.deadline) continue;
        const std::size_t k = o.runs.front();
        EndJob("rank " + std::to_string(r) + " did not return run " +
                   std::to_string(first_run + static_cast<std::int64_t>(k)) + " (experiment " +
                   experiments[requests[k].experiment].name + ") within " +
                   Seconds(job_->options.run_timeout_s) +
                   " (--run-timeout): it died or hangs; the job ends without results",
               kMpiRankLost);
      }
      if (done == n || (failed && !busy && working == 0)) break;
      if (!progressed) std::this_thread::sleep_for(kPollInterval);
    }
    for (std::thread& t : pool) t.join();
    job_->batch_s += std::chrono::duration<double>(Clock::now() - batch_start).count();
    if (failed) throw std::runtime_error(error);
    return results;
  }

 private:
  std::shared_ptr<Job> job_;
  std::size_t set_;
};

// A rank other than 0: runs what rank 0 sends until it says stop.
void Serve(const Job& job) {
  const LoseRank lose = ReadLoseRank();
  long runs = 0;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
    if (!arrived) {
      std::this_thread::sleep_for(kPollInterval);
      continue;
    }
    const std::vector<char> bytes = Receive(0, status.MPI_TAG);
    if (status.MPI_TAG == kStop) return;
    CCSRM_CHECK(status.MPI_TAG == kWork);
    Unpacker in(bytes);
    const std::vector<Experiment>& experiments = *job.sets.at(in.Get<std::uint64_t>());
    std::vector<std::uint64_t> ids;
    std::vector<RunRequest> requests;
    for (auto count = in.Get<std::uint64_t>(); count > 0; --count) {
      ids.push_back(in.Get<std::uint64_t>());
      requests.push_back(GetRequest(&in));
      CCSRM_CHECK(requests.back().experiment < experiments.size());
    }
    if (lose.rank == rank && runs >= lose.runs) {
      if (!lose.hang) _exit(9);
      for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    std::vector<RunResult> results(requests.size());
    std::vector<std::string> errors(requests.size());
    internal::ForEachInParallel(
        requests.size(), job.options.threads,
        [&](std::size_t k) {
          try {
            results[k] = internal::RunExperiment(experiments[requests[k].experiment], requests[k]);
          } catch (const std::exception& e) {
            errors[k] = std::string("rank ") + std::to_string(rank) + ": " + e.what();
          }
        },
        nullptr);
    runs += static_cast<long>(requests.size());
    Packer out;
    for (std::size_t k = 0; k < requests.size(); ++k) {
      out.Put<std::uint64_t>(ids[k]);
      out.Put<std::uint8_t>(errors[k].empty() ? 1 : 0);
      if (!errors[k].empty()) {
        out.PutString(errors[k]);
        continue;
      }
      PutResult(results[k], &out);
    }
    MPI_Send(out.bytes().data(), static_cast<int>(out.bytes().size()), MPI_CHAR, 0, kResults,
             MPI_COMM_WORLD);
  }
}

// What a rank loaded, to check that every rank loaded the same.
void PutFingerprint(const std::vector<const std::vector<Experiment>*>& sets, Packer* out) {
  out->Put<std::uint64_t>(sets.size());
  for (const std::vector<Experiment>* set : sets) {
    out->Put<std::uint64_t>(set->size());
    for (const Experiment& e : *set) {
      out->PutString(e.name);
      out->PutMatrix(e.measured);
    }
  }
}

}  // namespace

bool MpiCompiled() { return true; }

void StartMpi(int* argc, char*** argv) {
  // mpirun (Open MPI, MPICH) and srun set one of these in every rank.
  const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr ||
                        std::getenv("PMI_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
  if (!launched) return;
  int provided = 0;
  // Only the main thread of a rank calls MPI; the runs' threads do not.
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // Rank 0 prints the command's output and its errors; the others would
  // print the same again (and mpirun's ending of the job as interruptions).
  if (rank != 0 && (std::freopen("/dev/null", "w", stdout) == nullptr ||
                    std::freopen("/dev/null", "w", stderr) == nullptr)) {
    std::perror("ccsrm");
  }
}

void StopMpi(int status) {
  if (!started) return;
  if (rank == 0 && !servers_released) {
    // A command that ended before handing out work (bad input, a command
    // that does not use the ranks): servers may wait in ShareRuns.
    for (int r = 1; r < ranks; ++r) MPI_Send(nullptr, 0, MPI_CHAR, r, kStop, MPI_COMM_WORLD);
    servers_released = true;
  }
  started = false;
  // Under orte_abort_on_non_zero_status=0 (docs/cluster.md) mpirun would
  // end with 0 whatever rank 0 returned; an abort carries the status.
  if (rank == 0 && status != 0) {
    std::fflush(stdout);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, status);
  }
  MPI_Finalize();
}

int MpiRank() { return rank; }
int MpiRanks() { return ranks; }

std::vector<std::shared_ptr<SimulationBackend>> ShareRuns(
    const std::vector<const std::vector<Experiment>*>& sets, const MpiOptions& options) {
  CheckOptions(options);
  // Under mpirun even one rank goes through here (the same runs on its
  // threads), for the closing line's figures.
  if (!started) return ThreadBackends(sets, options.threads);
  auto job = std::make_shared<Job>();
  job->sets = sets;
  job->options = options;
  Packer fingerprint;
  PutFingerprint(sets, &fingerprint);
  if (rank != 0) {
    Packer ready;
    ready.Put<std::int32_t>(options.threads);
    ready.Append(fingerprint.bytes().data(), fingerprint.bytes().size());
    MPI_Send(ready.bytes().data(), static_cast<int>(ready.bytes().size()), MPI_CHAR, 0, kReady,
             MPI_COMM_WORLD);
    Serve(*job);
    return {};
  }
  // Every rank reports its threads and what it loaded, within the timeout.
  job->server_threads.assign(static_cast<std::size_t>(ranks), 0);
  job->server_threads[0] = options.threads;
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(options.run_timeout_s));
  for (int reported = 1; reported < ranks;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kReady, MPI_COMM_WORLD, &arrived, &status);
    if (!arrived) {
      if (Clock::now() > deadline) {
        for (int r = 1; r < ranks; ++r) {
          if (job->server_threads[static_cast<std::size_t>(r)] == 0) {
            EndJob("rank " + std::to_string(r) + " did not load the experiments within " +
                       Seconds(options.run_timeout_s) + " (--run-timeout)",
                   kMpiRankLost);
          }
        }
      }
      std::this_thread::sleep_for(kPollInterval);
      continue;
    }
    const std::vector<char> bytes = Receive(status.MPI_SOURCE, kReady);
    Unpacker in(bytes);
    job->server_threads[static_cast<std::size_t>(status.MPI_SOURCE)] = in.Get<std::int32_t>();
    if (!std::equal(fingerprint.bytes().begin(), fingerprint.bytes().end(),
                    bytes.begin() + sizeof(std::int32_t), bytes.end()) ||
        bytes.size() != fingerprint.bytes().size() + sizeof(std::int32_t)) {
      EndJob("rank " + std::to_string(status.MPI_SOURCE) +
                 " loaded other experiments than rank 0 (are the files the same on every node?)",
             kMpiRankLost);
    }
    ++reported;
  }
  std::vector<std::shared_ptr<SimulationBackend>> out;
  for (std::size_t s = 0; s < sets.size(); ++s) out.push_back(std::make_shared<MpiBackend>(job, s));
  return out;
}

#endif

}  // namespace ccsrm::identify
