#pragma once
// Steady simple-shear flow curves of the Baumgarten–Kamrin model, complete with every branch:
// the curve is swept parametrically in the structure f (E11, docs/equations.md), so S-shaped and DST
// branches are never lost by a root finder in gamma_dot or tau. Asymptotes E12–E14.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {

/// One steady state of homogeneous simple shear at volume fraction phi and structure f.
struct SteadyPoint {
  double phi = 0.0;
  double f = 0.0;
  double shear_rate = 0.0;             ///< gamma_dot [1/s]
  double shear_stress = 0.0;           ///< mixture tau = eta_r eta_0 gamma_dot [Pa]
  double granular_pressure = 0.0;      ///< p~ = eta_n eta_0 gamma_dot [Pa] (E4)
  double granular_shear_stress = 0.0;  ///< tau_bar = (mu_c + mu_h) p~ [Pa] (E5)
  double viscosity = 0.0;              ///< tau/gamma_dot [Pa s]
  double eta_r = 0.0;                  ///< relative viscosity (E3)
};

/// Throws InputError unless 0 < phi < phi_j (`where` names the source of phi, e.g. "--phi").
void validate_phi(const SteadyParams& p, double phi, const std::string& where);

/// Upper end of the structure sweep: f_u = min(f_m(phi), f_jam(phi)) (docs/equations.md, steady rheology).
double f_upper(const SteadyParams& p, double phi);

/// Steady state at structure f, where `gap` = f_u - f is given separately so that states
/// arbitrarily close to f_u are computed without cancellation. E11 for xi_dot_eps = 0; a
/// monotone safeguarded Newton solve in ln(gamma_dot) for xi_dot_eps > 0.
SteadyPoint steady_point(const SteadyParams& p, double phi, double f, double gap);

/// The flow curve at phi: `points` states with f increasing from 1e-10 f_u to f_u (1 - 1e-10),
/// clustered logistically at both ends so the asymptotes are resolved.
std::vector<SteadyPoint> flow_curve(const SteadyParams& p, double phi, int points = 400);

/// The columns of a flow-curve table, in order: `oobleck rheology flow-curve`'s CSV and
/// oobleck.flow_curve. shear_rate_dst is E14 at the row's phi (NaN where DST does not apply).
inline constexpr std::array<std::string_view, 9> kFlowCurveColumns = {
    "phi",       "f",     "shear_rate",    "shear_stress", "granular_pressure", "granular_shear_stress",
    "viscosity", "eta_r", "shear_rate_dst"};

/// The flow curves at each of `phis` (flow_curve with `points` states, one curve after the other)
/// as the kFlowCurveColumns, column-major: row i of column j at out[j * rows + i], rows =
/// phis.size() * points (points < 2 taken as 2, as flow_curve). `out` must hold 9 * rows values
/// (std::invalid_argument otherwise); each phi is checked by flow_curve (validate_phi).
void flow_curve_columns(const SteadyParams& p, std::span<const double> phis, int points, std::span<double> out);

/// The same columns in a new vector of 9 * phis.size() * points values.
std::vector<double> flow_curve_columns(const SteadyParams& p, std::span<const double> phis, int points);

/// E12: relative viscosity of the low-viscosity (f -> 0) branch.
double eta_r_low(const SteadyParams& p, double phi);
/// E13: relative viscosity of the high-viscosity (f -> 1) branch; defined for phi < phi_c.
double eta_r_high(const SteadyParams& p, double phi);

/// E14: the DST shear rate [1/s] for phi_c <= phi <= phi* with finite eta_B; nullopt where DST
/// does not apply (then `reason`, if given, says why).
std::optional<double> shear_rate_dst(const SteadyParams& p, double phi, std::string* reason = nullptr);

/// The fastest steady simple shear at phi: the supremum of gamma_dot over every branch of the
/// flow curve (E11). On an S-shaped curve it is the lower branch's turning point, and where the
/// curve ends in shear jamming (gamma_dot -> 0 at f_jam) its peak (both attained at a finite
/// stress); where the upper branch rises monotonically to the DST asymptote (E14) it is
/// gamma_dot_DST, approached as the stress diverges (`attained` false, `shear_stress` infinite).
/// No steady homogeneous flow at this phi is faster.
struct SteadyShearLimit {
  double shear_rate = 0.0;    ///< sup gamma_dot [1/s]
  double shear_stress = 0.0;  ///< mixture tau at the supremum [Pa] (infinite when not attained)
  double f = 0.0;             ///< structure at the supremum
  bool attained = true;       ///< false: the DST asymptote, reached only as tau -> infinity
};

/// nullopt where the flow curve is unbounded in gamma_dot (phi < phi_c: CST, any rate flows).
/// Throws InputError unless 0 < phi < phi_j.
std::optional<SteadyShearLimit> fastest_steady_shear(const SteadyParams& p, double phi);

}  // namespace oobleck::rheology
