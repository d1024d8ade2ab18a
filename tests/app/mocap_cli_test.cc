// `ccsrm mocap ...` and `ccsrm generate` as a user runs them: outputs, exit
// codes and one-line errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include "c3d_test_files.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/recording.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/paper_run.h"
#include "run_ccsrm.h"
#include "same_experiment.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::RunCcsrm;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

// The nominal configuration a generated case-1 experiment states: the
// paper's arm with case 1's friction (none), and no effects.
std::string NominalCase1() {
  ccsrm::sim::Config c = ccsrm::sim::LoadConfig(Paper());
  ccsrm::sim::ApplyPaperCase(1, &c.parameters);
  return ccsrm::sim::ToYaml(c);
}

fs::path FreshDir(const std::string& name) {
  return ccsrm::testing::ScratchDirectory("mocap_cli_" + name);
}

// A short generated experiment (0.3 s of case 1), made once (the suite runs
// as one process).
const fs::path& Generated() {
  static const fs::path dir = [] {
    const fs::path d = FreshDir("generated");
    const Outcome o =
        RunCcsrm("generate --config " + Paper() +
                 " --case 1 --duration 0.3 --quiet --seed 7 --out " + (d / "exp.h5").string());
    EXPECT_EQ(o.status, 0) << o.err;
    return d;
  }();
  return dir;
}

TEST(MocapInspect, ReadsOurHdf5ExperimentAndRun) {
  const Outcome exp = RunCcsrm("mocap inspect --json " + (Generated() / "exp.h5").string());
  ASSERT_EQ(exp.status, 0) << exp.err;
  const nlohmann::json j = nlohmann::json::parse(exp.out);
  EXPECT_EQ(j["format"], "ccsrm-dataset");
  EXPECT_EQ(j["frames"], 31);
  EXPECT_NEAR(j["rate_hz"].get<double>(), 100.0, 1e-9);
  EXPECT_EQ(j["labels"].size(), 52u);
  EXPECT_EQ(j["units_in_file"], "m");
  const Outcome run = RunCcsrm("mocap inspect --json " + (Generated() / "exp.truth.h5").string());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["invalid_points"], 0);  // noise-free, never hidden
}

TEST(Generate, WritesTheExperimentAndBothTruthFiles) {
  const fs::path& dir = Generated();
  const ccsrm::datasets::ExperimentFile e =
      ccsrm::datasets::ReadExperimentFile((dir / "exp.h5").string());
  EXPECT_EQ(e.source, ccsrm::datasets::ExperimentSource::kGenerated);
  EXPECT_EQ(e.config_yaml, NominalCase1());  // the nominal arm with its case, never the truth
  EXPECT_EQ(e.mocap_time.rows(), 31u);
  EXPECT_EQ(e.input_length_change.shape, (std::vector<std::size_t>{31, 6}));
  EXPECT_EQ(e.marker_names.size(), 52u);
  EXPECT_EQ(e.rigid_bodies.size(), 13u);
  const ccsrm::datasets::RunFile truth =
      ccsrm::datasets::ReadRunFile((dir / "exp.truth.h5").string());
  ASSERT_TRUE(truth.markers.has_value());
  EXPECT_EQ(truth.marker_names, e.marker_names);
  EXPECT_EQ(truth.case_name, "1");
  // Noise: the recorded markers differ from the truth by about 0.2 mm.
  double sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < e.mocap_markers.size(); ++i) {
    const double d = e.mocap_markers.values[i] - truth.markers->values[i];
    if (std::isfinite(d)) {
      sum_sq += d * d;
      ++n;
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), 0.2e-3, 0.02e-3);
  const std::string yaml = ccsrm::ReadTextFile((dir / "exp.truth.yaml").string());
  EXPECT_THAT(yaml, HasSubstr("schema: ccsrm-truth/1"));
  EXPECT_THAT(yaml, HasSubstr("mu: 0\n"));  // case 1: no friction
  EXPECT_THAT(yaml, HasSubstr("T_d0: 100"));
  EXPECT_THAT(yaml, HasSubstr("seed: 7"));
  EXPECT_THAT(yaml, HasSubstr("sigma_mm: 0.2"));
}

TEST(Generate, SameSeedGivesTheSameFilesAndParametersReachTheTruth) {
  const fs::path dir = FreshDir("reproducible");
  const std::string common = "generate --config " + Paper() + " --duration 0.1 --quiet ";
  ASSERT_EQ(
      RunCcsrm(common + "--seed 3 --set mu=0.15 --set T_d0=80 --out " + (dir / "a.h5").string())
          .status,
      0);
  // The truth file as --params reproduces the same truth.
  const Outcome b = RunCcsrm(common + "--seed 3 --params " + (dir / "a.truth.yaml").string() +
                             " --out " + (dir / "b.h5").string());
  ASSERT_EQ(b.status, 0) << b.err;
  const auto a_exp = ccsrm::datasets::ReadExperimentFile((dir / "a.h5").string());
  const auto b_exp = ccsrm::datasets::ReadExperimentFile((dir / "b.h5").string());
  EXPECT_EQ(a_exp.mocap_markers.values.size(), b_exp.mocap_markers.values.size());
  for (std::size_t i = 0; i < a_exp.mocap_markers.size(); ++i) {
    const double x = a_exp.mocap_markers.values[i], y = b_exp.mocap_markers.values[i];
    ASSERT_TRUE((std::isnan(x) && std::isnan(y)) || x == y) << i;
  }
  EXPECT_EQ(a_exp.input_length_change.values, b_exp.input_length_change.values);
  const auto a_truth = ccsrm::datasets::ReadRunFile((dir / "a.truth.h5").string());
  const auto b_truth = ccsrm::datasets::ReadRunFile((dir / "b.truth.h5").string());
  EXPECT_EQ(a_truth.joint_angles.values, b_truth.joint_angles.values);
  EXPECT_EQ(a_truth.wall_time_s, b_truth.wall_time_s);
  const std::string a_yaml = ccsrm::ReadTextFile((dir / "a.truth.yaml").string());
  EXPECT_THAT(a_yaml, HasSubstr("mu: 0.15"));
  EXPECT_THAT(a_yaml, HasSubstr("T_d0: 80"));
  // Another seed, other noise.
  ASSERT_EQ(
      RunCcsrm(common + "--seed 4 --set mu=0.15 --set T_d0=80 --out " + (dir / "c.h5").string())
          .status,
      0);
  const auto c_exp = ccsrm::datasets::ReadExperimentFile((dir / "c.h5").string());
  EXPECT_NE(c_exp.mocap_markers.values[0], a_exp.mocap_markers.values[0]);
}

TEST(Generate, RejectsUnknownParametersAndBadValuesWithOneLine) {
  const Outcome unknown =
      RunCcsrm("generate --config " + Paper() + " --set mu_x=0.1 --out /tmp/ccsrm_never.h5");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(unknown.err), 1) << unknown.err;
  EXPECT_THAT(
      unknown.err,
      HasSubstr("unknown parameter 'mu_x' (known: mu, mu_s, mu_c, mu_c_s, "
                "beta, c_sc, c_lc, T_p, T_d0, v_s, v_c_s, tau_f, tau_c_f, xi_f, xi_c, k_b, c_b; "
                "effects' parameters as <effect>.<parameter>"));
  const Outcome bounds =
      RunCcsrm("generate --config " + Paper() + " --set mu=3 --out /tmp/ccsrm_never.h5");
  EXPECT_EQ(bounds.status, 2);
  // The message of the one parameter table, as from a config file or --params.
  EXPECT_EQ(bounds.err, "ccsrm: --set: parameter 'mu' = 3 is outside [0, 2] 1\n");
  const Outcome not_h5 = RunCcsrm("generate --config " + Paper() + " --out /tmp/ccsrm_never.dat");
  EXPECT_EQ(not_h5.status, 2);
  EXPECT_THAT(not_h5.err, HasSubstr("must end in .h5"));
  const fs::path dir = FreshDir("params");
  ccsrm::WriteTextFileAtomically((dir / "p.yaml").string(), "mu: 0.1\nbeta: fast\n");
  const Outcome params = RunCcsrm("generate --config " + Paper() + " --params " +
                                  (dir / "p.yaml").string() + " --out /tmp/ccsrm_never.h5");
  EXPECT_EQ(params.status, 2);
  EXPECT_THAT(params.err, HasSubstr("p.yaml: line 2, key 'beta': expected a number"));
  EXPECT_FALSE(fs::exists("/tmp/ccsrm_never.h5"));
}

TEST(MocapProcess, ProcessesAGeneratedExperimentAndKeepsTheInput) {
  const fs::path& dir = Generated();
  const std::string in = (dir / "exp.h5").string();
  const auto before = fs::last_write_time(in);
  const std::string out = (FreshDir("process") / "processed.h5").string();
  const Outcome o = RunCcsrm("mocap process --in " + in + " --cutoff-hz 3 --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr("joint-constrained chain"));
  EXPECT_THAT(o.out, HasSubstr("world frame: from the ground cluster"));
  EXPECT_THAT(o.out, HasSubstr("max |twist|"));
  EXPECT_EQ(fs::last_write_time(in), before);
  const auto processed = ccsrm::datasets::ReadExperimentFile(out);
  ASSERT_TRUE(processed.measured_joint_angles.has_value());
  EXPECT_EQ(processed.measured_joint_angles->shape, (std::vector<std::size_t>{31, 12, 2}));
  EXPECT_EQ(processed.measured_link_pose->shape, (std::vector<std::size_t>{31, 12, 7}));
  EXPECT_EQ(processed.measured_joint_twist->shape, (std::vector<std::size_t>{31, 12}));
  EXPECT_EQ(processed.mocap_quality_units.at("marker_fit_rms"), "m");
  const Outcome same = RunCcsrm("mocap process --in " + in + " --out " + in);
  EXPECT_EQ(same.status, 2);
  EXPECT_THAT(same.err, HasSubstr("is an input file"));
}

TEST(MocapProcess, ConfigOrRigidBodiesFileGiveTheSimulatedAngles) {
  const fs::path dir = FreshDir("c3d");
  // The rigid-bodies command writes the default layout; processing the
  // noise-free truth run with it or with the configuration is the same.
  const std::string rb = (dir / "rb.yaml").string();
  const Outcome written = RunCcsrm("mocap rigid-bodies --config " + Paper() + " --out " + rb);
  ASSERT_EQ(written.status, 0) << written.err;
  EXPECT_THAT(ccsrm::ReadTextFile(rb), HasSubstr("schema: ccsrm-rigid-bodies/1"));
  const std::string run = (Generated() / "exp.truth.h5").string();
  const std::string out1 = (dir / "from_config.h5").string();
  Outcome o =
      RunCcsrm("mocap process --quiet --in " + run + " --config " + Paper() + " --out " + out1);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string out2 = (dir / "from_rb.h5").string();
  o = RunCcsrm("mocap process --quiet --in " + run + " --rigid-bodies " + rb + " --out " + out2);
  ASSERT_EQ(o.status, 0) << o.err;
  const auto a = ccsrm::datasets::ReadExperimentFile(out1);
  const auto b = ccsrm::datasets::ReadExperimentFile(out2);
  // Noise-free markers: both ways give the simulated angles.
  const auto truth = ccsrm::datasets::ReadRunFile(run);
  for (std::size_t i = 0; i < truth.joint_angles.size(); ++i) {
    EXPECT_NEAR(a.measured_joint_angles->values[i], truth.joint_angles.values[i], 2e-4) << i;
    EXPECT_NEAR(b.measured_joint_angles->values[i], truth.joint_angles.values[i], 2e-4) << i;
  }
  // A C3D file whose labels are not the arm's: one line, exit 2.
  const std::string other = (dir / "other_labels.c3d").string();
  ccsrm::mocap::WriteC3d(other, ccsrm::testing::LongLabelTable(8, 20));
  o = RunCcsrm("mocap process --in " + other + " --config " + Paper() + " --out " +
               (dir / "x.h5").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr("no marker of the rigid bodies"));
  // Neither rigid bodies nor a configuration for a C3D file.
  o = RunCcsrm("mocap process --in " + other + " --out " + (dir / "x.h5").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_THAT(o.err, HasSubstr("give --rigid-bodies FILE or --config FILE"));
}

TEST(MocapProcess, C3dFileBecomesANewExperimentWithOrWithoutInputs) {
  const fs::path dir = FreshDir("c3d_new");
  const std::string exp = (Generated() / "exp.h5").string();
  const std::string c3d = (dir / "recording.c3d").string();
  ccsrm::mocap::WriteC3d(c3d, ccsrm::mocap::ReadMarkerFile(exp));
  const std::string bare = (dir / "bare.h5").string();
  Outcome o =
      RunCcsrm("mocap process --quiet --in " + c3d + " --config " + Paper() + " --out " + bare);
  ASSERT_EQ(o.status, 0) << o.err;
  const auto a = ccsrm::datasets::ReadExperimentFile(bare);
  EXPECT_EQ(a.source, ccsrm::datasets::ExperimentSource::kRecorded);
  EXPECT_EQ(a.config_yaml, ccsrm::ReadTextFile(Paper()));
  EXPECT_EQ(a.input_length_change.shape, (std::vector<std::size_t>{1, 0}));  // no actuator record
  EXPECT_EQ(a.marker_names.size(), 52u);
  EXPECT_EQ(a.measured_joint_angles->shape, (std::vector<std::size_t>{31, 12, 2}));
  const std::string with_inputs = (dir / "with_inputs.h5").string();
  o = RunCcsrm("mocap process --quiet --in " + c3d + " --config " + Paper() + " --inputs " + exp +
               " --out " + with_inputs);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ccsrm::datasets::ReadExperimentFile(with_inputs).input_length_change.shape,
            (std::vector<std::size_t>{31, 6}));
  // A static trial: the first 0.3 s of the protocol barely move the arm, so
  // the refined positions stay within a fraction of a millimetre.
  const std::string rb = (dir / "refined.yaml").string();
  o = RunCcsrm("mocap rigid-bodies --config " + Paper() + " --static-trial " +
               (Generated() / "exp.truth.h5").string() + " --out " + rb);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr("marker positions refined (largest change 0.0"));
}

TEST(MocapProcess, BadRigidBodiesFileIsOneLineNamingLineAndKey) {
  const fs::path dir = FreshDir("bad_rb");
  const std::string rb = (dir / "rb.yaml").string();
  ccsrm::WriteTextFileAtomically(rb,
                                 "schema: ccsrm-rigid-bodies/1\n"
                                 "bodies:\n"
                                 "  - name: link1\n"
                                 "    link: 1\n"
                                 "    colour: red\n"
                                 "    markers: []\n");
  const Outcome o = RunCcsrm("mocap process --in " + (Generated() / "exp.h5").string() +
                             " --rigid-bodies " + rb + " --out " + (dir / "x.h5").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr(rb + ": line 5, key 'bodies[0].colour': unknown key"));
  EXPECT_FALSE(fs::exists(dir / "x.h5"));
}

TEST(MocapProcess, LibraryCallOnAnExperimentEqualsWhatTheCommandWrites) {
  const fs::path dir = FreshDir("library_call");
  const std::string exp = (Generated() / "exp.h5").string();
  const std::string out = (dir / "processed.h5").string();
  const Outcome o = RunCcsrm("mocap process --quiet --in " + exp + " --cutoff-hz 3 --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  ccsrm::mocap::RecordingRequest request;
  request.in = exp;
  request.name = "processed";
  request.processing.cutoff_hz = 3.0;
  const ccsrm::mocap::ProcessedRecording processed = ccsrm::mocap::ProcessRecording(request);
  ccsrm::testing::ExpectSameExperiment(processed.experiment,
                                       ccsrm::datasets::ReadExperimentFile(out));
  // The command prints the library's summary.
  EXPECT_THAT(o.out, HasSubstr(processed.result.summary.BriefReport()));
}

TEST(MocapProcess, LibraryCallOnAC3dFileWithInputsEqualsWhatTheCommandWrites) {
  const fs::path dir = FreshDir("library_call_c3d");
  const std::string exp = (Generated() / "exp.h5").string();
  const std::string c3d = (dir / "rec.c3d").string();
  ccsrm::mocap::WriteC3d(c3d, ccsrm::mocap::ReadMarkerFile(exp));
  const std::string out = (dir / "new.h5").string();
  const Outcome o = RunCcsrm("mocap process --quiet --in " + c3d + " --config " + Paper() +
                             " --inputs " + exp + " --no-rigid-fill --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  ccsrm::mocap::RecordingRequest request;
  request.in = c3d;
  request.config = Paper();
  request.inputs = exp;
  request.name = "new";  // the command names a new experiment after --out
  request.processing.rigid_fill = false;
  ccsrm::testing::ExpectSameExperiment(ccsrm::mocap::ProcessRecording(request).experiment,
                                       ccsrm::datasets::ReadExperimentFile(out));
}

TEST(MocapProcess, ExperimentProcessedInMemoryGivesTheCommandsMeasurement) {
  // What identification does with an experiment lacking measured angles.
  const fs::path dir = FreshDir("in_memory");
  const std::string exp = (Generated() / "exp.h5").string();
  const ccsrm::datasets::ExperimentFile read = ccsrm::datasets::ReadExperimentFile(exp);
  ASSERT_FALSE(read.measured_joint_angles.has_value());
  const std::string out = (dir / "processed.h5").string();
  const Outcome o = RunCcsrm("mocap process --quiet --in " + exp + " --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  const ccsrm::mocap::ProcessedRecording processed =
      ccsrm::mocap::AddMeasuredJointAngles(read, exp);
  ccsrm::testing::ExpectSameExperiment(processed.experiment,
                                       ccsrm::datasets::ReadExperimentFile(out));
}

// The real-file path of issue 11: an experiment's markers written as C3D,
// then processed with the paper's configuration and the experiment's inputs,
// give the experiment the HDF5 route gives.
TEST(MocapExport, C3dOfAnExperimentProcessesToTheSameMeasurementAsTheExperiment) {
  const fs::path dir = FreshDir("export");
  const std::string exp = (Generated() / "exp.h5").string();
  const std::string c3d = (dir / "exp.c3d").string();
  Outcome o = RunCcsrm("mocap export --in " + exp + " --out " + c3d);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(
      o.out,
      HasSubstr(
          "31 frames, 52 markers at 100 Hz, 0 analog channel(s) (C3D, Intel, float storage, mm)"));
  // The experiment's own configuration, as a lab would keep it beside the C3D.
  const std::string config = (dir / "nominal.yaml").string();
  ccsrm::WriteTextFileAtomically(config, ccsrm::datasets::ReadExperimentFile(exp).config_yaml);
  const std::string via_c3d = (dir / "exp_c3d.h5").string();
  o = RunCcsrm("mocap process --quiet --in " + c3d + " --config " + config + " --inputs " + exp +
               " --out " + via_c3d);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string via_h5 = (dir / "exp_h5.h5").string();
  o = RunCcsrm("mocap process --quiet --in " + exp + " --out " + via_h5);
  ASSERT_EQ(o.status, 0) << o.err;
  const auto a = ccsrm::datasets::ReadExperimentFile(via_c3d);
  const auto b = ccsrm::datasets::ReadExperimentFile(via_h5);

  // What identification reads is the same: inputs exactly, the frame times to
  // rounding (the C3D keeps the rate, 100 Hz, not the times: frame i is at
  // i / rate, which the generated times k * 10 ms start from 0 as well), the
  // nominal configuration, the layout.
  ccsrm::testing::ExpectSameArray(a.input_time, b.input_time, "/input/time");
  ccsrm::testing::ExpectSameArray(a.input_length_change, b.input_length_change,
                                  "/input/length_change");
  ccsrm::testing::ExpectSameArray(a.mocap_time, b.mocap_time, "/mocap/time", 1e-12);
  EXPECT_EQ(a.config_yaml, b.config_yaml);
  EXPECT_EQ(a.marker_names, b.marker_names);
  ASSERT_EQ(a.rigid_bodies.size(), b.rigid_bodies.size());
  for (std::size_t i = 0; i < a.rigid_bodies.size(); ++i) {
    ccsrm::testing::ExpectSameArray(a.rigid_bodies[i].local_position,
                                    b.rigid_bodies[i].local_position, a.rigid_bodies[i].name);
  }
  // The measurement. C3D stores float32 millimetres: below 2048 mm (the arm
  // reaches about 1.2 m) a coordinate is rounded by at most half of 2^-13 mm,
  // 6.1e-8 m. That moves a link's fitted rotation by at most about that over
  // the plate's narrowest spread (8 mm): 7.6e-6 rad, and the filter averages
  // it further. The bound is that worst case; the noise the measurement
  // carries (0.2 mm markers) is 100 times larger.
  constexpr double kC3dRoundingRad = 6.1e-8 / 8e-3;
  ASSERT_TRUE(a.measured_joint_angles && b.measured_joint_angles);
  ccsrm::testing::ExpectSameArray(*a.measured_joint_angles, *b.measured_joint_angles,
                                  "/measured/joint_angles", kC3dRoundingRad);
  ccsrm::testing::ExpectSameArray(*a.measured_joint_twist, *b.measured_joint_twist,
                                  "/measured/joint_twist", kC3dRoundingRad);
  double largest = 0.0;
  for (std::size_t i = 0; i < a.measured_joint_angles->size(); ++i) {
    const double d = a.measured_joint_angles->values[i] - b.measured_joint_angles->values[i];
    if (std::isfinite(d)) largest = std::max(largest, std::abs(d));
  }
  std::printf("C3D route vs HDF5 route: largest joint-angle difference %.3g rad\n", largest);
}

TEST(MocapExport, RefusesOtherFormatsAndItsOwnInput) {
  const fs::path dir = FreshDir("export_bad");
  const std::string exp = (Generated() / "exp.h5").string();
  Outcome o = RunCcsrm("mocap export --in " + exp + " --out " + (dir / "x.trc").string());
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_THAT(o.err, HasSubstr("x.trc: --out: unsupported format (expected .c3d)"));
  const std::string c3d = (dir / "a.c3d").string();
  ASSERT_EQ(RunCcsrm("mocap export --in " + exp + " --out " + c3d).status, 0);
  o = RunCcsrm("mocap export --in " + c3d + " --out " + c3d);
  EXPECT_EQ(o.status, 2);
  EXPECT_THAT(o.err, HasSubstr("is an input file"));
  o = RunCcsrm("mocap export --in " + exp + " --units cm --out " + c3d);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  EXPECT_FALSE(fs::exists(dir / "x.trc"));
}

// A C3D file with two analog channels (a trigger and a ramp, 4 samples per
// frame): `mocap inspect` lists them and `mocap export` writes them back.
TEST(MocapExport, AnalogChannelsAreListedAndWrittenBack) {
  const fs::path dir = FreshDir("export_analog");
  ccsrm::mocap::C3dRecording recording;
  recording.markers = ccsrm::testing::LongLabelTable(3, 20);
  ccsrm::mocap::C3dAnalog& analog = recording.analog;
  analog.labels = {"trigger", "ramp"};
  analog.units = {"V", "mV"};
  analog.samples_per_frame = 4;
  analog.rate_hz = 400.0;
  analog.sample_count = 80;
  analog.scale = {1.0, 1.0};
  analog.offset = {0.0, 0.0};
  for (std::size_t s = 0; s < analog.sample_count; ++s) {
    analog.values.push_back(s >= 37 ? 5.0 : 0.0);
    analog.values.push_back(0.25 * static_cast<double>(s));
  }
  const std::string in = (dir / "in.c3d").string();
  ccsrm::mocap::WriteC3d(in, recording);
  Outcome o = RunCcsrm("mocap inspect --json " + in);
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  ASSERT_TRUE(j.contains("analog"));
  EXPECT_EQ(j["analog"]["channels"], 2);
  EXPECT_DOUBLE_EQ(j["analog"]["rate_hz"].get<double>(), 400.0);
  EXPECT_EQ(j["analog"]["list"][0]["label"], "trigger");
  EXPECT_EQ(j["analog"]["list"][1]["units"], "mV");
  EXPECT_DOUBLE_EQ(j["analog"]["list"][1]["max"].get<double>(), 0.25 * 79);
  o = RunCcsrm("mocap inspect " + in);
  EXPECT_THAT(o.out,
              HasSubstr("analog:          2 channel(s) at 400 Hz (4 per frame, 80 samples)"));

  const std::string out = (dir / "out.c3d").string();
  o = RunCcsrm("mocap export --in " + in + " --out " + out);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_THAT(o.out, HasSubstr("2 analog channel(s)"));
  const ccsrm::mocap::C3dRecording back = ccsrm::mocap::ReadC3dRecording(out);
  EXPECT_EQ(back.analog.labels, analog.labels);
  EXPECT_EQ(back.analog.units, analog.units);
  EXPECT_EQ(back.analog.values, analog.values);  // small whole and quarter values: exact in float
}

TEST(Generate, ListEffectsGivesEveryEffectWithUnitsBoundsAndRealisticMagnitude) {
  const Outcome o = RunCcsrm("generate --list-effects --json");
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  // The seven of the library, then the loop's terms' carrier and the
  // per-segment pre-tension, marked.
  ASSERT_EQ(j["effects"].size(), 9u);
  EXPECT_EQ(j["effects"][0]["name"], "joint_friction");
  EXPECT_EQ(j["effects"][7]["name"], "joint_moment");
  EXPECT_FALSE(j["effects"][7]["library"].get<bool>());
  EXPECT_EQ(j["effects"][8]["name"], "segment_pretension");
  EXPECT_FALSE(j["effects"][8]["library"].get<bool>());
  EXPECT_TRUE(j["effects"][0]["library"].get<bool>());
  const nlohmann::json& p = j["effects"][0]["parameters"][0];
  EXPECT_EQ(p["name"], "joint_friction.coulomb_nm");
  EXPECT_EQ(p["units"], "N m");
  EXPECT_LE(p["lower"].get<double>(), p["realistic"].get<double>());
  EXPECT_LE(p["realistic"].get<double>(), p["upper"].get<double>());
  const Outcome text = RunCcsrm("generate --list-effects");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("mocap_offset (measurement)"));
  EXPECT_THAT(text.out, HasSubstr("table_tilt.lateral_rad"));
  EXPECT_THAT(text.out, HasSubstr("joint_moment (not of the library"));
  EXPECT_THAT(text.out, HasSubstr("segment_pretension.segment2_n"));
}

// The second arm (configs/three-segment.yaml) with every segment given
// `links` links: 3 makes a 9-joint arm, 5 a 15-joint one.
std::string ThreeSegmentArmWithLinks(const fs::path& dir, int links) {
  std::string text =
      ccsrm::ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  std::string pattern;
  for (int k = 0; k + 1 < links; ++k) {
    pattern += std::string(k ? ", " : "") + (k % 2 ? "large" : "small");
  }
  for (std::size_t at; (at = text.find("links: 4")) != std::string::npos;) {
    text.replace(at, 8, "links: " + std::to_string(links));
  }
  for (std::size_t at; (at = text.find("[small, large, small]")) != std::string::npos;) {
    text.replace(at, 21, "[" + pattern + "]");
  }
  const fs::path path = dir / ("arm" + std::to_string(3 * links) + ".yaml");
  ccsrm::WriteTextFileAtomically(path.string(), text);
  return path.string();
}

// Issue 32: effects are sized to the arm of --config, at every door.
TEST(Generate, EffectsAreSizedToTheArmOfTheConfiguration) {
  const fs::path dir = FreshDir("sized_effects");
  const std::string nine = ThreeSegmentArmWithLinks(dir, 3);
  const std::string fifteen = ThreeSegmentArmWithLinks(dir, 5);
  for (const auto& [config, joints] : {std::make_pair(nine, 9), std::make_pair(fifteen, 15)}) {
    const Outcome o = RunCcsrm("generate --list-effects --json --config " + config);
    ASSERT_EQ(o.status, 0) << o.err;
    const nlohmann::json j = nlohmann::json::parse(o.out);
    EXPECT_EQ(j["arm"]["joints"], joints);
    EXPECT_EQ(j["arm"]["config"], config);
    const nlohmann::json& offsets = j["effects"][6]["parameters"];
    ASSERT_EQ(j["effects"][6]["name"], "mocap_offset");
    ASSERT_EQ(offsets.size(), static_cast<std::size_t>(2 * joints));
    EXPECT_EQ(offsets.back()["name"], "mocap_offset.joint" + std::to_string(joints) + "_y_rad");
  }
  // A joint the arm does not have: one line naming the option and why.
  for (const std::string& args :
       {"generate --config " + nine + " --effect mocap_offset:joint12_x_rad=0.01 --out " +
            (dir / "x.h5").string(),
        "simulate --config " + nine + " --set mocap_offset.joint12_x_rad=0.01 --out " +
            (dir / "x.h5").string()}) {
    SCOPED_TRACE(args);
    const Outcome o = RunCcsrm(args + " --duration 0.1 --quiet");
    EXPECT_EQ(o.status, 2);
    EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
    EXPECT_THAT(o.err, HasSubstr("joint12_x_rad"));
    EXPECT_THAT(o.err, HasSubstr("this arm has 9 joints"));
    EXPECT_FALSE(fs::exists(dir / "x.h5"));
  }
  // On 15 joints, --effect mocap_offset offsets all of them in the truth.
  const std::string exp = (dir / "exp.h5").string();
  const Outcome g =
      RunCcsrm("generate --config " + fifteen +
               " --case 1 --duration 0.05 --quiet --effect mocap_offset --out " + exp);
  ASSERT_EQ(g.status, 0) << g.err;
  const std::string truth = ccsrm::ReadTextFile((dir / "exp.truth.yaml").string());
  EXPECT_THAT(truth, HasSubstr("joint15_y_rad: "));
  EXPECT_EQ(truth.find("joint16_x_rad"), std::string::npos);
}

TEST(Generate, EffectsGoToTheTruthOnlyAndMocapOffsetIntoTheRecordedAngles) {
  const fs::path dir = FreshDir("effects");
  const std::string effects = (dir / "effects.yaml").string();
  ccsrm::WriteTextFileAtomically(effects, "table_tilt: {lateral_rad: 0.001}\n");
  const std::string exp = (dir / "exp.h5").string();
  const Outcome g = RunCcsrm(
      "generate --config " + Paper() +
      " --case 1 --duration 0.3 --quiet --noise-mm 0 --no-occlusions "
      "--effects " +
      effects + " --effect mocap_offset:joint2_x_rad=0.01,joint9_y_rad=-0.004 --out " + exp);
  ASSERT_EQ(g.status, 0) << g.err;
  EXPECT_THAT(g.out, HasSubstr("effects on (truth only): table_tilt mocap_offset"));
  const auto e = ccsrm::datasets::ReadExperimentFile(exp);
  EXPECT_EQ(e.config_yaml, NominalCase1());  // nominal, no effects
  const std::string truth_yaml = ccsrm::ReadTextFile((dir / "exp.truth.yaml").string());
  EXPECT_THAT(truth_yaml, HasSubstr("table_tilt:\n    lateral_rad: 0.001"));
  EXPECT_THAT(truth_yaml, HasSubstr("joint2_x_rad: 0.01"));
  // The processed angles carry the offsets; the truth run does not.
  const std::string processed = (dir / "processed.h5").string();
  const Outcome p = RunCcsrm("mocap process --quiet --in " + exp + " --config " + Paper() +
                             " --out " + processed);
  ASSERT_EQ(p.status, 0) << p.err;
  const auto measured = ccsrm::datasets::ReadExperimentFile(processed).measured_joint_angles;
  ASSERT_TRUE(measured.has_value());
  const auto truth = ccsrm::datasets::ReadRunFile((dir / "exp.truth.h5").string());
  for (std::size_t f = 0; f < truth.frames(); ++f) {
    for (std::size_t j = 0; j < 12; ++j) {
      for (std::size_t a = 0; a < 2; ++a) {
        const double offset = j == 1 && a == 0 ? 0.01 : j == 8 && a == 1 ? -0.004 : 0.0;
        // 2e-4 rad: what processing noise-free markers resolves (above).
        EXPECT_NEAR(measured->at(f, j, a) - truth.joint_angles.at(f, j, a), offset, 2e-4)
            << "frame " << f << " joint " << j + 1 << " axis " << a;
      }
    }
  }
  // The truth file as --params brings the effects back.
  const Outcome again =
      RunCcsrm("generate --config " + Paper() + " --case 1 --duration 0.1 --quiet --params " +
               (dir / "exp.truth.yaml").string() + " --out " + (dir / "again.h5").string());
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_THAT(again.out, HasSubstr("effects on (truth only): table_tilt mocap_offset"));
}

TEST(Generate, BadEffectInputIsOneLine) {
  for (const std::string& bad :
       {std::string("--effect tilt"), std::string("--effect backlash:dead_band_rad=9"),
        std::string("--effect backlash:dead_band_rad"),
        std::string("--effects /nonexistent/e.yaml")}) {
    SCOPED_TRACE(bad);
    const Outcome o =
        RunCcsrm("generate --config " + Paper() + " " + bad + " --out /tmp/ccsrm_never.h5");
    EXPECT_EQ(o.status, 2);
    EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
  }
}

TEST(Generate, ExperimentRecordsTheCommandWhileTheTruthRunHasTheDelayedInputs) {
  const fs::path dir = FreshDir("delay");
  const std::string exp = (dir / "exp.h5").string();
  const Outcome g = RunCcsrm("generate --config " + Paper() +
                             " --case 1 --duration 0.3 --quiet --seed 7 --effect "
                             "actuator_delay:dead_time_s=0.1 --out " +
                             exp);
  ASSERT_EQ(g.status, 0) << g.err;
  const auto delayed = ccsrm::datasets::ReadExperimentFile(exp);
  const auto nominal = ccsrm::datasets::ReadExperimentFile((Generated() / "exp.h5").string());
  // The recorded inputs are the command, as without the effect.
  EXPECT_EQ(delayed.input_length_change.values, nominal.input_length_change.values);
  // The truth run drove the arm with the command 0.1 s late.
  const auto truth = ccsrm::datasets::ReadRunFile((dir / "exp.truth.h5").string());
  ASSERT_EQ(truth.input_length_change.shape, nominal.input_length_change.shape);
  for (std::size_t c = 0; c < 6; ++c) {
    EXPECT_NEAR(truth.input_length_change.at(30, c), nominal.input_length_change.at(20, c), 1e-9);
  }
}

// --- Issue 33: every door checks an experiment against its own config_yaml ---

// The generated experiment, changed by `change` and written to <dir>/<name>.h5
// (what a user's script or another tool could write: it passes
// ValidateExperimentFile, which knows nothing of the arm).
std::string Variant(const fs::path& dir, const std::string& name,
                    const std::function<void(ccsrm::datasets::ExperimentFile*)>& change) {
  ccsrm::datasets::ExperimentFile e =
      ccsrm::datasets::ReadExperimentFile((Generated() / "exp.h5").string());
  change(&e);
  const std::string path = (dir / (name + ".h5")).string();
  ccsrm::datasets::WriteExperimentFile(path, e);
  return path;
}

// Inputs for 5 cables on the 6-cable arm: refused by inspect, and by mocap
// process whether they come with the experiment or through --inputs, before
// anything is written.
TEST(ExperimentCheck, InputsForAnotherNumberOfCablesAreRefusedAtEveryDoor) {
  const fs::path dir = FreshDir("five_cables");
  const std::string five = Variant(dir, "five", [](ccsrm::datasets::ExperimentFile* e) {
    ccsrm::datasets::Array cut({e->input_time.rows(), 5});
    for (std::size_t i = 0; i < cut.rows(); ++i) {
      for (std::size_t c = 0; c < 5; ++c) cut.at(i, c) = e->input_length_change.at(i, c);
    }
    e->input_length_change = cut;
  });
  const std::string want = five +
                           ": /input/length_change: has 5 cable columns, the arm of its "
                           "config_yaml has 6 driving cables";
  const Outcome inspect = RunCcsrm("dataset inspect " + five);
  EXPECT_EQ(inspect.status, 2);
  EXPECT_EQ(inspect.err, "ccsrm: " + want + "\n");

  const std::string out = (dir / "out.h5").string();
  const Outcome own = RunCcsrm("mocap process --quiet --in " + five + " --out " + out);
  EXPECT_EQ(own.status, 2);
  EXPECT_EQ(own.err, "ccsrm: " + want + "\n");
  EXPECT_FALSE(fs::exists(out));

  const std::string exp = (Generated() / "exp.h5").string();
  const Outcome inputs =
      RunCcsrm("mocap process --quiet --in " + exp + " --inputs " + five + " --out " + out);
  EXPECT_EQ(inputs.status, 2);
  EXPECT_EQ(inputs.err, "ccsrm: " + five +
                            ": /input/length_change: has 5 cable columns, the arm of " + exp +
                            " (its config_yaml) has 6 driving cables\n");
  EXPECT_FALSE(fs::exists(out));
  const Outcome with_config = RunCcsrm("mocap process --quiet --in " + exp + " --config " +
                                       Paper() + " --inputs " + five + " --out " + out);
  EXPECT_EQ(with_config.status, 2);
  EXPECT_THAT(with_config.err, HasSubstr("the arm of " + Paper() + " has 6 driving cables"));
  EXPECT_FALSE(fs::exists(out));
}

// A config_yaml that does not parse, and angles no universal joint can take,
// are refused by inspect (and by identify: tests/identify).
TEST(ExperimentCheck, InspectRefusesABadConfigYamlAndAnglesOutOfRange) {
  const fs::path dir = FreshDir("inspect_check");
  const std::string bad_yaml = Variant(dir, "bad_yaml", [](ccsrm::datasets::ExperimentFile* e) {
    e->config_yaml = "arm: [unclosed";
  });
  const Outcome yaml = RunCcsrm("dataset inspect " + bad_yaml);
  EXPECT_EQ(yaml.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(yaml.err), 1) << yaml.err;
  EXPECT_THAT(yaml.err, HasSubstr("ccsrm: " + bad_yaml + ": attribute 'config_yaml'"));

  const std::string processed = (dir / "processed.h5").string();
  ASSERT_EQ(RunCcsrm("mocap process --quiet --in " + (Generated() / "exp.h5").string() + " --out " +
                     processed)
                .status,
            0);
  ccsrm::datasets::ExperimentFile e = ccsrm::datasets::ReadExperimentFile(processed);
  ASSERT_TRUE(e.measured_joint_angles.has_value());
  for (double& v : e.measured_joint_angles->values) v *= 1e30;
  const std::string huge = (dir / "huge.h5").string();
  ccsrm::datasets::WriteExperimentFile(huge, e);
  const Outcome angles = RunCcsrm("dataset inspect " + huge);
  EXPECT_EQ(angles.status, 2);
  EXPECT_EQ(ccsrm::testing::CountLines(angles.err), 1) << angles.err;
  EXPECT_THAT(angles.err, HasSubstr("ccsrm: " + huge + ": /measured/joint_angles: frame index "));
  EXPECT_THAT(angles.err, HasSubstr("outside the universal joint's range"));
}

// Markers never seen (all NaN, all infinite) and a one-frame recording are
// refused by mocap process where it reads them, naming the file and the
// dataset, instead of an experiment with no finite angle.
TEST(ExperimentCheck, MarkersNeverSeenAndASingleFrameAreRefused) {
  const fs::path dir = FreshDir("unseen");
  const std::string out = (dir / "out.h5").string();
  for (const double value : {std::nan(""), HUGE_VAL}) {
    const std::string unseen = Variant(dir, "unseen", [value](ccsrm::datasets::ExperimentFile* e) {
      for (double& v : e->mocap_markers.values) v = value;
    });
    const Outcome o = RunCcsrm("mocap process --quiet --in " + unseen + " --out " + out);
    EXPECT_EQ(o.status, 2) << value;
    EXPECT_EQ(o.err, "ccsrm: " + unseen +
                         ": /mocap/markers: has no finite sample (every position NaN or "
                         "infinite): no marker was ever seen, so there is no pose to fit\n");
    EXPECT_FALSE(fs::exists(out));
    const Outcome inspect = RunCcsrm("dataset inspect " + unseen);
    EXPECT_EQ(inspect.status, 2);
    EXPECT_THAT(inspect.err, HasSubstr(unseen + ": /mocap/markers: has no finite sample"));
  }

  const std::string one = Variant(dir, "one", [](ccsrm::datasets::ExperimentFile* e) {
    const std::size_t m = e->marker_names.size();
    e->mocap_time = ccsrm::datasets::Array({1}, e->mocap_time.at(0));
    ccsrm::datasets::Array markers({1, m, 3});
    std::copy(e->mocap_markers.values.begin(), e->mocap_markers.values.begin() + m * 3,
              markers.values.begin());
    e->mocap_markers = markers;
    e->measured_joint_angles.reset();
    e->measured_link_pose.reset();
    e->measured_joint_twist.reset();
    e->mocap_quality.clear();
    e->mocap_quality_units.clear();
  });
  const Outcome o = RunCcsrm("mocap process --quiet --in " + one + " --out " + out);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(o.err, "ccsrm: " + one +
                       ": /mocap/time: has 1 frame(s): processing needs at least 2 (a frame "
                       "rate for the time base and the low-pass filter)\n");
  const Outcome inspect = RunCcsrm("dataset inspect " + one);
  EXPECT_EQ(inspect.status, 2);
  EXPECT_THAT(inspect.err, HasSubstr(one + ": /mocap/time: has 1 frame: needs at least 2"));
}

}  // namespace
