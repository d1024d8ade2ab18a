// ccsrm.load_config, ccsrm.Model, ccsrm.simulate and its results
// (ccsrm.Run, ccsrm.SimulationSummary), ccsrm.read_run_file.
#include <Python.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/output_kinds.h"
#include "ccsrm/datasets/run_file.h"
#include "ccsrm/mocap/generate.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/paper_run.h"
#include "ccsrm/sim/simulator.h"
#include "ccsrm/sim_io/run_file.h"

namespace ccsrm::python {
namespace {

// A number the caller gave, refused unless finite (InputError naming it).
double Finite(double value, const char* name) {
  if (!std::isfinite(value))
    ThrowInputError(name, "", "must be a finite number, found " + std::to_string(value));
  return value;
}

// A configuration and the model built from it, shared read-only by every
// run (and every thread) that simulates it.
struct Model {
  sim::Config config;
  std::shared_ptr<const sim::ArmModel> model;
};

// A run: the record `ccsrm simulate` writes (the arrays numpy views borrow),
// and, for a run simulated here, its summary and description.
struct Run {
  datasets::RunFile file;
  std::optional<sim::SimulationSummary> summary;
  std::string description;
};

// Ctrl-C during a run. The simulator calls its progress callback from the
// simulating thread every `progress_interval_s` of wall time; there the GIL
// is taken for a moment and Python's signal handlers run (they only run in
// the main thread; elsewhere the check is a no-op). A pending
// KeyboardInterrupt sets the run's cancel flag, so the run stops at its next
// step, and is raised once the run has returned.
class InterruptWatch {
 public:
  // `options`: sim::SimulationOptions or mocap::GenerateOptions (their
  // cancel, progress and progress_interval_s).
  template <typename Options>
  void Attach(Options* options) {
    options->cancel = &cancel_;
    options->progress_interval_s = 0.1;  // the longest Ctrl-C waits [s]
    options->progress = [this](const sim::SimulationProgress&) {
      py::gil_scoped_acquire gil;
      if (type_ == nullptr && PyErr_CheckSignals() != 0) {
        PyErr_Fetch(&type_, &value_, &traceback_);
        cancel_ = true;
      }
    };
  }
  // With the GIL held: raises the interruption caught during the run.
  void RaiseIfInterrupted() {
    if (type_ == nullptr) return;
    PyErr_Restore(type_, value_, traceback_);
    type_ = value_ = traceback_ = nullptr;
    throw py::error_already_set();
  }

 private:
  std::atomic<bool> cancel_{false};
  PyObject* type_ = nullptr;
  PyObject* value_ = nullptr;
  PyObject* traceback_ = nullptr;
};

std::shared_ptr<Model> LoadModel(const py::object& path) {
  const std::string file = PathString(path);
  py::gil_scoped_release release;
  auto m = std::make_shared<Model>();
  m->config = sim::LoadConfig(file);
  m->model = std::make_shared<const sim::ArmModel>(m->config.arm);
  return m;
}

// Builds the run as `ccsrm simulate` does (sim::PreparePaperRun on the
// model's configuration) and simulates it with the GIL released.
std::shared_ptr<Run> SimulateRun(const Model& model, const py::object& params,
                                 std::optional<int> case_number, const py::object& protocol,
                                 const py::object& inputs, const py::object& sample_times,
                                 std::optional<double> duration,
                                 std::optional<double> amplitude_deg,
                                 std::optional<double> output_rate, double max_input_gap,
                                 bool quasi_static) {
  sim::Config config = model.config;
  std::map<std::string, double> overrides;
  if (py::isinstance<sim::ArmParameters>(params)) {
    const auto& given = params.cast<const sim::ArmParameters&>();
    if (given.arm != config.arm.size()) {
      ThrowInputError("params", "",
                      "parameters of an arm of " + std::to_string(given.arm.joints) +
                          " joints and " + std::to_string(given.arm.cables) +
                          " cables, the model has " + std::to_string(config.arm.size().joints) +
                          " and " + std::to_string(config.arm.size().cables));
    }
    config.parameters = given;
  } else if (!params.is_none()) {
    overrides = CastArgument<std::map<std::string, double>>(
        params, "params", "a dict of numbers by parameter name, or ccsrm.Parameters");
  }
  // The case's friction switches, then the given values: the order of
  // --case and --set.
  if (case_number) sim::ApplyPaperCase(*case_number, &config.parameters);
  for (const auto& [name, value] : overrides)
    sim::SetParameter(name, value, "params", &config.parameters);

  sim::PaperRunOptions options;
  if (!protocol.is_none()) sim::ApplyProtocolSpec(PathString(protocol), "protocol", &options);
  // NaN is PaperRunOptions' "not given": a NaN passed in is refused.
  if (duration) options.duration_s = Finite(*duration, "duration");
  if (amplitude_deg) options.amplitude_deg = Finite(*amplitude_deg, "amplitude_deg");
  if (output_rate) options.output_rate_hz = Finite(*output_rate, "output_rate");
  options.recorded_input_options.max_gap_s = max_input_gap;
  options.quasi_static = quasi_static;
  if (!inputs.is_none()) {
    // Columns as a table of inputs has them: time [s], then the pulled-in
    // length of each cable [m]; the library checks them as it checks a file.
    auto table = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(inputs);
    if (!table || table.ndim() != 2 || table.shape(1) < 2) {
      ThrowInputError("inputs", "",
                      "expected a 2-D array of N rows: time [s], then one pulled-in length [m] "
                      "per driving cable");
    }
    sim::RecordedInputs record;
    record.source_name = "inputs";
    record.time_name = "inputs[:, 0]";
    const py::ssize_t n = table.shape(0), c = table.shape(1) - 1;
    record.time_s.resize(n);
    record.length_change_m.resize(n, c);
    auto t = table.unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
      record.time_s(i) = t(i, 0);
      for (py::ssize_t k = 0; k < c; ++k) record.length_change_m(i, k) = t(i, k + 1);
    }
    for (py::ssize_t k = 0; k < c; ++k)
      record.cable_names.push_back("inputs[:, " + std::to_string(k + 1) + "]");
    options.recorded_inputs = std::move(record);
  }
  std::vector<double> samples;
  if (!sample_times.is_none()) {
    samples = CastArgument<std::vector<double>>(sample_times, "sample_times",
                                                "a 1-D sequence of frame times [s]");
  }

  auto run = std::make_shared<Run>();
  InterruptWatch watch;
  {
    py::gil_scoped_release release;
    sim::PaperRun prepared = sim::PreparePaperRun(options, std::move(config), model.model.get());
    // The case was applied above; the run names it as the command does.
    prepared.case_number = case_number.value_or(0);
    sim::SimulationOptions simulation = prepared.simulation;
    // Given frame times replace the run's own (the output grid, or the
    // poses of a quasi-static replay of recorded inputs).
    if (!samples.empty()) simulation.sample_times = std::move(samples);
    watch.Attach(&simulation);
    std::string error;
    if (!simulation.IsValid(&error)) ThrowInputError("sample_times", "", error);
    sim::SimulationResult result =
        sim::Simulate(prepared.model, prepared.config.parameters, prepared.inputs, simulation);
    run->file = sim_io::ToRunFile(prepared.model, result, sim_io::PaperRunFileInfo(prepared));
    run->summary = std::move(result.summary);
    run->description = sim::DescribeRun(prepared);
  }
  watch.RaiseIfInterrupted();
  return run;
}

// ccsrm.generate: `ccsrm generate` (mocap::GenerateExperiment), the
// parameters as values.
py::dict Generate(const py::object& out, const py::object& config, std::optional<int> case_number,
                  const py::object& protocol, const std::map<std::string, double>& params,
                  const std::vector<std::string>& effects, std::optional<double> duration,
                  std::optional<double> amplitude_deg, double noise_mm, double resolution_mm,
                  std::uint64_t seed, bool occlusions, bool quasi_static) {
  mocap::GenerateOptions options;
  options.out = PathString(out);
  options.run.config_path = sim::ConfigPathOrBundled(config.is_none() ? "" : PathString(config));
  options.run.case_number = case_number.value_or(0);
  if (!protocol.is_none()) sim::ApplyProtocolSpec(PathString(protocol), "protocol", &options.run);
  if (duration) options.run.duration_s = Finite(*duration, "duration");
  if (amplitude_deg) options.run.amplitude_deg = Finite(*amplitude_deg, "amplitude_deg");
  for (const auto& [name, value] : params) {
    char text[48];
    std::snprintf(text, sizeof(text), "=%.17g", value);  // to the last bit
    options.run.sets.push_back(name + text);
  }
  options.effects = effects;
  options.run.quasi_static = quasi_static;
  options.recording.noise_sigma_m = noise_mm * 1e-3;
  options.recording.resolution_m = resolution_mm * 1e-3;
  options.recording.seed = seed;
  options.recording.occlusions.enabled = occlusions;
  InterruptWatch watch;
  watch.Attach(&options);
  std::optional<mocap::GeneratedExperiment> generated;
  {
    py::gil_scoped_release release;
    generated.emplace(mocap::GenerateExperiment(options));
  }
  watch.RaiseIfInterrupted();
  const mocap::GeneratedExperiment& g = *generated;
  if (!g.simulation.completed()) {
    throw std::runtime_error(std::string("simulation ") +
                             sim::SimulationStatusName(g.simulation.status) + ": " +
                             g.simulation.message + " (nothing written)");
  }
  py::dict result;
  result["experiment"] = g.experiment_path;
  result["truth_yaml"] = g.truth_yaml_path;
  result["truth_h5"] = g.truth_h5_path;
  result["description"] = sim::DescribeRun(g.run);
  result["duration_s"] = g.run.simulation.duration_s;
  result["frames"] = g.frames;
  result["markers"] = g.markers;
  result["marker_gaps"] = g.recording.marker_gaps;
  result["link_losses"] = g.recording.link_losses;
  result["hidden_fraction"] = g.recording.hidden_fraction;
  result["effects"] = g.truth.parameters.EnabledEffects();
  result["wall_time_s"] = g.wall_time_s;
  return result;
}

py::list PerCable(const py::object& self, const Run& run,
                  datasets::Array datasets::CableRecord::*member) {
  py::list out;
  for (const datasets::CableRecord& cable : run.file.cables) out.append(View(cable.*member, self));
  return out;
}

// ccsrm.Model and ccsrm.load_config.
void AddModelClass(py::module_& m) {
  py::class_<Model, std::shared_ptr<Model>>(
      m, "Model",
      "An arm's configuration and its model, read-only (ccsrm.load_config). Shared by any "
      "number of runs, in any threads.")
      .def_property_readonly("path", [](const Model& mo) { return mo.config.source_name; })
      .def_property_readonly(
          "parameters", [](const Model& mo) { return mo.config.parameters; },
          "A copy of the configured parameters (ccsrm.Parameters).")
      .def_property_readonly("num_joints", [](const Model& mo) { return mo.model->num_joints(); })
      .def_property_readonly("num_links", [](const Model& mo) { return mo.model->num_links(); })
      .def_property_readonly("num_cables", [](const Model& mo) { return mo.model->num_cables(); })
      .def_property_readonly(
          "segment_links",
          [](const Model& mo) {
            std::vector<int> links;
            for (const sim::SegmentConfig& segment : mo.config.arm.segments)
              links.push_back(segment.links);
            return links;
          },
          "Links (= joints) of each segment, from the base.")
      .def(
          "effect_parameters",
          [](const Model& mo, const std::string& effect) {
            return sim::EffectParameterNames(effect, mo.config.arm.size(), "effect_parameters");
          },
          py::arg("effect"),
          "The full names of an effect's parameters on this arm (per joint and per cable ones "
          "once per joint or cable), as Parameters and --set take them.")
      .def_property_readonly(
          "joint_ranges_rad",
          [](const Model& mo) { return Copy(sim::JointRangesRad(mo.config.arm)); },
          "The largest bend of each joint before its disks meet [rad].")
      .def_property_readonly(
          "output_rate_hz", [](const Model& mo) { return mo.config.solver.output_rate_hz; },
          "Frames per second of a run without sample_times (solver.output_rate_hz).")
      .def_property_readonly(
          "warnings", [](const Model& mo) { return mo.config.warnings; },
          "Values far outside what arms of this kind have (the command line prints them).")
      .def_property_readonly(
          "yaml", [](const Model& mo) { return sim::ToYaml(mo.config); },
          "The configuration as YAML, in the schema of configs/paper.yaml.")
      .def("__repr__", [](const Model& mo) {
        return "<ccsrm.Model " + mo.config.source_name + ": " +
               std::to_string(mo.model->num_joints()) + " joints, " +
               std::to_string(mo.model->num_cables()) + " driving cables>";
      });

  m.def("load_config", &LoadModel, py::arg("path"),
        "Reads and checks an arm configuration (YAML, the schema of configs/paper.yaml) and "
        "builds its model. Raises InputError with the command line's message for a bad file.");
  m.def(
      "bundled_config", [](const std::string& name) { return sim::BundledConfigPath(name); },
      py::arg("name") = "paper.yaml",
      "The path of a configuration that ships with ccsrm (paper.yaml, three-segment.yaml, "
      "protocols/<name>.yaml).");
}

// A run and what it reports: ccsrm.SlackInterval, SimulationSummary, Run.
void AddRunClasses(py::module_& m) {
  py::class_<sim::SlackInterval>(m, "SlackInterval", "A stretch of time a driving cable was slack.")
      .def_readonly("cable", &sim::SlackInterval::cable, "1-based.")
      .def_readonly("start_s", &sim::SlackInterval::start_s)
      .def_readonly("end_s", &sim::SlackInterval::end_s)
      .def_readonly("most_elements", &sim::SlackInterval::most_elements);

  py::class_<sim::SimulationSummary>(m, "SimulationSummary",
                                     "How a run went (sim::SimulationSummary).")
      .def_property_readonly(
          "status",
          [](const sim::SimulationSummary& s) { return sim::SimulationStatusName(s.status); },
          "'completed', 'diverged' or 'cancelled'.")
      .def_property_readonly("completed", &sim::SimulationSummary::completed)
      .def_readonly("message", &sim::SimulationSummary::message)
      .def_readonly("simulated_s", &sim::SimulationSummary::simulated_s)
      .def_readonly("wall_time_s", &sim::SimulationSummary::wall_time_s)
      .def_readonly("real_time_factor", &sim::SimulationSummary::real_time_factor)
      .def_readonly("steps", &sim::SimulationSummary::steps)
      .def_readonly("rejected_steps", &sim::SimulationSummary::rejected_steps)
      .def_readonly("rhs_evaluations", &sim::SimulationSummary::rhs_evaluations)
      .def_readonly("stick_slip_switches", &sim::SimulationSummary::stick_slip_switches)
      .def_readonly("failed_releases", &sim::SimulationSummary::failed_releases)
      .def_readonly("max_constraint_violation", &sim::SimulationSummary::max_constraint_violation)
      .def_readonly("slack", &sim::SimulationSummary::slack)
      .def("brief_report", &sim::SimulationSummary::BriefReport)
      .def("full_report", &sim::SimulationSummary::FullReport)
      .def("__repr__", [](const sim::SimulationSummary& s) {
        return "<SimulationSummary " + s.BriefReport() + ">";
      });

  // Arrays are read-only views into the run's own memory (no copy), laid out
  // as in the ccsrm-run/1 file (datasets/README.md).
  py::class_<Run, std::shared_ptr<Run>>(
      m, "Run",
      "The frames of a run as numpy arrays (read-only views, no copy), laid out as the "
      "ccsrm-run/1 file `ccsrm simulate` writes: T frames, J joints, L links, C cables.")
      .def_property_readonly(
          "time", [](py::object self) { return View(self.cast<Run&>().file.time, self); }, "T [s].")
      .def_property_readonly(
          "joint_angles",
          [](py::object self) { return View(self.cast<Run&>().file.joint_angles, self); },
          "T x J x 2 (theta_x, theta_y) [rad].")
      .def_property_readonly(
          "joint_rates",
          [](py::object self) { return View(self.cast<Run&>().file.joint_rates, self); },
          "T x J x 2 [rad/s].")
      .def_property_readonly(
          "link_pose", [](py::object self) { return View(self.cast<Run&>().file.link_pose, self); },
          "T x L x 7 (x, y, z [m], e0..e3).")
      .def_property_readonly(
          "input_tension",
          [](py::object self) { return View(self.cast<Run&>().file.input_tension, self); },
          "T x C: tension at each cable's input [N].")
      .def_property_readonly(
          "input_length_change",
          [](py::object self) { return View(self.cast<Run&>().file.input_length_change, self); },
          "T x C: pulled-in length [m].")
      .def_property_readonly(
          "stuck_nodes",
          [](py::object self) { return View(self.cast<Run&>().file.stuck_nodes, self); },
          "T x C: stuck hole nodes per cable.")
      .def_property_readonly(
          "slack_elements",
          [](py::object self) -> py::object {
            const auto& slack = self.cast<Run&>().file.slack_elements;
            return slack ? py::object(View(*slack, self)) : py::object(py::none());
          },
          "T x C: elements of each cable that carry no tension (None in older files).")
      .def_property_readonly(
          "constraint_violation",
          [](py::object self) { return View(self.cast<Run&>().file.constraint_violation, self); },
          "T.")
      .def_property_readonly(
          "energy", [](py::object self) { return View(self.cast<Run&>().file.energy, self); },
          "T x 3: kinetic, elastic, dissipated [J].")
      .def_property_readonly(
          "cable_tensions",
          [](py::object self) {
            return PerCable(self, self.cast<Run&>(), &datasets::CableRecord::tension);
          },
          "Per cable, T x E_k: tension of every element [N].")
      .def_property_readonly(
          "slip_velocities",
          [](py::object self) {
            return PerCable(self, self.cast<Run&>(), &datasets::CableRecord::slip_velocity);
          },
          "Per cable, T x H_k: slip velocity of every hole node [m/s].")
      .def_property_readonly(
          "stuck",
          [](py::object self) {
            return PerCable(self, self.cast<Run&>(), &datasets::CableRecord::stuck);
          },
          "Per cable, T x H_k: 1 where the hole node is stuck.")
      .def_property_readonly(
          "summary", [](const Run& r) { return r.summary; },
          "The SimulationSummary (None for a run read from a file).")
      .def_property_readonly(
          "description", [](const Run& r) { return r.description; },
          "The lines `ccsrm simulate` prints above the summary.")
      .def_property_readonly("status",
                             [](const Run& r) { return datasets::RunStatusName(r.file.status); })
      .def_property_readonly("case_name", [](const Run& r) { return r.file.case_name; })
      .def_property_readonly("config_yaml", [](const Run& r) { return r.file.config_yaml; })
      .def_property_readonly("protocol_yaml", [](const Run& r) { return r.file.protocol_yaml; })
      .def_property_readonly("frames", [](const Run& r) { return r.file.frames(); })
      .def(
          "write",
          [](const Run& r, const py::object& path, bool overwrite) {
            const std::string file = PathString(path);
            CheckWriterPath(file, datasets::RunFileOutput(), overwrite);
            py::gil_scoped_release release;
            datasets::WriteRunFile(file, r.file);
          },
          py::arg("path"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the ccsrm-run/1 file `ccsrm simulate --out` would, under its output policy: an "
          "existing file is replaced only when it is a run file, or with overwrite=True.")
      .def("__len__", [](const Run& r) { return r.file.frames(); })
      .def("__repr__", [](const Run& r) {
        return "<ccsrm.Run " + std::to_string(r.file.frames()) + " frames, " +
               datasets::RunStatusName(r.file.status) + ">";
      });
}

}  // namespace

void AddSimulation(py::module_& m) {
  AddModelClass(m);
  AddRunClasses(m);
  m.def("simulate", &SimulateRun, py::arg("model"), py::arg("params") = py::none(), py::kw_only(),
        py::arg("case") = py::none(), py::arg("protocol") = py::none(),
        py::arg("inputs") = py::none(), py::arg("sample_times") = py::none(),
        py::arg("duration") = py::none(), py::arg("amplitude_deg") = py::none(),
        py::arg("output_rate") = py::none(),
        py::arg("max_input_gap") = sim::RecordedInputOptions().max_gap_s,
        py::arg("quasi_static") = false,
        "Simulates the arm as `ccsrm simulate` does and returns a Run.\n\n"
        "params: a Parameters object (it replaces the configured parameters; a case then "
        "switches friction off where the case says), or a dict of values by name, set after "
        "the case (like --set). case: 1..4, the paper's friction switches. "
        "The motion: protocol (a ccsrm-protocol/1 file), or inputs (N x (1 + C) array: time "
        "[s], then each cable's pulled-in length [m]), or neither (the configuration's paper "
        "protocol). sample_times: frame times [s] (default every 1 / output_rate). quasi_static: "
        "replay settled poses, as --quasi-static (needs presliding or no friction). The GIL is "
        "released while the arm is simulated; Ctrl-C cancels the run and raises "
        "KeyboardInterrupt. A diverged run is returned with its status, not raised.");

  m.def("generate", &Generate, py::arg("out"), py::arg("config") = py::none(), py::kw_only(),
        py::arg("case") = py::none(), py::arg("protocol") = py::none(),
        py::arg("params") = std::map<std::string, double>(),
        py::arg("effects") = std::vector<std::string>(), py::arg("duration") = py::none(),
        py::arg("amplitude_deg") = py::none(), py::arg("noise_mm") = 0.2,
        py::arg("resolution_mm") = 0.0, py::arg("seed") = 1, py::arg("occlusions") = true,
        py::arg("quasi_static") = false,
        "Generates a virtual experiment as `ccsrm generate --out OUT` does: the arm of `config` "
        "(default: the bundled paper.yaml) simulated with the truth (case, params by name, "
        "effects as 'NAME' or 'NAME:param=value,...'), recorded by virtual motion capture, "
        "written as OUT (a ccsrm-dataset/1 experiment stating the nominal configuration) with "
        "OUT's stem .truth.yaml and .truth.h5 beside it. protocol: a ccsrm-protocol/1 file, "
        "optionally 'file.yaml@name=value,...'. quasi_static: the arm replayed as settled poses "
        "(--quasi-static); the experiment says so (motion: settled_poses). The output policy is "
        "the command's: an "
        "existing file that is not an earlier output of its kind is refused. Returns a dict "
        "of the paths written and the recording's figures. The GIL is released while the arm "
        "is simulated; Ctrl-C cancels the run (nothing written) and raises KeyboardInterrupt; "
        "a run that diverges raises RuntimeError (nothing written).");

  m.def(
      "read_run_file",
      [](const py::object& path) {
        const std::string file = PathString(path);
        auto run = std::make_shared<Run>();
        py::gil_scoped_release release;
        run->file = datasets::ReadRunFile(file);
        return run;
      },
      py::arg("path"), "Reads a ccsrm-run/1 file as a Run (summary None).");
}

}  // namespace ccsrm::python
