#pragma once
// Structure-dependent dilation parameters, E1–E2 (docs/equations.md) (paper eqs. phim_func, a_func).
#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// E1: phi_m(f) = phi_j + (phi_c - phi_j) f.
inline double phi_m(const SteadyParams& p, double f) { return p.phi_j + (p.phi_c - p.phi_j) * f; }

/// E2: a(f) = a_0 + (a_inf - a_0) f.
inline double a_of_f(const SteadyParams& p, double f) { return p.a_0 + (p.a_inf - p.a_0) * f; }

/// Structure at which phi_m(f) = phi (the mixture jams): f_jam = (phi_j - phi)/(phi_j - phi_c).
inline double f_jam(const SteadyParams& p, double phi) { return (p.phi_j - phi) / (p.phi_j - p.phi_c); }

/// phi_m(f) - phi, computed from the gap to f_jam so that it stays accurate as f -> f_jam:
/// phi_m - phi = (phi_j - phi_c) (f_jam - f).
inline double phi_m_gap(const SteadyParams& p, double f_jam_minus_f) { return (p.phi_j - p.phi_c) * f_jam_minus_f; }

}  // namespace oobleck::rheology
