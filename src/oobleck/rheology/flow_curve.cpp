#include "oobleck/rheology/flow_curve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/numerics/roots.hpp"
#include "oobleck/rheology/dilation.hpp"
#include "oobleck/rheology/eta_b.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/structure_evolution.hpp"
#include "oobleck/rheology/viscosity.hpp"

namespace oobleck::rheology {

void validate_phi(const SteadyParams& p, double phi, const std::string& where) {
  if (!(std::isfinite(phi) && phi > 0.0 && phi < p.phi_j)) {
    throw InputError(
        fmt::format("{} = {}: must lie in (0, phi_j) with phi_j = {}; at phi >= phi_j the "
                    "suspension is jammed and has no steady flow",
                    where, phi, p.phi_j));
  }
}

double f_upper(const SteadyParams& p, double phi) { return std::min(f_m(p, phi), f_jam(p, phi)); }

SteadyPoint steady_point(const SteadyParams& p, double phi, double f, double gap) {
  const double fm = f_m(p, phi);
  const double fj = f_jam(p, phi);
  const double fu = std::min(fm, fj);
  const double fm_minus_f = (fm - fu) + gap;                            // f_m - f
  const double phim_minus_phi = phi_m_gap(p, (fj - fu) + gap);          // phi_m(f) - phi (E1)
  const double a = a_of_f(p, f);                                        // E2
  const double c = granular_viscosity(phi, a, phim_minus_phi, p.mu_c);  // tau_bar/(eta_0 gamma_dot)
  const double inv_eta_B = inverse_eta_B(p, phi);                       // E8

  // E11 (xi_dot_eps = 0): gamma_dot = tau*/(c eta_0) [(1 + c eta_0/eta_B) f/(f_m - f)]^{2/3}
  const double B = (1.0 + c * p.eta_0 * inv_eta_B) * f;
  double gamma_dot = p.tau_star / (c * p.eta_0) * std::cbrt(std::pow(B / fm_minus_f, 2.0));
  if (p.xi_dot_eps > 0.0 && f > 0.0) {
    // With xi_dot_eps > 0, E10 reads A g^{3/2} = B + C/g, A = (c eta_0/tau*)^{3/2}(f_m - f),
    // C = xi_dot_eps f. F(u) = ln A + 1.5 u - ln(B + C e^{-u}) is increasing in u = ln g with
    // slope in [1.5, 2.5]; the root lies in [ln g0, ln g0 + ln((B + C/g0)/B)/1.5].
    const double lnA = 1.5 * std::log(c * p.eta_0 / p.tau_star) + std::log(fm_minus_f);
    const double C = p.xi_dot_eps * f;
    const double u0 = std::log(gamma_dot);
    const double u1 = u0 + std::log((B + C / gamma_dot) / B) / 1.5 + 1e-12;
    auto fdf = [&](double u, double& F, double& dF) {
      const double e = C * std::exp(-u);
      F = lnA + 1.5 * u - std::log(B + e);
      dF = 1.5 + e / (B + e);
    };
    const auto root = numerics::newton_bracketed(fdf, u0 - 1e-12, u1, 1e-15, 1.0);
    if (!root.converged) {
      throw NumericalError(fmt::format("steady state with xi_dot_eps did not converge at phi = {}, f = {}", phi, f));
    }
    gamma_dot = std::exp(root.x);
  }

  SteadyPoint s;
  s.phi = phi;
  s.f = f;
  s.shear_rate = gamma_dot;
  s.eta_r = 1.0 + 2.5 * phi + c;                                              // E3
  s.granular_shear_stress = c * p.eta_0 * gamma_dot;                          // E5
  s.granular_pressure = eta_n(phi, a, phim_minus_phi) * p.eta_0 * gamma_dot;  // E4
  s.shear_stress = s.eta_r * p.eta_0 * gamma_dot;                             // E3
  s.viscosity = s.eta_r * p.eta_0;
  return s;
}

std::vector<SteadyPoint> flow_curve(const SteadyParams& p, double phi, int points) {
  validate_phi(p, phi, "phi");
  points = std::max(points, 2);
  const double fu = f_upper(p, phi);
  constexpr double kEnd = 1e-10;  // relative distance of the first/last point from 0 and f_u
  const double x_max = std::log((1.0 - kEnd) / kEnd);
  std::vector<SteadyPoint> curve;
  curve.reserve(static_cast<std::size_t>(points));
  for (int k = 0; k < points; ++k) {
    const double x = -x_max + 2.0 * x_max * k / (points - 1);
    const double s = 1.0 / (1.0 + std::exp(-x));     // f/f_u
    const double s_gap = 1.0 / (1.0 + std::exp(x));  // 1 - f/f_u, without cancellation
    curve.push_back(steady_point(p, phi, fu * s, fu * s_gap));
  }
  return curve;
}

double eta_r_low(const SteadyParams& p, double phi) {  // E12
  return eta_r(phi, p.a_0, p.phi_j - phi, p.mu_c);
}

double eta_r_high(const SteadyParams& p, double phi) {  // E13
  return eta_r(phi, p.a_inf, p.phi_c - phi, p.mu_c);
}

std::optional<double> shear_rate_dst(const SteadyParams& p, double phi, std::string* reason) {
  const double ps = phi_star(p);
  auto no = [&](std::string why) -> std::optional<double> {
    if (reason != nullptr) *reason = std::move(why);
    return std::nullopt;
  };
  if (phi < p.phi_c) {
    return no(fmt::format("phi = {} < phi_c = {}: continuous shear thickening (CST), no DST", phi, p.phi_c));
  }
  if (phi > ps) {
    return no(
        fmt::format("phi = {} > phi* = {} (Delta = {}): f_m is capped, the flow curve has no DST "
                    "asymptote (shear jamming)",
                    phi, ps, p.Delta));
  }
  const double inv_eta_B = inverse_eta_B(p, phi);
  if (!(inv_eta_B > 0.0)) {
    return no("eta_B is infinite (no eta_B terms): the DST rate tends to 0, i.e. shear jamming");
  }
  const double eta_B_over_eta_0 = 1.0 / (inv_eta_B * p.eta_0);
  const double r = eta_B_over_eta_0 * a_of_f(p, f_m(p, phi)) * phi / (p.phi_j - phi);
  return p.tau_star / p.eta_0 / std::cbrt(2.0 * p.mu_c * r * r);  // E14
}

std::optional<SteadyShearLimit> fastest_steady_shear(const SteadyParams& p, double phi) {
  validate_phi(p, phi, "phi");
  const double fu = f_upper(p, phi);
  // The flow curve in the logistic coordinate x of flow_curve (f/f_u = 1/(1 + e^-x)), so that
  // states next to f_u keep their gap f_u - f without cancellation.
  constexpr double kEnd = 1e-10;
  const double x_max = std::log((1.0 - kEnd) / kEnd);
  auto rate = [&](double x) {
    return steady_point(p, phi, fu / (1.0 + std::exp(-x)), fu / (1.0 + std::exp(x))).shear_rate;
  };
  constexpr int kSamples = 2000;
  const double dx = 2.0 * x_max / (kSamples - 1);
  int best = 0;
  double best_rate = -1.0;
  for (int k = 0; k < kSamples; ++k) {
    const double g = rate(-x_max + dx * k);
    if (g > best_rate) {
      best_rate = g;
      best = k;
    }
  }
  if (best == kSamples - 1) {
    // Rising to the end of the sweep: the DST asymptote (finite) or no bound at all.
    const auto dst = shear_rate_dst(p, phi);
    if (!dst) return std::nullopt;
    return SteadyShearLimit{*dst, INFINITY, fu, false};
  }
  // Golden-section refinement of the sampled maximum (gamma_dot is smooth in x and has a single
  // hump between the neighbouring samples).
  const double inv_phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = -x_max + dx * std::max(best - 1, 0), hi = -x_max + dx * std::min(best + 1, kSamples - 1);
  double x1 = hi - inv_phi * (hi - lo), x2 = lo + inv_phi * (hi - lo);
  double g1 = rate(x1), g2 = rate(x2);
  while (hi - lo > 1e-12 * std::max(1.0, std::fabs(hi))) {
    if (g1 < g2) {
      lo = x1;
      x1 = x2;
      g1 = g2;
      x2 = lo + inv_phi * (hi - lo);
      g2 = rate(x2);
    } else {
      hi = x2;
      x2 = x1;
      g2 = g1;
      x1 = hi - inv_phi * (hi - lo);
      g1 = rate(x1);
    }
  }
  const double x = 0.5 * (lo + hi);
  const SteadyPoint s = steady_point(p, phi, fu / (1.0 + std::exp(-x)), fu / (1.0 + std::exp(x)));
  return SteadyShearLimit{s.shear_rate, s.shear_stress, s.f, true};
}

void flow_curve_columns(const SteadyParams& p, std::span<const double> phis, int points, std::span<double> out) {
  const std::size_t rows = phis.size() * static_cast<std::size_t>(std::max(points, 2));
  if (out.size() != kFlowCurveColumns.size() * rows) {
    throw std::invalid_argument(fmt::format("flow_curve_columns: {} values for {} columns of {} rows", out.size(),
                                            kFlowCurveColumns.size(), rows));
  }
  double* c = out.data();
  std::size_t i = 0;
  for (const double phi : phis) {
    const double dst_rate = shear_rate_dst(p, phi).value_or(std::numeric_limits<double>::quiet_NaN());  // E14
    for (const auto& pt : flow_curve(p, phi, points)) {
      c[i] = pt.phi;
      c[rows + i] = pt.f;
      c[2 * rows + i] = pt.shear_rate;
      c[3 * rows + i] = pt.shear_stress;
      c[4 * rows + i] = pt.granular_pressure;
      c[5 * rows + i] = pt.granular_shear_stress;
      c[6 * rows + i] = pt.viscosity;
      c[7 * rows + i] = pt.eta_r;
      c[8 * rows + i] = dst_rate;
      ++i;
    }
  }
}

std::vector<double> flow_curve_columns(const SteadyParams& p, std::span<const double> phis, int points) {
  std::vector<double> out(kFlowCurveColumns.size() * phis.size() * static_cast<std::size_t>(std::max(points, 2)));
  flow_curve_columns(p, phis, points, out);
  return out;
}

}  // namespace oobleck::rheology
