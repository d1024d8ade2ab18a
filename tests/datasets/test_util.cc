#include "test_util.h"

#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "ccsrm/common/error.h"

namespace ccsrm::datasets::testing {
namespace fs = std::filesystem;
namespace {

// Test setup failures are bugs of the test: report them loudly.
hid_t Check(hid_t id, const char* what) {
  if (id < 0) throw std::runtime_error(std::string("test HDF5 surgery failed: ") + what);
  return id;
}

// Opens a file read-write for the duration of one surgery.
class OpenForEdit {
 public:
  explicit OpenForEdit(const std::string& file) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    id_ = Check(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), "H5Fopen");
  }
  ~OpenForEdit() { H5Fclose(id_); }
  hid_t id() const { return id_; }

 private:
  hid_t id_;
};

void WriteStringAttribute(hid_t object, const std::string& name, const std::string& value,
                          bool fixed_length) {
  if (H5Aexists(object, name.c_str()) > 0) Check(H5Adelete(object, name.c_str()), "H5Adelete");
  const hid_t type = Check(H5Tcopy(H5T_C_S1), "H5Tcopy");
  Check(H5Tset_size(type, fixed_length ? value.size() + 1 : H5T_VARIABLE), "H5Tset_size");
  Check(H5Tset_cset(type, fixed_length ? H5T_CSET_ASCII : H5T_CSET_UTF8), "H5Tset_cset");
  const hid_t space = Check(H5Screate(H5S_SCALAR), "H5Screate");
  const hid_t attribute =
      Check(H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "H5Acreate2");
  const char* text = value.c_str();
  Check(H5Awrite(attribute, type,
                 fixed_length ? static_cast<const void*>(text) : static_cast<const void*>(&text)),
        "H5Awrite");
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(type);
}

}  // namespace

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ccsrm_datasets_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> DirectoryEntries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

Array Ramp(std::vector<std::size_t> shape, double offset) {
  Array array(std::move(shape));
  for (std::size_t i = 0; i < array.size(); ++i) array.values[i] = offset + 0.37 * i;
  return array;
}

RunFile MakeRunFile(const RunSizes& sizes) {
  const std::size_t t = sizes.frames;
  const std::size_t c = sizes.elements.size();
  RunFile run;
  run.case_name = "3";
  run.config_yaml = "arm:\n  joints: 12\nfriction:\n  mu: 0.12  # µ, UTF-8 survives\n";
  run.created = "2026-01-02T03:04:05Z";
  run.ccsrm_version = "0.1.0-test";
  run.wall_time_s = 12.625;
  run.steps = 4321;
  run.rejected_steps = 17;
  run.rhs_evaluations = std::int64_t{1} << 40;  // beyond 32 bits
  run.status = RunStatus::kDiverged;
  run.status_message = "constraint violation 3.2e-3 above bound 1e-3 at t = 0.05 s";

  run.time = Array({t});
  for (std::size_t i = 0; i < t; ++i) run.time.at(i) = (static_cast<double>(i) - 2.0) * 0.01;
  run.joint_angles = Ramp({t, sizes.joints, 2}, 1.0);
  run.joint_rates = Ramp({t, sizes.joints, 2}, 2.0);
  run.link_pose = Ramp({t, sizes.links, 7}, 3.0);
  run.input_tension = Ramp({t, c}, 4.0);
  run.input_length_change = Ramp({t, c}, -5.0);
  run.stuck_nodes = Ramp({t, c}, 6.0);
  for (std::size_t k = 0; k < c; ++k) {
    CableRecord cable;
    cable.tension = Ramp({t, sizes.elements[k]}, 100.0 * (k + 1));
    cable.stuck = Ramp({t, sizes.holes[k]}, 200.0 * (k + 1));
    cable.slip_velocity = Ramp({t, sizes.holes[k]}, -300.0 * (k + 1));
    run.cables.push_back(cable);
  }
  run.constraint_violation = Ramp({t}, 1e-9);
  run.energy = Ramp({t, 3}, 7.0);
  // Extremes a sloppy conversion would damage.
  run.energy.values[0] = std::numeric_limits<double>::denorm_min();
  run.energy.values[1] = -0.0;
  run.energy.values[2] = std::numeric_limits<double>::max();
  if (sizes.markers > 0) {
    run.markers = Ramp({t, sizes.markers, 3}, 8.0);
    run.markers->values[4] = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t m = 0; m < sizes.markers; ++m) {
      run.marker_names.push_back("L" + std::to_string(m + 1) + "_marker");
    }
  }
  return run;
}

RunFile MakePaperSizedRunFile() {
  RunSizes sizes;
  sizes.frames = 4801;
  sizes.joints = 12;
  sizes.links = 12;
  sizes.elements = std::vector<std::size_t>(6, 12);
  sizes.holes = std::vector<std::size_t>(6, 11);
  sizes.markers = 0;
  return MakeRunFile(sizes);
}

ExperimentFile MakeExperimentFile() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ExperimentFile experiment;
  experiment.name = "bench-2026-03-case2-plus6";
  experiment.description = "+6° ramp, friction on all cables — recorded with 8 cameras";
  experiment.created = "2026-03-04T05:06:07Z";
  experiment.source = ExperimentSource::kGenerated;
  experiment.config_yaml = "arm:\n  joints: 12\n";

  const std::size_t n = 9, f = 6, c = 3, m = 4;
  experiment.input_time = Array({n});
  for (std::size_t i = 0; i < n; ++i) experiment.input_time.at(i) = 0.005 * static_cast<double>(i);
  experiment.input_length_change = Ramp({n, c}, -0.5);
  experiment.mocap_time = Array({f});
  for (std::size_t i = 0; i < f; ++i)
    experiment.mocap_time.at(i) = 0.01 * static_cast<double>(i) + 0.001;
  experiment.mocap_markers = Ramp({f, m, 3}, 0.25);
  // Marker 2 unseen in frames 1-2; marker 0 unseen in the last frame.
  for (std::size_t axis = 0; axis < 3; ++axis) {
    experiment.mocap_markers.at(1, 2, axis) = nan;
    experiment.mocap_markers.at(2, 2, axis) = nan;
    experiment.mocap_markers.at(f - 1, 0, axis) = nan;
  }
  experiment.marker_names = {"base_a", "base_b", "link1_a", "link1_b"};
  experiment.rigid_bodies = {
      {"base", {"base_a", "base_b"}, Ramp({2, 3}, -0.01)},
      {"link1", {"link1_a", "link1_b"}, Ramp({2, 3}, 0.02)},
  };
  experiment.mocap_quality["fit_rms"] = Ramp({f, 2}, 1e-4);
  experiment.mocap_quality_units["fit_rms"] = "m";
  experiment.measured_joint_angles = Ramp({f, 2, 2}, 0.001);
  experiment.measured_input_tension = Ramp({n, c}, 95.0);
  return experiment;
}

bool Identical(const Array& a, const Array& b) {
  if (a.shape != b.shape || a.values.size() != b.values.size()) return false;
  return a.values.empty() ||
         std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0;
}

std::string InputErrorMessage(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("(other exception: ") + error.what() + ")";
  }
  return "(no exception)";
}

void DeleteObject(const std::string& file, const std::string& path) {
  OpenForEdit edit(file);
  Check(H5Ldelete(edit.id(), path.c_str(), H5P_DEFAULT), "H5Ldelete");
}

void ReplaceDataset(const std::string& file, const std::string& path, const Array& array,
                    const std::optional<std::string>& units, bool store_as_integer) {
  OpenForEdit edit(file);
  if (H5Lexists(edit.id(), path.c_str(), H5P_DEFAULT) > 0) {
    Check(H5Ldelete(edit.id(), path.c_str(), H5P_DEFAULT), "H5Ldelete");
  }
  std::vector<hsize_t> dims(array.shape.begin(), array.shape.end());
  const hid_t space =
      Check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "H5Screate");
  const hid_t lcpl = Check(H5Pcreate(H5P_LINK_CREATE), "H5Pcreate");
  Check(H5Pset_create_intermediate_group(lcpl, 1), "intermediate groups");
  const hid_t dataset =
      Check(H5Dcreate2(edit.id(), path.c_str(), store_as_integer ? H5T_STD_I32LE : H5T_IEEE_F64LE,
                       space, lcpl, H5P_DEFAULT, H5P_DEFAULT),
            "H5Dcreate2");
  double dummy = 0.0;
  Check(H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                 array.values.empty() ? &dummy : array.values.data()),
        "H5Dwrite");
  if (units) WriteStringAttribute(dataset, "units", *units, false);
  H5Dclose(dataset);
  H5Pclose(lcpl);
  H5Sclose(space);
}

void SetUnits(const std::string& file, const std::string& path,
              const std::optional<std::string>& units) {
  OpenForEdit edit(file);
  const hid_t object = Check(H5Oopen(edit.id(), path.c_str(), H5P_DEFAULT), "H5Oopen");
  if (units) {
    WriteStringAttribute(object, "units", *units, false);
  } else {
    Check(H5Adelete(object, "units"), "H5Adelete");
  }
  H5Oclose(object);
}

void SetRootString(const std::string& file, const std::string& name, const std::string& value,
                   bool fixed_length) {
  OpenForEdit edit(file);
  const hid_t root = Check(H5Gopen2(edit.id(), "/", H5P_DEFAULT), "H5Gopen2");
  WriteStringAttribute(root, name, value, fixed_length);
  H5Gclose(root);
}

void DeleteRootAttribute(const std::string& file, const std::string& name) {
  OpenForEdit edit(file);
  const hid_t root = Check(H5Gopen2(edit.id(), "/", H5P_DEFAULT), "H5Gopen2");
  Check(H5Adelete(root, name.c_str()), "H5Adelete");
  H5Gclose(root);
}

}  // namespace ccsrm::datasets::testing
