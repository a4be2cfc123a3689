#pragma once
// V2 elastic wave problems shared by the tests (and mirrored by bench/mpm_wave_convergence.cpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

namespace oobleck::mpm::testing {

struct WaveResult {
  double period_s = 0;           ///< measured period (mean over the measured crossings)
  double period_exact_s = 0;     ///< analytic period
  double rel_period_error = 0;   ///< |T − T_exact| / T_exact
  double amplitude_ratio = 0;    ///< max |mode amplitude| over the last period / initial
  double l2_velocity_error = 0;  ///< mass-weighted RMS of v_x − v_exact at the end, / V
};

/// Uniaxial-strain standing wave in a plane-strain column, periodic in y.
///  * `fixed_ends = false`: periodic in x too, v_x = V sin(2πx/L), period L/c.
///  * `fixed_ends = true`: frictionless walls at x = 0 and x = L (v_x = 0 on the face and ghost
///    nodes), v_x = V sin(πx/L), period 2L/c.
/// c = √(M/ρ), M = λ + 2μ. Runs `periods` periods at Δt = cfl h/c with `ppc`² points per cell.
inline WaveResult run_standing_wave(ShapeKind shape, Transfer transfer, double flip, int cells_x, bool fixed_ends,
                                    int periods = 2, double cfl = 0.1, int ppc = 2) {
  const double L = 1.0, rho = 1000.0, V = 1e-4;
  material::LinearElasticParams ep;
  ep.youngs_modulus_Pa = 1e7;
  ep.poisson_ratio = 0.25;
  const double M = ep.p_wave_modulus_Pa(), c = std::sqrt(M / rho);
  const double h = L / cells_x;
  const int cells_y = 4;
  Grid<2> grid(Vec<2>(0.0, 0.0), h, {cells_x, cells_y}, {!fixed_ends, true});
  SolverOptions<PlaneStrain> opt;
  opt.shape = shape;
  opt.transfer = transfer;
  opt.flip_fraction = flip;
  opt.gimp_half_width_cells = 0.5 / ppc;
  opt.threads = 1;
  const double k = (fixed_ends ? 1.0 : 2.0) * M_PI / L;
  const double T_exact = 2.0 * M_PI / (c * k);
  // Δt = T/n with n steps per period so that the run ends on whole periods.
  const int steps_per_period = static_cast<int>(std::ceil(T_exact / (cfl * h / c)));
  opt.dt_s = T_exact / steps_per_period;
  Solver<PlaneStrain> s(grid, opt);
  if (fixed_ends) {
    s.boundaries()[0].type = WallType::Slip;
    s.boundaries()[1].type = WallType::Slip;
  }
  auto& b = s.add_body("column");
  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
  fill_box(b, Vec<2>(0.0, 0.0), Vec<2>(L, cells_y * h), h, ppc, rho,
           [&](const Vec<2>& x) { return Vec<2>(V * std::sin(k * x[0]), 0.0); });
  const std::vector<Vec<2>> x0 = b.x_m;
  // Mode amplitude a(t) = ∑ m v_x sin(k X) / ∑ m sin²(k X) with the reference positions X.
  auto amplitude = [&]() {
    double num = 0.0, den = 0.0;
    for (std::int64_t p = 0; p < b.size(); ++p) {
      const double sk = std::sin(k * x0[p][0]);
      num += b.mass_kg[p] * b.v_m_s[p][0] * sk;
      den += b.mass_kg[p] * sk * sk;
    }
    return num / den;
  };
  double a_prev = amplitude(), t_prev = 0.0, a_max_last = 0.0;
  std::vector<double> down_crossings;  // a(t) = V cos(ωt): downward zero crossings at T/4 + nT
  const int n_steps = periods * steps_per_period + steps_per_period / 2;
  for (int i = 0; i < n_steps; ++i) {
    s.step();
    const double a = amplitude(), t = s.time_s();
    if (a_prev > 0.0 && a <= 0.0) down_crossings.push_back(t_prev + (t - t_prev) * a_prev / (a_prev - a));
    if (i >= n_steps - steps_per_period) a_max_last = std::max(a_max_last, std::fabs(a));
    a_prev = a;
    t_prev = t;
  }
  WaveResult r;
  r.period_exact_s = T_exact;
  if (down_crossings.size() >= 2)
    r.period_s = (down_crossings.back() - down_crossings.front()) / static_cast<double>(down_crossings.size() - 1);
  r.rel_period_error = std::fabs(r.period_s - T_exact) / T_exact;
  // Amplitude and field error at the end (t = (periods + 1/2) T up to round-off: v = −V sin(kx)).
  double e2 = 0.0, m2 = 0.0;
  const double t = s.time_s();
  for (std::int64_t p = 0; p < b.size(); ++p) {
    const double ve = V * std::sin(k * x0[p][0]) * std::cos(c * k * t);
    e2 += b.mass_kg[p] * std::pow(b.v_m_s[p][0] - ve, 2);
    m2 += b.mass_kg[p];
  }
  r.l2_velocity_error = std::sqrt(e2 / m2) / V;
  r.amplitude_ratio = a_max_last / V;
  return r;
}

}  // namespace oobleck::mpm::testing
