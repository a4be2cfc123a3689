// oobleck._oobleck's steady rheology (flow curves E11, the DST rate E14, the structure f(tau),
// mass to volume fraction, every steady state at a rate or stress), the fits, and instrument
// exports read as tables.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include "bind.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/rheology/fit.hpp"
#include "oobleck/rheology/fit_curves.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"
#include "oobleck/rheology/steady_states.hpp"
#include "oobleck/rheology/structure_evolution.hpp"
#include "oobleck/rheology/volume_fraction.hpp"

namespace oobleck::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The flow curves at one or several phi as one (9, rows) C-contiguous array, row k the k-th
/// column of `rheology flow-curve` (rheology::kFlowCurveColumns, FLOW_CURVE_COLUMNS in Python):
/// one allocation, filled in place by rheology::flow_curve_columns without the GIL (no copy after
/// the sweep); the Python side views its rows as a dict or wraps it (transposed, no copy) as a
/// DataFrame. `phi` is a float or a sequence of floats.
py::array_t<double> flow_curve(const rheology::Preset& p, py::handle phi, int points) {
  if (points < 2) throw InputError(fmt::format("points = {}: must be >= 2", points));
  double one = 0.0;
  std::vector<double> many;
  const double* phis = &one;
  std::size_t n = 1;
  if (PyFloat_Check(phi.ptr())) {
    one = PyFloat_AS_DOUBLE(phi.ptr());
  } else {
    many = phi.cast<std::vector<double>>();
    phis = many.data();
    n = many.size();
  }
  for (std::size_t k = 0; k < n; ++k) {  // the message is formatted only for a bad phi
    const double v = phis[k];
    if (!(std::isfinite(v) && v > 0.0 && v < p.steady.phi_j))
      rheology::validate_phi(p.steady, v, fmt::format("phi (parameters: {})", p.name));
  }
  const auto rows = static_cast<py::ssize_t>(n) * points;
  py::array_t<double> block({py::ssize_t{9}, rows});
  {
    py::gil_scoped_release release;
    rheology::flow_curve_columns(p.steady, std::span<const double>(phis, n), points,
                                 std::span<double>(block.mutable_data(), static_cast<std::size_t>(9 * rows)));
  }
  return block;
}

std::optional<double> shear_rate_dst(const rheology::Preset& p, double phi) {
  rheology::validate_phi(p.steady, phi, fmt::format("phi (parameters: {})", p.name));
  return rheology::shear_rate_dst(p.steady, phi);
}

py::dict structure(const rheology::Preset& p, int points) {
  if (points < 2) throw InputError(fmt::format("points = {}: must be >= 2", points));
  std::vector<double> c[4];
  const double ts = p.steady.tau_star;
  for (int k = 0; k < points; ++k) {  // as `oobleck rheology structure`
    const double tau = ts * std::pow(10.0, -3.0 + 6.0 * k / (points - 1));
    const double H = rheology::hardening(tau, ts);           // E7 with tau_bar ~ tau
    const double f_model = rheology::steady_f(H, 1.0, 1.0);  // E10, S = 1 (eta_B -> inf), f_m = 1
    c[0].push_back(tau);
    c[1].push_back(f_model);
    c[2].push_back(1.0 - std::exp(-tau / ts));
    c[3].push_back(std::exp(-ts / tau));
  }
  py::dict d;
  d["stress"] = to_array(c[0]);
  d["f_model"] = to_array(c[1]);
  d["f_wyart_cates"] = to_array(c[2]);
  d["f_singh"] = to_array(c[3]);
  return d;
}

double volume_fraction(double mass_fraction, double rho_cs, double rho_liquid, double rho_water, double lambda,
                       double beta) {
  rheology::MassFractionInput in;
  in.mass_fraction = mass_fraction;
  in.rho_cs = rho_cs;
  in.rho_liquid = rho_liquid;
  in.rho_water = rho_water;
  in.lambda = lambda;
  in.beta = beta;
  rheology::validate_mass_fraction_input(in);
  return rheology::volume_fraction(in);
}

/// Every branch at each value: arrays (N, B) of viscosity, f, shear rate and stress, NaN-padded.
py::dict states_at(const rheology::Preset& p, double phi, const std::vector<double>& values, bool by_rate) {
  rheology::validate_phi(p.steady, phi, fmt::format("phi (parameters: {})", p.name));
  const char* what = by_rate ? "shear_rate" : "shear_stress";
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!(std::isfinite(values[k]) && values[k] > 0.0)) {
      throw InputError(fmt::format("{}[{}] = {}: must be a positive finite number [{}]", what, k, values[k],
                                   by_rate ? "1/s" : "Pa"));
    }
  }
  std::vector<std::vector<rheology::SteadyPoint>> all(values.size());
  std::size_t branches = 1;
  {
    py::gil_scoped_release release;
    const auto control = by_rate ? rheology::Control::shear_rate : rheology::Control::shear_stress;
    for (std::size_t k = 0; k < values.size(); ++k) {
      all[k] = rheology::steady_states_at(p.steady, phi, control, values[k]);
      branches = std::max(branches, all[k].size());
    }
  }
  const auto n = static_cast<py::ssize_t>(values.size()), b = static_cast<py::ssize_t>(branches);
  py::array_t<double> visc({n, b}), f({n, b}), rate({n, b}), stress({n, b});
  auto V = visc.mutable_unchecked<2>();
  auto F = f.mutable_unchecked<2>();
  auto R = rate.mutable_unchecked<2>();
  auto S = stress.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    for (py::ssize_t j = 0; j < b; ++j) {
      const auto& row = all[static_cast<std::size_t>(i)];
      const bool has = static_cast<std::size_t>(j) < row.size();
      const rheology::SteadyPoint* s = has ? &row[static_cast<std::size_t>(j)] : nullptr;
      V(i, j) = has ? s->viscosity : kNaN;
      F(i, j) = has ? s->f : kNaN;
      R(i, j) = has ? s->shear_rate : kNaN;
      S(i, j) = has ? s->shear_stress : kNaN;
    }
  }
  py::dict d;
  d["viscosity"] = visc;
  d["f"] = f;
  d["shear_rate"] = rate;
  d["shear_stress"] = stress;
  return d;
}

py::list fitted_parameters(const std::vector<rheology::FittedParameter>& ps) {
  py::list l;
  for (const auto& q : ps) l.append(py::make_tuple(q.name, q.value, q.std_error));
  return l;
}

/// The CLI's fits (low, high, dst); values as `oobleck rheology fit` reads them (eta_r or 1/s).
py::dict fit_asymptote(const std::string& kind_text, const std::vector<double>& phi, const std::vector<double>& values,
                       const rheology::Preset& base, int terms, const std::string& where) {
  const rheology::FitKind kind = rheology::parse_fit_kind(kind_text, "kind");
  rheology::FitOptions options;
  options.terms = terms;
  options.where = where;
  rheology::validate_fit_data(kind, phi, values, base.steady, options);
  rheology::FitResult r;
  {
    py::gil_scoped_release release;
    r = rheology::fit(kind, phi, values, base.steady, options);
  }
  rheology::Preset fitted = base;
  fitted.steady = r.params;
  try {
    rheology::validate(fitted, "fitted parameters");
  } catch (const InputError& e) {
    throw NumericalError(fmt::format("the fitted parameters break a rule: {}", e.what()));
  }
  std::vector<double> model, residuals;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    model.push_back(rheology::fit_model_value(kind, r.params, phi[k]));
    residuals.push_back(std::log(model.back()) - std::log(values[k]));
  }
  py::dict d;
  d["params"] = fitted;
  d["parameters"] = fitted_parameters(r.parameters);
  d["n"] = r.n;
  d["p"] = r.p;
  d["rms"] = r.rms;
  d["cost"] = r.cost;
  d["iterations"] = r.iterations;
  d["covariance_ok"] = r.covariance_ok;
  d["model"] = to_array(model);
  d["residuals"] = to_array(residuals);
  return d;
}

double fit_model_value(const std::string& kind, const rheology::Preset& p, double phi) {
  return rheology::fit_model_value(rheology::parse_fit_kind(kind, "kind"), p.steady, phi);
}

py::dict fit_curves(const std::vector<double>& phi, const std::vector<double>& rate, const std::vector<double>& stress,
                    const rheology::Preset& base, const std::vector<std::string>& names, const std::string& residual,
                    const std::vector<std::tuple<std::string, double, double>>& bounds, const std::string& where,
                    bool strict) {
  rheology::CurvesFitOptions o;
  o.strict = strict;
  o.parameters = names;
  o.residual = rheology::parse_curves_residual(residual, "residual");
  for (const auto& [name, lo, hi] : bounds) o.bounds.push_back({name, lo, hi});
  o.where = where;
  rheology::CurvesFitResult r;
  {
    py::gil_scoped_release release;
    r = rheology::fit_curves(phi, rate, stress, base, o);
  }
  const auto n = static_cast<py::ssize_t>(r.parameters.size());
  py::array_t<double> corr({n, n}), cov({n, n});
  auto C = corr.mutable_unchecked<2>();
  auto V = cov.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    for (py::ssize_t j = 0; j < n; ++j) {
      C(i, j) = r.correlation[static_cast<std::size_t>(i * n + j)];
      V(i, j) = r.covariance[static_cast<std::size_t>(i * n + j)];
    }
  }
  py::dict d;
  d["params"] = r.fitted;
  d["parameters"] = fitted_parameters(r.parameters);
  d["correlation"] = corr;
  d["covariance"] = cov;
  d["residuals"] = to_array(r.residuals);
  d["model"] = to_array(r.model);
  d["n"] = r.n;
  d["p"] = r.p;
  d["rms"] = r.rms;
  d["cost"] = r.cost;
  d["iterations"] = r.iterations;
  d["residual"] = rheology::to_string(o.residual);
  py::list held;
  for (const auto& h : r.held) held.append(py::make_tuple(h.name, h.value, h.reason));
  d["held"] = held;
  return d;
}

// ---- instrument exports ----------------------------------------------------------------------

/// An export as the columns of oobleck.read_rheometer's DataFrame: {"names", "columns" (arrays of
/// numbers or lists of str), "attrs"}.
py::dict read_rheometer(const std::string& path, const std::string& format, const std::string& step) {
  io::RheometerFile f;
  io::RheometerTable t;
  std::vector<std::size_t> steps;
  {
    py::gil_scoped_release release;
    f = io::read_rheometer(path, io::parse_rheometer_format(format, "format"));
    if (!step.empty()) steps = io::select_steps(f, step, "step");
    t = io::to_table(f, steps);
  }
  py::list names, columns;
  py::dict units, si_units, metadata;
  for (const auto& c : t.columns) {
    names.append(c.name);
    if (c.is_text) {
      columns.append(py::cast(c.text));
    } else {
      columns.append(to_array(c.values));
    }
    if (!c.si_unit.empty()) si_units[py::str(c.name)] = c.si_unit;
    if (!c.units_read.empty()) units[py::str(c.name)] = c.units_read;
  }
  py::dict attrs;
  attrs["file"] = path;
  attrs["format"] = io::to_string(f.format);
  attrs["encoding"] = f.encoding;
  attrs["separator"] = std::string(1, f.separator);
  attrs["decimal"] = std::string(1, f.decimal);
  for (const char* key : {"sample", "geometry", "instrument", "operator", "date", "procedure", "project", "test"}) {
    const auto it = f.attributes.find(key);
    if (it != f.attributes.end()) attrs[key] = it->second;
  }
  for (const auto& [key, value] : f.attributes) metadata[py::str(key)] = value;
  py::list step_names;
  for (std::size_t k = 0; k < f.steps.size(); ++k) {
    if (steps.empty() || std::find(steps.begin(), steps.end(), k) != steps.end()) step_names.append(f.steps[k].name);
  }
  attrs["steps"] = step_names;
  attrs["units"] = units;
  attrs["si_units"] = si_units;
  attrs["metadata"] = metadata;
  py::dict d;
  d["names"] = names;
  d["columns"] = columns;
  d["attrs"] = attrs;
  return d;
}

/// The flow-curve rows of an export (as `rheology fit --data FILE [--step S]`): shear rate
/// [1/s], shear stress [Pa], the steps used, the rows skipped.
py::tuple rheometer_flow_curve(const std::string& path, const std::string& step) {
  io::FlowCurveRows rows;
  std::vector<std::string> used;
  {
    py::gil_scoped_release release;
    const io::RheometerFile f = io::read_rheometer(path);
    rows = io::flow_curve_rows(f, step, "step");
    for (std::size_t k : rows.steps) used.push_back(f.steps[k].name);
  }
  return py::make_tuple(to_array(rows.shear_rate), to_array(rows.shear_stress), used, rows.skipped);
}

}  // namespace

void bind_rheology(py::module_& m) {
  py::list flow_curve_columns;
  for (std::string_view name : rheology::kFlowCurveColumns) flow_curve_columns.append(py::str(std::string(name)));
  m.attr("FLOW_CURVE_COLUMNS") = py::tuple(flow_curve_columns);
  m.def("flow_curve", &flow_curve, py::arg("params"), py::arg("phi"), py::arg("points"));
  m.def("shear_rate_dst", &shear_rate_dst, py::arg("params"), py::arg("phi"));
  m.def("structure", &structure, py::arg("params"), py::arg("points"));
  m.def("volume_fraction", &volume_fraction, py::arg("mass_fraction"), py::arg("rho_cs"), py::arg("rho_liquid"),
        py::arg("rho_water"), py::arg("lambda_"), py::arg("beta"));
  m.def("states_at", &states_at, py::arg("params"), py::arg("phi"), py::arg("values"), py::arg("by_rate"));
  m.def("fit_asymptote", &fit_asymptote, py::arg("kind"), py::arg("phi"), py::arg("values"), py::arg("base"),
        py::arg("terms"), py::arg("where"));
  m.def("fit_model_value", &fit_model_value, py::arg("kind"), py::arg("params"), py::arg("phi"));
  m.def("fit_curves", &fit_curves, py::arg("phi"), py::arg("shear_rate"), py::arg("shear_stress"), py::arg("base"),
        py::arg("parameters"), py::arg("residual"), py::arg("bounds"), py::arg("where"), py::arg("strict") = false);
  m.def("curves_default_parameters", &rheology::curves_default_parameters, py::arg("base"));
  m.def("read_rheometer", &read_rheometer, py::arg("path"), py::arg("format"), py::arg("step"));
  m.def("rheometer_flow_curve", &rheometer_flow_curve, py::arg("path"), py::arg("step"));
}

}  // namespace oobleck::python
