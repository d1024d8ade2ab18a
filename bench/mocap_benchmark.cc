// Google Benchmark of the mocap pipeline (SPEC 10: mocap frames per second).
// Run: ./build/bench/ccsrm_benchmarks --benchmark_filter=Mocap
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>

#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::mocap {
namespace {

constexpr std::size_t kFrames = 10000;
constexpr double kRate = 100.0;

// 40 markers: the ground and links 1-9 of the paper's arm, 4 markers each,
// 10 000 frames (100 s at 100 Hz) of a smooth bending motion with 0.2 mm
// noise and a 1 % of samples hidden in gaps of 5-25 frames.
struct Recording {
  MarkerLayout layout;
  MarkerTable table;
  JointChain chain;
};

const Recording& FortyMarkers() {
  static const Recording recording = [] {
    const sim::ArmModel model(
        sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml").arm);
    Recording r;
    r.layout = DefaultMarkerLayout(model);
    r.layout.bodies.resize(10);
    r.chain = JointChain::FromModel(model);
    r.table.Reset(kFrames, r.layout.MarkerNames(), false);
    r.table.rate_hz = kRate;
    std::mt19937_64 rng(1);
    std::normal_distribution<double> noise(0.0, 0.2e-3);
    for (std::size_t f = 0; f < kFrames; ++f) {
      const double t = static_cast<double>(f) / kRate;
      sim::JointAngles angles(model.num_joints());
      for (int j = 0; j < model.num_joints(); ++j) {
        angles[j] = Eigen::Vector2d(0.1 * std::sin(0.3 * t + 0.2 * j), 0.01 * std::cos(0.2 * t));
      }
      const auto p_WM = PlaceMarkers(r.layout, sim::ForwardKinematics(model, angles));
      for (std::size_t k = 0; k < p_WM.size(); ++k) {
        r.table.set_position(f, k, p_WM[k] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
      }
    }
    std::uniform_int_distribution<std::size_t> start(0, kFrames - 30), marker(0, 39), length(5, 25);
    for (int gap = 0; gap < 270; ++gap) {  // about 1 % of the samples
      const std::size_t m = marker(rng), s = start(rng), n = length(rng);
      for (std::size_t f = s; f < s + n; ++f) {
        r.table.set_position(f, m, Eigen::Vector3d::Constant(NAN));
      }
    }
    return r;
  }();
  return recording;
}

// The whole pipeline (fill, fit, joint angles, filter, quality) on 10 000
// frames; items per second = frames per second. Arg 0: each link fitted on
// its own; arg 1: the joint-constrained chain (the default with a config).
void BM_MocapProcessFortyMarkers(benchmark::State& state) {
  const Recording& r = FortyMarkers();
  const bool chain = state.range(0) != 0;
  for (auto _ : state) {
    const ProcessingResult result = ProcessMarkers(r.table, {}, r.layout, ProcessingOptions(),
                                                   "bench", chain ? &r.chain : nullptr);
    benchmark::DoNotOptimize(result.joint_angles.values.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kFrames));
}
BENCHMARK(BM_MocapProcessFortyMarkers)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ccsrm::mocap
