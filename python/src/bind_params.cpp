// oobleck._oobleck.Params: a complete parameter set (rheology::Preset) whose every assignment is
// validated on a copy before it is committed (oobleck.InputError naming Params.<property>); its
// number properties and parameter_table() come from rheology/parameter_table.cpp.
#include <algorithm>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include "bind.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/rheology/parameter_table.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::python {
namespace {

/// The docstring of a parameter's property: "[unit] meaning (equation)".
std::string property_doc(const rheology::Parameter& row) {
  std::string doc = fmt::format("{} {} ({})", rheology::unit_label(row), row.meaning, row.equation);
  if (!row.unset_means.empty()) doc += fmt::format("; < 0 means {} = {}", row.name, row.unset_means);
  return doc;
}

/// A property of Params for one row of the parameter table: get the member, set it on a copy,
/// validate the copy, commit.
void number_property(py::class_<rheology::Preset>& cls, const rheology::Parameter& row) {
  // pybind11 keeps pointers to the name and docstring: they live as long as the module.
  static std::deque<std::string> texts;
  const char* name = texts.emplace_back(row.name).c_str();
  const char* doc = texts.emplace_back(property_doc(row)).c_str();
  cls.def_property(
      name, [&row](const rheology::Preset& p) { return rheology::value(p, row); },
      [&row, name](rheology::Preset& p, double v) {
        rheology::Preset q = p;
        rheology::value(q, row) = v;
        rheology::validate(q, fmt::format("Params.{}", name));
        p = q;
      },
      doc);
}

/// One table row as a dict (oobleck.parameter_table()).
py::dict row_dict(const rheology::Parameter& row) {
  py::dict d;
  d["name"] = std::string(row.name);
  d["section"] = std::string(rheology::section_name(row.section));
  d["unit"] = std::string(row.unit);
  d["default"] = rheology::default_text(row);
  d["range"] = rheology::range_text(row);
  d["lower"] = row.lower;
  d["lower_open"] = row.lower_open;
  d["upper"] = row.upper;
  d["upper_open"] = row.upper_open;
  d["required"] = row.required;
  d["equation"] = std::string(row.equation);
  d["meaning"] = std::string(row.meaning);
  return d;
}

/// Params.from_dict: the keys of Params.to_dict (name, source, units, file, eta_B and the
/// parameters by name); the parameters a preset must give are required, the others default.
rheology::Preset from_dict(const py::dict& d) {
  rheology::Preset p;
  std::vector<std::string> known = {"name", "source", "units", "file", "eta_B"};
  for (const rheology::Parameter& row : rheology::parameter_table()) {
    if (row.section == rheology::Section::Fluid) continue;
    known.emplace_back(row.name);
    const py::str key(std::string(row.name));
    if (d.contains(key)) {
      rheology::value(p, row) = d[key].cast<double>();
    } else if (row.required) {
      throw InputError(fmt::format("Params.from_dict: missing '{}' ({} {}, required)", row.name,
                                   rheology::unit_label(row), row.meaning));
    }
  }
  for (const auto& [k, v] : d) {
    const auto key = k.cast<std::string>();
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string hint = closest_match(key, known);
    throw InputError(fmt::format("Params.from_dict: unknown key '{}'{}", key,
                                 hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint)));
  }
  if (d.contains("name")) p.name = d["name"].cast<std::string>();
  if (d.contains("source")) p.source = d["source"].cast<std::string>();
  if (d.contains("units")) p.units = d["units"].cast<std::string>();
  if (d.contains("file")) p.file = d["file"].cast<std::string>();
  if (p.units != "SI" && p.units != "normalized")
    throw InputError(fmt::format("Params.from_dict: units = '{}': must be 'SI' or 'normalized'", p.units));
  if (d.contains("eta_B")) {
    for (const py::handle term : d["eta_B"]) {
      if (py::isinstance<py::dict>(term)) {
        p.steady.eta_B_terms.push_back({term["phi_i"].cast<double>(), term["alpha"].cast<double>()});
      } else {
        const auto [phi_i, alpha] = term.cast<std::pair<double, double>>();
        p.steady.eta_B_terms.push_back({phi_i, alpha});
      }
    }
  }
  rheology::validate(p, "Params.from_dict");
  return p;
}

}  // namespace

void bind_params(py::module_& m) {
  py::class_<rheology::Preset> params(m, "Params",
                                      "A complete parameter set (a preset file): steady model (docs/equations.md, "
                                      "steady rheology) and granular law (docs/equations.md, time-dependent granular "
                                      "law). Every assignment is validated (oobleck.InputError).");
  params.def(py::init([](const rheology::Preset& p) { return p; }), py::arg("other"), "a copy");
  params.def_static("from_dict", &from_dict, py::arg("values"),
                    "A parameter set from a dict with the keys of to_dict(): the parameters by name (those a "
                    "preset must give are required, the others take their defaults), eta_B as a list of "
                    "{'phi_i', 'alpha'} or (phi_i, alpha), and optionally name, source, units; validated as a "
                    "whole (oobleck.InputError).");
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
  for (const rheology::Parameter& row : rheology::parameter_table()) {
    if (row.section != rheology::Section::Fluid) number_property(params, row);
  }
  m.def(
      "parameter_table",
      [] {
        py::list rows;
        for (const rheology::Parameter& row : rheology::parameter_table()) rows.append(row_dict(row));
        return rows;
      },
      "every steady, granular and fluid parameter (rheology/parameter_table.cpp) as a list of dicts");
  using P = rheology::Preset;
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
