#pragma once
// The loop tests' recordings and options: the paper's arm on the compressed
// protocol of synthetic_experiment.h with white noise of the mocap floor,
// and a declared fit of T_p alone, started away from its nominal value.
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/loop.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify::testing_support {

constexpr double kLoopNoiseDeg = 0.03;

// One experiment per seed, named "synthetic<seed>".
inline std::vector<Experiment> LoopRecordings(const sim::ArmParameters& truth,
                                              const std::vector<unsigned>& seeds) {
  std::vector<Experiment> out;
  for (unsigned seed : seeds) {
    out.push_back(MakeExperiment(Record(truth, kLoopNoiseDeg, seed),
                                 "synthetic" + std::to_string(seed) + ".h5", {}));
    out.back().name = "synthetic" + std::to_string(seed);
  }
  return out;
}

inline LoopOptions LoopTestOptions(std::vector<std::string> candidates) {
  LoopOptions o;
  o.fit.free_parameters = {"T_p"};
  o.fit.values = {{"T_p", 45.0}};  // nominal 50: the declared fit has work to do
  o.fit.threads = 2;
  o.candidates = std::move(candidates);
  return o;
}

}  // namespace ccsrm::identify::testing_support
