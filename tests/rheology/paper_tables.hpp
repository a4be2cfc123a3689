#pragma once
// The paper's Tables 1–3, typed in from the PNAS text (independent of presets/*.toml), and the
// closed forms E9, E12–E14 written out literally from the paper, independent of src/.
#include <cmath>
#include <string>
#include <vector>

namespace paper {

struct Term {
  double phi_i, alpha;
};
struct Fit {
  std::string name;
  double phi_c, phi_j, a_0, a_inf, tau_star, eta_0, mu_c, Delta;
  std::vector<Term> terms;
};

inline const std::vector<Fit>& fits() {
  static const std::vector<Fit> f = {
      {"singh2018a", 0.585, 0.65, 0.455, 0.841, 1.74, 1.0, 1.0, 1.0, {}},
      {"singh2018b", 0.585, 0.65, 0.455, 0.841, 1.44, 1.0, 1.0, 1.0, {{0.254, 1.0}}},
      {"dhaene1993", 0.57, 0.65, 1.08, 1.08, 5.21, 56e-3, 0.3, 0.0, {{8.83e6, 6}}},
      {"frith1996", 0.548, 0.642, 1.08, 1.08, 17.93, 130e-3, 0.3, 0.0, {{1.79e11, 12}, {4.5, 0.1}}},
      {"guy2015a", 0.56, 0.617, 1.577, 1.577, 423.0, 2.4e-3, 0.3, 0.0, {{3e6, 5}, {9e-2, 0.1}}},
      {"guy2015b", 0.563, 0.610, 1.09, 1.538, 3.5, 2.4e-3, 0.3, 0.0, {{1.0e6, 6}}},
      {"fall2015", 0.38, 0.454, 1.00, 1.00, 0.116, 0.89e-3, 1.19, 0.0, {{4.0e4, 3}}},
      {"hermes2016", 0.436, 0.535, 0.8, 0.8, 5.35, 6e-3, 1.19, 0.0, {{1.86e4, 4}, {9.3e-3, 0.1}}},
  };
  return f;
}

// eta_B (paper eq. eta_B); infinite without terms.
inline double eta_B(const Fit& p, double phi) {
  double s = 0;
  for (auto t : p.terms) s += t.phi_i * std::pow(p.phi_j - phi, t.alpha);
  return s > 0 ? 1.0 / s : INFINITY;
}
// f_m (paper eq. cmax).
inline double f_m(const Fit& p, double phi) {
  const double ps = p.phi_j + (p.phi_c - p.phi_j) * p.Delta;
  if (phi <= p.phi_c) return 1.0;
  if (phi <= ps) return (phi - p.phi_j) / (p.phi_c - p.phi_j);
  return (ps - p.phi_j) / (p.phi_c - p.phi_j);
}
// Paper SI eq. phi_j (f -> 0) and eq. phi_c (f -> 1).
inline double eta_r_low(const Fit& p, double phi) {
  return 1 + 2.5 * phi * p.phi_j / (p.phi_j - phi) + 2 * p.mu_c * std::pow(p.a_0 * phi / (p.phi_j - phi), 2);
}
inline double eta_r_high(const Fit& p, double phi) {
  return 1 + 2.5 * phi * p.phi_c / (p.phi_c - phi) + 2 * p.mu_c * std::pow(p.a_inf * phi / (p.phi_c - phi), 2);
}
// Paper SI eq. dst.
inline double gamma_dot_dst(const Fit& p, double phi) {
  const double a = p.a_0 + (p.a_inf - p.a_0) * f_m(p, phi);
  return p.tau_star / p.eta_0 *
         std::pow(2 * p.mu_c * std::pow(eta_B(p, phi) / p.eta_0 * a * phi / (p.phi_j - phi), 2), -1.0 / 3.0);
}

// The steady flow curve at structure f (E11 of docs/equations.md with xi_dot_eps = 0, from E6 = 0), with
// phi_m(f) = phi_j + (phi_c - phi_j) f (E1), a(f) = a_0 + (a_inf - a_0) f (E2) and
// c = tau_bar/(eta_0 gamma_dot) = eta_r - 1 - (5/2) phi, eta_r written out from E3.
inline double gamma_dot_of_f(const Fit& p, double phi, double f) {
  const double phi_m = p.phi_j + (p.phi_c - p.phi_j) * f;
  const double a = p.a_0 + (p.a_inf - p.a_0) * f;
  const double eta_r = 1 + 2.5 * phi * phi_m / (phi_m - phi) + 2 * p.mu_c * std::pow(a * phi / (phi_m - phi), 2);
  const double c = eta_r - 1 - 2.5 * phi;
  return p.tau_star / (c * p.eta_0) * std::pow((1 + c * p.eta_0 / eta_B(p, phi)) * f / (f_m(p, phi) - f), 2.0 / 3.0);
}

}  // namespace paper
