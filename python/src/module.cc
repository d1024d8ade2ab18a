// The `ccsrm._core` extension: the library's public API for Python. Every
// function here calls the same library functions as the command line; the
// module adds no physics and no checks of its own (STYLE: bindings sit over
// the public headers).
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/version.h"

namespace ccsrm::python {

py::array View(const double* values, const std::vector<std::size_t>& shape,
               const py::object& owner) {
  std::vector<py::ssize_t> extents(shape.begin(), shape.end());
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t stride = sizeof(double);
  for (std::size_t i = shape.size(); i-- > 0;) {
    strides[i] = stride;
    stride *= extents[i];
  }
  // With a base object numpy borrows the memory instead of copying it.
  py::array view(py::dtype::of<double>(), extents, strides, values, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

py::array View(const datasets::Array& array, const py::object& owner) {
  return View(array.values.data(), array.shape, owner);
}

py::array Copy(const std::vector<double>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return std::move(out);
}

std::string PathString(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path));
}

void CheckWriterPath(const std::string& path, OutputKind kind, bool overwrite) {
  kind.replace_any_existing = overwrite;
  CheckOutputPath(path, "path", kind, {});
}

void AddErrors(py::module_& m) {
  // A ValueError, so code that catches bad values generally catches it too;
  // its message is the library's one line, as the command line prints it.
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  // An argument of the wrong type that no CastArgument names: a TypeError
  // still, as Python's own functions raise, not pybind11's RuntimeError.
  py::register_local_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::cast_error& e) {
      PyErr_SetString(PyExc_TypeError, e.what());
    }
  });
}

}  // namespace ccsrm::python

PYBIND11_MODULE(_core, m) {
  namespace cp = ccsrm::python;
  m.doc() =
      "ccsrm: simulation, identification and experiment files of cable-driven continuum "
      "manipulators (the C++ library, from Python).";
  m.attr("__version__") = ccsrm::kVersion;
  cp::AddErrors(m);
  cp::AddParameters(m);
  cp::AddSimulation(m);
  cp::AddData(m);
  cp::AddIdentification(m);
}
