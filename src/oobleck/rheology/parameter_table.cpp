#include "oobleck/rheology/parameter_table.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"

namespace oobleck::rheology {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Range shorthands for the rows below.
struct Range {
  double lower = -kInf;
  bool lower_open = false;
  double upper = kInf;
  bool upper_open = false;
};
constexpr Range kPositive{0.0, true, kInf, false};
constexpr Range kNonNegative{0.0, false, kInf, false};
constexpr Range kOpenUnit{0.0, true, 1.0, true};
constexpr Range kClosedUnit{0.0, false, 1.0, false};

constexpr Parameter steady(std::string_view name, double SteadyParams::*member, std::string_view unit, Range r,
                           bool required, std::string_view equation, std::string_view meaning) {
  Parameter p;
  p.name = name;
  p.section = Section::Steady;
  p.unit = unit;
  p.meaning = meaning;
  p.equation = equation;
  p.lower = r.lower;
  p.lower_open = r.lower_open;
  p.upper = r.upper;
  p.upper_open = r.upper_open;
  p.required = required;
  p.steady = member;
  return p;
}

constexpr Parameter granular(std::string_view name, double GranularParams::*member, std::string_view unit, Range r,
                             std::string_view equation, std::string_view meaning) {
  Parameter p = steady(name, nullptr, unit, r, false, equation, meaning);
  p.section = Section::Granular;
  p.granular = member;
  return p;
}

constexpr Parameter fluid(std::string_view name, double FluidParams::*member, std::string_view unit, Range r,
                          std::string_view equation, std::string_view meaning) {
  Parameter p = steady(name, nullptr, unit, r, false, equation, meaning);
  p.section = Section::Fluid;
  p.fluid = member;
  return p;
}

constexpr Parameter fitted(Parameter p, CurvesFit how) {
  p.curves_fit = how;
  return p;
}

constexpr Parameter with_summary_name(Parameter p, std::string_view summary_name) {
  p.summary_name = summary_name;
  return p;
}

constexpr Parameter with_unset_meaning(Parameter p, std::string_view unset_means) {
  p.unset_means = unset_means;
  return p;
}

constexpr Parameter with_default_note(Parameter p, std::string_view note) {
  p.default_note = note;
  return p;
}

using S = SteadyParams;
using G = GranularParams;
using F = FluidParams;

const std::array kTable{
    // steady model (paper Tables 1–3)
    fitted(steady("a_0", &S::a_0, "1", kPositive, true, "E2", "dilation parameter a at f = 0"), CurvesFit::by_default),
    fitted(steady("phi_j", &S::phi_j, "1", kOpenUnit, true, "E1", "frictionless jamming fraction φ_j"),
           CurvesFit::by_default),
    fitted(steady("a_inf", &S::a_inf, "1", kPositive, true, "E2", "dilation parameter a at f = 1"),
           CurvesFit::by_default),
    fitted(steady("phi_c", &S::phi_c, "1", kOpenUnit, true, "E1", "frictional jamming fraction φ_c (< φ_j)"),
           CurvesFit::by_default),
    fitted(steady("tau_star", &S::tau_star, "Pa", kPositive, true, "E7", "repulsive stress scale τ*"),
           CurvesFit::by_default),
    steady("eta_0", &S::eta_0, "Pa s", kPositive, true, "E3, E25", "fluid viscosity η_0"),
    with_summary_name(steady("mu_c", &S::mu_c, "1", kPositive, true, "E3, E5, E20", "contact friction μ_c (= μ_1)"),
                      "mu_1"),
    fitted(steady("Delta", &S::Delta, "1", kClosedUnit, false, "E9", "compliance parameter Δ of f_m"),
           CurvesFit::when_named),
    steady("xi_dot_eps", &S::xi_dot_eps, "1/s", kNonNegative, false, "E7",
           "Brownian/electrostatic structure decay rate ξ̇_ε"),
    // time-dependent granular law
    granular("d", &G::d, "m", kPositive, "E19, E29", "grain diameter"),
    granular("rho_s", &G::rho_s, "kg/m^3", kPositive, "E19, E28", "grain true density ρ_s"),
    with_unset_meaning(granular("mu_2", &G::mu_2, "1", kNonNegative, "E20", "inertial friction limit μ_2 (≥ μ_c)"),
                       "mu_c"),
    granular("b", &G::b, "1", kNonNegative, "E20", "inertial friction scale b"),
    granular("K_3", &G::K_3, "1", kNonNegative, "E18", "dilatancy slope K_3"),
    granular("K_4", &G::K_4, "1", kNonNegative, "E23", "compaction-rate weight K_4"),
    granular("G", &G::G, "Pa", kPositive, "E16", "granular shear modulus G"),
    granular("K", &G::K, "Pa", kPositive, "E16", "granular bulk modulus K"),
    granular("K_0", &G::K_0, "1", kPositive, "E6, E24", "rate factor K_0 of the f evolution"),
    // fluid law (a scene's [fluid])
    fluid("rho_f", &F::rho_f0_kg_m3, "kg/m^3", kPositive, "E26", "fluid rest true density ρ_f0"),
    fluid("kappa", &F::kappa_Pa, "Pa", kPositive, "E26",
          "fluid bulk modulus κ; the paper gives none — keep fluid strains < 1 %"),
    with_default_note(fluid("eta_0", &F::eta_0_Pa_s, "Pa s", kPositive, "E25",
                            "fluid viscosity η_0; replaces the material's (one viscosity)"),
                      "steady eta_0"),
};

std::string format_number(double v) { return fmt::format("{}", v); }

}  // namespace

std::string_view section_name(Section s) {
  switch (s) {
    case Section::Steady: return "steady";
    case Section::Granular: return "granular";
    case Section::Fluid: return "fluid";
  }
  return "";
}

std::span<const Parameter> parameter_table() { return kTable; }

const Parameter& parameter(Section section, std::string_view name) {
  std::vector<std::string> names;
  for (const Parameter& row : kTable) {
    if (row.section != section) continue;
    if (row.name == name) return row;
    names.emplace_back(row.name);
  }
  const std::string hint = closest_match(std::string(name), names);
  throw InputError(fmt::format("unknown {} parameter '{}'{}; known: {}", section_name(section), name,
                               hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint), fmt::join(names, ", ")));
}

const Parameter& parameter(double SteadyParams::*member) {
  for (const Parameter& row : kTable) {
    if (row.steady == member) return row;
  }
  throw std::logic_error("a steady member with no row in the parameter table");
}

const Parameter& parameter(double GranularParams::*member) {
  for (const Parameter& row : kTable) {
    if (row.granular == member) return row;
  }
  throw std::logic_error("a granular member with no row in the parameter table");
}

double& value(Preset& p, const Parameter& row) {
  if (row.steady != nullptr) return p.steady.*row.steady;
  if (row.granular != nullptr) return p.granular.*row.granular;
  throw std::logic_error(fmt::format("parameter '{}' is not part of a preset", row.name));
}

double value(const Preset& p, const Parameter& row) {
  if (row.steady != nullptr) return p.steady.*row.steady;
  if (row.granular != nullptr) return p.granular.*row.granular;
  throw std::logic_error(fmt::format("parameter '{}' is not part of a preset", row.name));
}

double& value(FluidParams& f, const Parameter& row) {
  if (row.fluid != nullptr) return f.*row.fluid;
  throw std::logic_error(fmt::format("parameter '{}' is not a fluid parameter", row.name));
}

double value(const FluidParams& f, const Parameter& row) {
  if (row.fluid != nullptr) return f.*row.fluid;
  throw std::logic_error(fmt::format("parameter '{}' is not a fluid parameter", row.name));
}

double effective_value(const Preset& p, const Parameter& row) {
  const double v = value(p, row);
  if (v >= 0.0 || row.unset_means.empty()) return v;
  for (const Parameter& other : kTable) {
    if (other.name == row.unset_means && other.section != Section::Fluid) return value(p, other);
  }
  throw std::logic_error(
      fmt::format("parameter '{}': unset meaning '{}' names no parameter", row.name, row.unset_means));
}

double default_value(const Parameter& row) {
  if (row.fluid != nullptr) return FluidParams{}.*row.fluid;
  return value(Preset{}, row);
}

std::string default_text(const Parameter& row) {
  if (row.required) return "required";
  if (!row.default_note.empty()) return std::string(row.default_note);
  const double v = default_value(row);
  if (v < 0.0 && !row.unset_means.empty()) return std::string(row.unset_means);
  return format_number(v);
}

bool positive_scale(const Parameter& row) { return row.lower == 0.0 && row.lower_open && !std::isfinite(row.upper); }

bool admissible(const Parameter& row, double v) {
  if (!std::isfinite(v)) return false;
  if (v < 0.0 && !row.unset_means.empty()) return true;
  const bool above = row.lower_open ? v > row.lower : v >= row.lower;
  const bool below = row.upper_open ? v < row.upper : v <= row.upper;
  return above && below;
}

std::string range_text(const Parameter& row) {
  const bool has_lower = std::isfinite(row.lower), has_upper = std::isfinite(row.upper);
  if (has_lower && has_upper) {
    return fmt::format("{}{}, {}{}", row.lower_open ? '(' : '[', format_number(row.lower), format_number(row.upper),
                       row.upper_open ? ')' : ']');
  }
  if (has_lower) return fmt::format("{} {}", row.lower_open ? ">" : ">=", format_number(row.lower));
  if (has_upper) return fmt::format("{} {}", row.upper_open ? "<" : "<=", format_number(row.upper));
  return "any";
}

std::string unit_label(const Parameter& row) { return row.unit == "1" ? "[-]" : fmt::format("[{}]", row.unit); }

std::string rule(const Parameter& row) {
  const std::string unit = row.unit == "1" ? "" : fmt::format(" [{}]", row.unit);
  const bool has_upper = std::isfinite(row.upper);
  std::string text;
  if (!has_upper && row.lower == 0.0) {
    text = row.lower_open ? "must be positive" : "must be >= 0";
  } else if (!has_upper && std::isfinite(row.lower)) {
    text = fmt::format("must be {} {}", row.lower_open ? ">" : ">=", format_number(row.lower));
  } else {
    text = fmt::format("must lie in {}", range_text(row));
  }
  text += unit;
  if (!row.unset_means.empty()) text += fmt::format(", or negative for {} = {}", row.name, row.unset_means);
  return text;
}

}  // namespace oobleck::rheology
