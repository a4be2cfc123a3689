#pragma once
// Fluid phase law (E25–E27, docs/equations.md) as pure per-point functions. They know nothing of
// grids or bodies: the MPM solver and any point driver call them with a point's state.
//
//   E25  τ_f = η_0 (1 + (5/2) φ) (∇v_f + ∇v_fᵀ − (2/3) div v_f 1)   (Einstein-corrected viscosity)
//   E26  p_f = κ ln(ρ_f/ρ_f0) = −κ ln J,   J = ρ_f0/ρ_f
//   E27  (n/ρ_f) Dρ_f/Dt = −div q,  q = (1−n) v_s + n v_f  ⇒  J ← J exp(Δt div q / n),
//        in logarithms ln J ← ln J + Δt div q / n (the form the MPM solver integrates: E26 needs
//        only ln J, so no exp and log per point and step, and ln J keeps its relative precision
//        where J is within 1e-3 of 1)
//
// Stress is positive in tension; p_f is positive in compression. Tensors are 3×3 in every
// geometry mode (plane strain: zero third row/column of L; axisymmetric: (r, z, θ) order).
#include <Eigen/Core>
#include <cmath>

#include "oobleck/rheology/params.hpp"

namespace oobleck::material {

/// Parameters of the fluid law, SI units (declared with the other material parameters).
using FluidParams = rheology::FluidParams;

/// Effective mixture viscosity seen by the fluid phase, η_0 (1 + 5φ/2) [Pa s] (E25).
inline double fluid_effective_viscosity(double eta_0_Pa_s, double phi) { return eta_0_Pa_s * (1.0 + 2.5 * phi); }

/// E25: deviatoric viscous stress τ_f [Pa] from the fluid velocity gradient L = ∇v_f [1/s]
/// (L_ij = ∂v_i/∂x_j) at granular volume fraction φ.
inline Eigen::Matrix3d fluid_viscous_stress(const Eigen::Matrix3d& L, double phi, double eta_0_Pa_s) {
  const double eta = fluid_effective_viscosity(eta_0_Pa_s, phi);
  const double div = L.trace();
  Eigen::Matrix3d tau = eta * (L + L.transpose());
  tau.diagonal().array() -= eta * (2.0 / 3.0) * div;
  return tau;
}

/// E26: fluid pressure p_f [Pa] from the volume ratio J = ρ_f0/ρ_f: p_f = κ ln(ρ_f/ρ_f0) = −κ ln J.
inline double fluid_pressure(double J, double kappa_Pa) { return -kappa_Pa * std::log(J); }

/// E26 written with densities.
inline double fluid_pressure_from_density(double rho_f, double rho_f0, double kappa_Pa) {
  return kappa_Pa * std::log(rho_f / rho_f0);
}

/// E27, integrated exponentially over one step with div q and n frozen:
/// J ← J exp(Δt div q / n), q = (1−n) v_s + n v_f evaluated at the nodes and interpolated.
/// `porosity` n must be > 0 (the solver clamps it with a named minimum, E28 in docs/equations.md).
inline double update_fluid_volume_ratio(double J, double div_q_per_s, double porosity, double dt_s) {
  return J * std::exp(dt_s * div_q_per_s / porosity);
}

/// E26 from the logarithmic volume ratio: p_f = −κ ln J [Pa].
inline double fluid_pressure_from_log_volume_ratio(double ln_J, double kappa_Pa) { return -kappa_Pa * ln_J; }

/// E27 in logarithms, the same integration as update_fluid_volume_ratio (div q and n frozen over
/// the step): ln J ← ln J + Δt div q / n. `porosity` n must be > 0.
inline double update_fluid_log_volume_ratio(double ln_J, double div_q_per_s, double porosity, double dt_s) {
  return ln_J + dt_s * div_q_per_s / porosity;
}

/// Fluid Cauchy stress σ_f = τ_f − p_f 1 [Pa] (E25) for a given pressure p_f [Pa].
inline Eigen::Matrix3d fluid_cauchy_stress_at_pressure(const Eigen::Matrix3d& L, double phi, double p_f_Pa,
                                                       double eta_0_Pa_s) {
  Eigen::Matrix3d s = fluid_viscous_stress(L, phi, eta_0_Pa_s);
  s.diagonal().array() -= p_f_Pa;
  return s;
}

/// Fluid Cauchy stress σ_f = τ_f − p_f 1 [Pa] (E25 + E26); `J` = ρ_f0/ρ_f.
inline Eigen::Matrix3d fluid_cauchy_stress(const Eigen::Matrix3d& L, double phi, double J, const FluidParams& p) {
  return fluid_cauchy_stress_at_pressure(L, phi, fluid_pressure(J, p.kappa_Pa), p.eta_0_Pa_s);
}

/// Fluid pressure-wave speed √(κ/ρ_f) [m/s] used by the stable time step (docs/mpm.md, "The step").
inline double fluid_wave_speed(double kappa_Pa, double rho_f_kg_m3) { return std::sqrt(kappa_Pa / rho_f_kg_m3); }

}  // namespace oobleck::material
