#pragma once
// Steady viscous-regime stresses, E3–E5 (docs/equations.md) (paper eqs. effective_viscosity,
// normal_viscosity; mu_h from the base model). All functions take the gap phi_m - phi
// explicitly so that callers near jamming can supply it without cancellation.
namespace oobleck::rheology {

/// E4: eta_n = p~/(eta_0 gamma_dot) = 2 (a phi/(phi_m - phi))^2.
inline double eta_n(double phi, double a, double phi_m_minus_phi) {
  const double r = a * phi / phi_m_minus_phi;
  return 2.0 * r * r;
}

/// E5: mu_h = (5/4)(phi_m - phi)/a^2 (fluid-mediated friction at steady state).
inline double mu_h(double a, double phi_m_minus_phi) { return 1.25 * phi_m_minus_phi / (a * a); }

/// c = tau_bar/(eta_0 gamma_dot) = (mu_c + mu_h) eta_n = mu_c eta_n + (5/2) phi^2/(phi_m - phi).
inline double granular_viscosity(double phi, double a, double phi_m_minus_phi, double mu_c) {
  return mu_c * eta_n(phi, a, phi_m_minus_phi) + 2.5 * phi * phi / phi_m_minus_phi;
}

/// E3: eta_r = tau/(eta_0 gamma_dot) = 1 + (5/2) phi phi_m/(phi_m - phi) + 2 mu_c (a phi/(phi_m - phi))^2,
/// identical to (1 + 5 phi/2) + c (mixture = fluid with Einstein correction + granular).
inline double eta_r(double phi, double a, double phi_m_minus_phi, double mu_c) {
  return 1.0 + 2.5 * phi + granular_viscosity(phi, a, phi_m_minus_phi, mu_c);
}

}  // namespace oobleck::rheology
