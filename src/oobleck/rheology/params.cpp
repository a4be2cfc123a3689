#include "oobleck/rheology/params.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/toml_reader.hpp"
#include "oobleck/rheology/parameter_table.hpp"

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
  const toml::table empty;
  io::TomlReader none(empty, path, "granular");
  std::optional<io::TomlReader> g = top.optional_table("granular");
  for (const Parameter& row : parameter_table()) {
    if (row.section == Section::Fluid) continue;
    io::TomlReader& t = row.section == Section::Steady ? s : (g ? *g : none);
    double& v = value(p, row);
    v = row.required ? t.number(row.name) : t.number_or(row.name, v);
  }
  for (io::TomlReader term : s.table_array("eta_B")) {
    EtaBTerm t;
    t.phi_i = term.number("phi_i");
    t.alpha = term.number("alpha");
    term.finish();
    p.steady.eta_B_terms.push_back(t);
  }
  s.finish();
  if (g) g->finish();
  top.finish();
  validate(p, path);
  return p;
}

}  // namespace

void validate(const Preset& p, const std::string& where) {
  for (const Parameter& row : parameter_table()) {
    if (row.section == Section::Fluid) continue;
    const std::string key = fmt::format("{}.{}", section_name(row.section), row.name);
    check(admissible(row, value(p, row)), where, key.c_str(), value(p, row), rule(row));
  }
  const SteadyParams& s = p.steady;
  check(s.phi_c < s.phi_j, where, "steady.phi_c", s.phi_c,
        fmt::format("must be smaller than steady.phi_j = {} (phi_c < phi_j)", s.phi_j));
  for (std::size_t i = 0; i < s.eta_B_terms.size(); ++i) {
    const auto key_phi = fmt::format("steady.eta_B[{}].phi_i", i);
    const auto key_alpha = fmt::format("steady.eta_B[{}].alpha", i);
    check(s.eta_B_terms[i].phi_i >= 0.0 && std::isfinite(s.eta_B_terms[i].phi_i), where, key_phi.c_str(),
          s.eta_B_terms[i].phi_i, "must be >= 0 [1/(Pa s)]");
    check(s.eta_B_terms[i].alpha >= 0.0 && std::isfinite(s.eta_B_terms[i].alpha), where, key_alpha.c_str(),
          s.eta_B_terms[i].alpha, "must be >= 0");
  }
  const GranularParams& g = p.granular;
  check(g.mu_2 < 0.0 || g.mu_2 >= s.mu_c, where, "granular.mu_2", g.mu_2,
        "must be >= steady.mu_c (or omitted, meaning mu_2 = mu_c)");
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
  std::string out = fmt::format("name = \"{}\"\nsource = \"{}\"\nunits = \"{}\"\n", p.name, p.source, p.units);
  auto write = [&](Section section) {
    out += fmt::format("\n[{}]\n", section_name(section));
    for (const Parameter& row : parameter_table()) {
      if (row.section != section) continue;
      const double v = value(p, row);
      if (v < 0.0 && !row.unset_means.empty()) continue;  // unset: the reader's default means the same
      const std::string line = fmt::format("{} = {:.17g}", row.name, v);
      out += fmt::format("{:<30}# {} {}\n", line, unit_label(row), row.meaning);
    }
  };
  write(Section::Steady);
  for (const auto& t : p.steady.eta_B_terms) {
    out += fmt::format(
        "\n[[steady.eta_B]]      # eta_B = (sum phi_i (phi_j - phi)^alpha)^-1\n"
        "phi_i = {:.17g}       # [1/(Pa s)]\nalpha = {:.17g}       # [-]\n",
        t.phi_i, t.alpha);
  }
  write(Section::Granular);
  return out;
}

}  // namespace oobleck::rheology
