// The error policy as a table (docs/conventions.md): bad inputs by class,
// each run through the ccsrm program as a user would. For every row: exit
// status 2, one line on stderr naming the file (or option) and the field,
// and the scratch folder byte for byte as it was: no output left, no input
// changed. The rows are the documentation of what is refused, and where.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "run_ccsrm.h"

namespace {
namespace fs = std::filesystem;
using ccsrm::testing::RunCcsrm;
using ::testing::HasSubstr;
using Outcome = ccsrm::testing::CommandOutcome;

std::string Paper() { return std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml"; }

// Every entry under `dir`: relative path -> size and FNV-1a checksum of its
// bytes ("folder" for a folder), so that a changed, added or removed file
// shows by name.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).string();
    if (!e.is_regular_file()) {
      files[rel] = "folder";
      continue;
    }
    const std::string bytes = ccsrm::ReadTextFile(e.path().string());
    std::uint64_t hash = 1469598103934665603ull;
    for (unsigned char c : bytes) hash = (hash ^ c) * 1099511628211ull;
    files[rel] = std::to_string(bytes.size()) + " bytes, fnv " + std::to_string(hash);
  }
  return files;
}

// The entries added, removed or changed between two snapshots, by name.
std::string Differences(const std::map<std::string, std::string>& before,
                        const std::map<std::string, std::string>& after) {
  std::string out;
  for (const auto& [name, state] : after) {
    const auto it = before.find(name);
    if (it == before.end())
      out += " added " + name + ";";
    else if (it->second != state)
      out += " changed " + name + ";";
  }
  for (const auto& [name, state] : before) {
    if (after.count(name) == 0) out += " removed " + name + ";";
  }
  return out;
}

void Write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// Debian's Python, with python3-h5py (scripts/install-deps.sh).
constexpr const char* kPython = "/usr/bin/python3";

bool HaveH5py() {
  return std::system((std::string(kPython) + " -c 'import h5py' >/dev/null 2>&1").c_str()) == 0;
}

// Copies `from` to `to` and edits it in place with h5py: `python` runs with
// `f` the open file and put(path, array) replacing a dataset (units kept).
void MutateHdf5(const fs::path& from, const fs::path& to, const std::string& python) {
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
  const fs::path script = to.string() + ".py";
  Write(script,
        "import h5py, numpy as np\n"
        "f = h5py.File('" +
            to.string() +
            "', 'r+')\n"
            "def put(path, data):\n"
            "    units = f[path].attrs['units']\n"
            "    del f[path]\n"
            "    f[path] = data\n"
            "    f[path].attrs['units'] = units\n" +
            python + "\nf.close()\n");
  ASSERT_EQ(std::system((std::string(kPython) + " " + script.string()).c_str()), 0) << python;
  fs::remove(script);
}

// A paper.yaml whose first line matching `pattern` is replaced by
// `replacement` ("$&" is the line itself).
std::string EditedPaper(const std::string& pattern, const std::string& replacement) {
  const std::string text = ccsrm::ReadTextFile(Paper());
  return std::regex_replace(text, std::regex(pattern), replacement,
                            std::regex_constants::format_first_only);
}

// The second arm (configs/three-segment.yaml) edited as EditedPaper does.
std::string EditedThreeSegment(const std::string& pattern, const std::string& replacement) {
  const std::string text =
      ccsrm::ReadTextFile(std::string(CCSRM_SOURCE_DIR) + "/configs/three-segment.yaml");
  return std::regex_replace(text, std::regex(pattern), replacement,
                            std::regex_constants::format_first_only);
}

class BadInputTable : public ::testing::Test {
 protected:
  // The inputs of every row, made once: configurations, parameter files, a
  // short generated experiment, its processed angles and broken copies.
  static void SetUpTestSuite() {
    if (!HaveH5py()) return;  // each test skips, saying why
    dir_ = ccsrm::testing::ScratchDirectory("bad_input_table");
    const fs::path& d = dir_;
    fs::copy_file(Paper(), d / "c.yaml");
    Write(d / "dup.yaml", EditedPaper("  *link_mass_kg: .*", "$&\n$&"));
    Write(d / "dupsolver.yaml",
          ccsrm::ReadTextFile(Paper()) + "solver:\n  relative_tolerance: 1.0e-6\n");
    Write(d / "stiff.yaml", EditedPaper("youngs_modulus_pa: .*", "youngs_modulus_pa: 1e300"));
    Write(d / "typo.yaml", EditedPaper("link_mass_kg", "link_mas_kg"));
    Write(d / "syntax.yaml", "schema: ccsrm-config/1\narm: [unclosed\n");
    // Layouts whose cables cannot bend segment 2 about both axes (issue 32).
    Write(d / "nocable.yaml", EditedThreeSegment("    - \\{segment: 2, hole_angle_deg: 40.0\\}\n"
                                                 "    - \\{segment: 2, hole_angle_deg: 160.0\\}\n"
                                                 "    - \\{segment: 2, hole_angle_deg: 280.0\\}\n",
                                                 ""));
    Write(d / "twocables.yaml",
          EditedThreeSegment("    - \\{segment: 2, hole_angle_deg: 280.0\\}\n", ""));
    Write(d / "samehole.yaml", EditedThreeSegment("hole_angle_deg: 160.0", "hole_angle_deg: 40.0"));
    Write(d / "halfplane.yaml",
          EditedThreeSegment("hole_angle_deg: 280.0", "hole_angle_deg: 100.0"));
    // Issue 44: segment 3's hole circle beyond its 0.08 m links (0.16 m, mm
    // read as m), and one within them (0.075 m) that sets joint 1's range.
    Write(d / "wide3.yaml",
          EditedThreeSegment("hole_circle_radius_m: 0.015", "hole_circle_radius_m: 0.16"));
    Write(d / "wider3.yaml",
          EditedThreeSegment("hole_circle_radius_m: 0.015", "hole_circle_radius_m: 0.075"));
    fs::create_directory(d / "confdir");
    Write(d / "p.yaml", "mu: 0.2\n");
    Write(d / "proto.yaml",
          "schema: ccsrm-protocol/1\nparameters: {amplitude_deg: 2}\nsegments:\n  all:\n"
          "    - move: {to: {theta_x_deg: amplitude_deg}, duration_s: 1}\n");
    Write(d / "pbounds.yaml", "mu: {value: 0.5, free: true, bounds: [0.1, 0.3]}\n");
    Write(d / "prange.yaml", "mu: {value: 5, free: true}\n");
    Write(d / "pdup.yaml", "mu: 0.2\nmu_s: 0.3\nmu: 0.25\n");
    Write(d / "notes.h5", "not an HDF5 file\n");
    Write(d / "notes.c3d", "my notes, not a C3D file\n");
    fs::create_directory(d / "mine");
    Write(d / "mine" / "precious.txt", "the user's own file\n");
    // Actuator logs and their maps (issue 27): six cables of the paper's arm.
    std::string map = "schema: ccsrm-actuators/1\ntime: {column: t_s, unit: s}\ncables:\n";
    std::string header = "t_s";
    std::string row = "";
    for (int c = 1; c <= 6; ++c) {
      map += "  - {column: m" + std::to_string(c) +
             ", signal: motor_angle, unit: deg, drum_radius_m: 0.01}\n";
      header += ",m" + std::to_string(c);
      row += ",1.5";
    }
    Write(d / "map.yaml", map);
    Write(d / "nodrum.yaml", std::regex_replace(map, std::regex(", drum_radius_m: 0.01"), "",
                                                std::regex_constants::format_first_only));
    Write(d / "unknowncol.yaml", std::regex_replace(map, std::regex("column: m6"), "column: m7"));
    Write(d / "log.csv", header + "\n0" + row + "\n0.01" + row + "\n0.02" + row + "\n");
    Write(d / "nanlog.csv", header + "\n0" + row + "\n0.01,1,2,NaN,4,5,6\n");
    Write(d / "backlog.csv", header + "\n0" + row + "\n0.02" + row + "\n0.01" + row + "\n");
    Write(d / "gaplog.csv", header + "\n0" + row + "\n5" + row + "\n");
    // Issue 47, 7: what dataset assemble took before. Cable lengths in mm
    // declared m (17.7 mm read as 17.7 m), a length of 1e9 mm, a counter
    // said to wrap at 2 counts, a mapped column twice, a row of 8 cells.
    std::string lengths = "schema: ccsrm-actuators/1\ntime: {column: t_s, unit: s}\ncables:\n";
    std::string counts = lengths;
    for (int c = 1; c <= 6; ++c) {
      lengths += "  - {column: m" + std::to_string(c) + ", signal: length_change, unit: m}\n";
      counts += "  - {column: m" + std::to_string(c) +
                ", signal: motor_angle, unit: counts, drum_radius_m: 0.01, counts_per_turn: "
                "4096, wrap_counts: 2}\n";
    }
    Write(d / "metres.yaml", lengths);
    Write(d / "mmlengths.yaml", std::regex_replace(lengths, std::regex("unit: m\\}"), "unit: mm}"));
    Write(d / "wrap2.yaml", counts);
    Write(d / "mmlog.csv", header + "\n0,0,0,0,0,0,0\n0.01,17.7,0,0,0,0,0\n");
    Write(d / "hugelog.csv", header + "\n0,0,0,0,0,0,0\n0.01,0,1e9,0,0,0,0\n");
    Write(d / "duplog.csv", "t_s,m1,m2,m3,m4,m5,m6,m3\n0,0,0,0,0,0,0,0\n0.01,0,0,0,0,0,0,0\n");
    Write(d / "widelog.csv", header + "\n0" + row + "\n0.01" + row + ",7\n");
    // Issue 47, 10 and 9: inputs that tore the arm apart (the run hung at
    // t = 0), a protocol of a billion pieces, a 1 MHz sine.
    Write(d / "torn.csv",
          "time_s,cable1_m,cable2_m,cable3_m,cable4_m,cable5_m,cable6_m\n0,0,0,0,0,0,0\n"
          "0.01,10,0,0,0,0,0\n");
    Write(d / "jerk.csv",
          "time_s,cable1_m,cable2_m,cable3_m,cable4_m,cable5_m,cable6_m\n0,0,0,0,0,0,0\n"
          "0.01,0,0.05,0,0,0,0\n");
    Write(d / "nested.yaml",
          "schema: ccsrm-protocol/1\nsegments:\n  all:\n    - repeat:\n        times: 1000\n"
          "        pieces:\n          - repeat:\n              times: 1000\n              pieces:\n"
          "                - repeat: {times: 1000, pieces: [{hold: {duration_s: 1}}]}\n");
    Write(d / "megahertz.yaml",
          "schema: ccsrm-protocol/1\nsegments:\n  all:\n"
          "    - sine: {amplitude: {theta_x_deg: 1}, frequency_hz: 1.0e6, duration_s: 1}\n");
    // Issue 47, 11: configurations every run of which fails or never ends.
    Write(d / "hugeh.yaml", EditedPaper("smoothing_step_s: .*", "smoothing_step_s: 1e300"));
    Write(d / "hugealpha.yaml",
          EditedPaper("baumgarte_alpha_per_s: .*", "baumgarte_alpha_per_s: 1e300"));
    Write(d / "hugeramp.yaml", EditedPaper("  ramp_s: .*", "  ramp_s: 1e300"));
    // Issue 47, 13: a checkpoint cut short.
    fs::create_directory(d / "cutfit");
    Write(d / "cutfit" / "checkpoint.json", "{\"schema\": \"ccsrm-checkpoint/1\", \"itera");

    // Made in a work folder, then moved in: the rows compare the scratch
    // folder with itself, and these are its inputs.
    const fs::path w = ccsrm::testing::ScratchDirectory("bad_input_table_work");
    Outcome o =
        RunCcsrm("generate --config " + Paper() +
                 " --case 1 --duration 0.3 --quiet --seed 3 --out " + (w / "exp.h5").string());
    ASSERT_EQ(o.status, 0) << o.err;
    o = RunCcsrm("mocap process --quiet --in " + (w / "exp.h5").string() + " --out " +
                 (w / "processed.h5").string());
    ASSERT_EQ(o.status, 0) << o.err;
    o = RunCcsrm("simulate --config " + Paper() + " --case 1 --duration 0.2 --quiet --out " +
                 (w / "run.h5").string());
    ASSERT_EQ(o.status, 0) << o.err;
    // The second arm's (nine cables): the paper's six-cable inputs do not fit it.
    o = RunCcsrm("generate --config " + std::string(CCSRM_SOURCE_DIR) +
                 "/configs/three-segment.yaml --case 1 --duration 0.3 --quiet --seed 3 --out " +
                 (w / "exp9.h5").string());
    ASSERT_EQ(o.status, 0) << o.err;
    for (const char* name : {"exp.h5", "processed.h5", "run.h5", "exp9.h5"}) {
      fs::rename(w / name, d / name);
    }
    const fs::path processed = d / "processed.h5";
    MutateHdf5(processed, d / "five.h5",
               "put('/input/length_change', f['/input/length_change'][:, :5])");
    MutateHdf5(processed, d / "badyaml.h5", "f.attrs['config_yaml'] = 'arm: [unclosed'");
    MutateHdf5(processed, d / "nanlength.h5",
               "x = f['/input/length_change'][...]\nx[3, 2] = np.nan\n"
               "put('/input/length_change', x)");
    MutateHdf5(processed, d / "huge.h5",
               "put('/measured/joint_angles', f['/measured/joint_angles'][...] * 1e30)");
    MutateHdf5(processed, d / "cut5.h5",
               "put('/measured/joint_angles', f['/measured/joint_angles'][:, :5, :])");
    // One mocap frame: every array over the frames cut to its first.
    MutateHdf5(processed, d / "one.h5",
               "F = f['/mocap/time'].shape[0]\n"
               "paths = []\n"
               "f.visititems(lambda n, o: paths.append(n) if isinstance(o, h5py.Dataset) and "
               "(n.startswith('mocap') or n.startswith('measured')) and o.ndim >= 1 and "
               "o.shape[0] == F else None)\n"
               "for n in paths: put('/' + n, f[n][:1])");
    MutateHdf5(d / "exp.h5", d / "nan.h5",
               "put('/mocap/markers', np.full(f['/mocap/markers'].shape, np.nan))");
    MutateHdf5(d / "exp.h5", d / "inf.h5",
               "put('/mocap/markers', np.full(f['/mocap/markers'].shape, np.inf))");
    // One marker coordinate far outside any capture volume (issue 47, 6).
    MutateHdf5(d / "exp.h5", d / "outlier.h5",
               "x = f['/mocap/markers'][...]\nx[2, 1, 0] = 1e20\nput('/mocap/markers', x)");
    MutateHdf5(d / "exp.h5", d / "outlier1k.h5",
               "x = f['/mocap/markers'][...]\nx[5, 0, 2] = 1e3\nput('/mocap/markers', x)");
    // Issue 47, 12: files one command refused and another read.
    MutateHdf5(d / "run.h5", d / "nanrun.h5",
               "x = f['/input_length_change'][...]\nx[1, 0] = np.nan\n"
               "put('/input_length_change', x)");
    MutateHdf5(d / "run.h5", d / "noconfigrun.h5", "f.attrs['config_yaml'] = ''");
    MutateHdf5(processed, d / "negmass.h5",
               "import re\nf.attrs['config_yaml'] = re.sub(r'link_mass_kg: [0-9.e-]+', "
               "'link_mass_kg: -1.0', f.attrs['config_yaml'], count=1)");
    // Issue 47, 13: a C3D whose parameter name a damaged byte made "LAB\nLS"
    // and whose type another made 32.
    o = RunCcsrm("mocap export --in " + (d / "exp.h5").string() + " --out " +
                 (w / "flip.c3d").string());
    ASSERT_EQ(o.status, 0) << o.err;
    fs::rename(w / "flip.c3d", d / "flip.c3d");
    {
      std::string bytes = ccsrm::ReadTextFile((d / "flip.c3d").string());
      const std::size_t at = bytes.find("LABELS");
      ASSERT_NE(at, std::string::npos);
      bytes[at + 3] = '\n';
      bytes[at + 8] = 32;  // its type, after the 2-byte offset: none of -1, 1, 2, 4
      std::ofstream(d / "flip.c3d", std::ios::binary) << bytes;
    }
    // Issue 47, 6 at the marker files' own door: a C3D whose first point
    // sits 1000 m out (floating-point points: the header's scale is < 0).
    o = RunCcsrm("mocap export --in " + (d / "exp.h5").string() + " --out " +
                 (d / "outlier.c3d").string());
    ASSERT_EQ(o.status, 0) << o.err;
    Write(w / "far.py",
          "import struct, sys\np = sys.argv[1]\nb = bytearray(open(p, 'rb').read())\n"
          "scale = struct.unpack_from('<f', b, 12)[0]\nassert scale < 0, scale\n"
          "start = (struct.unpack_from('<H', b, 16)[0] - 1) * 512\n"
          "struct.pack_into('<f', b, start, 1.0e6)\nopen(p, 'wb').write(b)\n");
    ASSERT_EQ(std::system((std::string(kPython) + " " + (w / "far.py").string() + " " +
                           (d / "outlier.c3d").string())
                              .c_str()),
              0);
    fs::remove(w / "far.py");
    // A recorded experiment (issue 47, 4): its measurements no run gives back.
    MutateHdf5(processed, d / "recorded.h5", "f.attrs['source'] = 'recorded'");
    // A stub made to look like an earlier fit (issue 47, 3), and a real
    // report folder a user has added notes to.
    fs::create_directory(d / "stub");
    Write(d / "stub" / "fit.json", "{\"schema\":\"ccsrm-fit/1\"}");
    Write(d / "stub" / "thesis.tex", "\\documentclass{article}\n");
    o = RunCcsrm("report --in " + (d / "run.h5").string() + " --out " + (w / "report").string());
    ASSERT_EQ(o.status, 0) << o.err;
    fs::rename(w / "report", d / "noted_report");
    Write(d / "noted_report" / "notes.txt", "what I saw in this run\n");
  }

  void SetUp() override {
    if (!HaveH5py()) {
      GTEST_SKIP() << kPython << " cannot import h5py, which makes the broken HDF5 files "
                   << "(install python3-h5py: scripts/install-deps.sh)";
    }
  }

  static fs::path dir_;
};
fs::path BadInputTable::dir_;

struct BadInput {
  std::string input_class;         // configs, overrides, hdf5, markers, outputs
  std::string args;                // "{d}" is the scratch folder
  std::vector<std::string> names;  // what the one line must name ("{d}" too)
};

std::string Expand(std::string text, const fs::path& dir) {
  for (std::size_t at; (at = text.find("{d}")) != std::string::npos;) {
    text.replace(at, 3, dir.string());
  }
  return text;
}

// The table. Where a row comes from the issue that found it (issue 33), its
// item number is in the comment.
const std::vector<BadInput>& Rows() {
  static const std::vector<BadInput> rows = {
      // Configurations: refused by `config check` with the rule `simulate` hits.
      {"configs", "config check {d}/dup.yaml", {"{d}/dup.yaml", "link_mass_kg", "duplicate"}},  // 6
      {"configs",
       "config check {d}/dupsolver.yaml",
       {"{d}/dupsolver.yaml", "solver", "duplicate"}},                                      // 6
      {"configs", "config check {d}/stiff.yaml", {"{d}/stiff.yaml", "youngs_modulus_pa"}},  // 6
      {"configs",
       "simulate --config {d}/stiff.yaml --duration 0.1 --out {d}/run2.h5",
       {"{d}/stiff.yaml", "youngs_modulus_pa"}},  // 6
      {"configs",
       "simulate --config {d}/dup.yaml --duration 0.1 --out {d}/run2.h5",
       {"{d}/dup.yaml", "duplicate"}},
      {"configs", "config check {d}/confdir", {"{d}/confdir", "folder"}},  // 9
      {"configs", "config check {d}/typo.yaml", {"{d}/typo.yaml", "link_mas_kg"}},
      {"configs", "config check {d}/syntax.yaml", {"{d}/syntax.yaml", "line"}},
      {"configs", "config check {d}/missing.yaml", {"{d}/missing.yaml"}},
      // Layouts: a segment its cables cannot bend about both axes (issue 32).
      {"configs",
       "config check {d}/nocable.yaml",
       {"{d}/nocable.yaml", "arm.segments[1]", "segment 2", "no driving cable"}},
      {"configs",
       "config check {d}/twocables.yaml",
       {"{d}/twocables.yaml", "segment 2", "2 driving cables"}},
      {"configs",
       "config check {d}/samehole.yaml",
       {"{d}/samehole.yaml", "segment 2", "coincident holes"}},
      {"configs",
       "config check {d}/halfplane.yaml",
       {"{d}/halfplane.yaml", "segment 2", "half-plane"}},
      {"configs",
       "simulate --config {d}/halfplane.yaml --duration 0.1 --out {d}/run2.h5",
       {"{d}/halfplane.yaml", "segment 2", "half-plane"}},
      {"configs",
       "config check {d}/wide3.yaml",
       {"{d}/wide3.yaml", "hole_circle_radius_m", "beyond the link length 0.08 m",
        "check the units"}},  // issue 44
      {"configs",
       "simulate --config {d}/wider3.yaml --case 1 --amplitude 15 --out {d}/run2.h5",
       {"--amplitude", "past its 12.18 deg",
        "the hole circle of segment 3, whose cables pass joint 1"}},  // issue 44
      // Command-line values and parameter files.
      {"overrides",
       "simulate --config {d}/c.yaml --set mu=1e-400 --duration 0.1 --out {d}/run2.h5",
       {"--set", "1e-400"}},  // 9
      {"overrides",
       "simulate --config {d}/c.yaml --set mu=1e400 --duration 0.1 --out {d}/run2.h5",
       {"--set", "1e400"}},
      {"overrides",
       "simulate --config {d}/c.yaml --set mu=-1 --duration 0.1 --out {d}/run2.h5",
       {"--set", "mu"}},
      {"overrides",
       "identify --data {d}/processed.h5 --free '' --out {d}/fit",
       {"--free", "empty"}},  // 3
      {"overrides",
       "identify --data {d}/processed.h5 --free mu, --out {d}/fit",
       {"--free", "empty"}},
      {"overrides",
       "identify --data {d}/processed.h5 --resume --out {d}/nofit",
       {"{d}/nofit/checkpoint.json", "--resume", "no checkpoint"}},  // issue 29
      {"overrides",
       "identify --data {d}/processed.h5 --run-timeout 0 --out {d}/fit",
       {"--run-timeout"}},  // issue 29
      {"overrides",
       "derivatives --config {d}/c.yaml --duration 0.1 --run-timeout -1",
       {"--run-timeout"}},  // issue 29
      {"overrides",
       "loop --data {d}/processed.h5 --candidates '' --out {d}/loop",
       {"--candidates", "empty"}},  // 3
      // A declared value of a segment the arm does not have (issue 28).
      {"overrides",
       "simulate --config {d}/c.yaml --set declared.segment9.link_length=0.01 --duration 0.1 "
       "--out {d}/run2.h5",
       {"--set", "declared.segment9.link_length", "segments"}},
      {"overrides",
       "simulate --config {d}/c.yaml --set declared.joint_disk_gap=0.5 --duration 0.1 "
       "--out {d}/run2.h5",
       {"--set", "declared.joint_disk_gap", "outside"}},
      {"overrides",
       "derivatives --config {d}/c.yaml --parameters '' --duration 0.1",
       {"--parameters", "empty"}},
      {"overrides",
       "identify --data {d}/processed.h5 --params {d}/pbounds.yaml --out {d}/fit",
       {"{d}/pbounds.yaml", "mu"}},  // 9
      {"overrides",
       "identify --data {d}/processed.h5 --params {d}/prange.yaml --out {d}/fit",
       {"{d}/prange.yaml", "mu"}},
      {"overrides",
       "identify --data {d}/processed.h5 --params {d}/pdup.yaml --out {d}/fit",
       {"{d}/pdup.yaml", "mu", "duplicate"}},
      {"overrides",
       "predict --data {d}/processed.h5 --params {d}/prange.yaml --out {d}/pred",
       {"{d}/prange.yaml", "mu"}},
      {"overrides",
       "report --in {d}/run.h5 --instants -5 --out {d}/report",
       {"--instants", "-5"}},  // 8
      {"overrides", "report --in {d}/run.h5 --instants 1e4 --out {d}/report", {"--instants"}},
      // From the test's working folder, outside the repository: the value is
      // refused before the (bundled) configuration is read.
      {"overrides", "bench --duration 0", {"--duration"}},  // 9
      {"overrides",
       "simulate --config {d}/c.yaml --amplitude 100 --duration 0.1 --out {d}/run2.h5",
       {"--amplitude"}},
      // A plan past the joints' range, refused by the planner before it
      // runs (docs/model-notes.md row 27): issue 32's -40 deg on the
      // three-segment arm (range 35.5 deg), 45 deg on the paper's (41.7).
      {"overrides",
       "simulate --config " + std::string(CCSRM_SOURCE_DIR) +
           "/configs/three-segment.yaml --case 1 --amplitude -40 --out {d}/run2.h5",
       {"--amplitude", "bends joint 1 to 40 deg", "past its 35.49 deg"}},
      {"overrides",
       "generate --config {d}/c.yaml --amplitude 45 --out {d}/exp2.h5",
       {"--amplitude", "bends joint 1 to 45 deg", "past its 41.71 deg"}},
      // Experiment design (issue 26): its plans and priors, before any run.
      {"overrides",
       "design --free mu,,T_p --plans {d}/proto.yaml --out {d}/design",
       {"--free", "empty item"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml --resume --out {d}/nodesign",
       {"{d}/nodesign/checkpoint.json", "--resume", "no checkpoint"}},  // issue 29
      {"overrides",
       "design --free mu --plans {d}/proto.yaml@amplitude --out {d}/design",
       {"--plans", "expected name=value after '@'"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml@speed_deg=3 --out {d}/design",
       {"--plans", "speed_deg"}},
      {"overrides",
       "design --case 1 --free mu --plans {d}/proto.yaml --out {d}/design",
       {"--free", "mu", "its prior value is 0"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml --noise-from {d}/p.yaml --out {d}/design",
       {"{d}/p.yaml", "not JSON"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml --prior-box mu=0.3 --out {d}/design",
       {"--prior-box 'mu=0.3'", "expected name=lower:upper"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml --prior-box mu=0.3:0.1 --out {d}/design",
       {"--prior-box", "'mu' needs finite lower < upper"}},
      {"overrides",
       "design --free mu --plans {d}/proto.yaml --prior-box mu=0.1:0.3 --prior-box "
       "wobble=1:2 --out {d}/design",
       {"--prior-box", "wobble"}},
      // A protocol's parameters after '@' on every command that runs one.
      {"overrides",
       "generate --protocol {d}/proto.yaml@ramp_s --out {d}/exp2.h5",
       {"--protocol '{d}/proto.yaml@ramp_s'", "expected name=value after '@'"}},
      // HDF5 files: an experiment is checked against its own config_yaml at
      // every door (inspect, process, identify).
      {"hdf5",
       "identify --data {d}/five.h5 --out {d}/fit",
       {"{d}/five.h5", "/input/length_change"}},                                         // 5
      {"hdf5", "dataset inspect {d}/five.h5", {"{d}/five.h5", "/input/length_change"}},  // 5
      {"hdf5", "dataset inspect {d}/badyaml.h5", {"{d}/badyaml.h5", "config_yaml"}},     // 5
      {"hdf5", "identify --data {d}/badyaml.h5 --out {d}/fit", {"{d}/badyaml.h5", "config_yaml"}},
      {"hdf5",
       "identify --data {d}/huge.h5 --out {d}/fit",
       {"{d}/huge.h5", "/measured/joint_angles"}},                                          // 4
      {"hdf5", "dataset inspect {d}/huge.h5", {"{d}/huge.h5", "/measured/joint_angles"}},   // 4
      {"hdf5", "identify --data {d}/one.h5 --out {d}/fit", {"{d}/one.h5", "/mocap/time"}},  // 9
      {"hdf5",
       "identify --data {d}/cut5.h5 --out {d}/fit",
       {"{d}/cut5.h5", "/measured/joint_angles"}},  // 9
      {"hdf5", "dataset inspect {d}/cut5.h5", {"{d}/cut5.h5", "/measured/joint_angles"}},
      {"hdf5", "dataset inspect {d}/notes.h5", {"{d}/notes.h5", "HDF5"}},
      // Prediction (issue 25): the same door as identification.
      {"hdf5",
       "predict --data {d}/five.h5 --params {d}/p.yaml --out {d}/pred",
       {"{d}/five.h5", "/input/length_change"}},
      {"hdf5",
       "predict --data {d}/run.h5 --params {d}/p.yaml --out {d}/pred",
       {"{d}/run.h5", "ccsrm-dataset"}},
      {"hdf5",
       "predict --data {d}/processed.h5 --params {d}/run.h5 --out {d}/pred",
       {"{d}/run.h5"}},
      {"hdf5",
       "mocap process --in {d}/exp.h5 --inputs {d}/five.h5 --out {d}/x.h5",
       {"{d}/five.h5", "/input/length_change"}},  // 5
      // Inputs are checked against the arm where they enter (issue 32).
      {"hdf5",
       "mocap process --in {d}/exp9.h5 --inputs {d}/exp.h5 --out {d}/x.h5",
       {"{d}/exp.h5", "/input/length_change", "6 cable columns", "9 driving cables"}},
      {"hdf5",
       "mocap process --in {d}/exp9.h5 --inputs {d}/run.h5 --out {d}/x.h5",
       {"{d}/run.h5", "/input_length_change", "6 cable columns", "9 driving cables"}},
      {"hdf5",
       "mocap process --in {d}/exp.h5 --inputs {d}/nanlength.h5 --out {d}/x.h5",
       {"{d}/nanlength.h5", "/input/length_change", "cable 3", "finite"}},
      {"hdf5",
       "dataset inspect {d}/nanlength.h5",
       {"{d}/nanlength.h5", "/input/length_change", "finite"}},
      {"hdf5",
       "identify --data {d}/nanlength.h5 --out {d}/fit",
       {"{d}/nanlength.h5", "/input/length_change", "finite"}},
      // Marker data.
      {"markers",
       "mocap process --in {d}/nan.h5 --out {d}/x.h5",
       {"{d}/nan.h5", "/mocap/markers"}},  // 4
      {"markers",
       "mocap process --in {d}/inf.h5 --out {d}/x.h5",
       {"{d}/inf.h5", "/mocap/markers"}},  // 4
      {"markers", "mocap inspect {d}/notes.c3d", {"{d}/notes.c3d"}},
      {"markers",
       "mocap process --in {d}/outlier.h5 --out {d}/x.h5",
       {"{d}/outlier.h5", "/mocap/markers", "frame 2", "1e+20 m", "capture volume"}},  // 47: 6
      {"markers",
       "dataset inspect {d}/outlier.h5",
       {"{d}/outlier.h5", "/mocap/markers", "capture volume"}},  // 47: 6
      {"markers",
       "identify --data {d}/outlier1k.h5 --free mu --out {d}/f",
       {"{d}/outlier1k.h5", "/mocap/markers", "frame 5", "1000 m"}},  // 47: 6
      {"markers", "mocap process --in {d}/missing.c3d --out {d}/x.h5", {"{d}/missing.c3d"}},
      // Actuator logs and maps (dataset assemble, issue 27).
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/nodrum.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/nodrum.yaml", "line 4", "cables[0].drum_radius_m", "missing"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/unknowncol.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/log.csv", "line 1", "no column 'm7'", "cables[5].column"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/nanlog.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/nanlog.csv", "line 3", "column 'm3'", "not a finite number"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/backlog.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/backlog.csv", "line 4", "column 't_s'", "does not increase"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/gaplog.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/gaplog.csv", "line 3", "a gap of 5 s"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync sometimes --out {d}/x.h5",
       {"--sync", "sometimes"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/log.csv", "actuator log", "covers mocap time"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync trigger --out {d}/x.h5",
       {"{d}/map.yaml", "trigger", "missing"}},
      {"outputs",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/log.csv",
       {"{d}/log.csv", "--out", "input"}},
      // Output paths: nothing of the user's is replaced, no input written.
      {"outputs",
       "identify --data {d}/processed.h5 --free mu --out {d}/mine",
       {"{d}/mine", "--out", "not a ccsrm fit folder"}},  // 1
      {"outputs",
       "identify --data {d}/processed.h5 --free mu --out {d}/stub",
       {"{d}/stub", "--out", "'thesis.tex', which ccsrm did not write"}},  // 47: 3
      {"outputs",
       "report --in {d}/run.h5 --out {d}/noted_report",
       {"{d}/noted_report", "--out", "holds 'notes.txt', which ccsrm did not write"}},  // 47: 3
      {"outputs",
       "generate --config {d}/c.yaml --case 1 --duration 0.1 --out {d}/recorded.h5",
       {"{d}/recorded.h5", "--out", "not a generated ccsrm experiment"}},  // 47: 4
      // Issue 47, 8 and 9: empty values, NaN, out of range, given twice.
      {"overrides", "derivatives --sweep '' --duration 0.1", {"--sweep", "is empty"}},
      {"overrides", "simulate --config '' --out {d}/x.h5", {"--config", "is empty"}},
      {"overrides",
       "simulate --config {d}/c.yaml --output-rate nan --out {d}/x.h5",
       {"--output-rate", "nan"}},
      {"overrides",
       "generate --config {d}/c.yaml --noise-mm 1e9 --out {d}/g.h5",
       {"--noise-mm", "1e9"}},
      {"overrides", "generate --config {d}/c.yaml --seed -1 --out {d}/g.h5", {"--seed", "-1"}},
      {"overrides",
       "generate --config {d}/c.yaml --seed 99999999999999999999999 --out {d}/g.h5",
       {"--seed", "99999999999999999999999"}},
      {"overrides",
       "derivatives --config {d}/c.yaml --threads 100000 --duration 0.1",
       {"--threads", "100000"}},
      {"overrides",
       "simulate --config {d}/c.yaml --protocol {d}/proto.yaml@amplitude_deg=1,amplitude_deg=2 "
       "--out {d}/x.h5",
       {"amplitude_deg", "given twice"}},
      {"overrides",
       "identify --data {d}/processed.h5 {d}/./processed.h5 --free mu --out {d}/f",
       {"{d}/./processed.h5", "--data", "given twice"}},
      {"overrides",
       "loop --data {d}/processed.h5 --holdout {d}/processed.h5 --out {d}/l",
       {"{d}/processed.h5", "--holdout", "also in --data"}},
      // Issue 47, 7: actuator logs and maps.
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/mmlog.csv --actuator-map "
       "{d}/metres.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/mmlog.csv", "line 3, column 'm1'", "pulls cable 1 in by 17.7 m", "mm read as m"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/hugelog.csv --actuator-map "
       "{d}/mmlengths.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/hugelog.csv", "column 'm2'", "pulls cable 2 in by 1e+06 m"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/log.csv --actuator-map "
       "{d}/wrap2.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/wrap2.yaml", "cables[0].wrap_counts", "less than counts_per_turn"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/duplog.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/duplog.csv", "line 1", "column 'm3'", "appears twice"}},
      {"actuators",
       "dataset assemble --markers {d}/exp.h5 --actuators {d}/widelog.csv --actuator-map "
       "{d}/map.yaml --config {d}/c.yaml --sync offset=0 --out {d}/x.h5",
       {"{d}/widelog.csv", "line 3", "has 8 cells", "names 7 columns"}},
      // Issue 47, 9 and 10: runs that could not mean anything, or not end.
      {"overrides",
       "identify --data {d}/processed.h5 --free mu --max-iterations 0 --out {d}/f",
       {"--max-iterations", "is 0", "ccsrm predict"}},
      {"overrides",
       "loop --data {d}/processed.h5 --max-iterations 0 --out {d}/l",
       {"--max-iterations", "is 0"}},
      {"markers",
       "mocap process --in {d}/exp9.h5 --config {d}/c.yaml --out {d}/x.h5",
       {"{d}/exp9.h5", "/mocap/markers", "mm RMS", "not of this arm's marker set"}},
      {"overrides",
       "simulate --config {d}/c.yaml --protocol {d}/megahertz.yaml --out {d}/x.h5",
       {"{d}/megahertz.yaml", "frequency_hz", "1e+06 Hz is above the 50 Hz"}},
      {"overrides",
       "simulate --config {d}/c.yaml --protocol {d}/nested.yaml --duration 2 --out {d}/x.h5",
       {"{d}/nested.yaml", "times", "beyond the 100000"}},
      {"hdf5",
       "simulate --config {d}/c.yaml --inputs {d}/torn.csv --out {d}/x.h5",
       {"{d}/torn.csv", "line 3, column 'cable1_m'", "pulls cable 1 in by 10 m",
        "m of arm it runs through"}},
      {"hdf5",
       "simulate --config {d}/c.yaml --inputs {d}/jerk.csv --out {d}/x.h5",
       {"{d}/jerk.csv", "line 3, column 'cable2_m'", "moves at 5 m/s"}},
      // Issue 47, 11: configurations every run of which failed or never ended.
      {"configs", "config check {d}/hugeh.yaml", {"{d}/hugeh.yaml", "smoothing_step_s", "[0, 1]"}},
      {"configs",
       "config check {d}/hugealpha.yaml",
       {"{d}/hugealpha.yaml", "baumgarte_alpha_per_s", "1e+300"}},
      {"configs",
       "simulate --config {d}/hugeramp.yaml --out {d}/x.h5",
       {"{d}/hugeramp.yaml", "protocol.ramp_s", "[0, 100000]"}},
      // Issue 47, 12: one door per kind of file, at every command.
      {"hdf5",
       "report --in {d}/nanlength.h5 --out {d}/r",
       {"{d}/nanlength.h5", "/input/length_change", "finite"}},
      {"hdf5", "report --in {d}/badyaml.h5 --out {d}/r", {"{d}/badyaml.h5", "config_yaml"}},
      {"hdf5", "report --in {d}/one.h5 --out {d}/r", {"{d}/one.h5", "/mocap/time"}},
      {"hdf5",
       "dataset inspect {d}/nanrun.h5",
       {"{d}/nanrun.h5", "/input_length_change", "finite"}},
      {"hdf5",
       "dataset inspect {d}/noconfigrun.h5",
       {"{d}/noconfigrun.h5", "config_yaml", "empty"}},
      {"hdf5",
       "simulate --config {d}/c.yaml --inputs {d}/negmass.h5 --out {d}/x.h5",
       {"{d}/negmass.h5", "config_yaml", "link_mass_kg"}},
      {"hdf5",
       "simulate --config {d}/c.yaml --inputs {d}/badyaml.h5 --out {d}/x.h5",
       {"{d}/badyaml.h5", "config_yaml"}},
      // Issue 47, 13: messages that name the cause, on one line.
      {"overrides",
       "identify --data {d}/processed.h5 --free mu --resume --out {d}/cutfit",
       {"{d}/cutfit/checkpoint.json", "corrupt"}},
      {"markers", "mocap inspect {d}/flip.c3d", {"{d}/flip.c3d", "LAB\\x0ALS"}},
      {"markers",
       "mocap process --in {d}/outlier.c3d --config {d}/c.yaml --out {d}/x.h5",
       {"{d}/outlier.c3d", "at frame 0 has a coordinate of 1000 m", "capture volume"}},
      {"outputs",
       "loop --data {d}/processed.h5 --out {d}/mine",
       {"{d}/mine", "--out", "not a ccsrm loop folder"}},  // 1
      {"outputs",
       "predict --data {d}/processed.h5 --params {d}/p.yaml --out {d}/mine",
       {"{d}/mine", "--out", "not a ccsrm prediction folder"}},
      {"outputs",
       "predict --data {d}/processed.h5 --params {d}/p.yaml --out {d}",
       {"{d}", "--out", "holds the input"}},
      {"outputs",
       "report --in {d}/run.h5 --out {d}/mine",
       {"{d}/mine", "--out", "not a ccsrm report"}},
      {"outputs",
       "simulate --config {d}/c.yaml --out {d}/c.yaml",
       {"{d}/c.yaml", "--out", "input"}},  // 2
      {"outputs",
       "simulate --config {d}/c.yaml --params {d}/p.yaml --out {d}/p.yaml",
       {"{d}/p.yaml", "--out", "input"}},  // 2
      {"outputs",
       "generate --config {d}/c.yaml --out {d}/c.yaml",
       {"{d}/c.yaml", "--out", "input"}},
      {"outputs",
       "mocap process --in {d}/exp.h5 --out {d}/exp.h5",
       {"{d}/exp.h5", "--out", "input"}},
      {"outputs",
       "identify --data {d}/processed.h5 --out {d}",
       {"{d}", "--out", "holds the input"}},
      {"outputs", "report --in {d}/run.h5 --out {d}/run.h5", {"{d}/run.h5", "--out"}},
      {"outputs",
       "simulate --config {d}/c.yaml --out {d}/notes.h5",
       {"{d}/notes.h5", "not a ccsrm run file"}},
      {"outputs",
       "simulate --config {d}/c.yaml --out {d}/processed.h5",
       {"{d}/processed.h5", "not a ccsrm run file"}},
      {"outputs", "simulate --config {d}/c.yaml --out {d}/mine", {"{d}/mine", "folder"}},
      {"outputs",
       "simulate --config {d}/c.yaml --out {d}/nowhere/run.h5",
       {"{d}/nowhere/run.h5", "does not exist"}},
      {"outputs",
       "mocap export --in {d}/exp.h5 --out {d}/notes.c3d",
       {"{d}/notes.c3d", "not a C3D file"}},
      {"outputs",
       "derivatives --config {d}/c.yaml --duration 0.1 --json {d}/c.yaml",
       {"{d}/c.yaml", "--json"}},
      {"outputs", "cameras rig --out {d}/c.yaml", {"{d}/c.yaml", "not a camera file"}},
      {"outputs",
       "mocap rigid-bodies --config {d}/c.yaml --out {d}/p.yaml",
       {"{d}/p.yaml", "not a rigid-bodies file"}},
  };
  return rows;
}

TEST_F(BadInputTable, EveryRowExitsTwoWithOneLineAndLeavesTheFolderAsItWas) {
  std::map<std::string, int> per_class;
  const auto start = std::chrono::steady_clock::now();
  for (const BadInput& row : Rows()) {
    const std::string args = Expand(row.args, dir_);
    SCOPED_TRACE(row.input_class + ": ccsrm " + args);
    const auto before = Snapshot(dir_);
    const Outcome o = RunCcsrm(args);
    EXPECT_EQ(o.status, 2) << o.all();
    EXPECT_EQ(ccsrm::testing::CountLines(o.err), 1) << o.err;
    EXPECT_EQ(o.err.rfind("ccsrm: ", 0), 0u) << o.err;
    for (const std::string& name : row.names) {
      EXPECT_THAT(o.err, HasSubstr(Expand(name, dir_)));
    }
    const auto after = Snapshot(dir_);
    EXPECT_EQ(Differences(before, after), "") << "the folder changed";
    for (const auto& [name, state] : after) {  // so that the next rows start alike
      if (before.count(name) == 0) fs::remove_all(dir_ / name);
    }
    ++per_class[row.input_class];
  }
  std::string counts;
  for (const auto& [name, n] : per_class) counts += " " + name + " " + std::to_string(n);
  std::printf("bad-input table: %zu rows (%s ), %.1f s\n", Rows().size(), counts.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

// The other half of the policy: a command replaces its own earlier output,
// and removes what a killed run left beside it.
TEST_F(BadInputTable, OwnOutputsAreReplacedAndAKilledRunsTemporariesRemoved) {
  const fs::path d = ccsrm::testing::ScratchDirectory("bad_input_table_own");
  const std::string run = (d / "run.h5").string();
  const std::string simulate =
      "simulate --config " + Paper() + " --case 1 --duration 0.1 --quiet --out " + run;
  ASSERT_EQ(RunCcsrm(simulate).status, 0);
  // A run killed by SIGKILL while writing left this (its pid is above any
  // Linux pid_max, so no process has it).
  const std::string stale = run + ".tmp-2147483646-0";
  Write(stale, "half a run");
  const Outcome again = RunCcsrm(simulate);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);
}

// `ccsrm <args>` started with exec and interrupted with `signal_number`
// `delay` after its first progress line on stderr (so that the program is
// at work, past its start). False, with *why, when the premise of the test
// did not hold: the command printed nothing within 120 s (a guard against a
// hung test, not a speed) or ended by itself before the signal.
bool RunAndInterrupt(const std::string& args, std::chrono::milliseconds delay, int signal_number,
                     int* status, std::string* err, std::string* why) {
  const std::string err_path =
      (fs::temp_directory_path() / ("ccsrm_interrupt_" + std::to_string(::getpid()) + ".err"))
          .string();
  fs::remove(err_path);
  const std::string command =
      "exec " + std::string(CCSRM_PROGRAM) + " " + args + " >/dev/null 2>" + err_path;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto started = [&err_path] {
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(err_path, ec);
    return !ec && size > 0;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool ended_by_itself = false;
  while (!started() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!started()) *why = "it printed no progress within 120 s";
  std::this_thread::sleep_for(delay);
  // Still at work? A command that ended before the signal tests nothing.
  if (::waitpid(pid, status, WNOHANG) == pid) {
    ended_by_itself = true;
  } else {
    ::kill(pid, signal_number);
    ::waitpid(pid, status, 0);
  }
  *err = ccsrm::ReadTextFile(err_path);
  fs::remove(err_path);
  if (ended_by_itself) {
    *why = "it ended by itself (status " + std::to_string(WEXITSTATUS(*status)) +
           ") before the signal: give it more work";
  }
  return why->empty();
}

// Interrupts at several moments of a run, a fit, a loop, a design and a
// generated experiment: whatever the moment, the process ends by the signal
// and the output folder holds no temporary and no output, only what --resume
// continues from.
TEST_F(BadInputTable, InterruptsLeaveNoTemporaries) {
  const fs::path d = ccsrm::testing::ScratchDirectory("bad_input_table_interrupt");
  // Work that lasts far beyond the latest signal on any machine: 600 s of
  // case 2 (minutes at the simulator's 25x real time), and a fit of four
  // parameters over the bundled 48 s sample (five 48 s runs an iteration).
  // Each is signalled about a second after it starts, so its length costs
  // nothing; RunAndInterrupt still checks that it was at work.
  const std::string sample = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/train1.h5";
  const std::vector<std::pair<std::string, int>> commands = {
      {"simulate --config " + Paper() + " --case 2 --duration 600 --out " + (d / "run.h5").string(),
       SIGINT},
      {"identify --data " + sample + " --free mu,mu_c,T_p,c_sc --max-iterations 100 --threads 2 " +
           "--out " + (d / "fit").string(),
       SIGTERM},
  };
  // Issue 47: the other writing commands, each with one of the signals a
  // user or a scheduler sends.
  const std::string protocols = std::string(CCSRM_SOURCE_DIR) + "/configs/protocols/";
  const std::vector<std::pair<std::string, int>> more = {
      {"loop --data " + sample + " --max-rounds 3 --threads 2 --out " + (d / "loop").string(),
       SIGINT},
      {"design --free mu,mu_c,T_p --plans " + protocols + "paper.yaml " + protocols +
           "fast-reversals.yaml --threads 2 --out " + (d / "design").string(),
       SIGTERM},
      {"generate --config " + Paper() + " --case 2 --duration 600 --out " + (d / "gen.h5").string(),
       SIGTERM},
  };
  std::vector<std::pair<std::string, int>> all = commands;
  all.insert(all.end(), more.begin(), more.end());
  for (const auto& [args, signal_number] : all) {
    for (const int ms : {300, 900}) {
      SCOPED_TRACE(args + " interrupted after " + std::to_string(ms) + " ms");
      int status = 0;
      std::string err, why;
      ASSERT_TRUE(
          RunAndInterrupt(args, std::chrono::milliseconds(ms), signal_number, &status, &err, &why))
          << why << ": " << err;
      ASSERT_TRUE(WIFSIGNALED(status)) << "exited with " << WEXITSTATUS(status) << ": " << err;
      EXPECT_EQ(WTERMSIG(status), signal_number);
      EXPECT_THAT(err, HasSubstr("ccsrm: interrupted")) << err;
      // What --resume continues from is kept by design: a folder with the
      // job's checkpoint.json and runs.journal (docs/cluster.md).
      std::string left;
      for (const fs::directory_entry& e : fs::recursive_directory_iterator(d)) {
        const std::string name = e.path().filename().string();
        if (e.is_directory() && e.path().parent_path() == d &&
            name.find(".tmp-") == std::string::npos)
          continue;
        if (name == "checkpoint.json" || name == "runs.journal") continue;
        left += " " + fs::relative(e.path(), d).string();
      }
      EXPECT_EQ(left, "") << "an interrupted command left this in " << d;
      fs::remove_all(d);
      fs::create_directories(d);
    }
  }
}

// SIGKILL cannot be caught: a killed command leaves its temporaries and what
// --resume continues from (checkpoint.json, runs.journal), never an output
// half-written under its final name (every output is renamed into place
// whole); the next command into the same place removes the temporaries (the
// test above).
TEST_F(BadInputTable, AKilledCommandLeavesNoOutputUnderItsFinalName) {
  const fs::path d = ccsrm::testing::ScratchDirectory("bad_input_table_killed");
  const std::string sample = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/train1.h5";
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"identify --data " + sample + " --free mu,mu_c,T_p --threads 2 --out " +
           (d / "fit").string(),
       "fit"},
      {"loop --data " + sample + " --threads 2 --out " + (d / "loop").string(), "loop"},
      {"generate --config " + Paper() + " --case 2 --duration 600 --out " + (d / "gen.h5").string(),
       "gen.h5"},
  };
  for (const auto& [args, output] : commands) {
    SCOPED_TRACE(args);
    int status = 0;
    std::string err, why;
    ASSERT_TRUE(RunAndInterrupt(args, std::chrono::milliseconds(600), SIGKILL, &status, &err, &why))
        << why << ": " << err;
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    const auto left_by_design = [&d](const fs::path& p) {
      const std::string name = p.filename().string();
      return fs::relative(p, d).string().find(".tmp-") != std::string::npos ||
             name == "checkpoint.json" || name == "runs.journal";
    };
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(d)) {
      if (e.path() == d / output && e.is_directory()) continue;  // the resumable folder
      EXPECT_TRUE(left_by_design(e.path())) << "a killed command left " << e.path();
    }
    fs::remove_all(d);
    fs::create_directories(d);
  }
}

}  // namespace
