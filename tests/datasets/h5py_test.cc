// The files are a public contract for Python users: h5py (the same library
// they use) must see the documented paths, shapes, dtypes, units and
// attributes. Skipped when /usr/bin/python3 has no h5py.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"
#include "test_util.h"

namespace ccsrm::datasets {
namespace {
using ::ccsrm::datasets::testing::FreshDir;
using ::ccsrm::datasets::testing::MakeExperimentFile;
using ::ccsrm::datasets::testing::MakeRunFile;

constexpr const char* kPython = "/usr/bin/python3";

// Checks the documented layout generically (T, J, C, ... read from the
// arrays, as a user would) and prints what it saw.
constexpr const char* kScript = R"PY(
import sys
import h5py
import numpy as np

def check(cond, what):
    if not cond:
        print("FAILED:", what)
        sys.exit(1)

def dataset(f, path, units, shape):
    check(path in f, path + " present")
    d = f[path]
    check(d.dtype == np.dtype("<f8"), path + " is little-endian float64, got " + str(d.dtype))
    check(d.shape == shape, path + " shape " + str(d.shape) + " expected " + str(shape))
    check(d.attrs["units"] == units, path + " units " + repr(d.attrs["units"]))
    print("  %-36s %-14s %s" % (path, "x".join(map(str, d.shape)), units))
    return d[()]

def strings(f, path, n):
    names = [s.decode("utf-8") if isinstance(s, bytes) else s for s in f[path].asstr()[()]]
    check(len(names) == n, path + " has " + str(n) + " names")
    print("  %-36s %-14s %s" % (path, str(n), names))
    return names

run_path, exp_path = sys.argv[1], sys.argv[2]
with h5py.File(run_path, "r") as f:
    print("run:", run_path)
    for key in ["schema", "case", "config_yaml", "created", "ccsrm_version", "status",
                "status_message"]:
        check(isinstance(f.attrs[key], str), key + " is a str")
    check(f.attrs["schema"] == "ccsrm-run/1", "schema")
    print("  attrs:", {k: (v if k != "config_yaml" else "%d lines" % len(v.splitlines()))
                       for k, v in f.attrs.items()})
    check(isinstance(f.attrs["wall_time_s"], np.floating), "wall_time_s is float")
    for key in ["steps", "rejected_steps", "rhs_evaluations"]:
        check(f.attrs[key].dtype == np.int64, key + " is int64")
    t = dataset(f, "/time", "s", f["/time"].shape)
    T = len(t)
    J = f["/joint_angles"].shape[1]
    L = f["/link_pose"].shape[1]
    C = f["/input_tension"].shape[1]
    angles = dataset(f, "/joint_angles", "rad", (T, J, 2))
    dataset(f, "/joint_rates", "rad/s", (T, J, 2))
    dataset(f, "/link_pose", "m, 1", (T, L, 7))
    dataset(f, "/input_tension", "N", (T, C))
    dataset(f, "/input_length_change", "m", (T, C))
    dataset(f, "/stuck_nodes", "1", (T, C))
    check(sorted(f["/cables"].keys(), key=int) == [str(k) for k in range(1, C + 1)], "cables 1..C")
    for k in range(1, C + 1):
        E = f["/cables/%d/tension" % k].shape[1]
        H = f["/cables/%d/stuck" % k].shape[1]
        dataset(f, "/cables/%d/tension" % k, "N", (T, E))
        dataset(f, "/cables/%d/stuck" % k, "1", (T, H))
        dataset(f, "/cables/%d/slip_velocity" % k, "m/s", (T, H))
    dataset(f, "/diagnostics/constraint_violation", "mixed", (T,))
    dataset(f, "/diagnostics/energy", "J", (T, 3))
    M = f["/markers"].shape[1]
    dataset(f, "/markers", "m", (T, M, 3))
    strings(f, "/marker_names", M)
    # Row-major as documented: angles[i, j, 0] is theta_x of joint j+1 at frame i.
    check(angles[1, 2, 1] == 1.0 + 0.37 * ((1 * J + 2) * 2 + 1), "row-major order")
    print("  theta_x of joint 1 in degrees:", np.degrees(angles[:, 0, 0]))

with h5py.File(exp_path, "r") as f:
    print("experiment:", exp_path)
    for key in ["schema", "name", "description", "created", "source", "config_yaml"]:
        check(isinstance(f.attrs[key], str), key + " is a str")
    check(f.attrs["schema"] == "ccsrm-dataset/1", "schema")
    check(f.attrs["source"] in ("recorded", "generated"), "source")
    print("  attrs:", {k: (v if k != "config_yaml" else "%d lines" % len(v.splitlines()))
                       for k, v in f.attrs.items()})
    N = f["/input/time"].shape[0]
    C = f["/input/length_change"].shape[1]
    F = f["/mocap/time"].shape[0]
    M = f["/mocap/markers"].shape[1]
    dataset(f, "/input/time", "s", (N,))
    dataset(f, "/input/length_change", "m", (N, C))
    dataset(f, "/mocap/time", "s", (F,))
    markers = dataset(f, "/mocap/markers", "m", (F, M, 3))
    names = strings(f, "/mocap/marker_names", M)
    print("  unseen marker samples (NaN):", int(np.isnan(markers).sum()))
    check(np.isnan(markers).any(), "NaN marks unseen markers")
    for body in f["/mocap/rigid_bodies"]:
        base = "/mocap/rigid_bodies/" + body
        k = len(f[base + "/marker_names"])
        body_names = strings(f, base + "/marker_names", k)
        check(set(body_names) <= set(names), body + " markers listed")
        dataset(f, base + "/local_position", "m", (k, 3))
    J = f["/measured/joint_angles"].shape[1]
    dataset(f, "/measured/joint_angles", "rad", (F, J, 2))
    dataset(f, "/measured/input_tension", "N", (N, C))
    for q in f["/mocap/quality"]:
        d = f["/mocap/quality/" + q]
        print("  %-36s %-14s %s" % (d.name, "x".join(map(str, d.shape)), d.attrs["units"]))
print("OK")
)PY";

TEST(H5pyReadsTheDocumentedLayout, RunAndExperimentFiles) {
  const std::string probe = std::string(kPython) + " -c 'import h5py' > /dev/null 2>&1";
  if (std::system(probe.c_str()) != 0) {
    GTEST_SKIP() << kPython << " cannot import h5py (install python3-h5py to run this test)";
  }
  const auto dir = FreshDir("h5py");
  const std::string run = (dir / "run.h5").string();
  const std::string experiment = (dir / "exp.h5").string();
  const std::string script = (dir / "check_layout.py").string();
  WriteRunFile(run, MakeRunFile());
  WriteExperimentFile(experiment, MakeExperimentFile());
  std::ofstream(script) << kScript;

  const std::string command =
      std::string(kPython) + " " + script + " " + run + " " + experiment + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
  const int status = pclose(pipe);
  std::cout << output;
  EXPECT_EQ(status, 0) << output;
  EXPECT_NE(output.find("\nOK\n"), std::string::npos) << output;
}

}  // namespace
}  // namespace ccsrm::datasets
