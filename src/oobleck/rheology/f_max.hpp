#pragma once
// Upper bound of the steady structure, E9 (docs/equations.md) (paper eq. cmax).
#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// phi* = phi_j + (phi_c - phi_j) Delta.
inline double phi_star(const SteadyParams& p) { return p.phi_j + (p.phi_c - p.phi_j) * p.Delta; }

/// E9: f_m(phi) = 1 for phi <= phi_c; (phi - phi_j)/(phi_c - phi_j) for phi_c < phi <= phi*;
/// (phi* - phi_j)/(phi_c - phi_j) for phi > phi*.
/// (Both branches computed and selected, so that a loop over points that calls it vectorises.)
inline double f_m(const SteadyParams& p, double phi) {
  const double ps = phi_star(p);
  const double phi_eff = phi <= ps ? phi : ps;
  const double above = (phi_eff - p.phi_j) / (p.phi_c - p.phi_j);
  return phi <= p.phi_c ? 1.0 : above;
}

}  // namespace oobleck::rheology
