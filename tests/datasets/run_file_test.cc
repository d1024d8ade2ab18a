#include "ccsrm/datasets/run_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>

#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "test_util.h"

namespace ccsrm::datasets {
namespace {
namespace fs = std::filesystem;
using ::ccsrm::datasets::testing::DeleteObject;
using ::ccsrm::datasets::testing::DeleteRootAttribute;
using ::ccsrm::datasets::testing::DirectoryEntries;
using ::ccsrm::datasets::testing::FreshDir;
using ::ccsrm::datasets::testing::Identical;
using ::ccsrm::datasets::testing::InputErrorMessage;
using ::ccsrm::datasets::testing::MakeExperimentFile;
using ::ccsrm::datasets::testing::MakePaperSizedRunFile;
using ::ccsrm::datasets::testing::MakeRunFile;
using ::ccsrm::datasets::testing::Ramp;
using ::ccsrm::datasets::testing::ReplaceDataset;
using ::ccsrm::datasets::testing::RunSizes;
using ::ccsrm::datasets::testing::SetRootString;
using ::ccsrm::datasets::testing::SetUnits;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Writes a good run file into a fresh directory and returns its path.
std::string WriteGoodRun(const std::string& test_name) {
  const std::string path = (FreshDir(test_name) / "run.h5").string();
  WriteRunFile(path, MakeRunFile());
  return path;
}

void ExpectSameRun(const RunFile& expected, const RunFile& actual) {
  EXPECT_EQ(actual.case_name, expected.case_name);
  EXPECT_EQ(actual.config_yaml, expected.config_yaml);
  EXPECT_EQ(actual.created, expected.created);
  EXPECT_EQ(actual.ccsrm_version, expected.ccsrm_version);
  EXPECT_EQ(actual.wall_time_s, expected.wall_time_s);
  EXPECT_EQ(actual.steps, expected.steps);
  EXPECT_EQ(actual.rejected_steps, expected.rejected_steps);
  EXPECT_EQ(actual.rhs_evaluations, expected.rhs_evaluations);
  EXPECT_EQ(actual.status, expected.status);
  EXPECT_EQ(actual.status_message, expected.status_message);
  EXPECT_TRUE(Identical(actual.time, expected.time));
  EXPECT_TRUE(Identical(actual.joint_angles, expected.joint_angles));
  EXPECT_TRUE(Identical(actual.joint_rates, expected.joint_rates));
  EXPECT_TRUE(Identical(actual.link_pose, expected.link_pose));
  EXPECT_TRUE(Identical(actual.input_tension, expected.input_tension));
  EXPECT_TRUE(Identical(actual.input_length_change, expected.input_length_change));
  EXPECT_TRUE(Identical(actual.stuck_nodes, expected.stuck_nodes));
  ASSERT_EQ(actual.cables.size(), expected.cables.size());
  for (std::size_t k = 0; k < expected.cables.size(); ++k) {
    SCOPED_TRACE("cable " + std::to_string(k + 1));
    EXPECT_TRUE(Identical(actual.cables[k].tension, expected.cables[k].tension));
    EXPECT_TRUE(Identical(actual.cables[k].stuck, expected.cables[k].stuck));
    EXPECT_TRUE(Identical(actual.cables[k].slip_velocity, expected.cables[k].slip_velocity));
  }
  EXPECT_TRUE(Identical(actual.constraint_violation, expected.constraint_violation));
  EXPECT_TRUE(Identical(actual.energy, expected.energy));
  ASSERT_EQ(actual.markers.has_value(), expected.markers.has_value());
  if (expected.markers) {
    EXPECT_TRUE(Identical(*actual.markers, *expected.markers));
  }
  EXPECT_EQ(actual.marker_names, expected.marker_names);
}

// Lowers this process's file size limit (RLIMIT_FSIZE) so that writes beyond
// `bytes` fail with EFBIG, as on a full disk; restores it on destruction.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_handler_);
  }

 private:
  rlimit saved_{};
  void (*previous_handler_)(int) = nullptr;
};

// --- Round trip ----------------------------------------------------------------

TEST(RunFileRoundTrip, PreservesEveryArrayAndAttribute) {
  const std::string path = (FreshDir("run_round_trip") / "run.h5").string();
  const RunFile run = MakeRunFile();
  WriteRunFile(path, run);
  ExpectSameRun(run, ReadRunFile(path));
}

TEST(RunFileRoundTrip, GeneralCountsAndNoMarkers) {
  const std::string path = (FreshDir("run_round_trip_general") / "run.h5").string();
  RunSizes sizes;
  sizes.frames = 1;  // a run that diverged on its first step still has t0
  sizes.joints = 5;
  sizes.links = 2;
  sizes.elements = {1, 8, 3};
  sizes.holes = {0, 6, 1};  // a cable without holes has T×0 hole datasets
  sizes.markers = 0;
  RunFile run = MakeRunFile(sizes);
  run.status = RunStatus::kCompleted;
  run.status_message.clear();
  run.case_name = "custom";
  WriteRunFile(path, run);
  const RunFile back = ReadRunFile(path);
  ExpectSameRun(run, back);
  EXPECT_FALSE(back.markers.has_value());
}

TEST(RunFileRoundTrip, EmptyCreatedIsStampedAtWriting) {
  const std::string path = (FreshDir("run_created") / "run.h5").string();
  RunFile run = MakeRunFile();
  run.created.clear();
  WriteRunFile(path, run);
  EXPECT_TRUE(run.created.empty());  // the input is not modified
  EXPECT_TRUE(std::regex_match(ReadRunFile(path).created,
                               std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
}

TEST(RunFileWrite, StoresLittleEndianDoublesAndUtf8VariableLengthStrings) {
  const std::string path = WriteGoodRun("run_types");
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t dataset = H5Dopen2(file, "/joint_angles", H5P_DEFAULT);
  const hid_t type = H5Dget_type(dataset);
  EXPECT_GT(H5Tequal(type, H5T_IEEE_F64LE), 0);
  const hid_t attribute = H5Aopen(file, "schema", H5P_DEFAULT);
  const hid_t string_type = H5Aget_type(attribute);
  EXPECT_GT(H5Tis_variable_str(string_type), 0);
  EXPECT_EQ(H5Tget_cset(string_type), H5T_CSET_UTF8);
  const hid_t steps = H5Aopen(file, "steps", H5P_DEFAULT);
  const hid_t steps_type = H5Aget_type(steps);
  EXPECT_GT(H5Tequal(steps_type, H5T_STD_I64LE), 0);
  H5Tclose(steps_type);
  H5Aclose(steps);
  H5Tclose(string_type);
  H5Aclose(attribute);
  H5Tclose(type);
  H5Dclose(dataset);
  H5Fclose(file);
}

TEST(RunFileWrite, LargeDatasetsAreChunkedWithShuffleAndGzip) {
  const std::string path = (FreshDir("run_compression") / "run.h5").string();
  const RunFile run = MakePaperSizedRunFile();
  WriteRunFile(path, run);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  auto filters = [&](const char* name) {
    const hid_t dataset = H5Dopen2(file, name, H5P_DEFAULT);
    const hid_t create = H5Dget_create_plist(dataset);
    std::vector<H5Z_filter_t> ids;
    for (int i = 0; i < H5Pget_nfilters(create); ++i) {
      unsigned flags = 0;
      std::size_t count = 0;
      unsigned config = 0;
      ids.push_back(H5Pget_filter2(create, static_cast<unsigned>(i), &flags, &count, nullptr, 0,
                                   nullptr, &config));
    }
    H5Pclose(create);
    H5Dclose(dataset);
    return ids;
  };
  // 4801×12×7 = 403284 values: compressed. 4801 values: stored plainly.
  EXPECT_THAT(filters("/link_pose"), ElementsAre(H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE));
  EXPECT_THAT(filters("/cables/6/tension"), ElementsAre(H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE));
  EXPECT_TRUE(filters("/time").empty());
  H5Fclose(file);
  ExpectSameRun(run, ReadRunFile(path));
}

// --- Failed writes -------------------------------------------------------------

TEST(RunFileWrite, InconsistentArraysAreRejectedBeforeAnythingIsCreated) {
  const fs::path dir = FreshDir("run_inconsistent");
  const std::string path = (dir / "run.h5").string();
  RunFile run = MakeRunFile();
  run.cables[1].slip_velocity = Ramp({run.frames(), 5}, 0.0);  // 2 holes per /stuck
  EXPECT_THAT(InputErrorMessage([&] { WriteRunFile(path, run); }),
              AllOf(StartsWith(path + ": /cables/2/slip_velocity: "),
                    HasSubstr("expected shape T×H with T=7 (from /time), H=2 (from "
                              "/cables/2/stuck), found 7×5")));
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

TEST(RunFileWrite, ArrayWhoseValuesDisagreeWithItsShapeIsRejected) {
  const fs::path dir = FreshDir("run_bad_array");
  const std::string path = (dir / "run.h5").string();
  RunFile run = MakeRunFile();
  run.energy.values.pop_back();
  EXPECT_THAT(InputErrorMessage([&] { WriteRunFile(path, run); }),
              AllOf(StartsWith(path + ": /diagnostics/energy: "),
                    HasSubstr("array holds 20 values but its shape 7×3 needs 21")));
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

TEST(RunFileWrite, FailureMidWriteLeavesNoFileAndNoTemporary) {
  const fs::path dir = FreshDir("run_mid_write");
  const std::string path = (dir / "run.h5").string();
  const RunFile run = MakePaperSizedRunFile();  // several MB
  std::string message;
  {
    const FileSizeLimit limit(64 * 1024);  // the "disk" fills after 64 KiB
    message = InputErrorMessage([&] { WriteRunFile(path, run); });
  }
  EXPECT_THAT(message, StartsWith(path + ": "));
  EXPECT_THAT(message, HasSubstr("cannot"));
  std::cout << "message: " << message << "\n";
  EXPECT_TRUE(DirectoryEntries(dir).empty())
      << "left: " << ::testing::PrintToString(DirectoryEntries(dir));
}

TEST(RunFileWrite, FailureMidWriteKeepsThePreviousFile) {
  const fs::path dir = FreshDir("run_keep_previous");
  const std::string path = (dir / "run.h5").string();
  const RunFile small = MakeRunFile();
  WriteRunFile(path, small);
  const std::string before = ReadBytes(path);
  {
    const FileSizeLimit limit(64 * 1024);
    EXPECT_THAT(InputErrorMessage([&] { WriteRunFile(path, MakePaperSizedRunFile()); }),
                StartsWith(path + ": "));
  }
  EXPECT_EQ(ReadBytes(path), before);
  EXPECT_THAT(DirectoryEntries(dir), ElementsAre("run.h5"));
  ExpectSameRun(small, ReadRunFile(path));
}

TEST(RunFileWrite, MissingDirectoryIsRejected) {
  const fs::path dir = FreshDir("run_no_dir");
  const std::string path = (dir / "gone" / "run.h5").string();
  EXPECT_THAT(InputErrorMessage([&] { WriteRunFile(path, MakeRunFile()); }),
              AllOf(StartsWith(path + ": "), HasSubstr("does not exist")));
  EXPECT_TRUE(DirectoryEntries(dir).empty());
}

// --- Rejection of bad files ------------------------------------------------------

TEST(RunFileRead, RejectsTruncatedFile) {
  const std::string good = WriteGoodRun("run_truncated");
  const std::string bytes = ReadBytes(good);
  const std::string path = good + ".half.h5";
  std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const std::string message = InputErrorMessage([&] { ReadRunFile(path); });
  EXPECT_THAT(message, AllOf(StartsWith(path + ": "), HasSubstr("truncated")));
  EXPECT_EQ(message.find('\n'), std::string::npos);
  std::cout << "message: " << message << "\n";
}

TEST(RunFileRead, RejectsNonHdf5File) {
  const std::string path = (FreshDir("run_not_hdf5") / "run.h5").string();
  std::ofstream(path) << "time,theta\n0,0\n";
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("not an HDF5 file")));
}

TEST(RunFileRead, RejectsMissingFile) {
  const std::string path = (FreshDir("run_missing") / "nothing.h5").string();
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("no such file")));
}

TEST(RunFileRead, RejectsExperimentFileAsWrongKind) {
  const std::string path = (FreshDir("run_wrong_kind") / "exp.h5").string();
  WriteExperimentFile(path, MakeExperimentFile());
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("is a ccsrm-dataset file"),
                    HasSubstr("expected ccsrm-run")));
}

TEST(RunFileRead, RejectsUnsupportedVersion) {
  const std::string path = WriteGoodRun("run_version");
  SetRootString(path, "schema", "ccsrm-run/2");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path +
                ": attribute 'schema' is 'ccsrm-run/2': unsupported version (this ccsrm reads "
                "ccsrm-run/1)");
}

TEST(RunFileRead, RejectsFileWithoutSchema) {
  const std::string path = WriteGoodRun("run_no_schema");
  DeleteRootAttribute(path, "schema");
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": "), HasSubstr("'schema' missing")));
}

TEST(RunFileRead, RejectsMissingRequiredDataset) {
  const std::string path = WriteGoodRun("run_missing_dataset");
  DeleteObject(path, "/joint_rates");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }), path + ": /joint_rates: missing");
}

TEST(RunFileRead, RejectsMissingCableDataset) {
  const std::string path = WriteGoodRun("run_missing_cable_dataset");
  DeleteObject(path, "/cables/2/stuck");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }), path + ": /cables/2/stuck: missing");
}

TEST(RunFileRead, RejectsMissingCableGroup) {
  const std::string path = WriteGoodRun("run_missing_cable");
  DeleteObject(path, "/cables/2");
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": /cables: "),
                    HasSubstr("expected C=2 cable groups (from /input_tension), found 1")));
}

TEST(RunFileRead, RejectsMissingRootAttribute) {
  const std::string path = WriteGoodRun("run_missing_attribute");
  DeleteRootAttribute(path, "rhs_evaluations");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path + ": attribute 'rhs_evaluations': missing");
}

TEST(RunFileRead, RejectsWrongShape) {
  const std::string path = WriteGoodRun("run_wrong_shape");
  ReplaceDataset(path, "/joint_angles", Ramp({7, 3, 3}, 0.0), "rad");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path + ": /joint_angles: expected shape T×J×2 with T=7 (from /time), found 7×3×3");
}

TEST(RunFileRead, RejectsShapeInconsistentWithOtherArrays) {
  const std::string path = WriteGoodRun("run_inconsistent_shape");
  ReplaceDataset(path, "/joint_rates", Ramp({7, 4, 2}, 0.0), "rad/s");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path +
                ": /joint_rates: expected shape T×J×2 with T=7 (from /time), J=3 (from "
                "/joint_angles), found 7×4×2");
}

TEST(RunFileRead, RejectsMissingUnits) {
  const std::string path = WriteGoodRun("run_missing_units");
  SetUnits(path, "/time", std::nullopt);
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path + ": /time: missing units attribute");
}

TEST(RunFileRead, RejectsWrongUnits) {
  const std::string path = WriteGoodRun("run_wrong_units");
  SetUnits(path, "/joint_angles", "deg");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path + ": /joint_angles: units attribute is 'deg', expected 'rad'");
}

TEST(RunFileRead, RejectsIntegerDataset) {
  const std::string path = WriteGoodRun("run_integer");
  ReplaceDataset(path, "/stuck_nodes", Ramp({7, 2}, 0.0), "1", /*store_as_integer=*/true);
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }),
            path + ": /stuck_nodes: expected floating-point values, found integer values");
}

TEST(RunFileRead, RejectsNonIncreasingTime) {
  const std::string path = WriteGoodRun("run_time_order");
  Array time = MakeRunFile().time;
  time.at(4) = time.at(3);
  ReplaceDataset(path, "/time", time, "s");
  EXPECT_THAT(
      InputErrorMessage([&] { ReadRunFile(path); }),
      AllOf(StartsWith(path + ": /time: "), HasSubstr("not strictly increasing: index 4 holds ")));
}

TEST(RunFileRead, RejectsNonFiniteTime) {
  const std::string path = WriteGoodRun("run_time_nan");
  Array time = MakeRunFile().time;
  time.at(2) = std::numeric_limits<double>::quiet_NaN();
  ReplaceDataset(path, "/time", time, "s");
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              AllOf(StartsWith(path + ": /time: "), HasSubstr("index 2 is nan")));
}

TEST(RunFileRead, RejectsUnknownCaseAndStatus) {
  const std::string path = WriteGoodRun("run_case");
  SetRootString(path, "case", "7");
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              HasSubstr(path + ": attribute 'case' is '7': expected 1, 2, 3, 4 or custom"));
  SetRootString(path, "case", "2");
  SetRootString(path, "status", "crashed");
  EXPECT_THAT(InputErrorMessage([&] { ReadRunFile(path); }),
              HasSubstr(path + ": attribute 'status' is 'crashed': expected 'completed', "
                               "'diverged' or 'cancelled'"));
  SetRootString(path, "status", "cancelled");
  EXPECT_EQ(ReadRunFile(path).status, RunStatus::kCancelled);
}

TEST(RunFileRead, RejectsMarkersWithoutNames) {
  const std::string path = WriteGoodRun("run_marker_names");
  DeleteObject(path, "/marker_names");
  EXPECT_EQ(InputErrorMessage([&] { ReadRunFile(path); }), path + ": /marker_names: missing");
}

TEST(RunFileRead, LeavesTheFileUnchanged) {
  const std::string path = WriteGoodRun("run_read_only");
  const std::string before = ReadBytes(path);
  const auto modified = fs::last_write_time(path);
  ReadRunFile(path);
  EXPECT_EQ(ReadBytes(path), before);
  EXPECT_EQ(fs::last_write_time(path), modified);
}

}  // namespace
}  // namespace ccsrm::datasets
