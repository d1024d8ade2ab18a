#pragma once
// Shared pieces of the Python module (python/src/*.cc): numpy views of the
// library's arrays and the registration function of each part.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>
#include <vector>

#include "ccsrm/common/output_policy.h"
#include "ccsrm/datasets/array.h"

namespace ccsrm::python {

namespace py = pybind11;

// A read-only numpy view of `values` (row-major, of `shape`) that keeps
// `owner` (the Python object holding the memory) alive: no copy is made.
// Read-only because the owner's other views and summaries describe the same
// numbers; .copy() gives a writable array.
py::array View(const double* values, const std::vector<std::size_t>& shape,
               const py::object& owner);
py::array View(const datasets::Array& array, const py::object& owner);

// A copy of `values` as a new numpy array (for small vectors built on the fly).
py::array Copy(const std::vector<double>& values);

// `value` as a T, or TypeError "<name>: expected <expected>, found <type>"
// (pybind11's own cast_error would reach Python as a RuntimeError naming a
// C++ type).
template <typename T>
T CastArgument(const py::handle& value, const char* name, const char* expected) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(name) + ": expected " + expected + ", found " +
                         py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() +
                         (py::hasattr(value, "shape")
                              ? " of shape " + py::str(value.attr("shape")).cast<std::string>()
                              : std::string()));
  }
}

// Reads a path argument (str or os.PathLike) as a string.
std::string PathString(const py::handle& path);

// A Python writer's `path` under the command line's output policy
// (common/output_policy.h): refused (InputError naming the path) unless it
// is new, empty or an earlier output of `kind`; `overwrite` (the writer's
// overwrite=True) replaces whatever is there.
void CheckWriterPath(const std::string& path, OutputKind kind, bool overwrite);

void AddErrors(py::module_& m);
void AddParameters(py::module_& m);
void AddSimulation(py::module_& m);
void AddData(py::module_& m);
void AddIdentification(py::module_& m);

}  // namespace ccsrm::python
