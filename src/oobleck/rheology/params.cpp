#include "oobleck/rheology/params.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/toml_reader.hpp"

namespace oobleck::rheology {

const std::vector<std::string>& preset_names() {
  static const std::vector<std::string> names = {"singh2018a", "singh2018b", "dhaene1993", "frith1996",
                                                 "guy2015a",   "guy2015b",   "fall2015",   "hermes2016"};
  return names;
}

std::string preset_dir() {
  if (const char* env = std::getenv("OOBLECK_PRESETS"); env != nullptr && *env != '\0') return env;
  return std::string(OOBLECK_SOURCE_DIR) + "/presets";
}

namespace {

void check(bool ok, const std::string& where, const char* key, double value, const std::string& rule) {
  if (!ok) throw InputError(fmt::format("{}: key '{}' = {}: {}", where, key, value, rule));
}

Preset read(const std::string& path) {
  const toml::table root = io::parse_toml_file(path);
  io::TomlReader top(root, path);
  Preset p;
  p.file = path;
  p.name = top.string_or("name", std::filesystem::path(path).stem().string());
  p.source = top.string_or("source", "");
  p.units = top.string_or("units", "SI");
  if (p.units != "SI" && p.units != "normalized") {
    top.fail("units", fmt::format("= \"{}\": must be \"SI\" or \"normalized\"", p.units));
  }

  io::TomlReader s = top.table("steady");
  SteadyParams& st = p.steady;
  st.phi_c = s.number("phi_c");
  st.phi_j = s.number("phi_j");
  st.a_0 = s.number("a_0");
  st.a_inf = s.number("a_inf");
  st.tau_star = s.number("tau_star");
  st.eta_0 = s.number("eta_0");
  st.mu_c = s.number("mu_c");
  st.Delta = s.number_or("Delta", 0.0);
  st.xi_dot_eps = s.number_or("xi_dot_eps", 0.0);
  for (io::TomlReader term : s.table_array("eta_B")) {
    EtaBTerm t;
    t.phi_i = term.number("phi_i");
    t.alpha = term.number("alpha");
    term.finish();
    st.eta_B_terms.push_back(t);
  }
  s.finish();

  if (auto g = top.optional_table("granular")) {
    GranularParams& gr = p.granular;
    gr.d = g->number_or("d", gr.d);
    gr.rho_s = g->number_or("rho_s", gr.rho_s);
    gr.mu_2 = g->number_or("mu_2", gr.mu_2);
    gr.b = g->number_or("b", gr.b);
    gr.K_3 = g->number_or("K_3", gr.K_3);
    gr.K_4 = g->number_or("K_4", gr.K_4);
    gr.G = g->number_or("G", gr.G);
    gr.K = g->number_or("K", gr.K);
    gr.K_0 = g->number_or("K_0", gr.K_0);
    g->finish();
  }
  top.finish();
  validate(p, path);
  return p;
}

}  // namespace

void validate(const Preset& p, const std::string& where) {
  const SteadyParams& s = p.steady;
  auto finite = [&](const char* key, double v) { check(std::isfinite(v), where, key, v, "must be finite"); };
  finite("steady.phi_c", s.phi_c);
  finite("steady.phi_j", s.phi_j);
  check(s.phi_c > 0.0 && s.phi_c < 1.0, where, "steady.phi_c", s.phi_c, "must lie in (0, 1)");
  check(s.phi_j > 0.0 && s.phi_j < 1.0, where, "steady.phi_j", s.phi_j, "must lie in (0, 1)");
  check(s.phi_c < s.phi_j, where, "steady.phi_c", s.phi_c,
        fmt::format("must be smaller than steady.phi_j = {} (phi_c < phi_j)", s.phi_j));
  check(s.a_0 > 0.0 && std::isfinite(s.a_0), where, "steady.a_0", s.a_0, "must be positive");
  check(s.a_inf > 0.0 && std::isfinite(s.a_inf), where, "steady.a_inf", s.a_inf, "must be positive");
  check(s.tau_star > 0.0 && std::isfinite(s.tau_star), where, "steady.tau_star", s.tau_star, "must be positive [Pa]");
  check(s.eta_0 > 0.0 && std::isfinite(s.eta_0), where, "steady.eta_0", s.eta_0, "must be positive [Pa s]");
  check(s.mu_c > 0.0 && std::isfinite(s.mu_c), where, "steady.mu_c", s.mu_c, "must be positive");
  check(s.Delta >= 0.0 && s.Delta <= 1.0, where, "steady.Delta", s.Delta, "must lie in [0, 1]");
  check(s.xi_dot_eps >= 0.0 && std::isfinite(s.xi_dot_eps), where, "steady.xi_dot_eps", s.xi_dot_eps,
        "must be >= 0 [1/s]");
  for (std::size_t i = 0; i < s.eta_B_terms.size(); ++i) {
    const auto key_phi = fmt::format("steady.eta_B[{}].phi_i", i);
    const auto key_alpha = fmt::format("steady.eta_B[{}].alpha", i);
    check(s.eta_B_terms[i].phi_i >= 0.0 && std::isfinite(s.eta_B_terms[i].phi_i), where, key_phi.c_str(),
          s.eta_B_terms[i].phi_i, "must be >= 0 [1/(Pa s)]");
    check(s.eta_B_terms[i].alpha >= 0.0 && std::isfinite(s.eta_B_terms[i].alpha), where, key_alpha.c_str(),
          s.eta_B_terms[i].alpha, "must be >= 0");
  }
  const GranularParams& g = p.granular;
  check(g.d > 0.0 && std::isfinite(g.d), where, "granular.d", g.d, "must be positive [m]");
  check(g.rho_s > 0.0 && std::isfinite(g.rho_s), where, "granular.rho_s", g.rho_s, "must be positive [kg/m^3]");
  check(g.mu_2 < 0.0 || g.mu_2 >= s.mu_c, where, "granular.mu_2", g.mu_2,
        "must be >= steady.mu_c (or omitted, meaning mu_2 = mu_c)");
  check(g.b >= 0.0, where, "granular.b", g.b, "must be >= 0");
  check(g.K_3 >= 0.0, where, "granular.K_3", g.K_3, "must be >= 0");
  check(g.K_4 >= 0.0, where, "granular.K_4", g.K_4, "must be >= 0");
  check(g.G > 0.0 && std::isfinite(g.G), where, "granular.G", g.G, "must be positive [Pa]");
  check(g.K > 0.0 && std::isfinite(g.K), where, "granular.K", g.K, "must be positive [Pa]");
  check(g.K_0 > 0.0 && std::isfinite(g.K_0), where, "granular.K_0", g.K_0, "must be positive");
}

Preset load_preset(const std::string& name) {
  const auto& names = preset_names();
  const std::string path = preset_dir() + "/" + name + ".toml";
  // A name, not a path ("../x", "/dev/zero"): a parameter file is passed as --params FILE.
  if (name.find('/') != std::string::npos || name.empty() || name[0] == '.' || !std::filesystem::exists(path)) {
    const std::string hint = closest_match(name, names);
    throw InputError(fmt::format("unknown preset '{}'{}; known presets: {} (or pass --params FILE.toml)", name,
                                 hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint),
                                 fmt::join(names, ", ")));
  }
  return read(path);
}

Preset load_params_file(const std::string& path) { return read(path); }

std::string to_toml(const Preset& p) {
  const SteadyParams& s = p.steady;
  const GranularParams& g = p.granular;
  std::string out;
  out += fmt::format("name = \"{}\"\nsource = \"{}\"\nunits = \"{}\"\n\n", p.name, p.source, p.units);
  out += "[steady]\n";
  out += fmt::format("phi_c = {:.17g}       # [-] frictional jamming fraction\n", s.phi_c);
  out += fmt::format("phi_j = {:.17g}       # [-] frictionless jamming fraction\n", s.phi_j);
  out += fmt::format("a_0 = {:.17g}         # [-] dilation parameter at f = 0\n", s.a_0);
  out += fmt::format("a_inf = {:.17g}       # [-] dilation parameter at f = 1\n", s.a_inf);
  out += fmt::format("tau_star = {:.17g}    # [Pa] repulsive stress scale\n", s.tau_star);
  out += fmt::format("eta_0 = {:.17g}       # [Pa s] fluid viscosity\n", s.eta_0);
  out += fmt::format("mu_c = {:.17g}        # [-] contact friction\n", s.mu_c);
  out += fmt::format("Delta = {:.17g}       # [-] compliance parameter of f_m\n", s.Delta);
  out += fmt::format("xi_dot_eps = {:.17g}  # [1/s] Brownian structure decay rate\n", s.xi_dot_eps);
  for (const auto& t : s.eta_B_terms) {
    out += fmt::format(
        "\n[[steady.eta_B]]      # eta_B = (sum phi_i (phi_j - phi)^alpha)^-1\n"
        "phi_i = {:.17g}       # [1/(Pa s)]\nalpha = {:.17g}       # [-]\n",
        t.phi_i, t.alpha);
  }
  out += "\n[granular]\n";
  out += fmt::format("d = {:.17g}           # [m] grain diameter\n", g.d);
  out += fmt::format("rho_s = {:.17g}       # [kg/m^3] grain density\n", g.rho_s);
  if (g.mu_2 >= 0.0) out += fmt::format("mu_2 = {:.17g}        # [-]\n", g.mu_2);
  out += fmt::format("b = {:.17g}           # [-]\n", g.b);
  out += fmt::format("K_3 = {:.17g}         # [-] dilatancy slope\n", g.K_3);
  out += fmt::format("K_4 = {:.17g}         # [-] compaction-rate weight\n", g.K_4);
  out += fmt::format("G = {:.17g}           # [Pa] shear modulus\n", g.G);
  out += fmt::format("K = {:.17g}           # [Pa] bulk modulus\n", g.K);
  out += fmt::format("K_0 = {:.17g}         # [-] structure rate factor\n", g.K_0);
  return out;
}

}  // namespace oobleck::rheology
