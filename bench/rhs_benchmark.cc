// Google Benchmark kernels of the simulator's right-hand side (SPEC 10).
// Run: ./build/bench/ccsrm_benchmarks
#include <benchmark/benchmark.h>

#include <string>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/protocol.h"
#include "dynamics.h"
#include "kernels/ale_element.h"

namespace ccsrm::sim {
namespace {

Config PaperCase(int case_number) {
  Config c = LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
  ApplyPaperCase(case_number, &c.parameters);
  return c;
}

// One full evaluation of eqs. 59-68 for the paper's arm in a bent, moving
// state (every stage of ArmDynamics::Evaluate, the sparse solve included).
// Arguments: the paper case; 1 with the cable nodes embedded (the default),
// 0 solving the full system.
void BM_RightHandSide(benchmark::State& state) {
  Config config = PaperCase(static_cast<int>(state.range(0)));
  config.solver.embed_cable_nodes = state.range(1) != 0;
  const ArmModel model(config.arm);
  const CableInputs inputs =
      PlanCableInputs(model, PaperTrajectory(model, config.protocol), 48.0, 1e-2);
  internal::ArmDynamics dynamics(model, config.parameters, inputs, config.solver);
  Eigen::VectorXd y = dynamics.InitialState();
  Eigen::VectorXd ydot(y.size());
  // A little velocity everywhere so that no term is trivially zero.
  for (int k = 0; k < dynamics.num_coordinates(); ++k)
    y[dynamics.num_coordinates() + k] = 1e-4 * ((k % 7) - 3);
  for (auto _ : state) {
    benchmark::DoNotOptimize(dynamics.Evaluate(10.0, y.data(), ydot.data()));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RightHandSide)
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({2, 1})
    ->Args({2, 0})
    ->Unit(benchmark::kMicrosecond);

// What a parameter change costs: building the model (routing, layout,
// sparsity pattern and its AMD ordering) happens once; each run only sets up
// its own data over it (kernel parameters, initial state, numeric
// workspace and the symbolic analysis of the fixed pattern).
void BM_ArmModelBuild(benchmark::State& state) {
  const Config config = PaperCase(2);
  for (auto _ : state) benchmark::DoNotOptimize(ArmModel(config.arm).num_coordinates());
}
BENCHMARK(BM_ArmModelBuild)->Unit(benchmark::kMillisecond);

void BM_RunSetUp(benchmark::State& state) {
  const Config config = PaperCase(2);
  const ArmModel model(config.arm);
  const CableInputs inputs =
      PlanCableInputs(model, PaperTrajectory(model, config.protocol), 48.0, 1e-2);
  ArmParameters parameters = config.parameters;
  for (auto _ : state) {
    parameters.mu *= 1.0000001;  // a new parameter set each run
    internal::ArmDynamics dynamics(model, parameters, inputs, config.solver);
    benchmark::DoNotOptimize(dynamics.state_size());
  }
}
BENCHMARK(BM_RunSetUp)->Unit(benchmark::kMillisecond);

void BM_AleElement(benchmark::State& state) {
  internal::AleElementParams p{7850.0 * 1.3273e-6, 2.6e10 * 1.3273e-6, 1e-3, 0.01};
  internal::Vector8d q, qd;
  q << 0, 0, 0, 0.001, 0.002, 0.016, 0.0, 0.01595;
  qd << 0, 0, 0, 1e-3, 0, 2e-3, 1e-3, 2e-3;
  for (auto _ : state) benchmark::DoNotOptimize(internal::EvaluateAleElement(p, q, qd));
}
BENCHMARK(BM_AleElement);

}  // namespace
}  // namespace ccsrm::sim

BENCHMARK_MAIN();
