// oobleck._oobleck: the Python module's compiled core (pybind11). Every number comes from the
// same library as the CLI (liboobleck); the module only converts arguments and results, runs the
// long computations without the GIL and maps oobleck::InputError / NumericalError to the Python
// exceptions oobleck.InputError / oobleck.NumericalError with the same message. The bindings are
// split by topic (bind.hpp): Params, rheology, point experiments, runs. The Python package
// (python/oobleck) builds DataFrames and the user-facing signatures on top.
#include <exception>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "oobleck/core/build_info.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/rheology/params.hpp"

namespace py = pybind11;
using namespace oobleck;

PYBIND11_MODULE(_oobleck, m) {
  m.doc() = "oobleck's compiled core (pybind11 over liboobleck); use the package oobleck, not this module";
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<NumericalError> numerical_error(m, "NumericalError", PyExc_RuntimeError);
  // pybind11's translator type is the function pointer void (*)(std::exception_ptr): the lambda
  // must take the pointer by value to convert to it.
  // NOLINTNEXTLINE(performance-unnecessary-value-param)
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical_error.ptr(), e.what());
    }
  });

  m.def("version", &version_string, "oobleck's version and build (as `oobleck --version`)");
  m.def("library_instruction_set", &library_instruction_set,
        "which CPU variant of liboobleck is loaded (glibc-hwcaps level)");
  m.def("preset_names", &rheology::preset_names);
  m.def("preset_dir", &rheology::preset_dir);
  m.def("load_preset", &rheology::load_preset, py::arg("name"));
  m.def("load_params_file", &rheology::load_params_file, py::arg("path"));

  python::bind_params(m);
  python::bind_rheology(m);
  python::bind_point(m);
  python::bind_run(m);
}
