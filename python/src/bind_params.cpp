// oobleck._oobleck.Params: a complete parameter set (rheology::Preset) whose every assignment is
// validated on a copy before it is committed (oobleck.InputError naming Params.<property>).
#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include "bind.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::python {
namespace {

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

}  // namespace

void bind_params(py::module_& m) {
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
}

}  // namespace oobleck::python
