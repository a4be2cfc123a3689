#pragma once
// Volume fraction from mass fraction for swelling starch grains, E15 (docs/equations.md) (paper SI,
// after Peters et al. 2016).
namespace oobleck::rheology {

struct MassFractionInput {
  double mass_fraction = 0.0;  ///< phi_W = m_cs/(m_cs + m_l) [-], in (0, 1)
  double rho_cs = 0.0;         ///< [kg/m^3] cornstarch grain density
  double rho_liquid = 0.0;     ///< [kg/m^3] suspending liquid density
  double rho_water = 0.0;      ///< [kg/m^3] water density
  double lambda = 0.3;         ///< [-] pore-space correction
  double beta = 0.1;           ///< [-] swelling (absorbed water) correction
};

/// E15: phi = (1 + lambda)(1 - beta) / [(1 - beta) + ((1 - phi_W)/phi_W)(rho_cs/rho_l) + beta rho_cs/rho_w].
/// Inputs must be validated by the caller (see validate_mass_fraction_input).
double volume_fraction(const MassFractionInput& in);
/// Throws InputError naming the offending option when a value is out of range.
void validate_mass_fraction_input(const MassFractionInput& in);

}  // namespace oobleck::rheology
