// Identification on the second arm shipped in configs/ (three-segment.yaml:
// three segments of four links, nine cables), on the compressed protocol of
// synthetic_experiment.h: what runs on the paper's arm runs on any arm the
// configuration describes (about 10 s; the loop: second_arm_loop_slow_test).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/sim/effects.h"
#include "synthetic_experiment.h"

namespace ccsrm::identify {
namespace {

using ::testing::HasSubstr;
using testing_support::Recordings;
using testing_support::SecondArm;

constexpr double kNoiseDeg = testing_support::kSecondArmNoiseDeg;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

TEST(SecondArm, IdentificationRecoversTheConnectingPretension) {
  const auto start = std::chrono::steady_clock::now();
  sim::ArmParameters truth = SecondArm().parameters;
  truth.T_p = 65.0;  // nominal 50
  const std::vector<Experiment> x = Recordings(truth, {7}, SecondArm());
  ASSERT_EQ(x[0].joints, 12);
  ASSERT_EQ(x[0].model->num_cables(), 9);
  IdentificationOptions o;
  o.free_parameters = {"T_p"};
  o.threads = 2;
  const IdentificationSummary s = Identify(x, o);
  const ParameterEstimate* tp = s.Find("T_p");
  ASSERT_NE(tp, nullptr);
  std::printf(
      "second arm: T_p %.3f N (truth 65, start 50), 95 %% [%.3f, %.3f], RMS %.4f deg, %.1f s\n",
      tp->value, tp->ci95_lower, tp->ci95_upper, s.errors.rms_deg_overall, Seconds(start));
  EXPECT_EQ(s.termination, IdentificationTermination::kConverged) << s.message;
  // The data were made at 65 N with 0.03 deg of white noise: the truth
  // inside the 95 % interval, and the residual at the noise (the model
  // is the truth's).
  EXPECT_LE(tp->ci95_lower, 65.0);
  EXPECT_GE(tp->ci95_upper, 65.0);
  EXPECT_NEAR(s.errors.rms_deg_overall, kNoiseDeg, 0.2 * kNoiseDeg);
  // A joint this arm does not have is refused before any run.
  o.free_parameters = {"mocap_offset.joint13_x_rad"};
  try {
    Identify(x, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown parameter 'mocap_offset.joint13_x_rad' (this arm "
                                    "has 12 joints"));
  }
}

}  // namespace
}  // namespace ccsrm::identify
