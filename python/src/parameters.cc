// ccsrm.Parameters (sim::ArmParameters as a mapping by the table's names),
// ccsrm.ParameterInfo and the effect library.
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::python {
namespace {

// Where errors of a Parameters object say the value came from, in the form
// the command line's "--set: ..." has.
constexpr const char* kWhere = "Parameters";

// The names a Parameters object lists: the model's parameters, then those
// of each effect that is on. AllParameters would list every per-joint offset
// of every effect, most of them off.
std::vector<std::string> ListedNames(const sim::ArmParameters& p) {
  std::vector<std::string> names;
  for (const sim::ParameterInfo& info : sim::Parameters()) names.push_back(info.name);
  for (const std::string& effect : p.EnabledEffects()) {
    for (const std::string& name : sim::EffectParameterNames(effect, p.arm, kWhere))
      names.push_back(name);
  }
  return names;
}

bool Known(const sim::ArmParameters& p, const std::string& name) {
  for (const sim::ParameterInfo& info : sim::AllParameters(p.arm))
    if (info.name == name) return true;
  return false;
}

}  // namespace

void AddParameters(py::module_& m) {
  py::class_<sim::ParameterInfo>(m, "ParameterInfo",
                                 "One row of the parameter table (sim::Parameters): name, "
                                 "units, bounds, configuration key.")
      .def_readonly("name", &sim::ParameterInfo::name)
      .def_readonly("config_key", &sim::ParameterInfo::config_key,
                    "Its key in a configuration file ('' for an effect parameter).")
      .def_readonly("units", &sim::ParameterInfo::units, "SI units ('1': dimensionless).")
      .def_readonly("lower", &sim::ParameterInfo::lower, "Lower bound, checked by every door.")
      .def_readonly("upper", &sim::ParameterInfo::upper, "Upper bound.")
      .def_readonly("description", &sim::ParameterInfo::description)
      .def_readonly("effect", &sim::ParameterInfo::effect, "The effect it belongs to, or ''.")
      .def_readonly("realistic", &sim::ParameterInfo::realistic,
                    "Effect parameters: the magnitude an air-table arm realistically has.")
      .def_property_readonly("is_effect", &sim::ParameterInfo::is_effect)
      .def("__repr__", [](const sim::ParameterInfo& i) {
        return "<ParameterInfo " + i.name + " [" +
               py::str(py::float_(i.lower)).cast<std::string>() + ", " +
               py::str(py::float_(i.upper)).cast<std::string>() + "] " + i.units + ">";
      });

  py::class_<sim::ArmParameters>(
      m, "Parameters",
      "Friction, damping, pre-tension and effect parameters of one run, by the names of the "
      "command line's --set (mu, mu_s, ..., joint_friction.coulomb_nm). A mapping: p['mu'], "
      "p['mu'] = 0.2 (checked against the bounds; InputError otherwise), keys(), items(). "
      "Setting an effect's parameter switches the effect on. Get one from Model.parameters "
      "(a copy: changing it leaves the model as it is).")
      .def("__getitem__", [](const sim::ArmParameters& p,
                             const std::string& name) { return sim::GetParameter(p, name); })
      .def("__setitem__", [](sim::ArmParameters& p, const std::string& name,
                             double value) { sim::SetParameter(name, value, kWhere, &p); })
      .def("__contains__",
           [](const sim::ArmParameters& p, const std::string& name) { return Known(p, name); })
      .def("__len__", [](const sim::ArmParameters& p) { return ListedNames(p).size(); })
      .def("__iter__",
           [](const sim::ArmParameters& p) { return py::iter(py::cast(ListedNames(p))); })
      .def("keys", &ListedNames, "The model's parameters, then those of every effect that is on.")
      .def("items",
           [](const sim::ArmParameters& p) {
             std::vector<std::pair<std::string, double>> items;
             for (const std::string& name : ListedNames(p))
               items.emplace_back(name, sim::GetParameter(p, name));
             return items;
           })
      .def("to_dict",
           [](const sim::ArmParameters& p) {
             py::dict d;
             for (const std::string& name : ListedNames(p))
               d[py::str(name)] = sim::GetParameter(p, name);
             return d;
           })
      .def(
          "update",
          [](sim::ArmParameters& p, const std::map<std::string, double>& values) {
            // Checked whole first, so a bad entry changes nothing.
            sim::ArmParameters updated = p;
            for (const auto& [name, value] : values)
              sim::SetParameter(name, value, kWhere, &updated);
            p = std::move(updated);
          },
          py::arg("values"), "Sets several parameters; none changes if one is refused.")
      .def(
          "info",
          [](const sim::ArmParameters& p, const std::string& name) {
            return sim::FindParameter(name, kWhere, p.arm);
          },
          py::arg("name"), "The table's row of a parameter: units, bounds, description.")
      .def(
          "all_parameters", [](const sim::ArmParameters& p) { return sim::AllParameters(p.arm); },
          "Every parameter this arm has, effects' included (what identification offers).")
      .def_property_readonly("effects_on", &sim::ArmParameters::EnabledEffects,
                             "The effects that are on, in the library's order.")
      .def(
          "enable_effect",
          [](sim::ArmParameters& p, const std::string& effect, bool realistic) {
            if (realistic) {
              sim::EnableEffectAtRealisticMagnitude(effect, "enable_effect", &p);
            } else {
              p.EnableEffect(effect, "enable_effect");
            }
          },
          py::arg("effect"), py::arg("realistic") = false,
          "Switches an effect on: its parameters at their neutral defaults, or with "
          "realistic=True at the magnitudes `ccsrm generate --effect NAME` uses.")
      .def("disable_effect", &sim::ArmParameters::DisableEffect, py::arg("effect"))
      .def("copy", [](const sim::ArmParameters& p) { return p; })
      .def("__copy__", [](const sim::ArmParameters& p) { return p; })
      .def("__eq__",
           [](const sim::ArmParameters& a, const sim::ArmParameters& b) {
             return ListedNames(a) == ListedNames(b) && [&] {
               for (const std::string& n : ListedNames(a))
                 if (sim::GetParameter(a, n) != sim::GetParameter(b, n)) return false;
               return true;
             }();
           })
      .def("__repr__", [](const sim::ArmParameters& p) {
        std::string text = "Parameters(";
        bool first = true;
        for (const std::string& name : ListedNames(p)) {
          text += (first ? "" : ", ") + name + "=" +
                  py::repr(py::float_(sim::GetParameter(p, name))).cast<std::string>();
          first = false;
        }
        return text + ")";
      });

  m.def("parameter_table", &sim::Parameters,
        "The model's parameters (SPEC 6's nine, then v_s, v_c_s, tau_f, tau_c_f, xi_f, xi_c, "
        "k_b, c_b) with units and bounds.");

  py::class_<sim::EffectInfo>(m, "EffectInfo", "One effect of the effect library (SPEC 7).")
      .def_readonly("name", &sim::EffectInfo::name)
      .def_readonly("description", &sim::EffectInfo::description)
      .def_readonly("measurement", &sim::EffectInfo::measurement,
                    "True for an effect on what is measured, not on the dynamics.")
      .def_readonly("fingerprint", &sim::EffectInfo::fingerprint)
      .def("__repr__", [](const sim::EffectInfo& e) {
        return "<EffectInfo " + e.name + ": " + e.description + ">";
      });
  m.def("effects", &sim::Effects, "Every effect of the library, in its fixed order.");
}

}  // namespace ccsrm::python
