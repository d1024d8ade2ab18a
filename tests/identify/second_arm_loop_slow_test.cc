// The loop on the second arm shipped in configs/ (three-segment.yaml: three
// segments of four links, nine cables): it finds a tilted table the declared
// model lacks, as on the paper's arm. About 30 s on one core (label `slow`).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ccsrm/identify/loop.h"
#include "ccsrm/sim/parameters.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::ElementsAre;
using testing_support::Recordings;
using testing_support::SecondArm;

constexpr double kNoiseDeg = testing_support::kSecondArmNoiseDeg;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

TEST(SecondArm, TheLoopFindsATiltedTable) {
  const auto start = std::chrono::steady_clock::now();
  // A table 0.02 rad (1.1 deg) off level both ways, which bends this arm
  // about as much as the mocap noise (0.03 deg RMS over the 3 s). The
  // realistic 1 mrad bends it by 0.0015 deg, which 3 s of 0.03 deg noise
  // cannot show (the paper arm's loop finds it over the 48 s protocol,
  // docs/loop.md).
  sim::ArmParameters truth = SecondArm().parameters;
  sim::SetParameter("table_tilt.lateral_rad", 0.02, "test", &truth);
  sim::SetParameter("table_tilt.longitudinal_rad", 0.02, "test", &truth);
  const std::vector<Experiment> training = Recordings(truth, {1}, SecondArm());
  const std::vector<Experiment> holdout = Recordings(truth, {2}, SecondArm());
  LoopOptions o;
  o.fit.free_parameters = {"T_p"};
  o.fit.values = {{"T_p", 45.0}};  // nominal 50: the declared fit has work to do
  o.fit.threads = 2;
  o.candidates = {"table_tilt", "actuator_delay"};
  const LoopSummary s = CloseLoop(training, holdout, o);
  std::printf("second arm loop: added %s, RMS %.4f -> %.4f deg (held out %.4f -> %.4f), %.1f s\n",
              s.added_effects.empty() ? "nothing" : s.added_effects.front().c_str(),
              s.rms_before_deg, s.rms_after_deg, s.holdout_rms_before_deg.value_or(NAN),
              s.holdout_rms_after_deg.value_or(NAN), Seconds(start));
  EXPECT_THAT(s.added_effects, ElementsAre("table_tilt"));
  // The loop's own bar (loop_test.cc): after within 1.5x the noise floor.
  EXPECT_LT(s.rms_after_deg, 1.5 * kNoiseDeg);
  EXPECT_LT(s.rms_after_deg, s.rms_before_deg);
}

}  // namespace
}  // namespace ccsrm::identify
