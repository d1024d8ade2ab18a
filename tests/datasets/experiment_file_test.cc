#include "ccsrm/datasets/experiment_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/run_file.h"
#include "test_util.h"

namespace ccsrm::datasets {
namespace {
namespace fs = std::filesystem;
using ::ccsrm::datasets::testing::DeleteObject;
using ::ccsrm::datasets::testing::DirectoryEntries;
using ::ccsrm::datasets::testing::FreshDir;
using ::ccsrm::datasets::testing::Identical;
using ::ccsrm::datasets::testing::InputErrorMessage;
using ::ccsrm::datasets::testing::MakeExperimentFile;
using ::ccsrm::datasets::testing::MakeRunFile;
using ::ccsrm::datasets::testing::Ramp;
using ::ccsrm::datasets::testing::ReplaceDataset;
using ::ccsrm::datasets::testing::SetRootString;
using ::ccsrm::datasets::testing::SetUnits;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string WriteGoodExperiment(const std::string& test_name) {
  const std::string path = (FreshDir(test_name) / "exp.h5").string();
  WriteExperimentFile(path, MakeExperimentFile());
  return path;
}

std::vector<std::string> BodyNames(const ExperimentFile& experiment) {
  std::vector<std::string> names;
  for (const RigidBody& body : experiment.rigid_bodies) names.push_back(body.name);
  return names;
}

void ExpectSameExperiment(const ExperimentFile& expected, const ExperimentFile& actual) {
  EXPECT_EQ(actual.name, expected.name);
  EXPECT_EQ(actual.description, expected.description);
  EXPECT_EQ(actual.created, expected.created);
  EXPECT_EQ(actual.source, expected.source);
  EXPECT_EQ(actual.config_yaml, expected.config_yaml);
  EXPECT_TRUE(Identical(actual.input_time, expected.input_time));
  EXPECT_TRUE(Identical(actual.input_length_change, expected.input_length_change));
  EXPECT_TRUE(Identical(actual.mocap_time, expected.mocap_time));
  EXPECT_TRUE(Identical(actual.mocap_markers, expected.mocap_markers));
  EXPECT_EQ(actual.marker_names, expected.marker_names);
  ASSERT_EQ(BodyNames(actual), BodyNames(expected));
  for (std::size_t b = 0; b < expected.rigid_bodies.size(); ++b) {
    SCOPED_TRACE(expected.rigid_bodies[b].name);
    EXPECT_EQ(actual.rigid_bodies[b].marker_names, expected.rigid_bodies[b].marker_names);
    EXPECT_TRUE(
        Identical(actual.rigid_bodies[b].local_position, expected.rigid_bodies[b].local_position));
  }
  ASSERT_EQ(actual.mocap_quality.size(), expected.mocap_quality.size());
  for (const auto& [name, array] : expected.mocap_quality) {
    ASSERT_EQ(actual.mocap_quality.count(name), 1u) << name;
    EXPECT_TRUE(Identical(actual.mocap_quality.at(name), array)) << name;
  }
  EXPECT_EQ(actual.mocap_quality_units, expected.mocap_quality_units);
  ASSERT_EQ(actual.measured_joint_angles.has_value(), expected.measured_joint_angles.has_value());
  if (expected.measured_joint_angles) {
    EXPECT_TRUE(Identical(*actual.measured_joint_angles, *expected.measured_joint_angles));
  }
  ASSERT_EQ(actual.measured_input_tension.has_value(), expected.measured_input_tension.has_value());
  if (expected.measured_input_tension) {
    EXPECT_TRUE(Identical(*actual.measured_input_tension, *expected.measured_input_tension));
  }
}

// --- Round trip ----------------------------------------------------------------

TEST(ExperimentFileRoundTrip, PreservesEveryArrayAttributeAndUnseenMarker) {
  const std::string path = (FreshDir("exp_round_trip") / "exp.h5").string();
  const ExperimentFile experiment = MakeExperimentFile();
  WriteExperimentFile(path, experiment);
  const ExperimentFile back = ReadExperimentFile(path);
  ExpectSameExperiment(experiment, back);
  EXPECT_TRUE(std::isnan(back.mocap_markers.at(1, 2, 0)));
  EXPECT_FALSE(std::isnan(back.mocap_markers.at(1, 1, 0)));
}

TEST(ExperimentFileRoundTrip, OptionalPartsMayBeAbsent) {
  const std::string path = (FreshDir("exp_minimal") / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  experiment.source = ExperimentSource::kRecorded;
  experiment.rigid_bodies.clear();
  experiment.mocap_quality.clear();
  experiment.mocap_quality_units.clear();
  experiment.measured_joint_angles.reset();
  experiment.measured_input_tension.reset();
  WriteExperimentFile(path, experiment);
  ExpectSameExperiment(experiment, ReadExperimentFile(path));
}

TEST(ExperimentFileRead, ReturnsRigidBodiesSortedByLinkNumber) {
  const std::string path = (FreshDir("exp_body_order") / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  experiment.marker_names = {"a", "b", "c", "d"};
  experiment.mocap_markers = Ramp({6, 4, 3}, 0.0);
  experiment.rigid_bodies.clear();
  for (const char* name : {"link10", "link2", "base", "link1", "link12"}) {
    experiment.rigid_bodies.push_back({name, {"a", "c"}, Ramp({2, 3}, 0.0)});
  }
  WriteExperimentFile(path, experiment);
  // HDF5 lists names alphabetically (link1, link10, link12, link2): the
  // reader orders them as the arm does.
  EXPECT_EQ(BodyNames(ReadExperimentFile(path)),
            (std::vector<std::string>{"base", "link1", "link2", "link10", "link12"}));
}

TEST(ExperimentFileRead, AcceptsFixedLengthStringsAsWrittenByMatlab) {
  const std::string path = WriteGoodExperiment("exp_fixed_strings");
  SetRootString(path, "name", "matlab-trial-7", /*fixed_length=*/true);
  EXPECT_EQ(ReadExperimentFile(path).name, "matlab-trial-7");
}

// --- Failed writes -------------------------------------------------------------

TEST(ExperimentFileWrite, RigidBodyMarkerNotInMarkerListIsRejected) {
  const fs::path dir = FreshDir("exp_body_marker");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  experiment.rigid_bodies[1].marker_names[1] = "link1_z";
  EXPECT_EQ(InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
            path +
                ": /mocap/rigid_bodies/link1/marker_names: marker 'link1_z' is not in "
                "/mocap/marker_names");
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

TEST(ExperimentFileWrite, InvalidRigidBodyNameIsRejected) {
  const fs::path dir = FreshDir("exp_body_name");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  experiment.rigid_bodies[1].name = "link01";
  EXPECT_THAT(
      InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
      AllOf(StartsWith(path + ": /mocap/rigid_bodies/link01: "), HasSubstr("'base' or 'link<n>'")));
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

TEST(ExperimentFileWrite, QualityFigureWithoutUnitsIsRejected) {
  const fs::path dir = FreshDir("exp_quality_units");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  experiment.mocap_quality["visibility"] = Ramp({4}, 0.0);
  EXPECT_THAT(InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
              AllOf(StartsWith(path + ": /mocap/quality/visibility: "), HasSubstr("no units")));
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

TEST(ExperimentFileRoundTrip, MeasuredLinkPoseAndTwistExtensionsRoundTrip) {
  const fs::path dir = FreshDir("exp_measured_pose");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  const std::size_t f = experiment.mocap_time.rows();
  experiment.measured_link_pose = Ramp({f, 2, 7}, 0.01);
  experiment.measured_joint_twist = Ramp({f, 2}, 1e-4);
  WriteExperimentFile(path, experiment);
  const ExperimentFile back = ReadExperimentFile(path);
  ASSERT_TRUE(back.measured_link_pose && back.measured_joint_twist);
  EXPECT_TRUE(Identical(*back.measured_link_pose, *experiment.measured_link_pose));
  EXPECT_TRUE(Identical(*back.measured_joint_twist, *experiment.measured_joint_twist));
  // A twist for another number of joints than the joint angles is refused.
  experiment.measured_joint_twist = Ramp({f, 3}, 1e-4);
  EXPECT_THAT(InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
              AllOf(StartsWith(path + ": /measured/joint_twist: "), HasSubstr("expected J=2")));
}

// Issue 46: a pose log's experiment says its rows are settled poses, its
// markers in the capture frame, and labels each input sample with its pattern.
TEST(ExperimentFileRoundTrip, SettledPosesInTheCaptureFrameWithLabelsRoundTrip) {
  const fs::path dir = FreshDir("exp_settled_poses");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  WriteExperimentFile(path, experiment);
  ExperimentFile back = ReadExperimentFile(path);
  // Absent, as in every file written before them: a continuous motion in W.
  EXPECT_EQ(back.motion, RecordedMotion::kContinuous);
  EXPECT_EQ(back.marker_frame, MarkerFrame::kWorld);
  EXPECT_TRUE(back.input_labels.empty());

  experiment.motion = RecordedMotion::kSettledPoses;
  experiment.marker_frame = MarkerFrame::kCapture;
  const std::size_t n = experiment.input_time.size();
  for (std::size_t i = 0; i < n; ++i) {
    experiment.input_labels.push_back(i < n / 2 ? "seg1_dir0" : "seg1_dir0_hold");
  }
  WriteExperimentFile(path, experiment);
  back = ReadExperimentFile(path);
  EXPECT_EQ(back.motion, RecordedMotion::kSettledPoses);
  EXPECT_EQ(back.marker_frame, MarkerFrame::kCapture);
  EXPECT_EQ(back.input_labels, experiment.input_labels);

  SetRootString(path, "motion", "stream");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": attribute 'motion' is 'stream': expected 'continuous' or 'settled_poses'");
  experiment.input_labels.pop_back();
  EXPECT_EQ(InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
            path + ": /input/labels: expected N=" + std::to_string(n) +
                " labels (from /input/time), found " + std::to_string(n - 1));
}

// Issue 33: joint angles cut to fewer joints than the twist and the link poses
// they were written with are the odd one out, and the message names them.
TEST(ExperimentFileRead, AnglesCutToFewerJointsAreBlamedNotTheTwist) {
  const fs::path dir = FreshDir("exp_cut_angles");
  const std::string path = (dir / "exp.h5").string();
  ExperimentFile experiment = MakeExperimentFile();
  const std::size_t f = experiment.mocap_time.rows();
  experiment.measured_joint_angles = Ramp({f, 3, 2}, 0.0);
  experiment.measured_link_pose = Ramp({f, 3, 7}, 0.01);
  experiment.measured_joint_twist = Ramp({f, 3}, 1e-4);
  WriteExperimentFile(path, experiment);
  ReplaceDataset(path, "/measured/joint_angles", Ramp({f, 2, 2}, 0.0), std::string("rad"));
  EXPECT_THAT(InputErrorMessage([&] { ReadExperimentFile(path); }),
              AllOf(StartsWith(path + ": /measured/joint_angles: has J=2 joints"),
                    HasSubstr("/measured/joint_twist has 3"),
                    HasSubstr("/measured/link_pose has 3 links")));
  // Without link poses to tell, the angles are still the ones named.
  experiment.measured_link_pose.reset();
  experiment.measured_joint_angles = Ramp({f, 2, 2}, 0.0);
  EXPECT_THAT(InputErrorMessage([&] { WriteExperimentFile(path, experiment); }),
              StartsWith(path + ": /measured/joint_angles: has J=2 joints"));
}

// --- Rejection of bad files ------------------------------------------------------

TEST(ExperimentFileRead, RejectsMissingMarkers) {
  const std::string path = WriteGoodExperiment("exp_missing_markers");
  DeleteObject(path, "/mocap/markers");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": /mocap/markers: missing");
}

TEST(ExperimentFileRead, RejectsRunFileAsWrongKind) {
  const std::string path = (FreshDir("exp_wrong_kind") / "run.h5").string();
  WriteRunFile(path, MakeRunFile());
  EXPECT_THAT(InputErrorMessage([&] { ReadExperimentFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("is a ccsrm-run file"),
                    HasSubstr("expected ccsrm-dataset")));
}

TEST(ExperimentFileRead, RejectsUnsupportedVersion) {
  const std::string path = WriteGoodExperiment("exp_version");
  SetRootString(path, "schema", "ccsrm-dataset/3");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path +
                ": attribute 'schema' is 'ccsrm-dataset/3': unsupported version (this ccsrm "
                "reads ccsrm-dataset/1)");
}

TEST(ExperimentFileRead, RejectsUnknownSource) {
  const std::string path = WriteGoodExperiment("exp_source");
  SetRootString(path, "source", "simulated");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": attribute 'source' is 'simulated': expected 'recorded' or 'generated'");
}

TEST(ExperimentFileRead, RejectsMarkerNamesNotMatchingMarkers) {
  const std::string path = WriteGoodExperiment("exp_marker_count");
  ReplaceDataset(path, "/mocap/markers", Ramp({6, 5, 3}, 0.0), "m");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": /mocap/marker_names: expected M=5 names (from /mocap/markers), found 4");
  DeleteObject(path, "/mocap/marker_names");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": /mocap/marker_names: missing");
}

TEST(ExperimentFileRead, RejectsWrongShapeAgainstInputTime) {
  const std::string path = WriteGoodExperiment("exp_tension_shape");
  ReplaceDataset(path, "/measured/input_tension", Ramp({8, 3}, 90.0), "N");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path +
                ": /measured/input_tension: expected shape N×C with N=9 (from /input/time), "
                "C=3 (from /input/length_change), found 8×3");
}

TEST(ExperimentFileRead, RejectsWrongUnitsOnMarkers) {
  const std::string path = WriteGoodExperiment("exp_marker_units");
  SetUnits(path, "/mocap/markers", "mm");
  EXPECT_EQ(InputErrorMessage([&] { ReadExperimentFile(path); }),
            path + ": /mocap/markers: units attribute is 'mm', expected 'm'");
}

TEST(ExperimentFileRead, RejectsNonIncreasingMocapTime) {
  const std::string path = WriteGoodExperiment("exp_mocap_time");
  Array time = MakeExperimentFile().mocap_time;
  std::swap(time.at(2), time.at(3));
  ReplaceDataset(path, "/mocap/time", time, "s");
  EXPECT_THAT(
      InputErrorMessage([&] { ReadExperimentFile(path); }),
      AllOf(StartsWith(path + ": /mocap/time: "), HasSubstr("not strictly increasing: index 3")));
}

TEST(ExperimentFileRead, RejectsTruncatedFile) {
  const std::string good = WriteGoodExperiment("exp_truncated");
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string path = good + ".half.h5";
  std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THAT(InputErrorMessage([&] { ReadExperimentFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("truncated")));
}

}  // namespace
}  // namespace ccsrm::datasets
