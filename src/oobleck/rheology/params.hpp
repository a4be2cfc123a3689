#pragma once
// Material parameters of the Baumgarten–Kamrin model, named as in docs/equations.md.
// Every field carries its unit; parameter_table.hpp gives each its name, range and meaning. Built only through
// load_preset()/validate(), which check every rule below; the laws themselves assume validated parameters.
#include <string>
#include <vector>

namespace oobleck::rheology {

/// One term of the buckling resistance series E8: phi_i (phi_j - phi)^alpha.
struct EtaBTerm {
  double phi_i = 0.0;  ///< [1/(Pa s)] (normalized units for the Singh presets)
  double alpha = 0.0;  ///< [-]
};

/// Steady-rheology parameters (paper Tables 1–3; docs/equations.md, steady rheology).
struct SteadyParams {
  double phi_c = 0.0;                 ///< [-] frictional jamming fraction (phi_c < phi_j)
  double phi_j = 0.0;                 ///< [-] frictionless jamming fraction
  double a_0 = 0.0;                   ///< [-] dilation parameter at f = 0
  double a_inf = 0.0;                 ///< [-] dilation parameter at f = 1
  double tau_star = 0.0;              ///< [Pa] repulsive stress scale
  double eta_0 = 0.0;                 ///< [Pa s] fluid viscosity
  double mu_c = 0.0;                  ///< [-] contact friction (= mu_1)
  double Delta = 0.0;                 ///< [-] compliance parameter of f_m (E9), in [0, 1]
  double xi_dot_eps = 0.0;            ///< [1/s] Brownian/electrostatic structure decay rate
  std::vector<EtaBTerm> eta_B_terms;  ///< E8; empty means eta_B = infinity
};

/// Parameters of the time-dependent granular law (E16–E24, docs/equations.md) that the steady model does not
/// need. Defaults: the cornstarch values of the paper's dynamic scenes.
struct GranularParams {
  double d = 5.85e-6;   ///< [m] grain diameter
  double rho_s = 1620;  ///< [kg/m^3] grain true density
  double mu_2 = -1;     ///< [-] inertial friction limit (E20); < 0 means "= mu_c"
  double b = 0.0;       ///< [-] inertial friction scale (E20)
  double K_3 = 4.715;   ///< [-] dilatancy slope (E18)
  double K_4 = 0.0;     ///< [-] compaction-rate weight (E23)
  double G = 3.8e5;     ///< [Pa] granular shear modulus (E16)
  double K = 8.3e5;     ///< [Pa] granular bulk modulus (E16)
  double K_0 = 1.0;     ///< [-] rate factor of the f evolution (E24)
};

/// Parameters of the fluid law (E25–E27, docs/equations.md), SI units. Not part of a preset: a
/// scene's [fluid] table (scene::FluidConfig) and the fluid body's law (material/fluid.hpp).
struct FluidParams {
  double eta_0_Pa_s = 1e-3;      ///< [Pa s] fluid viscosity η_0 (E25)
  double kappa_Pa = 1e6;         ///< [Pa] fluid bulk modulus κ (E26; not given by the paper)
  double rho_f0_kg_m3 = 1000.0;  ///< [kg/m^3] fluid rest true density ρ_f0 (E26)
};

/// A complete parameter set: what a preset file holds.
struct Preset {
  std::string name;          ///< e.g. "hermes2016"
  std::string source;        ///< literature source (free text)
  std::string units = "SI";  ///< "SI" or "normalized" (Singh: stresses in eta_0 gamma_dot_0)
  std::string file;          ///< file it was read from ("" when built in code)
  SteadyParams steady;
  GranularParams granular;
};

/// Names of the presets shipped in presets/ (the paper's eight fits).
const std::vector<std::string>& preset_names();
/// Folder holding the shipped presets: $OOBLECK_PRESETS if set, else the source tree's presets/.
std::string preset_dir();
/// Load presets/<name>.toml; an unknown name is an InputError listing the known ones.
Preset load_preset(const std::string& name);
/// Load a user parameter file (same format as the shipped presets).
Preset load_params_file(const std::string& path);
/// Check every rule (phi_c < phi_j, eta_0 > 0, ...); `where` prefixes the messages (a file name).
void validate(const Preset& p, const std::string& where);
/// Write a preset file that load_params_file() reads back to the same values.
std::string to_toml(const Preset& p);

}  // namespace oobleck::rheology
