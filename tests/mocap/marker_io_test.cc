// ReadMarkerFile dispatch and the inspect summaries.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::InputErrorOf;
using testing::WriteFile;

TEST(ReadMarkerFile, ChoosesTheReaderByExtensionAndFirstLine) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  CCSRM_SHARED_FILE_OR_SKIP(nexus_trc, "data/mocap/text/nexus_markers.trc");
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  CCSRM_SHARED_FILE_OR_SKIP(pc_real_c3d, "data/mocap/c3d/pc_real.c3d");
  EXPECT_EQ(ReadMarkerFile(eb015pi_c3d).format, "c3d");
  EXPECT_EQ(ReadMarkerFile(nexus_trc).format, "trc");
  EXPECT_EQ(ReadMarkerFile(nexus_csv).format, "nexus-csv");

  const fs::path dir = FreshTempDir("dispatch");
  WriteFile(dir / "take.csv",
            "Format Version,1.23,Export Frame Rate,100,Length Units,Meters\n\n"
            ",Type,Marker,Marker,Marker\n,Name,A,A,A\n,ID,1,1,1\n,,Position,Position,Position\n"
            "Frame,Time (Seconds),X,Y,Z\n0,0,1,2,3\n");
  EXPECT_EQ(ReadMarkerFile((dir / "take.csv").string()).format, "motive-csv");

  // The extension is case-insensitive (a link, not a copy, of the shared file).
  fs::create_symlink(pc_real_c3d, dir / "UPPER.C3D");
  EXPECT_EQ(ReadMarkerFile((dir / "UPPER.C3D").string()).processor, "intel");
}

TEST(ReadMarkerFile, UnknownExtensionOrCsvFlavourIsAnInputError) {
  const fs::path dir = FreshTempDir("dispatch_errors");
  WriteFile(dir / "markers.xyz", "1 2 3\n");
  const std::string unknown = InputErrorOf([&] { ReadMarkerFile((dir / "markers.xyz").string()); });
  EXPECT_NE(unknown.find("markers.xyz"), std::string::npos);
  EXPECT_NE(unknown.find(".c3d, .trc, .csv, .h5 or .hdf5"), std::string::npos);

  WriteFile(dir / "table.csv", "time,x,y,z\n0,1,2,3\n");
  const std::string csv = InputErrorOf([&] { ReadMarkerFile((dir / "table.csv").string()); });
  EXPECT_NE(csv.find("table.csv: line 1: unrecognised CSV"), std::string::npos) << csv;

  const std::string missing = InputErrorOf([&] { ReadMarkerFile((dir / "missing.c3d").string()); });
  EXPECT_NE(missing.find("missing.c3d: cannot open"), std::string::npos) << missing;
}

TEST(Inspect, JsonSummaryOfAC3dFileHasTheDocumentedKeys) {
  CCSRM_SHARED_FILE_OR_SKIP(eb015pi_c3d, "data/mocap/c3d/Eb015pi.c3d");
  const nlohmann::json j = InspectJson(ReadMarkerFile(eb015pi_c3d));
  for (const char* key : {"format",
                          "frames",
                          "markers",
                          "rate_hz",
                          "first_frame_number",
                          "duration_s",
                          "labels",
                          "units_in_file",
                          "up_axis",
                          "invalid_points",
                          "invalid_fraction",
                          "longest_gap_frames",
                          "longest_gap_marker",
                          "visibility",
                          "first_frame",
                          "has_residual",
                          "warnings",
                          "processor",
                          "storage",
                          "point_scale_m"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["format"], "c3d");
  EXPECT_EQ(j["frames"], 450);
  EXPECT_EQ(j["rate_hz"], 50.0);
  EXPECT_EQ(j["labels"].size(), 26u);
  EXPECT_EQ(j["processor"], "intel");
  EXPECT_EQ(j["storage"], "integer");
  EXPECT_EQ(j["invalid_points"], 226);
  EXPECT_TRUE(j["first_frame"]["LFT1"].is_null());
  ASSERT_TRUE(j["first_frame"]["RFT1"].is_array());
  EXPECT_NEAR(j["first_frame"]["RFT1"][0].get<double>(), 0.248583, 1e-6);
}

TEST(Inspect, JsonOfATextFileHasNoC3dKeysAndTextIsReadable) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  const MarkerTable t = ReadMarkerFile(nexus_csv);
  const nlohmann::json j = InspectJson(t);
  EXPECT_FALSE(j.contains("processor"));
  EXPECT_NEAR(j["first_frame"]["boite:gauche_ext"][2].get<double>(), 0.675697, 1e-12);
  const std::string text = InspectText(t);
  EXPECT_NE(text.find("nexus-csv"), std::string::npos);
  EXPECT_NE(text.find("580 at 100 Hz"), std::string::npos);
  EXPECT_NE(text.find("boite:gauche_ext"), std::string::npos);
}

TEST(Inspect, Latin1LabelsAreReadAsUtf8SoTheJsonAlwaysSerializes) {
  // Found by the C3D fuzzer: a label byte that is not UTF-8 made
  // nlohmann::json::dump throw. C3D labels are read as UTF-8, or Latin-1
  // where they are not valid UTF-8.
  MarkerTable t;
  t.rate_hz = 100;
  t.Reset(1, {"\xE9paule", "coude", "caf\xC3\xA9"}, false);  // Latin-1, ASCII, UTF-8
  t.set_position(0, 0, Eigen::Vector3d(1, 2, 3));
  const MarkerTable read = ReadC3dFromMemory(EncodeC3d(t), "latin1.c3d");
  EXPECT_EQ(read.labels, (std::vector<std::string>{"\xC3\xA9paule", "coude", "caf\xC3\xA9"}));
  const std::string json = InspectJson(read).dump();
  EXPECT_NE(json.find("\xC3\xA9paule"), std::string::npos);
  // A hand-built table with invalid bytes serializes too.
  t.warnings.push_back("bad byte \xFF");
  EXPECT_NO_THROW(InspectJson(t).dump());
}

}  // namespace
}  // namespace ccsrm::mocap
