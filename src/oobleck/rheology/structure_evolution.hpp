#pragma once
// Evolution of the micro-structure f, E6, E7, E10 (docs/equations.md) (paper eqs. c_model, hardening,
// softening, steadyf).
#include <cmath>

namespace oobleck::rheology {

/// E7: hardening rate H = (tau_bar/tau*)^{3/2}.
inline double hardening(double tau_bar, double tau_star) {
  const double x = tau_bar / tau_star;
  return x * std::sqrt(x);
}

/// E7: softening rate S = 1 + tau_bar/(eta_B gamma_dot) + xi_dot_eps/gamma_dot, with 1/eta_B given.
inline double softening(double tau_bar, double gamma_dot, double inv_eta_B, double xi_dot_eps) {
  return 1.0 + (tau_bar * inv_eta_B + xi_dot_eps) / gamma_dot;
}

/// E6: f_dot = K_0 gamma_dot (H (f_m - f) - S f).
inline double f_rate(double K_0, double gamma_dot, double H, double S, double f_m, double f) {
  return K_0 * gamma_dot * (H * (f_m - f) - S * f);
}

/// E10: steady structure f = H f_m/(H + S).
inline double steady_f(double H, double S, double f_m) { return H * f_m / (H + S); }

}  // namespace oobleck::rheology
