#pragma once
// Shared helpers of the material tests: presets with overrides, and the closed-form steady state
// (rheology::steady_point, E11 in docs/equations.md) at a given shear rate or structure.
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::test {

inline rheology::Preset preset(const std::string& name, double d = -1.0) {
  rheology::Preset p = rheology::load_preset(name);
  if (d > 0.0) p.granular.d = d;
  return p;
}

/// Closed-form steady state at structure f (gap to f_u computed directly).
inline rheology::SteadyPoint steady_at_f(const rheology::SteadyParams& s, double phi, double f) {
  const double fu = rheology::f_upper(s, phi);
  return rheology::steady_point(s, phi, f, fu - f);
}

/// All structures f on the closed-form curve with steady shear rate `rate` (bisection between
/// sign changes of gamma_dot(f) - rate on a fine parametric sweep); the one nearest `f_hint`.
inline double steady_f_at_rate(const rheology::SteadyParams& s, double phi, double rate, double f_hint) {
  const auto curve = rheology::flow_curve(s, phi, 2000);
  double best = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
    double a = curve[i].f, b = curve[i + 1].f;
    double ra = curve[i].shear_rate - rate, rb = curve[i + 1].shear_rate - rate;
    if ((ra > 0.0) == (rb > 0.0)) continue;
    for (int k = 0; k < 200 && (b - a) > 1e-15 * b; ++k) {
      const double m = 0.5 * (a + b);
      const double rm = steady_at_f(s, phi, m).shear_rate - rate;
      if ((rm > 0.0) == (ra > 0.0)) {
        a = m;
        ra = rm;
      } else {
        b = m;
      }
    }
    const double f = 0.5 * (a + b);
    if (std::isnan(best) || std::fabs(f - f_hint) < std::fabs(best - f_hint)) best = f;
  }
  return best;
}

inline double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

/// A random 3x3 tensor of Frobenius norm `mag` (normal entries, rescaled).
inline Eigen::Matrix3d random_tensor(std::mt19937_64& rng, double mag) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = n(rng);
  return mag * m / m.norm();
}

/// A value uniform in log between lo and hi.
inline double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}

}  // namespace oobleck::test
