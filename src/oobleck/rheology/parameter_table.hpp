#pragma once
// The material parameters, declared once: name, section, member, unit, meaning, equation and
// admissible range of every steady, granular and fluid parameter. The preset reader and writer
// (params.cpp), the scene file's [material] and [fluid] sections (scene/config.cpp),
// summary.json's "parameters" (run/run_summary.cpp), the fit's parameter names (fit_curves.cpp),
// the Python `Params` properties and `oobleck.parameter_table()` all read this table, and
// docs/scenes.md's parameter list is checked against it (tests/rheology/test_parameter_table.cpp).
//
// Adding a parameter: a member in SteadyParams, GranularParams or FluidParams (params.hpp, with
// its default) and one row in parameter_table.cpp.
#include <limits>
#include <span>
#include <string>
#include <string_view>

#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// Where a parameter lives: the preset file's [steady] / [granular] tables (a scene's
/// [material.steady] / [material.granular]) or a scene's [fluid] table.
enum class Section { Steady, Granular, Fluid };

/// "steady", "granular" or "fluid": the TOML table name.
std::string_view section_name(Section s);

/// Whether the flow-curves fit (fit_curves.hpp) fits a steady parameter: by default, only when
/// named, or never.
enum class CurvesFit { never, by_default, when_named };

/// One row of the table.
struct Parameter {
  std::string_view name;  ///< key in its TOML table, Python attribute, summary.json key
  Section section = Section::Steady;
  std::string_view unit;                                    ///< SI unit as written in outputs ("1": dimensionless)
  std::string_view meaning;                                 ///< one line
  std::string_view equation;                                ///< where it enters, "E7" or "E16, E24" (docs/equations.md)
  double lower = -std::numeric_limits<double>::infinity();  ///< admissible range: lower end
  bool lower_open = false;                                  ///< (lower, ...: lower excluded
  double upper = std::numeric_limits<double>::infinity();   ///< admissible range: upper end
  bool upper_open = false;                                  ///< ..., upper): upper excluded
  bool required = false;  ///< a preset file must give it (else the member's default applies)
  /// What a negative value means (the parameter is then unset and left out of preset files):
  /// "" when a negative value is just out of range.
  std::string_view unset_means;
  /// The default as docs/scenes.md states it where the member's default is not the whole story
  /// (fluid eta_0: the material's); "" otherwise.
  std::string_view default_note;
  /// The flow-curves fit: whether it fits this parameter (steady rows only).
  CurvesFit curves_fit = CurvesFit::never;
  /// summary.json's key where it differs from `name` (mu_c is written as "mu_1").
  std::string_view summary_name;
  /// summary.json's key of the parameter: summary_name, else name.
  std::string_view summary_key() const { return summary_name.empty() ? name : summary_name; }
  double SteadyParams::*steady = nullptr;      ///< the member (Section::Steady)
  double GranularParams::*granular = nullptr;  ///< the member (Section::Granular)
  double FluidParams::*fluid = nullptr;        ///< the member (Section::Fluid)
};

/// Every parameter, steady then granular then fluid, in the order of docs/scenes.md (the steady
/// ones in the order the flow-curves fit lists them: a_0, phi_j, a_inf, phi_c, tau_star, ...).
std::span<const Parameter> parameter_table();

/// The row of `name` in `section`; an unknown name is an InputError listing the known ones.
const Parameter& parameter(Section section, std::string_view name);

/// The row of a steady member (&SteadyParams::a_0): its name where code knows the member.
const Parameter& parameter(double SteadyParams::*member);
/// The row of a granular member (&GranularParams::G).
const Parameter& parameter(double GranularParams::*member);

/// The member a steady or granular row names, in a preset (logic_error for a fluid row).
double& value(Preset& p, const Parameter& row);
double value(const Preset& p, const Parameter& row);
/// The member a fluid row names (logic_error for a steady or granular row).
double& value(FluidParams& f, const Parameter& row);
double value(const FluidParams& f, const Parameter& row);

/// The value in effect: a negative value of a row with an unset meaning resolves to the named
/// parameter's (mu_2 < 0: mu_c).
double effective_value(const Preset& p, const Parameter& row);

/// The default of a row: the member's value in a default-constructed struct (0 for the steady
/// parameters a preset must give).
double default_value(const Parameter& row);

/// The default as tables state it: "required", the default note, what an unset value means
/// (mu_2: "mu_c"), or the number.
std::string default_text(const Parameter& row);

/// Whether a positive scale with no upper end (a_0, tau_star, ...): fits step through its logarithm.
bool positive_scale(const Parameter& row);

/// Whether `v` is admissible for `row`: finite, inside the range, or negative where the row has
/// an unset meaning.
bool admissible(const Parameter& row, double v);
/// The range as a rule for error messages: "must be positive [Pa]", "must lie in [0, 1]", ...
std::string rule(const Parameter& row);
/// The unit in brackets for help texts and file comments: "[Pa]", "[-]" for dimensionless.
std::string unit_label(const Parameter& row);
/// The range in interval notation for tables: "(0, 1)", "> 0", ">= 0", "any".
std::string range_text(const Parameter& row);

}  // namespace oobleck::rheology
