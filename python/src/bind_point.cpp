// oobleck._oobleck's point experiments (E16–E24 at one homogeneous material point): the checks,
// time step and relaxation sweep of `oobleck point shear/relax` (material/point_driver.hpp),
// messages naming the Python arguments; the runs without the GIL, results as dicts of arrays.
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bind.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::python {
namespace {

py::dict point_shear(const rheology::Preset& p, double phi, std::optional<double> rate, std::optional<double> stress,
                     double duration, std::optional<double> dt, double f0, int samples) {
  material::ShearInput in;
  in.phi = phi;
  in.shear_rate = rate;
  in.shear_stress = stress;
  in.duration = duration;
  in.dt = dt;
  in.f0 = f0;
  in.samples = samples;
  material::validate(in, material::ArgStyle::python);
  material::ShearResult res;
  double used_dt = 0.0;
  {
    py::gil_scoped_release release;
    const material::GranularLaw law(p);
    const material::ShearOptions so = material::shear_options(law, in);
    used_dt = so.dt;
    res = material::run_shear(law, so);
  }
  std::vector<double> c[16];
  std::vector<std::string> regime;
  for (const auto& x : res.samples) {
    const double v[16] = {x.time,
                          x.strain,
                          x.shear_rate,
                          x.shear_stress,
                          x.granular_shear_stress,
                          x.granular_pressure,
                          x.sigma_xy,
                          x.f,
                          x.phi,
                          x.gamma_dot_p,
                          x.I_v,
                          x.I_m,
                          x.beta,
                          x.mu_p,
                          x.phi_eq,
                          static_cast<double>(x.iterations)};
    for (int k = 0; k < 16; ++k) c[k].push_back(v[k]);
    regime.emplace_back(material::regime_name(x.regime));
  }
  static const char* names[16] = {"time",
                                  "strain",
                                  "shear_rate",
                                  "shear_stress",
                                  "granular_shear_stress",
                                  "granular_pressure",
                                  "sigma_xy",
                                  "f",
                                  "phi",
                                  "gamma_dot_p",
                                  "I_v",
                                  "I_m",
                                  "beta",
                                  "mu_p",
                                  "phi_eq",
                                  "iterations"};
  py::dict d;
  for (int k = 0; k < 16; ++k) d[names[k]] = to_array(c[k]);
  d["regime"] = regime;
  d["dt"] = used_dt;
  d["steps"] = res.steps;
  return d;
}

py::dict point_relax(const rheology::Preset& base, double phi, std::optional<double> rate, std::optional<double> stress,
                     double duration, std::optional<double> dt, int samples, std::vector<double> Gs,
                     std::vector<double> K0s) {
  material::RelaxInput in;
  in.phi = phi;
  in.shear_rate = rate;
  in.shear_stress = stress;
  in.duration = duration;
  in.dt = dt;
  in.samples = samples;
  in.G = std::move(Gs);
  in.K_0 = std::move(K0s);
  material::validate(in, base.steady, material::ArgStyle::python);
  std::vector<material::RelaxResult> results;
  {
    py::gil_scoped_release release;
    results = material::run_relax_sweep(base, in);
  }
  const auto columns = material::relax_columns();
  std::vector<std::vector<double>> c(columns.size());
  std::vector<std::string> regime;
  for (std::size_t k = 0; k < results.size(); ++k) {
    for (const auto& x : results[k].samples) {
      const auto row = material::relax_row(k, results[k], x);
      for (std::size_t j = 0; j < columns.size(); ++j)
        if (!columns[j].unit.empty()) c[j].push_back(row[j]);
      regime.emplace_back(material::regime_name(x.regime));
    }
  }
  py::dict d;
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (!columns[j].unit.empty()) d[py::str(std::string(columns[j].name))] = to_array(c[j]);
  d["regime"] = regime;
  return d;
}

}  // namespace

void bind_point(py::module_& m) {
  py::list relax_columns;
  for (const material::PointColumn& c : material::relax_columns()) relax_columns.append(py::str(std::string(c.name)));
  m.attr("RELAX_COLUMNS") = py::tuple(relax_columns);
  m.def("point_shear", &point_shear, py::arg("params"), py::arg("phi"), py::arg("shear_rate"), py::arg("shear_stress"),
        py::arg("duration"), py::arg("dt"), py::arg("f0"), py::arg("samples"));
  m.def("point_relax", &point_relax, py::arg("params"), py::arg("phi"), py::arg("shear_rate"), py::arg("shear_stress"),
        py::arg("duration"), py::arg("dt"), py::arg("samples"), py::arg("G"), py::arg("K0"));
}

}  // namespace oobleck::python
