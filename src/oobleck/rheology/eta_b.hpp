#pragma once
// Resistance to buckling-induced structure loss, E8 (docs/equations.md) (paper eq. eta_B).
#include <cmath>
#include <limits>

#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// 1/eta_B(phi) = sum_i phi_i (phi_j - phi)^alpha_i  [1/(Pa s)]; 0 means eta_B = infinity.
/// Working with the inverse keeps the "no terms" case (Singh fit (a)) finite.
inline double inverse_eta_B(const SteadyParams& p, double phi) {
  const double gap = p.phi_j - phi;
  if (gap <= 0.0) return 0.0;  // jammed: structure cannot buckle away
  double sum = 0.0;
  for (const EtaBTerm& t : p.eta_B_terms) sum += t.phi_i * std::pow(gap, t.alpha);
  return sum;
}

/// E8: eta_B(phi) [Pa s]; +infinity when there are no terms.
inline double eta_B(const SteadyParams& p, double phi) {
  const double inv = inverse_eta_B(p, phi);
  return inv > 0.0 ? 1.0 / inv : std::numeric_limits<double>::infinity();
}

}  // namespace oobleck::rheology
