// ccsrm.identify, ccsrm.loop and ccsrm.predict: `ccsrm identify`, `ccsrm
// loop` and `ccsrm predict` from Python (their jobs, identify/job.h), their
// summaries and JSON.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/name_list.h"
#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/identification.h"
#include "ccsrm/identify/job.h"
#include "ccsrm/identify/loop.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::python {
namespace {

// A fit and the experiments it was made on (what writing its folder needs).
struct Fit {
  identify::IdentificationSummary summary;
  std::vector<identify::Experiment> experiments;
};

// A list of names, or one comma-separated string as the option `option`
// takes it (read by the commands' reader, with their messages).
std::vector<std::string> Names(const py::object& names, const std::string& option) {
  if (py::isinstance<py::str>(names)) return SplitNameList(names.cast<std::string>(), option);
  return CastArgument<std::vector<std::string>>(names, option.c_str(),
                                                "a list of names or one comma-separated string");
}

// Values by name, from a dict of numbers or from "name=value" strings as
// --set takes them.
std::vector<std::pair<std::string, double>> Values(const py::object& values) {
  std::vector<std::pair<std::string, double>> out;
  if (values.is_none()) return out;
  if (py::isinstance<py::dict>(values)) {
    for (const auto& [name, value] : values.cast<py::dict>()) {
      out.emplace_back(CastArgument<std::string>(name, "set", "parameter names (str)"),
                       CastArgument<double>(value, "set", "numbers as values"));
    }
    return out;
  }
  for (const std::string& text : CastArgument<std::vector<std::string>>(
           values, "set", "a dict of numbers by name, or 'name=value' strings")) {
    out.push_back(sim::ParseParameterAssignment(text, "--set"));
  }
  return out;
}

// The fit's parameters as the jobs take them.
identify::FitParameterChoice Parameters(const py::object& free, const py::object& params,
                                        const py::object& set) {
  identify::FitParameterChoice choice;
  if (!free.is_none()) choice.free = Names(free, "--free");
  if (!params.is_none()) choice.params_path = PathString(params);
  choice.values = Values(set);
  return choice;
}

std::string OptionalPath(const py::object& path) { return path.is_none() ? "" : PathString(path); }

// Calls a Python function from the fit's own thread (the GIL is released
// around the fit): the iteration's figures as a dict, or the loop's progress
// line. An exception the function raises cannot cross the optimiser: it is
// kept, later calls are skipped, and it is raised once the fit returns.
class ProgressRelay {
 public:
  explicit ProgressRelay(py::object function) : function_(std::move(function)) {}
  bool active() const { return !function_.is_none(); }
  template <typename MakeArgument>
  void Call(const MakeArgument& make) {
    py::gil_scoped_acquire gil;
    if (error_) return;
    try {
      function_(make());
    } catch (py::error_already_set& e) {
      error_ = std::make_unique<py::error_already_set>(std::move(e));
    }
  }
  // With the GIL held.
  void RaiseIfFailed() {
    if (error_) throw std::move(*error_);
  }

 private:
  py::object function_;
  std::unique_ptr<py::error_already_set> error_;
};

py::dict IterationDict(const identify::IterationProgress& p) {
  py::dict values;
  for (const auto& [name, value] : p.values) values[py::str(name)] = value;
  py::dict d;
  d["iteration"] = p.iteration;
  d["cost"] = p.cost;
  d["rms_deg"] = p.rms_deg;
  d["rms_mm"] = p.rms_mm;
  d["step_accepted"] = p.step_accepted;
  d["simulations"] = p.simulations;
  d["wall_time_s"] = p.wall_time_s;
  d["values"] = values;
  return d;
}

// A prediction and the recordings it predicted.
struct Prediction {
  identify::PredictionSummary summary;
  std::vector<identify::Experiment> recordings;
};

// A loop and the experiments it ran on.
struct Loop {
  identify::LoopSummary summary;
  std::vector<identify::Experiment> training, holdout;
};

// One path or a sequence of them.
std::vector<std::string> Paths(const py::object& data) {
  std::vector<std::string> paths;
  if (data.is_none()) return paths;
  if (py::isinstance<py::str>(data) || py::hasattr(data, "__fspath__")) {
    paths.push_back(PathString(data));
  } else {
    for (const py::handle& p : data) paths.push_back(PathString(p));
  }
  return paths;
}

// The arguments identify and loop take alike, as their jobs take them.
void FillFitJob(const py::object& data, const py::object& free, const py::object& params,
                const py::object& set, std::optional<int> threads, int max_iterations,
                std::optional<double> noise_deg, const py::object& out, bool resume,
                identify::FitJobOptions* job) {
  job->data = Paths(data);
  job->parameters = Parameters(free, params, set);
  if (threads) job->runs.threads = *threads;
  job->max_iterations = max_iterations;
  job->noise_deg = noise_deg;
  job->out = OptionalPath(out);
  job->resume = resume;
}

std::shared_ptr<Loop> RunLoop(const py::object& data, const py::object& holdout,
                              const py::object& candidates, const py::object& free,
                              const py::object& params, const py::object& set,
                              const py::object& config, std::optional<int> threads, int max_rounds,
                              int max_iterations, std::optional<double> noise_deg,
                              const py::object& out, bool resume, const py::object& progress) {
  identify::LoopJobOptions job;
  FillFitJob(data, free, params, set, threads, max_iterations, noise_deg, out, resume, &job);
  job.holdout = Paths(holdout);
  if (!candidates.is_none()) job.candidates = Names(candidates, "--candidates");
  job.config_path = OptionalPath(config);
  job.max_rounds = max_rounds;
  ProgressRelay relay(progress);
  if (relay.active()) {
    job.reporting.on_loop_progress = [&relay](const identify::LoopProgress& p) {
      relay.Call([&] { return py::str(p.message); });
    };
  }
  auto loop = std::make_shared<Loop>();
  {
    py::gil_scoped_release release;
    identify::LoopJobResult r = identify::RunLoopJob(job);
    loop->summary = std::move(r.summary);
    loop->training = std::move(r.training);
    loop->holdout = std::move(r.holdout);
  }
  relay.RaiseIfFailed();
  return loop;
}

std::shared_ptr<Prediction> RunPredict(const py::object& data, const py::object& params,
                                       const py::object& effects, const py::object& config,
                                       std::optional<int> threads, std::optional<double> noise_deg,
                                       double point_noise_mm, const py::object& out) {
  identify::PredictJobOptions job;
  job.data = Paths(data);
  job.params_path = PathString(params);
  job.effects_path = OptionalPath(effects);
  job.config_path = OptionalPath(config);
  if (threads) job.threads = *threads;
  job.noise_deg = noise_deg;
  job.point_noise_mm = point_noise_mm;
  job.out = OptionalPath(out);
  auto prediction = std::make_shared<Prediction>();
  py::gil_scoped_release release;
  identify::PredictJobResult r = identify::RunPredictJob(job);
  prediction->summary = std::move(r.summary);
  prediction->recordings = std::move(r.recordings);
  return prediction;
}

std::shared_ptr<Fit> RunIdentify(const py::object& data, const py::object& free,
                                 const py::object& params, const py::object& set,
                                 std::optional<int> threads, int max_iterations,
                                 double relative_step, std::optional<double> noise_deg,
                                 double point_noise_mm, bool central_throughout,
                                 const py::object& out, bool resume, const py::object& progress) {
  identify::IdentifyJobOptions job;
  FillFitJob(data, free, params, set, threads, max_iterations, noise_deg, out, resume, &job);
  job.point_noise_mm = point_noise_mm;
  job.relative_step = relative_step;
  job.central_differences_throughout = central_throughout;
  ProgressRelay relay(progress);
  if (relay.active()) {
    job.reporting.on_iteration = [&relay](const identify::IterationProgress& p) {
      relay.Call([&] { return IterationDict(p); });
    };
  }
  auto fit = std::make_shared<Fit>();
  {
    py::gil_scoped_release release;
    identify::IdentifyJobResult r = identify::RunIdentifyJob(job);
    fit->summary = std::move(r.summary);
    fit->experiments = std::move(r.experiments);
  }
  relay.RaiseIfFailed();
  return fit;
}

// ParameterEstimate and Fit, what ccsrm.identify returns.
void AddFitClasses(py::module_& m) {
  using identify::ParameterEstimate;
  py::class_<ParameterEstimate>(m, "ParameterEstimate", "One parameter of a fit.")
      .def_readonly("name", &ParameterEstimate::name)
      .def_readonly("units", &ParameterEstimate::units)
      .def_readonly("free", &ParameterEstimate::free)
      .def_readonly("start", &ParameterEstimate::start)
      .def_readonly("value", &ParameterEstimate::value)
      .def_readonly("lower", &ParameterEstimate::lower)
      .def_readonly("upper", &ParameterEstimate::upper)
      .def_readonly("scale", &ParameterEstimate::scale)
      .def_readonly("identifiable", &ParameterEstimate::identifiable)
      .def_readonly("std_error", &ParameterEstimate::std_error, "NaN when not identifiable.")
      .def_readonly("ci95_lower", &ParameterEstimate::ci95_lower)
      .def_readonly("ci95_upper", &ParameterEstimate::ci95_upper)
      .def_readonly("at_bound", &ParameterEstimate::at_bound)
      .def_readonly("derivative_step_disagreement",
                    &ParameterEstimate::derivative_step_disagreement,
                    "Its derivatives at derivative_step and a third of it differ by this "
                    "(relative); above 0.05 the angles are not smooth in it. NaN: not checked.")
      .def_readonly("derivative_step", &ParameterEstimate::derivative_step,
                    "The relative finite-difference step of its derivative in the intervals: "
                    "the fit's, or a third of it where the angles bend between the two.")
      .def("__repr__", [](const ParameterEstimate& p) {
        return "<ParameterEstimate " + p.name + " = " +
               py::repr(py::float_(p.value)).cast<std::string>() + " " + p.units + ">";
      });

  py::class_<Fit, std::shared_ptr<Fit>>(
      m, "Fit",
      "The result of ccsrm.identify: the identification summary (estimates, standard errors, "
      "correlations, identifiability) and its fit.json.")
      .def_property_readonly(
          "termination",
          [](const Fit& f) { return identify::TerminationName(f.summary.termination); })
      .def_property_readonly("converged", [](const Fit& f) { return f.summary.converged(); })
      .def_property_readonly(
          "adequate", [](const Fit& f) { return f.summary.adequacy.adequate(); },
          "Whether the fitted model explains the data: no joint axis's residual stands above "
          "its measured noise (read `verdict` before `converged`).")
      .def_property_readonly(
          "verdict", [](const Fit& f) { return f.summary.adequacy.Verdict(); },
          "One line: whether the model explains the data, with the worst joint axis.")
      .def_property_readonly(
          "adequacy",
          [](const Fit& f) {
            return py::module_::import("json").attr("loads")(
                identify::ToJson(f.summary.adequacy).dump());
          },
          "fit.json's 'adequacy' as a dict: the verdict, the channels above the noise, the "
          "misfit scale of the intervals.")
      .def_property_readonly("message", [](const Fit& f) { return f.summary.message; })
      .def_property_readonly("iterations", [](const Fit& f) { return f.summary.iterations; })
      .def_property_readonly("simulations", [](const Fit& f) { return f.summary.simulations; })
      .def_property_readonly("wall_time_s", [](const Fit& f) { return f.summary.wall_time_s; })
      .def_property_readonly("initial_cost", [](const Fit& f) { return f.summary.initial_cost; })
      .def_property_readonly("final_cost", [](const Fit& f) { return f.summary.final_cost; })
      .def_property_readonly("cost_history", [](const Fit& f) { return f.summary.cost_history; })
      .def_property_readonly("free_names", [](const Fit& f) { return f.summary.free_names; })
      .def_property_readonly(
          "parameters", [](const Fit& f) { return f.summary.parameters; },
          "Every parameter's estimate, the free ones first.")
      .def_property_readonly(
          "correlation", [](const Fit& f) { return f.summary.correlation; },
          "free x free; NaN rows for parameters not identifiable.")
      .def_property_readonly("singular_values",
                             [](const Fit& f) { return f.summary.singular_values; })
      .def_property_readonly(
          "rms_deg", [](const Fit& f) { return f.summary.errors.rms_deg_overall; },
          "RMS error of the fitted joint angles over every experiment [deg].")
      .def("__getitem__",
           [](const Fit& f, const std::string& name) {
             const ParameterEstimate* p = f.summary.Find(name);
             if (p == nullptr) throw py::key_error(name);
             return *p;
           })
      .def("brief_report", [](const Fit& f) { return f.summary.BriefReport(); })
      .def(
          "full_report", [](const Fit& f) { return f.summary.FullReport(); },
          "The table `ccsrm identify` prints.")
      .def(
          "json", [](const Fit& f) { return identify::ToJson(f.summary).dump(2) + "\n"; },
          "The summary as JSON: fit.json without the names of the files of the fit folder "
          "(those come with write()).")
      .def(
          "to_dict",
          [](const Fit& f) {
            return py::module_::import("json").attr("loads")(identify::ToJson(f.summary).dump());
          },
          "json() as a dict.")
      .def(
          "write",
          [](const Fit& f, const py::object& directory, bool overwrite) {
            const std::string dir = PathString(directory);
            CheckWriterPath(dir, identify::FitFolderOutput(), overwrite);
            py::gil_scoped_release release;
            return identify::WriteFitDirectory(f.summary, f.experiments, dir);
          },
          py::arg("directory"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the fit folder `ccsrm identify --out` writes; returns the paths. An existing "
          "folder is replaced only when it is an earlier fit folder holding nothing but what "
          "ccsrm wrote, or with overwrite=True.")
      .def("__repr__", [](const Fit& f) { return "<ccsrm.Fit " + f.summary.BriefReport() + ">"; });
}

// ccsrm.Loop and ccsrm.loop.
void AddLoop(py::module_& m) {
  py::class_<Loop, std::shared_ptr<Loop>>(
      m, "Loop",
      "The result of ccsrm.loop: the declared model's fit, the effects added round by round "
      "and the final fit, with loop.json.")
      .def_property_readonly("added_effects", [](const Loop& l) { return l.summary.added_effects; })
      .def_property_readonly("conclusion", [](const Loop& l) { return l.summary.conclusion; })
      .def_property_readonly(
          "unit", [](const Loop& l) { return l.summary.unit; },
          "The unit of every RMS figure: 'deg', or 'mm' for recordings of tracked points.")
      .def_property_readonly("rms_before_deg",
                             [](const Loop& l) { return l.summary.rms_before_deg; })
      .def_property_readonly("rms_after_deg", [](const Loop& l) { return l.summary.rms_after_deg; })
      .def_property_readonly("holdout_rms_before_deg",
                             [](const Loop& l) { return l.summary.holdout_rms_before_deg; })
      .def_property_readonly("holdout_rms_after_deg",
                             [](const Loop& l) { return l.summary.holdout_rms_after_deg; })
      .def_property_readonly("simulations", [](const Loop& l) { return l.summary.simulations; })
      .def_property_readonly("wall_time_s", [](const Loop& l) { return l.summary.wall_time_s; })
      .def_property_readonly(
          "declared",
          [](const Loop& l) {
            return std::make_shared<Fit>(Fit{l.summary.declared, l.training});
          },
          "The declared model's Fit.")
      .def_property_readonly(
          "final_fit",
          [](const Loop& l) {
            return std::make_shared<Fit>(Fit{l.summary.final_fit, l.training});
          },
          "The final model's Fit (the declared one when nothing was added).")
      .def(
          "full_report", [](const Loop& l) { return l.summary.FullReport(); },
          "What `ccsrm loop` prints at the end.")
      .def(
          "json",
          [](const Loop& l) {
            return identify::ToJson(l.summary, l.training, l.holdout).dump(2) + "\n";
          },
          "loop.json's summary (schema ccsrm-loop/1).")
      .def(
          "to_dict",
          [](const Loop& l) {
            return py::module_::import("json").attr("loads")(
                identify::ToJson(l.summary, l.training, l.holdout).dump());
          },
          "json() as a dict.")
      .def(
          "write",
          [](const Loop& l, const py::object& directory, bool overwrite) {
            const std::string dir = PathString(directory);
            CheckWriterPath(dir, identify::LoopFolderOutput(), overwrite);
            py::gil_scoped_release release;
            return identify::WriteLoopDirectory(l.summary, l.training, l.holdout, dir);
          },
          py::arg("directory"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the loop folder `ccsrm loop --out` writes. An existing folder is replaced only "
          "when it is an earlier loop folder holding nothing but what ccsrm wrote, or with "
          "overwrite=True.")
      .def("__repr__", [](const Loop& l) { return "<ccsrm.Loop " + l.summary.conclusion + ">"; });

  m.def("loop", &RunLoop, py::arg("data"), py::kw_only(), py::arg("holdout") = py::none(),
        py::arg("candidates") = py::none(), py::arg("free") = py::none(),
        py::arg("params") = py::none(), py::arg("set") = py::none(), py::arg("config") = py::none(),
        py::arg("threads") = py::none(), py::arg("max_rounds") = identify::LoopOptions().max_rounds,
        py::arg("max_iterations") = identify::IdentificationOptions().max_iterations,
        py::arg("noise_deg") = py::none(), py::arg("out") = py::none(), py::arg("resume") = false,
        py::arg("progress") = py::none(),
        "Closes the loop as `ccsrm loop` does, with its options: data (training experiments), "
        "holdout (held-out experiments), candidates (effects, a list or 'a,b'; default every "
        "effect that is off), free (the declared model's free parameters; default mu,mu_c,T_p), "
        "params, set, config (the declared arm instead of each recording's own), threads, "
        "max_rounds, max_iterations, noise_deg, out (also write the loop folder, under the "
        "command's output policy), resume (run again over the journal of the loop stopped in "
        "out), progress (called with each progress line). Returns a Loop. The GIL is "
        "released while it runs.");
}

// ccsrm.Prediction and ccsrm.predict.
void AddPrediction(py::module_& m) {
  const auto json_dict = [](const Prediction& p) {
    return py::module_::import("json").attr("loads")(identify::ToJson(p.summary).dump());
  };
  py::class_<Prediction, std::shared_ptr<Prediction>>(
      m, "Prediction",
      "The result of ccsrm.predict: each recording simulated from its own inputs with the "
      "model and compared as identification compares, with pred.json.")
      .def_property_readonly("completed", [](const Prediction& p) { return p.summary.completed; })
      .def_property_readonly(
          "message", [](const Prediction& p) { return p.summary.message; },
          "'every run completed', or the first run that did not, '<recording>: <why>'.")
      .def_property_readonly(
          "adequate", [](const Prediction& p) { return p.summary.adequacy.adequate(); },
          "Whether the model explains the recordings (no channel above its noise).")
      .def_property_readonly("verdict",
                             [](const Prediction& p) { return p.summary.adequacy.Verdict(); })
      .def_property_readonly(
          "rms_deg", [](const Prediction& p) { return p.summary.errors.channels.rms_deg_overall; },
          "RMS error of the predicted joint angles over every recording [deg] (NaN without "
          "angles).")
      .def_property_readonly(
          "weighted_rms", [](const Prediction& p) { return p.summary.errors.weighted_rms; },
          "RMS of the residuals over their noise, 1 at the noise floor.")
      .def_property_readonly(
          "tracked_points",
          [](const Prediction& p) {
            py::dict d;
            for (const identify::RecordingPrediction& r : p.summary.recordings) {
              if (r.tracked_points.empty()) continue;
              py::dict e;
              e["rms_mm"] = r.points.rms_mm;
              e["rms_mean_removed_mm"] = r.points.rms_mean_removed_mm;
              e["placement_from_fit"] = r.placement_from_fit;
              d[py::str(r.name)] = e;
            }
            return d;
          },
          "Per recording of tracked points: the points' RMS error [mm], the same with the mean "
          "offset removed (the publishing project's metric) and whether the capture placement "
          "came from the fit.")
      .def_property_readonly("simulations",
                             [](const Prediction& p) { return p.summary.simulations; })
      .def_property_readonly("wall_time_s",
                             [](const Prediction& p) { return p.summary.wall_time_s; })
      .def("brief_report", [](const Prediction& p) { return p.summary.BriefReport(); })
      .def(
          "full_report", [](const Prediction& p) { return p.summary.FullReport(); },
          "The report `ccsrm predict` prints.")
      .def(
          "json", [](const Prediction& p) { return identify::ToJson(p.summary).dump(2) + "\n"; },
          "pred.json's summary (schema ccsrm-prediction/1).")
      .def("to_dict", json_dict, "json() as a dict.")
      .def(
          "write",
          [](const Prediction& p, const py::object& directory, bool overwrite) {
            const std::string dir = PathString(directory);
            CheckWriterPath(dir, identify::PredictionFolderOutput(), overwrite);
            py::gil_scoped_release release;
            return identify::WritePredictionDirectory(p.summary, p.recordings, dir);
          },
          py::arg("directory"), py::kw_only(), py::arg("overwrite") = false,
          "Writes the prediction folder `ccsrm predict --out` writes. An existing folder is "
          "replaced only when it is an earlier prediction folder holding nothing but what ccsrm "
          "wrote, or with overwrite=True.")
      .def("__repr__", [](const Prediction& p) {
        return "<ccsrm.Prediction " + p.summary.BriefReport() + ">";
      });

  m.def("predict", &RunPredict, py::arg("data"), py::kw_only(), py::arg("params"),
        py::arg("effects") = py::none(), py::arg("config") = py::none(),
        py::arg("threads") = py::none(), py::arg("noise_deg") = py::none(),
        py::arg("point_noise_mm") = identify::ExperimentLoadOptions().point_noise_mm,
        py::arg("out") = py::none(),
        "Predicts recordings with a fitted model as `ccsrm predict` does, with its options: "
        "data (one or more ccsrm-dataset/1 files), params (a fit.json, a fit or loop folder, or "
        "a parameter file), effects (a YAML file switching effects on over the model), config "
        "(an arm instead of each recording's own), threads, noise_deg, point_noise_mm, out "
        "(also write the prediction folder, under the command's output policy). Returns a "
        "Prediction; a run that does not complete is reported in it (completed, message), not "
        "raised. The GIL is released while it runs.");
}

}  // namespace

void AddIdentification(py::module_& m) {
  AddFitClasses(m);
  m.def("identify", &RunIdentify, py::arg("data"), py::kw_only(), py::arg("free") = py::none(),
        py::arg("params") = py::none(), py::arg("set") = py::none(),
        py::arg("threads") = py::none(),
        py::arg("max_iterations") = identify::IdentificationOptions().max_iterations,
        py::arg("relative_step") = identify::IdentificationOptions().relative_step,
        py::arg("noise_deg") = py::none(),
        py::arg("point_noise_mm") = identify::ExperimentLoadOptions().point_noise_mm,
        py::arg("central_throughout") = false, py::arg("out") = py::none(),
        py::arg("resume") = false, py::arg("progress") = py::none(),
        "Fits parameters to recorded experiments as `ccsrm identify` does, with its options: "
        "data (one or more ccsrm-dataset/1 files), free (names, a list or 'mu,T_p'; default "
        "SPEC 6's nine), params (a parameter file), set (dict or 'name=value' strings), "
        "threads (default every core), max_iterations, relative_step, noise_deg (default "
        "estimated), point_noise_mm (of tracked points' coordinates), central_throughout, out "
        "(also write the fit folder, under the command's "
        "output policy: an earlier fit folder is replaced, anything else refused), resume "
        "(continue the fit stopped in out from its checkpoint), progress (called "
        "after every iteration with a dict: iteration, cost, rms_deg, rms_mm (tracked points; "
        "NaN without), step_accepted, "
        "simulations, wall_time_s, values). Returns a Fit. The "
        "GIL is released during the fit.");
  AddLoop(m);
  AddPrediction(m);
  m.def("default_threads", &identify::DefaultThreads, "Simulations at a time by default.");
}

}  // namespace ccsrm::python
