// The rigid-bodies file (ccsrm-rigid-bodies/1): round trip, one-line errors
// naming file, line and key; experiment records; static-trial refinement.
#include "ccsrm/mocap/rigid_bodies.h"

#include <gtest/gtest.h>

#include <random>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "mocap_test_util.h"

namespace ccsrm::mocap {
namespace {

using testing::InputErrorOf;

const sim::ArmModel& PaperModel() {
  static const sim::ArmModel model(sim::LoadConfig(CCSRM_SOURCE_DIR "/configs/paper.yaml").arm);
  return model;
}

const char* kSmall = R"(schema: ccsrm-rigid-bodies/1
bodies:
  - name: link1
    link: 1
    markers:
      - {name: A, position_m: [0.03, -0.02, -0.02]}
      - {name: B, position_m: [0.03, 0.02, -0.01]}
      - {name: C, position_m: [0.035, 0.0, 0.02]}
  - name: base
    link: 0
    markers:
      - {name: G1, position_m: [0.02, -0.04, -0.06]}
      - {name: G2, position_m: [0.04, 0.04, -0.06]}
      - {name: G3, position_m: [0.03, 0.0, -0.10]}
)";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::string ErrorOf(const std::string& text) {
  return InputErrorOf([&] { ParseRigidBodies(text, "rb.yaml"); });
}

TEST(RigidBodiesFile, ParsesSortsAndRoundTripsTheDefaultLayout) {
  const MarkerLayout small = ParseRigidBodies(kSmall, "rb.yaml");
  ASSERT_EQ(small.bodies.size(), 2u);
  EXPECT_EQ(small.bodies[0].name, "base");  // base first, then by link
  EXPECT_EQ(small.bodies[1].link, 1);
  EXPECT_EQ(small.bodies[1].p_BM[2], Eigen::Vector3d(0.035, 0.0, 0.02));

  const MarkerLayout layout = DefaultMarkerLayout(PaperModel());
  const MarkerLayout back = ParseRigidBodies(RigidBodiesToYaml(layout), "rb.yaml");
  ASSERT_EQ(back.bodies.size(), layout.bodies.size());
  for (std::size_t b = 0; b < layout.bodies.size(); ++b) {
    EXPECT_EQ(back.bodies[b].name, layout.bodies[b].name);
    EXPECT_EQ(back.bodies[b].marker_names, layout.bodies[b].marker_names);
    for (std::size_t m = 0; m < layout.bodies[b].p_BM.size(); ++m) {
      EXPECT_LT((back.bodies[b].p_BM[m] - layout.bodies[b].p_BM[m]).norm(), 1e-7);
    }
  }
  const MarkerLayout from_records = LayoutFromExperiment(ToExperimentRigidBodies(layout), "exp.h5");
  EXPECT_EQ(from_records.MarkerNames(), layout.MarkerNames());
  EXPECT_EQ(from_records.bodies[5].p_BM[1], layout.bodies[5].p_BM[1]);
}

TEST(RigidBodiesFile, UnknownKeyNamesFileLineAndKey) {
  const std::string e = ErrorOf(Replace(kSmall, "position_m: [0.035", "positon_m: [0.035"));
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_NE(e.find("rb.yaml: line 8, key 'bodies[0].markers[2].positon_m': unknown key"),
            std::string::npos)
      << e;
}

TEST(RigidBodiesFile, FewerThanThreeMarkersIsAnError) {
  const std::string two =
      Replace(kSmall, "      - {name: C, position_m: [0.035, 0.0, 0.02]}\n", "");
  const std::string e = ErrorOf(two);
  EXPECT_NE(
      e.find("rb.yaml: line 6, key 'bodies[0].markers': has 2 markers; a pose needs at least 3"),
      std::string::npos)
      << e;
}

TEST(RigidBodiesFile, DuplicateNamesAreErrors) {
  std::string e = ErrorOf(Replace(kSmall, "{name: G2", "{name: B"));
  EXPECT_NE(e.find("rb.yaml: line 13, key 'bodies[1].markers[1].name': duplicate marker 'B' "
                   "(first at line 7)"),
            std::string::npos)
      << e;
  e = ErrorOf(Replace(Replace(kSmall, "name: base", "name: link1"), "link: 0", "link: 1"));
  EXPECT_NE(e.find("rb.yaml: line 9, key 'bodies[1].name': duplicate body 'link1' "
                   "(first at line 3)"),
            std::string::npos)
      << e;
}

TEST(RigidBodiesFile, DuplicateKeyNamesBothLines) {
  // yaml-cpp keeps the first 'link' and would drop the second without a word.
  EXPECT_EQ(ErrorOf(Replace(kSmall, "    link: 0\n", "    link: 0\n    link: 2\n")),
            "rb.yaml: line 11, key 'bodies[1].link': duplicate key (first at line 10)");
}

TEST(RigidBodiesFile, OtherProblemsNameTheirKey) {
  EXPECT_NE(ErrorOf(Replace(kSmall, "ccsrm-rigid-bodies/1", "ccsrm-rigid-bodies/2"))
                .find("line 1, key 'schema': is 'ccsrm-rigid-bodies/2'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(kSmall, "name: link1", "name: link2"))
                .find("key 'bodies[0].name': is 'link2', expected 'link1'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(kSmall, "[0.03, 0.02, -0.01]", "[0.03, 0.02]"))
                .find("key 'bodies[0].markers[1].position_m': expected [x, y, z]"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(kSmall, "[0.03, 0.02, -0.01]", "[0.03, zero, -0.01]"))
                .find("expected a number"),
            std::string::npos);
  // Read by the one YAML number reader: an overflow is named as such.
  EXPECT_NE(ErrorOf(Replace(kSmall, "[0.03, 0.02, -0.01]", "[0.03, 1e400, -0.01]"))
                .find("key 'bodies[0].markers[1].position_m': '1e400' is outside the range"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(kSmall, "    link: 1\n", "")).find("key 'bodies[0].link': missing"),
            std::string::npos);
  const std::string collinear =
      Replace(Replace(kSmall, "[0.03, 0.02, -0.01]", "[0.03, -0.02, 0.0]"), "[0.035, 0.0, 0.02]",
              "[0.03, -0.02, 0.02]");
  EXPECT_NE(ErrorOf(collinear).find("collinear"), std::string::npos);
  EXPECT_NE(ErrorOf("schema: [").find("rb.yaml: line"), std::string::npos);
  EXPECT_NE(InputErrorOf([] {
              ReadRigidBodiesFile("/nonexistent/rb.yaml");
            }).find("/nonexistent/rb.yaml: cannot open"),
            std::string::npos);
}

TEST(StaticTrial, RefinementRecoversWhereTheMarkersReallyAre) {
  const sim::ArmModel& model = PaperModel();
  const MarkerLayout nominal = DefaultMarkerLayout(model);
  // The real plates sit a few millimetres off the nominal positions.
  MarkerLayout real = nominal;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> offset(-3e-3, 3e-3);
  for (RigidBody& body : real.bodies) {
    if (body.link == 0) continue;
    for (Eigen::Vector3d& p : body.p_BM)
      p += Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
  }
  // A straight-arm trial of 1000 frames with 0.2 mm noise, in a lab frame.
  const Eigen::Isometry3d X_FW =
      Eigen::Translation3d(0.5, 0.2, 1.0) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  const auto straight =
      sim::ForwardKinematics(model, sim::JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  const std::vector<Eigen::Vector3d> p_WM = PlaceMarkers(real, straight);
  MarkerTable trial;
  trial.Reset(1000, real.MarkerNames(), false);
  trial.rate_hz = 100.0;
  std::normal_distribution<double> noise(0.0, 0.2e-3);
  for (std::size_t f = 0; f < 1000; ++f) {
    for (std::size_t k = 0; k < p_WM.size(); ++k) {
      trial.set_position(f, k,
                         X_FW * p_WM[k] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
  }
  const StaticTrialRefinement refined = RefineFromStaticTrial(nominal, model, trial, "static.c3d");
  EXPECT_TRUE(refined.warnings.empty());
  for (std::size_t b = 1; b < real.bodies.size(); ++b) {
    for (std::size_t m = 0; m < real.bodies[b].p_BM.size(); ++m) {
      // Noise averaged over 1000 frames, plus the ground fit's own error
      // (its rotation error acts on a lever of up to 1.1 m).
      EXPECT_LT((refined.layout.bodies[b].p_BM[m] - real.bodies[b].p_BM[m]).norm(), 0.2e-3)
          << real.bodies[b].marker_names[m];
    }
  }
  EXPECT_GT(refined.displacement_m[5], 0.0);
}

}  // namespace
}  // namespace ccsrm::mocap
