// Experiment files (ccsrm-dataset/1) and marker files (C3D, TRC, Nexus and
// Motive CSV, our HDF5 files): ccsrm.read_dataset, ccsrm.read_markers,
// ccsrm.write_c3d, and the mocap pipeline (ccsrm.process_markers).
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/output_kinds.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_io.h"
#include "ccsrm/mocap/marker_table.h"
#include "ccsrm/mocap/recording.h"

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

// The pipeline's outcome: the experiment it made and its quality summary.
struct Processed {
  std::shared_ptr<ExperimentFile> dataset;
  mocap::ProcessingSummary summary;
};

// The Dataset class: an experiment file's attributes and read-only arrays.
void AddDatasetClass(py::module_& m) {
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
      .def_property_readonly(
          "motion", [](const ExperimentFile& e) { return datasets::RecordedMotionName(e.motion); },
          "'continuous' or 'settled_poses' (each row a settled pose of a pose log).")
      .def_property_readonly(
          "marker_frame",
          [](const ExperimentFile& e) { return datasets::MarkerFrameName(e.marker_frame); },
          "'world' or 'capture' (placement relative to the arm unknown).")
      .def_readonly("input_labels", &ExperimentFile::input_labels,
                    "N pattern labels of the inputs ([] when the file has none).")
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
}

}  // namespace

void AddData(py::module_& m) {
  AddDatasetClass(m);
  py::class_<Processed>(m, "ProcessedRecording",
                        "What the mocap pipeline made of a recording (ccsrm.process_markers).")
      .def_readonly("dataset", &Processed::dataset,
                    "The experiment: markers, inputs, measured joint angles, link poses.")
      .def("brief_report", [](const Processed& p) { return p.summary.BriefReport(); })
      .def(
          "full_report", [](const Processed& p) { return p.summary.FullReport(); },
          "The quality figures `ccsrm mocap process` prints.")
      .def_property_readonly("warnings", [](const Processed& p) { return p.summary.warnings; })
      .def(
          "write",
          [](const Processed& p, const py::object& path, bool overwrite) {
            const std::string file = PathString(path);
            CheckWriterPath(file, datasets::ExperimentFileOutput(), overwrite);
            py::gil_scoped_release release;
            datasets::WriteExperimentFile(file, *p.dataset);
          },
          py::arg("path"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the experiment as `ccsrm mocap process --out` does, under its output policy: "
          "an existing file is replaced only when it is an experiment, or with overwrite=True.");

  m.def(
      "process_markers",
      [](const py::object& in, const py::object& config, const py::object& rigid_bodies,
         const py::object& static_trial, const py::object& inputs, const std::string& name) {
        mocap::RecordingRequest request;
        request.in = PathString(in);
        if (!config.is_none()) request.config = PathString(config);
        if (!rigid_bodies.is_none()) request.rigid_bodies = PathString(rigid_bodies);
        if (!static_trial.is_none()) request.static_trial = PathString(static_trial);
        if (!inputs.is_none()) request.inputs = PathString(inputs);
        request.name = name;
        std::string error;
        if (!request.IsValid(&error)) ThrowInputError("process_markers", "", error);
        py::gil_scoped_release release;
        mocap::ProcessedRecording processed = mocap::ProcessRecording(request);
        return Processed{std::make_shared<ExperimentFile>(std::move(processed.experiment)),
                         std::move(processed.result.summary)};
      },
      py::arg("path"), py::kw_only(), py::arg("config") = py::none(),
      py::arg("rigid_bodies") = py::none(), py::arg("static_trial") = py::none(),
      py::arg("inputs") = py::none(), py::arg("name") = "",
      "The mocap pipeline of `ccsrm mocap process` with default processing settings: a "
      "marker file (C3D, TRC, CSV) or an experiment or run file to measured joint angles. "
      "config: the arm (YAML); rigid_bodies: a ccsrm-rigid-bodies/1 file; static_trial: a "
      "marker file of the straight arm; inputs: the run or experiment whose /input the "
      "experiment records. Returns a ProcessedRecording (nothing is written).");

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
         const std::vector<std::string>& labels, double rate_hz, const std::string& units,
         bool overwrite) {
        const std::string file = PathString(path);
        CheckWriterPath(file, mocap::C3dFileOutput(), overwrite);
        MarkerTable table = TableFromArrays(positions, labels, rate_hz);
        mocap::C3dWriteOptions options;
        options.units = units;
        std::string error;
        if (!options.IsValid(&error)) ThrowInputError("units", "", error);
        py::gil_scoped_release release;
        mocap::WriteC3d(file, table, options);
      },
      py::arg("path"), py::arg("positions"), py::arg("labels"), py::arg("rate_hz"),
      py::arg("units") = "mm", py::kw_only(), py::arg("overwrite") = false,
      "Writes markers (frames x markers x 3 [m], NaN = not seen) as an Intel float C3D file. "
      "An existing file is replaced only when it is a C3D file, or with overwrite=True.");
  m.def(
      "write_c3d",
      [](const py::object& path, const MarkerTable& table, const std::string& units,
         bool overwrite) {
        const std::string file = PathString(path);
        CheckWriterPath(file, mocap::C3dFileOutput(), overwrite);
        mocap::C3dWriteOptions options;
        options.units = units;
        std::string error;
        if (!options.IsValid(&error)) ThrowInputError("units", "", error);
        py::gil_scoped_release release;
        mocap::WriteC3d(file, table, options);
      },
      py::arg("path"), py::arg("table"), py::arg("units") = "mm", py::kw_only(),
      py::arg("overwrite") = false,
      "Writes a MarkerTable (e.g. from read_markers) as an Intel float C3D file. An existing "
      "file is replaced only when it is a C3D file, or with overwrite=True.");
}

}  // namespace ccsrm::python
