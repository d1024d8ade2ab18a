// The mocap pipeline as one library call (recording.h): ProcessRecording on
// files, AddMeasuredJointAngles on an experiment in memory, the marker
// source hook the camera front end uses, and the one-line errors.
//
// One short virtual recording (paper case 4, quintic ramps of 2 s: 4.4 s,
// 441 frames at 100 Hz, 0.2 mm noise and occlusions), simulated once and
// shared (ONE_PROCESS). With 2 s ramps the default 1 Hz filter leaves about
// 0.07 deg RMS (round_trip_test.cc: the arm's own ~3 Hz response is lost).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/mocap/recording.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim_io/experiment_check.h"
#include "mocap_test_util.h"
#include "round_trip.h"
#include "same_experiment.h"

namespace ccsrm::mocap::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

const RoundTripTrial& Trial() {
  static const RoundTripTrial trial = MakeRoundTripTrial(
      /*case_number=*/4, ProtocolConfig{2.0, 0.2, 2.0, 0.2}, /*seed=*/5, "recording_call");
  return trial;
}

std::string Paper() { return CCSRM_SOURCE_DIR "/configs/paper.yaml"; }

bool HasOneLine(const std::string& message) {
  return !message.empty() && message.find('\n') == std::string::npos;
}

TEST(RecordingCall, AddMeasuredJointAnglesEqualsProcessRecordingOfTheFile) {
  const RoundTripTrial& trial = Trial();
  ASSERT_TRUE(trial.completed) << trial.message;
  RecordingRequest request;
  request.in = trial.experiment_path;
  const ProcessedRecording from_file = ProcessRecording(request);
  const ProcessedRecording in_memory =
      AddMeasuredJointAngles(trial.experiment, trial.experiment_path);
  ccsrm::testing::ExpectSameExperiment(in_memory.experiment, from_file.experiment);
  EXPECT_EQ(in_memory.result.summary.BriefReport(), from_file.result.summary.BriefReport());
}

TEST(RecordingCall, AddMeasuredJointAnglesFillsTheMeasurementAndKeepsTheRest) {
  const RoundTripTrial& trial = Trial();
  ASSERT_FALSE(trial.experiment.measured_joint_angles.has_value());
  const ProcessedRecording processed = AddMeasuredJointAngles(trial.experiment, "exp");
  const datasets::ExperimentFile& e = processed.experiment;
  ASSERT_TRUE(e.measured_joint_angles.has_value());
  EXPECT_EQ(e.measured_joint_angles->shape, (std::vector<std::size_t>{441, 12, 2}));
  EXPECT_TRUE(processed.result.summary.joint_constrained);  // chain from config_yaml
  EXPECT_TRUE(processed.result.summary.world_from_ground);
  EXPECT_FALSE(e.mocap_quality.empty());
  // Everything recorded is kept as it was.
  EXPECT_EQ(e.name, trial.experiment.name);
  EXPECT_EQ(e.source, datasets::ExperimentSource::kGenerated);
  EXPECT_EQ(e.config_yaml, trial.experiment.config_yaml);
  EXPECT_EQ(e.input_length_change.values, trial.experiment.input_length_change.values);
  ccsrm::testing::ExpectSameArray(e.mocap_markers, trial.experiment.mocap_markers, "markers");
  // The measurement is the simulated motion to the pipeline's accuracy on
  // 2 s ramps (about 0.07 deg RMS; the round-trip tests hold 0.05 deg on
  // slower ones). This bound only says the angles are the arm's, not another
  // joint's or an unfiltered mess: a regression guard, not a target.
  const AngleErrors errors = CompareJointAngles(*e.measured_joint_angles, trial.truth.joint_angles);
  EXPECT_LT(errors.worst_rms_deg, 0.2) << errors.Report();
}

TEST(RecordingCall, ExperimentsOwnRigidBodiesComeBeforeItsConfigurationsDefaultLayout) {
  // A recorded arm whose link-3 plate sits 5 mm further out than the default
  // layout says: its own rigid bodies must be used (and kept), not the
  // default layout of its config_yaml.
  datasets::ExperimentFile moved = Trial().experiment;
  datasets::RigidBody* link3 = nullptr;
  for (datasets::RigidBody& body : moved.rigid_bodies) {
    if (body.name == "link3") link3 = &body;
  }
  ASSERT_NE(link3, nullptr);
  for (std::size_t k = 0; k < link3->marker_names.size(); ++k) {
    link3->local_position.at(k, 0) += 0.005;
  }
  const ProcessedRecording processed = AddMeasuredJointAngles(moved, "moved");
  ASSERT_EQ(processed.experiment.rigid_bodies.size(), moved.rigid_bodies.size());
  for (std::size_t b = 0; b < moved.rigid_bodies.size(); ++b) {
    ccsrm::testing::ExpectSameArray(processed.experiment.rigid_bodies[b].local_position,
                                    moved.rigid_bodies[b].local_position,
                                    moved.rigid_bodies[b].name);
  }
  // And used: the plate now disagrees with the joints of the chain fit by
  // 5 mm, which turns the neighbouring links by degrees (5 mm over links of
  // about 9 cm), so the angles differ from those of the recorded layout.
  const ProcessedRecording original = AddMeasuredJointAngles(Trial().experiment, "original");
  double largest = 0.0;
  for (std::size_t i = 0; i < original.experiment.measured_joint_angles->size(); ++i) {
    const double d = processed.experiment.measured_joint_angles->values[i] -
                     original.experiment.measured_joint_angles->values[i];
    if (std::isfinite(d)) largest = std::max(largest, std::abs(d));
  }
  EXPECT_GT(largest, 1e-3);  // rad; the same layout would give exactly 0
}

TEST(RecordingCall, WithoutRigidBodiesTheConfigurationsDefaultLayoutIsUsed) {
  datasets::ExperimentFile bare = Trial().experiment;
  bare.rigid_bodies.clear();
  const ProcessedRecording processed = AddMeasuredJointAngles(bare, "bare");
  const sim::ArmModel model(sim::ParseConfig(bare.config_yaml, "nominal").arm);
  const std::vector<datasets::RigidBody> expected =
      ToExperimentRigidBodies(DefaultMarkerLayout(model));
  ASSERT_EQ(processed.experiment.rigid_bodies.size(), expected.size());
  for (std::size_t b = 0; b < expected.size(); ++b) {
    EXPECT_EQ(processed.experiment.rigid_bodies[b].marker_names, expected[b].marker_names);
  }
  ASSERT_TRUE(processed.experiment.measured_joint_angles.has_value());
}

TEST(RecordingCall, ExperimentWithNeitherRigidBodiesNorConfigurationIsOneLine) {
  datasets::ExperimentFile bare = Trial().experiment;
  bare.rigid_bodies.clear();
  bare.config_yaml.clear();
  const std::string message = InputErrorOf([&] { AddMeasuredJointAngles(bare, "bare.h5"); });
  EXPECT_TRUE(HasOneLine(message)) << message;
  EXPECT_THAT(message, StartsWith("bare.h5: /mocap/rigid_bodies: none, and no attribute "
                                  "'config_yaml'"));
}

TEST(RecordingCall, InconsistentExperimentIsRefusedBeforeProcessing) {
  datasets::ExperimentFile broken = Trial().experiment;
  broken.marker_names.pop_back();
  const std::string message = InputErrorOf([&] { AddMeasuredJointAngles(broken, "broken.h5"); });
  EXPECT_TRUE(HasOneLine(message)) << message;
  EXPECT_THAT(message, StartsWith("broken.h5: /mocap/"));
}

TEST(RecordingCall, RequestNeedsOneMarkerSourceAndValidOptions) {
  std::string error;
  RecordingRequest request;
  EXPECT_FALSE(request.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("no marker source"));
  request.in = "x.c3d";
  EXPECT_TRUE(request.IsValid(&error)) << error;
  request.reconstruct = [](const MarkerLayout&, const sim::ArmModel*) {
    return ReconstructedMarkers{};
  };
  EXPECT_FALSE(request.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("not both"));
  request.in.clear();
  EXPECT_FALSE(request.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("needs `rigid_bodies` or `config`"));
  request.config = Paper();
  EXPECT_TRUE(request.IsValid(&error)) << error;
  request.processing.cutoff_hz = -1.0;
  EXPECT_FALSE(request.IsValid(&error));
  EXPECT_THAT(error, StartsWith("processing: "));
  const std::string message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_THAT(message, StartsWith("mocap recording request: processing: "));
}

TEST(RecordingCall, BadFilesGetTheReadersOneLineNamingTheFile) {
  const std::filesystem::path dir = FreshTempDir("recording_call_bad");
  RecordingRequest request;
  // A C3D with neither rigid bodies nor a configuration.
  request.in = (dir / "rec.c3d").string();
  WriteC3d(request.in, MarkerTableFromExperiment(Trial().experiment));
  std::string message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_TRUE(HasOneLine(message)) << message;
  EXPECT_EQ(message, request.in +
                         ": rigid bodies: give --rigid-bodies FILE or --config FILE (the default "
                         "marker layout)");
  // A configuration that does not exist.
  request.config = (dir / "missing.yaml").string();
  message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_TRUE(HasOneLine(message)) << message;
  EXPECT_THAT(message, StartsWith(request.config));
  // A static trial without any arm model.
  request.config.clear();
  request.rigid_bodies = (dir / "rb.yaml").string();
  WriteRigidBodiesFile(request.rigid_bodies,
                       LayoutFromExperiment(Trial().experiment.rigid_bodies, "exp"));
  request.static_trial = request.in;
  message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_EQ(message, request.in + ": --static-trial: needs --config (the arm's kinematics)");
  // A run without virtual markers.
  datasets::RunFile run = Trial().truth;
  run.markers.reset();
  run.marker_names.clear();
  const std::string run_path = (dir / "run.h5").string();
  datasets::WriteRunFile(run_path, run);
  request = RecordingRequest();
  request.in = run_path;
  request.config = Paper();
  message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_EQ(message, run_path + ": /markers: missing: this run has no virtual markers");
  // An --inputs file that is not a ccsrm file.
  request = RecordingRequest();
  request.in = Trial().experiment_path;
  request.inputs = (dir / "rec.c3d").string();
  message = InputErrorOf([&] { ProcessRecording(request); });
  EXPECT_TRUE(HasOneLine(message)) << message;
  EXPECT_THAT(message, StartsWith(request.inputs + ": "));
}

TEST(RecordingCall, RunWithMarkersBecomesAGeneratedExperimentWithTheRunsInputs) {
  RecordingRequest request;
  request.in = Trial().directory + "/truth.h5";
  datasets::WriteRunFile(request.in, Trial().truth);
  request.config = Paper();
  const ProcessedRecording processed = ProcessRecording(request);
  EXPECT_EQ(processed.experiment.name, "truth");  // the stem of the file, no name given
  EXPECT_EQ(processed.experiment.source, datasets::ExperimentSource::kGenerated);
  EXPECT_EQ(processed.experiment.input_length_change.values,
            Trial().truth.input_length_change.values);
  EXPECT_EQ(processed.experiment.config_yaml, ReadTextFile(Paper()));
  // Noise-free markers: the simulated angles, to the filter's smoothing of
  // the arm's ~3 Hz response (a regression guard against a wrong route).
  const AngleErrors errors =
      CompareJointAngles(*processed.experiment.measured_joint_angles, Trial().truth.joint_angles);
  EXPECT_LT(errors.worst_rms_deg, 0.2) << errors.Report();
}

TEST(RecordingCall, ReconstructionIsCalledWithTheResolvedLayoutAndModel) {
  // The hook of the camera front end, without cameras: markers handed over
  // as a reconstruction process as the same markers read from a file.
  const RoundTripTrial& trial = Trial();
  RecordingRequest request;
  request.config = Paper();
  request.reconstruction_source = "fake-cameras.yaml";
  std::size_t calls = 0;
  request.reconstruct = [&](const MarkerLayout& layout, const sim::ArmModel* model) {
    ++calls;
    EXPECT_EQ(layout.bodies.size(), 13u);  // the default layout of the paper's arm
    EXPECT_NE(model, nullptr);
    return ReconstructedMarkers{MarkerTableFromExperiment(trial.experiment), "fake report\n"};
  };
  const ProcessedRecording reconstructed = ProcessRecording(request);
  EXPECT_EQ(calls, 1u);
  EXPECT_EQ(reconstructed.reconstruction_report, "fake report\n");
  EXPECT_EQ(reconstructed.experiment.description,
            "markers of fake-cameras.yaml (ccsrm-dataset), processed by ccsrm mocap process");

  RecordingRequest from_file;
  from_file.in = trial.experiment_path;
  from_file.config = Paper();
  const ProcessedRecording file = ProcessRecording(from_file);
  // The file's time base against frame i at i / rate: the same to rounding.
  ccsrm::testing::ExpectSameArray(*reconstructed.experiment.measured_joint_angles,
                                  *file.experiment.measured_joint_angles, "joint angles", 1e-12);
}

// Inputs of another arm are refused where they enter, before any marker is
// reconstructed or processed (issue 32: `mocap process --inputs` used to
// work through a recording first).
TEST(RecordingCall, InputsOfAnotherArmAreRefusedBeforeTheMarkers) {
  RecordingRequest request;
  request.config = std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml";  // 9 cables
  request.inputs = Trial().experiment_path;  // the paper arm's 6
  request.reconstruction_source = "fake-cameras.yaml";
  bool reconstructed = false;
  request.reconstruct = [&](const MarkerLayout&, const sim::ArmModel*) {
    reconstructed = true;
    return ReconstructedMarkers{MarkerTableFromExperiment(Trial().experiment), ""};
  };
  std::string message;
  try {
    ProcessRecording(request);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_EQ(message, request.inputs + ": /input/length_change: has 6 cable columns, the arm of " +
                         request.config + " has 9 driving cables");
  EXPECT_FALSE(reconstructed);
}

// The one check of recorded inputs (sim_io::CheckInputs), on inputs
// assembled in memory: the time base, the lengths, the arm's cables.
TEST(InputCheck, TimeBaseLengthsAndCablesAreCheckedWithOneLine) {
  const sim::ArmModel arm(sim::LoadConfig(Paper()).arm);
  datasets::ExperimentFile good = Trial().experiment;
  EXPECT_NO_THROW(sim_io::CheckInputs(good, "e.h5", &arm, "arm.yaml"));
  const auto error = [&](const std::function<void(datasets::ExperimentFile*)>& change) {
    datasets::ExperimentFile e = good;
    change(&e);
    try {
      sim_io::CheckInputs(e, "e.h5", &arm, "arm.yaml");
    } catch (const InputError& x) {
      return std::string(x.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(
      error([](datasets::ExperimentFile* e) { e->input_time.values[5] = e->input_time.values[4]; }),
      HasSubstr("e.h5: /input/time: not strictly increasing: sample 5 holds "));
  EXPECT_THAT(error([](datasets::ExperimentFile* e) { e->input_time.values[2] = NAN; }),
              HasSubstr("e.h5: /input/time: sample 2 is nan: the time base must be finite"));
  EXPECT_THAT(
      error([](datasets::ExperimentFile* e) { e->input_length_change.at(7, 4) = INFINITY; }),
      HasSubstr("e.h5: /input/length_change: sample 7, cable 5 is inf: a length change "
                "must be finite"));
  EXPECT_EQ(error([](datasets::ExperimentFile* e) {
              e->input_length_change = datasets::Array({e->input_time.rows(), 4}, 0.0);
            }),
            "e.h5: /input/length_change: has 4 cable columns, the arm of arm.yaml has 6 driving "
            "cables");
  // No cable column: a recording without an actuator record, allowed.
  EXPECT_EQ(error([](datasets::ExperimentFile* e) {
              e->input_length_change = datasets::Array({e->input_time.rows(), 0});
            }),
            "(no error)");
}

}  // namespace
}  // namespace ccsrm::mocap::testing
