#pragma once
// Interphase drag (E29, docs/equations.md, fluid phase and coupling) and its semi-implicit nodal update.
//
//   E29  f_d = C_V (v_s − v_f),  C_V = 18 φ (1−φ) η_0 / d² · F̂(φ, Re)      [force per mixture volume]
//        Re = |v_s − v_f| n ρ_f d / η_0
//   Beetstra et al. 2007 (AIChE J. 53:489):
//        F̂ = 10φ/(1−φ)² + (1−φ)²(1 + 1.5√φ)
//            + 0.413 Re/(24(1−φ)²) · (1/(1−φ) + 3φ(1−φ) + 8.4 Re^{−0.343}) / (1 + 10^{3φ} Re^{−(1+4φ)/2})
//        (the Re term is exactly 0 at Re = 0 and tends to 0 continuously as Re → 0)
//   Carman–Kozeny alternative: permeability k = d² (1−φ)³ / (K_CK φ²) (K_CK = 180), i.e. a Darcy
//        drag C_V = η_0 n²/k = K_CK φ² η_0 / (d² (1−φ)), which in E29's form is
//        F̂_CK = (K_CK/18) φ/(1−φ)² (= Beetstra's first term for K_CK = 180). No Stokes limit.
//
// The grains receive −f_d, the fluid +f_d (per unit mixture volume).
#include <cmath>
#include <numbers>

namespace oobleck::material {

enum class DragLaw { Beetstra, CarmanKozeny };

struct DragParams {
  DragLaw law = DragLaw::Beetstra;
  double d_m = 5.85e-6;            ///< [m] grain diameter d
  double eta_0_Pa_s = 1e-3;        ///< [Pa s] fluid viscosity η_0
  double kozeny_constant = 180.0;  ///< [-] K_CK of the Carman–Kozeny permeability
  bool use_reynolds = true;        ///< Beetstra only: include the finite-Re term (false ⇒ Re = 0)
};

/// The exponents of the two powers in Beetstra's Re term, as arguments of exp given ln Re:
/// Re^{−0.343} = exp(beetstra_arg1(ln Re)), 10^{3φ} Re^{−(1+4φ)/2} = exp(beetstra_arg2(φ, ln Re)).
inline double beetstra_arg1(double ln_Re) { return -0.343 * ln_Re; }
inline double beetstra_arg2(double phi, double ln_Re) {
  return 3.0 * phi * std::numbers::ln10 - 0.5 * (1.0 + 4.0 * phi) * ln_Re;
}

/// Beetstra's F̂ (E29) given the two powers of its Re term (unused for Re <= 0):
/// r1 = Re^{−0.343}, r2 = 10^{3φ} Re^{−(1+4φ)/2}.
inline double beetstra_F_with_powers(double phi, double Re, double r1, double r2) {
  const double n = 1.0 - phi;
  double F = 10.0 * phi / (n * n) + n * n * (1.0 + 1.5 * std::sqrt(phi));
  if (Re > 0.0) {
    const double num = 1.0 / n + 3.0 * phi * n + 8.4 * r1;
    const double den = 1.0 + r2;
    F += 0.413 * Re / (24.0 * n * n) * num / den;
  }
  return F;
}

/// Beetstra's normalized drag F̂(φ, Re) [-] (E29). The powers through one logarithm and two
/// exponentials (instead of three pow calls); relative difference < 2e-14 for 1e-12 < Re < 1e3.
inline double beetstra_F(double phi, double Re) {
  if (!(Re > 0.0)) return beetstra_F_with_powers(phi, Re, 0.0, 0.0);
  const double ln_Re = std::log(Re);
  return beetstra_F_with_powers(phi, Re, std::exp(beetstra_arg1(ln_Re)), std::exp(beetstra_arg2(phi, ln_Re)));
}

/// Carman–Kozeny drag written as E29's F̂ [-].
inline double carman_kozeny_F(double phi, double kozeny_constant = 180.0) {
  const double n = 1.0 - phi;
  return kozeny_constant / 18.0 * phi / (n * n);
}

/// Particle Reynolds number Re = |v_s − v_f| n ρ_f d / η_0 [-] (E29).
inline double drag_reynolds(double rel_speed_m_s, double porosity, double rho_f_kg_m3, double d_m, double eta_0_Pa_s) {
  return rel_speed_m_s * porosity * rho_f_kg_m3 * d_m / eta_0_Pa_s;
}

/// Normalized drag F̂ [-] of the selected law.
inline double drag_F(const DragParams& p, double phi, double Re) {
  switch (p.law) {
    case DragLaw::CarmanKozeny: return carman_kozeny_F(phi, p.kozeny_constant);
    case DragLaw::Beetstra:
    default: return beetstra_F(phi, p.use_reynolds ? Re : 0.0);
  }
}

/// E29's prefactor 18 φ(1−φ) η_0/d² [Pa s/m²]: C_V = prefactor · F̂.
inline double drag_stokes_prefactor(const DragParams& p, double phi) {
  return 18.0 * phi * (1.0 - phi) * p.eta_0_Pa_s / (p.d_m * p.d_m);
}

/// E29 drag coefficient per unit mixture volume C_V = 18 φ(1−φ) η_0/d² F̂ [Pa s/m² = kg/(m³ s)].
/// Multiply by the nodal mixture volume V_i to get the nodal C_i [kg/s].
inline double drag_coefficient_per_volume(const DragParams& p, double phi, double Re) {
  return drag_stokes_prefactor(p, phi) * drag_F(p, phi, Re);
}

/// drag_coefficient_per_volume of numerics::kMathBlock (φ, Re) pairs [Pa s/m²], the powers of
/// Beetstra's Re term in vector lanes (numerics/vector_math.hpp; drag.cpp): the nodal drag of a
/// step, a log and two exps per mixture node.
void drag_coefficient_per_volume_block(const DragParams& p, const double* phi, const double* Re, double* C_V);

/// Semi-implicit nodal drag (E29, docs/equations.md). Given the nodal masses m_s, m_f [kg], the predicted
/// velocities v_s*, v_f* [m/s] that include every other force of the step, the nodal drag
/// coefficient C [kg/s] and Δt [s], returns the drag force F_d [N] on the fluid (the grains get
/// −F_d):
///     F_d = C/(1 + Δt C (1/m_s + 1/m_f)) (v_s* − v_f*)
/// so that v_s = v_s* − Δt F_d/m_s, v_f = v_f* + Δt F_d/m_f is exact backward Euler for the
/// relative velocity, Δv_new = Δv*/(1 + Δt C (1/m_s + 1/m_f)), and conserves m_s v_s + m_f v_f
/// exactly. Unconditionally stable (Δt C/m ≫ 1 drives Δv_new → 0, never overshoots). Nodes with
/// one phase missing (m ≤ 0) get no drag. Vec is any type with `a - b` and `scalar * a`.
template <class Vec>
inline Vec semi_implicit_drag_force(double m_s_kg, double m_f_kg, const Vec& v_s, const Vec& v_f, double C_kg_s,
                                    double dt_s) {
  if (!(m_s_kg > 0.0) || !(m_f_kg > 0.0) || !(C_kg_s > 0.0)) return 0.0 * (v_s - v_f);
  // Written as 1/(1/C + Δt(1/m_s + 1/m_f)) so that C → ∞ (rigid coupling) stays finite.
  const double k = 1.0 / (1.0 / C_kg_s + dt_s * (1.0 / m_s_kg + 1.0 / m_f_kg));
  return k * (v_s - v_f);
}

/// Scalar relative-velocity factor of the semi-implicit update, 1/(1 + Δt C (1/m_s + 1/m_f)).
inline double semi_implicit_drag_relaxation(double m_s_kg, double m_f_kg, double C_kg_s, double dt_s) {
  return 1.0 / (1.0 + dt_s * C_kg_s * (1.0 / m_s_kg + 1.0 / m_f_kg));
}

}  // namespace oobleck::material
