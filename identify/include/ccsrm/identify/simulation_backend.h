#pragma once
// Where identification's simulations run. A fit asks for batches of runs
// (the base point of every experiment, then the trial points of the finite
// differences) and waits for the whole batch; a backend decides where they
// run. ThreadBackend runs them on this machine's cores. A request holds only
// an experiment index and parameter values, so another backend can send
// batches to other machines that loaded the same experiments.
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {

struct RunRequest {
  std::size_t experiment = 0;  // index into the experiments the backend was given
  sim::ArmParameters parameters;
  bool keep_trajectory = false;  // also return every sampled frame
  // Parameter sets that differ from `parameters` only in measurement
  // effects' parameters (mocap_offset): the same run is recorded once more
  // through each, without simulating again (RunResult::variant_simulated).
  std::vector<sim::ArmParameters> measurement_variants;
  // Return the physical joint angles of every frame the run sampled instead
  // of the recorded ones at the experiment's frames (RunResult::angles_rad):
  // what `ccsrm derivatives` differentiates (SampledJointAnglesDeg), so that
  // its runs go to a backend's ranks like any other. No measurement variants.
  bool every_frame = false;
};

struct RunResult {
  sim::SimulationSummary summary;
  // The simulated angles at the experiment's sample times [rad], laid out as
  // Experiment::measured and made comparable with them
  // (Experiment::AsMeasured: the measurement's gaps and low-pass); rows
  // beyond a run that ended early are NaN. With RunRequest::every_frame:
  // the joint angles θx, θy of joint j in columns 2 j, 2 j + 1, one row per
  // frame the run reached, nothing recorded or filtered.
  Eigen::MatrixXd simulated;
  sim::Trajectory trajectory;  // only with keep_trajectory
  // The angles as recorded through each of the request's measurement_variants.
  std::vector<Eigen::MatrixXd> variant_simulated;
};

// Called after each finished run, one call at a time.
using RunFinishedCallback =
    std::function<void(std::size_t finished, std::size_t total, const RunResult& result)>;

class SimulationBackend {
 public:
  virtual ~SimulationBackend() = default;
  // Runs every request; result k belongs to request k. Deterministic: the
  // same requests give the same results whatever the backend's parallelism.
  // A run that diverges is reported in its summary, not thrown.
  virtual std::vector<RunResult> RunBatch(const std::vector<RunRequest>& requests,
                                          const RunFinishedCallback& on_finished) = 0;
  // Runs at a time (for reports).
  virtual int parallelism() const = 0;
};

// Runs on `threads` threads of this process, each run with its own
// simulation data over the experiments' shared, read-only models.
// `experiments` must outlive the backend.
std::unique_ptr<SimulationBackend> MakeThreadBackend(const std::vector<Experiment>* experiments,
                                                     int threads);

}  // namespace ccsrm::identify
