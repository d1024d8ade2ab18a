// Experiment files (ccsrm-dataset/1) and marker files (C3D, TRC, Nexus and
// Motive CSV, our HDF5 files): ccsrm.read_dataset, ccsrm.read_markers,
// ccsrm.write_c3d.
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/marker_table.h"

namespace ccsrm::python {
namespace {

using datasets::ExperimentFile;
using mocap::MarkerTable;

py::object OptionalView(const std::optional<datasets::Array>& array, const py::object& self) {
  return array ? py::object(View(*array, self)) : py::object(py::none());
}

MarkerTable TableFromArrays(const py::object& positions, const std::vector<std::string>& labels,
                            double rate_hz) {
  auto p = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(positions);
  if (!p || p.ndim() != 3 || p.shape(2) != 3 ||
      p.shape(1) != static_cast<py::ssize_t>(labels.size())) {
    ThrowInputError("positions", "",
                    "expected an array of frames x " + std::to_string(labels.size()) +
                        " markers (one per label) x 3 [m]");
  }
  MarkerTable table;
  table.Reset(static_cast<std::size_t>(p.shape(0)), labels, false);
  std::copy(p.data(), p.data() + p.size(), table.positions_m.begin());
  table.rate_hz = rate_hz;
  table.units_in_file = "m";
  return table;
}

}  // namespace

void AddData(py::module_& m) {
  py::class_<ExperimentFile, std::shared_ptr<ExperimentFile>>(
      m, "Dataset",
      "A ccsrm-dataset/1 experiment file (datasets/README.md): N input samples, F mocap "
      "frames, M markers, J joints, C cables. Arrays are read-only views (no copy).")
      .def_readonly("name", &ExperimentFile::name)
      .def_readonly("description", &ExperimentFile::description)
      .def_readonly("created", &ExperimentFile::created)
      .def_property_readonly(
          "source",
          [](const ExperimentFile& e) { return datasets::ExperimentSourceName(e.source); })
      .def_readonly("config_yaml", &ExperimentFile::config_yaml)
      .def_readonly("protocol_yaml", &ExperimentFile::protocol_yaml)
      .def_readonly("inputs_file", &ExperimentFile::inputs_file)
      .def_readonly("marker_names", &ExperimentFile::marker_names)
      .def_property_readonly(
          "input_time",
          [](py::object self) { return View(self.cast<ExperimentFile&>().input_time, self); },
          "N [s].")
      .def_property_readonly(
          "input_length_change",
          [](py::object self) {
            return View(self.cast<ExperimentFile&>().input_length_change, self);
          },
          "N x C: pulled-in length [m].")
      .def_property_readonly(
          "mocap_time",
          [](py::object self) { return View(self.cast<ExperimentFile&>().mocap_time, self); },
          "F [s].")
      .def_property_readonly(
          "mocap_markers",
          [](py::object self) { return View(self.cast<ExperimentFile&>().mocap_markers, self); },
          "F x M x 3 [m]; NaN where not seen.")
      .def_property_readonly(
          "measured_joint_angles",
          [](py::object self) {
            return OptionalView(self.cast<ExperimentFile&>().measured_joint_angles, self);
          },
          "F x J x 2 [rad], or None when the file has none.")
      .def_property_readonly(
          "measured_input_tension",
          [](py::object self) {
            return OptionalView(self.cast<ExperimentFile&>().measured_input_tension, self);
          },
          "N x C [N], or None.")
      .def_property_readonly(
          "measured_link_pose",
          [](py::object self) {
            return OptionalView(self.cast<ExperimentFile&>().measured_link_pose, self);
          },
          "F x L x 7, or None.")
      .def_property_readonly(
          "measured_joint_twist",
          [](py::object self) {
            return OptionalView(self.cast<ExperimentFile&>().measured_joint_twist, self);
          },
          "F x J [rad], or None.")
      .def("__repr__", [](const ExperimentFile& e) {
        return "<ccsrm.Dataset '" + e.name + "': " + std::to_string(e.input_time.rows()) +
               " input samples, " + std::to_string(e.mocap_time.rows()) + " mocap frames>";
      });

  m.def(
      "read_dataset",
      [](const py::object& path) {
        const std::string file = PathString(path);
        py::gil_scoped_release release;
        return std::make_shared<ExperimentFile>(datasets::ReadExperimentFile(file));
      },
      py::arg("path"), "Reads and checks a ccsrm-dataset/1 experiment file.");

  py::class_<MarkerTable, std::shared_ptr<MarkerTable>>(
      m, "MarkerTable", "Marker trajectories in metres, as read from a motion-capture file.")
      .def_readonly("labels", &MarkerTable::labels)
      .def_property_readonly(
          "positions",
          [](py::object self) {
            const auto& t = self.cast<MarkerTable&>();
            return View(t.positions_m.data(), {t.frames(), t.markers(), 3}, self);
          },
          "frames x markers x 3 [m]; NaN where a marker was not seen (a read-only view).")
      .def_readonly("rate_hz", &MarkerTable::rate_hz)
      .def_readonly("first_frame_number", &MarkerTable::first_frame_number)
      .def_readonly("format", &MarkerTable::format)
      .def_readonly("units_in_file", &MarkerTable::units_in_file)
      .def_readonly("up_axis", &MarkerTable::up_axis)
      .def_readonly("warnings", &MarkerTable::warnings,
                    "What the reader tolerated (a header count that disagrees with the data, ...).")
      .def_property_readonly("frames", &MarkerTable::frames)
      .def_property_readonly("markers", &MarkerTable::markers)
      .def("__repr__", [](const MarkerTable& t) {
        return "<ccsrm.MarkerTable " + t.format + ": " + std::to_string(t.frames()) + " frames, " +
               std::to_string(t.markers()) + " markers>";
      });

  m.def(
      "read_markers",
      [](const py::object& path) {
        const std::string file = PathString(path);
        py::gil_scoped_release release;
        return std::make_shared<MarkerTable>(mocap::ReadMarkerFile(file));
      },
      py::arg("path"),
      "Reads a marker file by its extension: .c3d, .trc, .csv (Vicon Nexus or OptiTrack "
      "Motive), .h5 (an experiment's /mocap/markers or a run's /markers).");

  m.def(
      "write_c3d",
      [](const py::object& path, const py::object& positions,
         const std::vector<std::string>& labels, double rate_hz, const std::string& units) {
        const std::string file = PathString(path);
        MarkerTable table = TableFromArrays(positions, labels, rate_hz);
        mocap::C3dWriteOptions options;
        options.units = units;
        std::string error;
        if (!options.IsValid(&error)) ThrowInputError("units", "", error);
        py::gil_scoped_release release;
        mocap::WriteC3d(file, table, options);
      },
      py::arg("path"), py::arg("positions"), py::arg("labels"), py::arg("rate_hz"),
      py::arg("units") = "mm",
      "Writes markers (frames x markers x 3 [m], NaN = not seen) as an Intel float C3D file.");
  m.def(
      "write_c3d",
      [](const py::object& path, const MarkerTable& table, const std::string& units) {
        const std::string file = PathString(path);
        mocap::C3dWriteOptions options;
        options.units = units;
        std::string error;
        if (!options.IsValid(&error)) ThrowInputError("units", "", error);
        py::gil_scoped_release release;
        mocap::WriteC3d(file, table, options);
      },
      py::arg("path"), py::arg("table"), py::arg("units") = "mm",
      "Writes a MarkerTable (e.g. from read_markers) as an Intel float C3D file.");
}

}  // namespace ccsrm::python
