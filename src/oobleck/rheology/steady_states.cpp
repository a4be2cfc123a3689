#include "oobleck/rheology/steady_states.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::rheology {

SteadyPoint steady_point_at_x(const SteadyParams& p, double phi, double x) {
  const double fu = f_upper(p, phi);
  return steady_point(p, phi, fu / (1.0 + std::exp(-x)), fu / (1.0 + std::exp(x)));
}

SteadyCurve::SteadyCurve(const SteadyParams& p, double phi, int samples) : p_(p), phi_(phi) {
  if (samples < 2) samples = 2;
  const double dx = 2.0 * kSweepX / (samples - 1);
  for (int k = 0; k < samples; ++k) {
    const double x = k == samples - 1 ? kSweepX : -kSweepX + dx * k;
    const SteadyPoint s = steady_point_at_x(p_, phi_, x);
    x_.push_back(x);
    ln_rate_.push_back(std::log(s.shear_rate));
    ln_stress_.push_back(std::log(s.shear_stress));
  }
}

std::vector<SteadyPoint> SteadyCurve::states_at(Control control, double value) const {
  const double target = std::log(value);
  const std::vector<double>& y = control == Control::shear_rate ? ln_rate_ : ln_stress_;
  auto g = [&](double x, SteadyPoint& s) {
    s = steady_point_at_x(p_, phi_, x);
    return std::log(control == Control::shear_rate ? s.shear_rate : s.shear_stress) - target;
  };
  std::vector<SteadyPoint> out;
  SteadyPoint s;
  for (std::size_t k = 0; k < x_.size(); ++k) {
    const double gk = y[k] - target;
    if (gk == 0.0) {
      g(x_[k], s);
      out.push_back(s);
      continue;
    }
    if (k + 1 == x_.size()) break;
    const double gn = y[k + 1] - target;
    if (!(std::isfinite(gk) && std::isfinite(gn)) || gn == 0.0 || (gk < 0.0) == (gn < 0.0)) continue;
    double lo = x_[k], hi = x_[k + 1];  // g(lo) and g(hi) of opposite signs
    const bool rising = gk < 0.0;
    for (int it = 0; it < 200; ++it) {
      const double m = 0.5 * (lo + hi);
      if (!(m > lo && m < hi)) break;  // the bracket is at the resolution of doubles
      const double gm = g(m, s);
      if (gm == 0.0) {
        lo = hi = m;
        break;
      }
      ((gm < 0.0) == rising ? lo : hi) = m;
    }
    g(0.5 * (lo + hi), s);
    out.push_back(s);
  }
  return out;
}

SteadyPoint SteadyCurve::fastest_sample() const {
  const auto k = std::max_element(ln_rate_.begin(), ln_rate_.end()) - ln_rate_.begin();
  return steady_point_at_x(p_, phi_, x_[static_cast<std::size_t>(k)]);
}

std::vector<SteadyPoint> steady_states_at(const SteadyParams& p, double phi, Control control, double value,
                                          int samples) {
  validate_phi(p, phi, "phi");
  if (!(std::isfinite(value) && value > 0.0)) {
    throw InputError(fmt::format("{} = {}: must be a positive finite number [{}]",
                                 control == Control::shear_rate ? "shear_rate" : "shear_stress", value,
                                 control == Control::shear_rate ? "1/s" : "Pa"));
  }
  return SteadyCurve(p, phi, samples).states_at(control, value);
}

}  // namespace oobleck::rheology
