// The round trip over the paper's full 48 s protocol on case 2 (friction on
// all cables), CTest label `slow`. Expected to fail until the simulator fix
// for case 2 lands: the simulation currently diverges at t = 16.02 s
// (docs/model-notes.md), and this test requires a completed run.
#include "round_trip.h"

#include <gtest/gtest.h>

namespace ccsrm::mocap::testing {
namespace {

TEST(RoundTripSlow, PaperCase2FullProtocolWithin005DegRms) {
  const RoundTripTrial trial = MakeRoundTripTrial(
      /*case_number=*/2, ProtocolConfig{20.0, 4.0, 20.0, 4.0}, /*seed=*/5, "case2_full");
  ASSERT_TRUE(trial.completed) << "simulation of case 2 did not complete: " << trial.message;
  const ProcessingResult result = ProcessTrial(trial);
  const AngleErrors errors = CompareJointAngles(result.joint_angles, trial.truth.joint_angles);
  std::printf("case 2, 48 s: %s\n", errors.Report().c_str());
  ExpectWithinTarget(errors, result);
  // And through a C3D file.
  const std::string c3d = trial.directory + "/recording.c3d";
  WriteC3d(c3d, MarkerTableFromExperiment(trial.experiment));
  const sim::ArmModel model(sim::ParseConfig(trial.experiment.config_yaml, "nominal").arm);
  const JointChain chain = JointChain::FromModel(model);
  const ProcessingResult from_c3d = ProcessMarkers(
      ReadMarkerFile(c3d), {}, DefaultMarkerLayout(model), ProcessingOptions(), c3d, &chain);
  const AngleErrors c3d_errors =
      CompareJointAngles(from_c3d.joint_angles, trial.truth.joint_angles);
  std::printf("case 2, 48 s, C3D: %s\n", c3d_errors.Report().c_str());
  ExpectWithinTarget(c3d_errors, from_c3d);
}

}  // namespace
}  // namespace ccsrm::mocap::testing
