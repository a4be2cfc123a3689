// oobleck._oobleck: the Python module's compiled core (pybind11). Every number comes from the
// same library as the CLI (liboobleck); this file only converts arguments and results, runs the
// long computations without the GIL and maps oobleck::InputError / NumericalError to the Python
// exceptions oobleck.InputError / oobleck.NumericalError with the same message. The Python
// package (python/oobleck/__init__.py) builds DataFrames and the user-facing signatures on top.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include "oobleck/core/build_info.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/fit.hpp"
#include "oobleck/rheology/fit_curves.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"
#include "oobleck/rheology/steady_states.hpp"
#include "oobleck/rheology/structure_evolution.hpp"
#include "oobleck/rheology/volume_fraction.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

namespace py = pybind11;
using namespace oobleck;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// A property of Params: get a double field, set it on a copy, validate the copy, commit.
template <class Get>
void number_property(py::class_<rheology::Preset>& cls, const char* name, Get get, const char* doc) {
  cls.def_property(
      name, [get](const rheology::Preset& p) { return *get(const_cast<rheology::Preset&>(p)); },
      [get, name](rheology::Preset& p, double v) {
        rheology::Preset q = p;
        *get(q) = v;
        rheology::validate(q, fmt::format("Params.{}", name));
        p = q;
      },
      doc);
}

// ---- rheology ------------------------------------------------------------------------------

/// The flow curves at one or several phi as one (9, rows) C-contiguous array, row k the k-th
/// column of `rheology flow-curve` (FLOW_CURVE_COLUMNS in Python): one allocation, filled in place
/// without the GIL (no copy after the sweep); the Python side views its rows as a dict or wraps
/// it (transposed, no copy) as a DataFrame. `phi` is a float or a sequence of floats.
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
  double* c = block.mutable_data();
  {
    py::gil_scoped_release release;
    std::size_t i = 0;
    const auto r = static_cast<std::size_t>(rows);
    for (std::size_t k = 0; k < n; ++k) {
      const double dst_rate = rheology::shear_rate_dst(p.steady, phis[k]).value_or(kNaN);
      for (const auto& pt : rheology::flow_curve(p.steady, phis[k], points)) {
        c[i] = pt.phi;
        c[r + i] = pt.f;
        c[2 * r + i] = pt.shear_rate;
        c[3 * r + i] = pt.shear_stress;
        c[4 * r + i] = pt.granular_pressure;
        c[5 * r + i] = pt.granular_shear_stress;
        c[6 * r + i] = pt.viscosity;
        c[7 * r + i] = pt.eta_r;
        c[8 * r + i] = dst_rate;
        ++i;
      }
    }
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

// ---- point experiments -----------------------------------------------------------------------

py::dict point_shear(const rheology::Preset& p, double phi, std::optional<double> rate, std::optional<double> stress,
                     double duration, std::optional<double> dt, double f0, int samples) {
  // The checks and the default time step of `oobleck point shear`, argument names as in Python.
  if (!(std::isfinite(phi) && phi > 0.0 && phi < 1.0))
    throw InputError(fmt::format("phi = {}: must lie in (0, 1)", phi));
  if (rate && stress) throw InputError("shear_rate and shear_stress: give one of them, not both");
  if (!rate && !stress) throw InputError("one of shear_rate or shear_stress is required");
  const bool by_stress = stress.has_value();
  if (!by_stress && !(std::isfinite(*rate) && *rate > 0.0))
    throw InputError(fmt::format("shear_rate = {}: must be positive [1/s]", *rate));
  if (by_stress && !(std::isfinite(*stress) && *stress > 0.0))
    throw InputError(fmt::format("shear_stress = {}: must be positive [Pa]", *stress));
  if (!(std::isfinite(duration) && duration > 0.0))
    throw InputError(fmt::format("duration = {}: must be positive [s]", duration));
  if (dt && !(std::isfinite(*dt) && *dt > 0.0 && *dt <= duration))
    throw InputError(fmt::format("dt = {}: must lie in (0, duration = {}] [s]", *dt, duration));
  if (!(f0 >= 0.0 && f0 <= 1.0)) throw InputError(fmt::format("f0 = {}: must lie in [0, 1]", f0));
  if (samples < 2) throw InputError(fmt::format("samples = {}: must be >= 2", samples));
  material::ShearResult res;
  double used_dt = 0.0;
  {
    py::gil_scoped_release release;
    const material::GranularLaw law(p);
    material::ShearOptions so;
    so.phi = phi;
    so.stress_controlled = by_stress;
    so.shear_rate = by_stress ? 0.0 : *rate;
    so.shear_stress = by_stress ? *stress : 0.0;
    so.duration = duration;
    so.dt = dt ? *dt : 0.0;
    so.f0 = f0;
    so.samples = samples;
    if (so.dt <= 0.0) {
      const double rate_scale =
          by_stress ? *stress / (p.steady.eta_0 * rheology::eta_r_low(p.steady, std::min(phi, 0.999 * p.steady.phi_j)))
                    : *rate;
      so.dt = material::default_dt(law, phi, rate_scale, duration);
    }
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
  if (!(std::isfinite(phi) && phi > 0.0 && phi < 1.0))
    throw InputError(fmt::format("phi = {}: must lie in (0, 1)", phi));
  rheology::validate_phi(base.steady, phi, "phi");
  if (rate && stress) throw InputError("shear_rate and shear_stress: give one of them, not both");
  if (!rate && !stress) throw InputError("one of shear_rate or shear_stress is required");
  const bool by_stress = stress.has_value();
  if (!by_stress && !(std::isfinite(*rate) && *rate > 0.0))
    throw InputError(fmt::format("shear_rate = {}: must be positive [1/s]", *rate));
  if (by_stress && !(std::isfinite(*stress) && *stress > 0.0))
    throw InputError(fmt::format("shear_stress = {}: must be positive [Pa]", *stress));
  if (!(std::isfinite(duration) && duration > 0.0))
    throw InputError(fmt::format("duration = {}: must be positive [s]", duration));
  if (dt && !(std::isfinite(*dt) && *dt > 0.0 && *dt <= duration))
    throw InputError(fmt::format("dt = {}: must lie in (0, duration = {}] [s]", *dt, duration));
  if (samples < 2) throw InputError(fmt::format("samples = {}: must be >= 2", samples));
  for (double g : Gs)
    if (!(std::isfinite(g) && g > 0.0)) throw InputError(fmt::format("G = {}: must be positive [Pa]", g));
  for (double k : K0s)
    if (!(std::isfinite(k) && k > 0.0)) throw InputError(fmt::format("K0 = {}: must be positive", k));
  if (by_stress) (void)material::steady_rate_at_stress(base.steady, phi, *stress);  // range check
  if (Gs.empty()) Gs = {base.granular.G};
  if (K0s.empty()) K0s = {base.granular.K_0};
  std::vector<material::RelaxResult> results;
  {
    py::gil_scoped_release release;
    for (double K0 : K0s) {
      for (double G : Gs) {
        rheology::Preset p = base;
        p.granular.G = G;
        p.granular.K_0 = K0;
        const material::GranularLaw law(p);
        material::RelaxOptions ro;
        ro.phi = phi;
        ro.stress_controlled = by_stress;
        ro.shear_rate = by_stress ? 0.0 : *rate;
        ro.shear_stress = by_stress ? *stress : 0.0;
        ro.duration = duration;
        ro.dt = dt ? *dt : 0.0;
        ro.samples = samples;
        results.push_back(material::run_relax(law, ro));
      }
    }
  }
  std::vector<double> c[10];
  std::vector<std::string> regime;
  for (std::size_t k = 0; k < results.size(); ++k) {
    for (const auto& x : results[k].samples) {
      const double v[10] = {static_cast<double>(k), results[k].G,  results[k].K_0, x.time, x.tau_bar, x.p, x.f,
                            x.gamma_dot_p,          x.ode_tau_bar, x.ode_f};
      for (int j = 0; j < 10; ++j) c[j].push_back(v[j]);
      regime.emplace_back(material::regime_name(x.regime));
    }
  }
  static const char* names[10] = {"case",
                                  "G",
                                  "K_0",
                                  "time",
                                  "granular_shear_stress",
                                  "granular_pressure",
                                  "f",
                                  "gamma_dot_p",
                                  "ode_granular_shear_stress",
                                  "ode_f"};
  py::dict d;
  for (int k = 0; k < 10; ++k) d[names[k]] = to_array(c[k]);
  d["regime"] = regime;
  return d;
}

// ---- runs --------------------------------------------------------------------------------------

/// `oobleck run` without the GIL. Every 0.1 s (and at the end) the GIL is taken to deliver
/// signals (Ctrl-C: PyErr_CheckSignals raises KeyboardInterrupt, which stops the run after the
/// current step with a checkpoint) and to call `progress(done, total, time)`. Returns the summary
/// as JSON text and whether the run was interrupted; the pending Python exception, if any, is
/// raised by the caller (oobleck.run) after the run folder is complete.
py::tuple run_scene(const std::string& scene, const std::vector<std::string>& sets, const std::string& out, int threads,
                    long checkpoint_every, long stop_after, bool restart, py::object progress) {
  if (threads < 0) throw InputError(fmt::format("threads = {}: must be >= 0", threads));
  run::RunOptions ro;
  ro.threads = threads;
  ro.checkpoint_every = checkpoint_every;
  ro.quiet = true;  // progress is Python's (tqdm or text)
  ro.stop_after_steps = stop_after;
  scene::SceneConfig cfg;
  if (restart) {
    cfg = run::restart_scene(out, sets, ro);  // sets: [time] keys only
  } else {
    cfg = scene::load_scene(scene, sets);
    ro.out_dir = out.empty() ? "out/" + cfg.name : out;
  }
  bool interrupted = false;
  py::object error_type, error_value, error_trace;
  // With the GIL held: stop the run, keeping the pending Python exception for the caller.
  auto stop_with_pending_error = [&] {
    interrupted = true;
    PyObject *t = nullptr, *v = nullptr, *tb = nullptr;
    PyErr_Fetch(&t, &v, &tb);
    error_type = py::reinterpret_steal<py::object>(t);
    error_value = py::reinterpret_steal<py::object>(v);
    error_trace = py::reinterpret_steal<py::object>(tb);
    return false;
  };
  using clock = std::chrono::steady_clock;
  auto last = clock::now();
  ro.on_step = [&](long done, long total, double time) {
    const auto now = clock::now();
    if (done < total && now - last < std::chrono::milliseconds(100)) return true;
    last = now;
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) return stop_with_pending_error();
    if (!progress.is_none()) {
      try {
        progress(done, total, time);
      } catch (py::error_already_set& e) {
        e.restore();
        return stop_with_pending_error();
      }
    }
    return true;
  };
  nlohmann::json summary;
  {
    py::gil_scoped_release release;
    summary = run::run_scene(cfg, ro);
  }
  py::object err = py::none();
  if (interrupted && error_value)
    err = error_value;
  else if (interrupted && error_type)
    err = error_type();
  return py::make_tuple(summary.dump(), ro.out_dir, err);
}

}  // namespace

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

  py::class_<rheology::Preset> params(m, "Params",
                                      "A complete parameter set (a preset file): steady model (docs/equations.md, "
                                      "steady rheology) and granular law (docs/equations.md, time-dependent granular "
                                      "law). Every assignment is validated (oobleck.InputError).");
  params.def(py::init([](const rheology::Preset& p) { return p; }), py::arg("other"), "a copy");
  params.def_readwrite("name", &rheology::Preset::name, "name of the set (str)");
  params.def_readwrite("source", &rheology::Preset::source, "literature source (str)");
  params.def_property(
      "units", [](const rheology::Preset& p) { return p.units; },
      [](rheology::Preset& p, const std::string& u) {
        if (u != "SI" && u != "normalized")
          throw InputError(fmt::format("Params.units = '{}': must be 'SI' or 'normalized'", u));
        p.units = u;
      },
      "'SI' or 'normalized' (Singh presets: stresses in eta_0 gamma_dot_0)");
  params.def_readonly("file", &rheology::Preset::file, "file the set was read from ('' if built in code)");
  using P = rheology::Preset;
  number_property(
      params, "phi_c", [](P& p) { return &p.steady.phi_c; }, "[-] frictional jamming fraction");
  number_property(
      params, "phi_j", [](P& p) { return &p.steady.phi_j; }, "[-] frictionless jamming fraction");
  number_property(
      params, "a_0", [](P& p) { return &p.steady.a_0; }, "[-] dilation parameter at f = 0 (E2)");
  number_property(
      params, "a_inf", [](P& p) { return &p.steady.a_inf; }, "[-] dilation parameter at f = 1 (E2)");
  number_property(
      params, "tau_star", [](P& p) { return &p.steady.tau_star; }, "[Pa] repulsive stress scale (E7)");
  number_property(
      params, "eta_0", [](P& p) { return &p.steady.eta_0; }, "[Pa s] fluid viscosity");
  number_property(
      params, "mu_c", [](P& p) { return &p.steady.mu_c; }, "[-] contact friction (mu_1)");
  number_property(
      params, "Delta", [](P& p) { return &p.steady.Delta; }, "[-] compliance parameter of f_m (E9)");
  number_property(
      params, "xi_dot_eps", [](P& p) { return &p.steady.xi_dot_eps; },
      "[1/s] Brownian/electrostatic structure decay rate");
  number_property(
      params, "d", [](P& p) { return &p.granular.d; }, "[m] grain diameter");
  number_property(
      params, "rho_s", [](P& p) { return &p.granular.rho_s; }, "[kg/m^3] grain density");
  number_property(
      params, "mu_2", [](P& p) { return &p.granular.mu_2; },
      "[-] inertial friction limit (E20); < 0 means mu_2 = mu_c");
  number_property(
      params, "b", [](P& p) { return &p.granular.b; }, "[-] inertial friction scale (E20)");
  number_property(
      params, "K_3", [](P& p) { return &p.granular.K_3; }, "[-] dilatancy slope (E18)");
  number_property(
      params, "K_4", [](P& p) { return &p.granular.K_4; }, "[-] compaction-rate weight (E23)");
  number_property(
      params, "G", [](P& p) { return &p.granular.G; }, "[Pa] granular shear modulus (E16)");
  number_property(
      params, "K", [](P& p) { return &p.granular.K; }, "[Pa] granular bulk modulus (E16)");
  number_property(
      params, "K_0", [](P& p) { return &p.granular.K_0; }, "[-] rate factor of the f evolution (E24)");
  params.def_property(
      "eta_B",
      [](const P& p) {
        py::list l;
        for (const auto& t : p.steady.eta_B_terms) l.append(py::make_tuple(t.phi_i, t.alpha));
        return l;
      },
      [](P& p, const std::vector<std::pair<double, double>>& terms) {
        P q = p;
        q.steady.eta_B_terms.clear();
        for (const auto& [phi_i, alpha] : terms) q.steady.eta_B_terms.push_back({phi_i, alpha});
        rheology::validate(q, "Params.eta_B");
        p = q;
      },
      "E8 terms [(phi_i [1/(Pa s)], alpha [-]), ...]: 1/eta_B = sum phi_i (phi_j - phi)^alpha; [] means eta_B = inf");
  params.def(
      "toml", [](const P& p) { return rheology::to_toml(p); },
      "the parameter file's text (loads back with load_params to the same values)");
  params.def("__copy__", [](const P& p) { return p; });
  params.def(
      "__deepcopy__", [](const P& p, const py::dict& /*memo*/) { return p; }, py::arg("memo"));

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
  m.def("point_shear", &point_shear, py::arg("params"), py::arg("phi"), py::arg("shear_rate"), py::arg("shear_stress"),
        py::arg("duration"), py::arg("dt"), py::arg("f0"), py::arg("samples"));
  m.def("point_relax", &point_relax, py::arg("params"), py::arg("phi"), py::arg("shear_rate"), py::arg("shear_stress"),
        py::arg("duration"), py::arg("dt"), py::arg("samples"), py::arg("G"), py::arg("K0"));
  m.def("run_scene", &run_scene, py::arg("scene"), py::arg("sets"), py::arg("out"), py::arg("threads"),
        py::arg("checkpoint_every"), py::arg("stop_after"), py::arg("restart"), py::arg("progress"));
}
