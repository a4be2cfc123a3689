#pragma once
// The parts of the module oobleck._oobleck (python/src/module.cpp), one function per topic, and
// the conversion they share. Each part only converts arguments and results around liboobleck.
#include <algorithm>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace oobleck::python {

namespace py = pybind11;

/// A copy of `v` as a 1-D numpy array.
inline py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// The class Params (rheology::Preset) with its validated properties (bind_params.cpp).
void bind_params(py::module_& m);
/// Steady rheology, fits and instrument exports (bind_rheology.cpp).
void bind_rheology(py::module_& m);
/// Point experiments: point_shear, point_relax (bind_point.cpp).
void bind_point(py::module_& m);
/// Scene runs: run_scene (bind_run.cpp).
void bind_run(py::module_& m);

}  // namespace oobleck::python
