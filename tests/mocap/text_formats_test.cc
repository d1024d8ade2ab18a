// TRC, Vicon Nexus CSV and OptiTrack Motive CSV readers.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ccsrm/mocap/text_formats.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::FreshTempDir;
using testing::WriteFile;

// The eight markers on the rigid box of the pyomeca trial.
const std::vector<std::string> kBoxMarkers = {"gauche_ext",    "gauche_int",    "droite_int",
                                              "droite_ext",    "avant_gauche",  "avant_droit",
                                              "arriere_droit", "arriere_gauche"};

TEST(NexusCsv, FirstFrameOfBoiteGaucheExtIsTheRecordedPosition) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  const MarkerTable t = ReadNexusCsv(nexus_csv);
  EXPECT_EQ(t.format, "nexus-csv");
  EXPECT_EQ(t.markers(), 51u);
  EXPECT_EQ(t.frames(), 580u);
  EXPECT_DOUBLE_EQ(t.rate_hz, 100.0);
  EXPECT_EQ(t.units_in_file, "mm");
  EXPECT_EQ(t.first_frame_number, 1);
  const auto m = t.index_of("boite:gauche_ext");
  ASSERT_TRUE(m.has_value());
  const Eigen::Vector3d p = t.position(0, *m);
  EXPECT_NEAR(p.x(), 44.1628e-3, 1e-12);
  EXPECT_NEAR(p.y(), -276.862e-3, 1e-12);
  EXPECT_NEAR(p.z(), 675.697e-3, 1e-12);
}

TEST(NexusCsv, EmptyCellsAreMarkersNotSeen) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  const MarkerTable t = ReadNexusCsv(nexus_csv);
  // 915 empty cells in the file = 305 samples × 3 coordinates.
  EXPECT_EQ(Summarize(t).invalid_points, 305u);
  EXPECT_TRUE(t.warnings.empty());
}

TEST(Trc, FirstFrameAndLabelsOfTheCommaSeparatedNexusExport) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_trc, "data/mocap/text/nexus_markers.trc");
  const MarkerTable t = ReadTrc(nexus_trc);
  EXPECT_EQ(t.format, "trc");
  EXPECT_EQ(t.markers(), 51u);
  EXPECT_DOUBLE_EQ(t.rate_hz, 100.0);
  EXPECT_EQ(t.units_in_file, "mm");
  // The header says NumFrames 652 but the file holds 93 rows: read the rows,
  // say so in a warning.
  EXPECT_EQ(t.frames(), 93u);
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_NE(t.warnings[0].find("652"), std::string::npos);
  // The TRC names the Nexus marker "boite:gauche_ext" "boite_gauche_ext".
  EXPECT_FALSE(t.index_of("boite:gauche_ext").has_value());
  const auto m = t.index_of("boite_gauche_ext");
  ASSERT_TRUE(m.has_value());
  const Eigen::Vector3d p = t.position(0, *m);
  EXPECT_NEAR(p.x(), 65.9025e-3, 1e-12);
  EXPECT_NEAR(p.y(), -256.7239e-3, 1e-12);
  EXPECT_NEAR(p.z(), 179.7892e-3, 1e-12);
}

// The TRC and CSV files are two recordings (different positions, see
// README) of the same rigid box: the distances between its eight markers must
// agree, which checks that both readers pair names and columns correctly.
TEST(Trc, BoxGeometryMatchesTheNexusCsvOfTheSameSetup) {
  CCSRM_SHARED_FILE_OR_SKIP(nexus_trc, "data/mocap/text/nexus_markers.trc");
  CCSRM_SHARED_FILE_OR_SKIP(nexus_csv, "data/mocap/text/nexus_markers.csv");
  const MarkerTable trc = ReadTrc(nexus_trc);
  const MarkerTable csv = ReadNexusCsv(nexus_csv);
  for (std::size_t i = 0; i < kBoxMarkers.size(); ++i) {
    for (std::size_t j = i + 1; j < kBoxMarkers.size(); ++j) {
      const std::size_t ti = *trc.index_of("boite_" + kBoxMarkers[i]);
      const std::size_t tj = *trc.index_of("boite_" + kBoxMarkers[j]);
      const std::size_t ci = *csv.index_of("boite:" + kBoxMarkers[i]);
      const std::size_t cj = *csv.index_of("boite:" + kBoxMarkers[j]);
      const double d_trc = (trc.position(0, ti) - trc.position(0, tj)).norm();
      const double d_csv = (csv.position(0, ci) - csv.position(0, cj)).norm();
      EXPECT_NEAR(d_trc, d_csv, 1.5e-3) << kBoxMarkers[i] << " - " << kBoxMarkers[j];
    }
  }
}

TEST(Trc, TabSeparatedFileWithBlankCellsAndMetres) {
  const std::string text =
      "PathFileType\t4\t(X/Y/Z)\tsmall.trc\n"
      "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\t"
      "OrigNumFrames\n"
      "60\t60\t3\t2\tm\t60\t1\t3\n"
      "Frame#\tTime\tHip\t\t\tKnee\t\t\n"
      "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\n"
      "\n"
      "1\t0.000\t0.1\t0.2\t0.3\t1\t2\t3\n"
      "2\t0.017\t\t\t\t1.5\t2.5\t3.5\n"
      "3\t0.033\t0.4\t0.5\t0.6\t\t\t\n";
  const MarkerTable t = ReadTrcFromString(text, "small.trc");
  EXPECT_EQ(t.labels, (std::vector<std::string>{"Hip", "Knee"}));
  EXPECT_EQ(t.frames(), 3u);
  EXPECT_DOUBLE_EQ(t.rate_hz, 60.0);
  EXPECT_EQ(t.units_in_file, "m");
  EXPECT_TRUE(t.warnings.empty());
  EXPECT_TRUE(t.position(0, 0).isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_FALSE(t.is_valid(1, 0));
  EXPECT_TRUE(t.position(1, 1).isApprox(Eigen::Vector3d(1.5, 2.5, 3.5)));
  EXPECT_FALSE(t.is_valid(2, 1));
}

// A small file in the layout of a Motive 2.x CSV export (format 1.23): a
// rigid body with its solved markers, then labelled and unlabelled markers;
// Y-up, millimetres, blank cells where a marker was occluded.
std::string MotiveCsvSample() {
  return "Format Version,1.23,Take Name,arm_static,Take Notes,,Capture Frame Rate,120.000000,"
         "Export Frame Rate,120.000000,Capture Start Time,2023-05-04 10.21.07.512 AM,"
         "Capture Start Frame,1053,Total Frames in Take,4,Total Exported Frames,4,"
         "Rotation Type,Quaternion,Length Units,Millimeters,Coordinate Space,Global\r\n"
         "\r\n"
         ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,"
         "Rigid Body,Rigid Body Marker,Rigid Body Marker,Rigid Body Marker,Rigid Body Marker,"
         "Marker,Marker,Marker,Marker,Marker,Marker\r\n"
         ",Name,Link1,Link1,Link1,Link1,Link1,Link1,Link1,Link1,Link1:Marker1,Link1:Marker1,"
         "Link1:Marker1,Link1:Marker1,Link1:Marker1,Link1:Marker1,Link1:Marker1,"
         "Unlabeled 1000,Unlabeled 1000,Unlabeled 1000\r\n"
         ",ID,1,1,1,1,1,1,1,1,1,1,1,1,2,2,2,\"9F:A01\",\"9F:A01\",\"9F:A01\"\r\n"
         ",,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Mean Marker Error,"
         "Position,Position,Position,Marker Quality,Position,Position,Position,Position,Position,"
         "Position\r\n"
         "Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,,X,Y,Z,,X,Y,Z,X,Y,Z\r\n"
         "0,0.000000,0.01,0.02,0.03,0.99,100.0,1200.0,-50.0,0.0002,101.0,1201.0,-49.0,1.0,"
         "101.5,1201.5,-48.5,300.0,20.0,400.0\r\n"
         "1,0.008333,0.01,0.02,0.03,0.99,100.1,1200.1,-50.1,0.0002,101.1,1201.1,-49.1,1.0,"
         ",,,300.1,20.1,400.1\r\n"
         "2,0.016667,0.01,0.02,0.03,0.99,100.2,1200.2,-50.2,0.0002,101.2,1201.2,-49.2,1.0,"
         "101.7,1201.7,-48.7,,,\r\n"
         "3,0.025000,0.01,0.02,0.03,0.99,100.3,1200.3,-50.3,0.0002,101.3,1201.3,-49.3,1.0,"
         "101.8,1201.8,-48.8,300.3,20.3,400.3\r\n";
}

TEST(MotiveCsv, ReadsOnlyMarkerPositionColumnsInMetresWithYUp) {
  const auto dir = FreshTempDir("motive");
  const std::string path = (dir / "take.csv").string();
  WriteFile(path, MotiveCsvSample());
  const MarkerTable t = ReadMotiveCsv(path);
  EXPECT_EQ(t.format, "motive-csv");
  EXPECT_EQ(t.up_axis, "y");
  EXPECT_EQ(t.units_in_file, "mm");
  EXPECT_DOUBLE_EQ(t.rate_hz, 120.0);
  EXPECT_EQ(t.first_frame_number, 0);
  EXPECT_EQ(t.labels, (std::vector<std::string>{"Link1:Marker1", "Unlabeled 1000"}));
  ASSERT_EQ(t.frames(), 4u);
  EXPECT_TRUE(t.warnings.empty());
  // The "Marker" column of Link1:Marker1, not its solved rigid-body marker.
  EXPECT_TRUE(t.position(0, 0).isApprox(Eigen::Vector3d(0.1015, 1.2015, -0.0485)));
  EXPECT_FALSE(t.is_valid(1, 0));
  EXPECT_TRUE(t.position(1, 1).isApprox(Eigen::Vector3d(0.3001, 0.0201, 0.4001)));
  EXPECT_FALSE(t.is_valid(2, 1));
  EXPECT_EQ(Summarize(t).invalid_points, 2u);
}

TEST(MotiveCsv, ParentRowAndTimeCodeColumnOfNewerExports) {
  const std::string text =
      "Format Version,1.24,Take Name,t,Export Frame Rate,100.000000,Length Units,Meters\n"
      "\n"
      ",Type,,Marker,Marker,Marker\n"
      ",Name,,Tip,Tip,Tip\n"
      ",ID,,\"4CF0:1\",\"4CF0:1\",\"4CF0:1\"\n"
      ",Parent,,,,\n"
      ",,,Position,Position,Position\n"
      "Frame,Time (Seconds),TimeCode,X,Y,Z\n"
      "7,0.000000,15:26:46:12.02,0.5,1.5,-0.25\n";
  const MarkerTable t = ReadMotiveCsvFromString(text, "newer.csv");
  EXPECT_EQ(t.labels, (std::vector<std::string>{"Tip"}));
  EXPECT_EQ(t.units_in_file, "m");
  EXPECT_EQ(t.first_frame_number, 7);
  EXPECT_TRUE(t.position(0, 0).isApprox(Eigen::Vector3d(0.5, 1.5, -0.25)));
}

}  // namespace
}  // namespace ccsrm::mocap
