// V4 settling (scenes.md V4): a uniform, non-density-matched suspension in a periodic box settles
// at the velocity that balances buoyant weight and E29 drag.
//
// Derivation (per unit mixture volume, steady, uniform; buoyancy split E28 with an imposed mean
// pressure gradient ∇p, grains get −φ∇p, fluid −n∇p):
//   grains:  φ ρ_s g − φ ∇p − C_V (v_s − v_f) = 0
//   fluid:   n ρ_f g − n ∇p + C_V (v_s − v_f) = 0
// Their sum fixes ∇p = ρ_mix g (ρ_mix = φ ρ_s + n ρ_f), and then
//   C_V Δv = φ (ρ_s − ρ_mix) g = φ n (ρ_s − ρ_f) g,   C_V = 18 φ n η_0 F̂(φ, Re)/d²
//   ⇒ Δv = (ρ_s − ρ_f) g d² / (18 η_0 F̂(φ, Re)),   Re = |Δv| n ρ_f d/η_0.
// In the frame of zero mixture volume flux (φ v_s + n v_f = 0) the grains settle at
//   u_settle = n Δv = (1 − φ)(ρ_s − ρ_f) g d² / (18 η_0 F̂(φ, Re)).
// The periodic box cannot hold a mean pressure gradient in p_f itself, so ∇p_0 = ρ_mix g is
// imposed as the background gradient (MixtureOptions); total momentum then stays zero.
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/material/drag.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

using namespace oobleck::mpm;
namespace mat = oobleck::material;

namespace {

struct SettlingResult {
  double u_settle_m_s;  // grains, downward, zero-volume-flux frame
  double u_exact_m_s;
  double momentum_y;  // total mixture momentum (should stay 0)
  double momentum_scale;
  double max_pressure_Pa;
};

SettlingResult run_settling(double phi, double d, double eta0, mat::DragLaw law, int steps, ShapeKind shape) {
  const double rho_s = 1620.0, rho_f = 1000.0, g = 9.81, h = 1e-3;
  const int cells = 8;
  Grid<2> grid(Vec<2>(0.0, 0.0), h, {cells, cells}, {true, true});
  SolverOptions<PlaneStrain> opt;
  opt.shape = shape;
  opt.transfer = Transfer::Apic;
  opt.threads = 1;
  opt.dt_s = 1e-5;
  opt.gravity_m_s2 = Vec<2>(0.0, -g);
  opt.mixture.rho_s_kg_m3 = rho_s;
  opt.mixture.rho_f0_kg_m3 = rho_f;
  opt.mixture.drag.d_m = d;
  opt.mixture.drag.eta_0_Pa_s = eta0;
  opt.mixture.drag.law = law;
  const double rho_mix = phi * rho_s + (1.0 - phi) * rho_f;
  opt.mixture.background_pressure_gradient_Pa_m = rho_mix * opt.gravity_m_s2;
  Solver<PlaneStrain> s(grid, opt);
  auto& grains = s.add_body("grains", Phase::Grains);  // no law: separated grains, σ̃ = 0
  auto& fluid = s.add_body("fluid", Phase::Fluid);
  mat::FluidParams fp;
  fp.eta_0_Pa_s = eta0;
  fp.kappa_Pa = 1e6;
  fp.rho_f0_kg_m3 = rho_f;
  fluid.set_law(std::make_unique<FluidLaw<PlaneStrain>>(fp, opt.mixture.min_porosity));
  // Both phases fill the box, 2 × 2 points per cell; point volume = mixture volume it represents.
  auto zero = [](const Vec<2>&) { return Vec<2>::Zero(); };
  fill_box(grains, Vec<2>(0, 0), Vec<2>(cells * h, cells * h), h, 2, phi * rho_s, zero);
  fill_box(fluid, Vec<2>(0, 0), Vec<2>(cells * h, cells * h), h, 2, (1.0 - phi) * rho_f, zero);
  for (int i = 0; i < steps; ++i) s.step();
  const double vs = grains.total_momentum()[1] / grains.total_mass();
  const double vf = fluid.total_momentum()[1] / fluid.total_mass();
  const double j = phi * vs + (1.0 - phi) * vf;  // mixture volume flux
  SettlingResult r;
  r.u_settle_m_s = -(vs - j);
  // Analytic, with the Re dependence of F̂ solved by fixed-point iteration.
  mat::DragParams dp;
  dp.law = law;
  dp.d_m = d;
  dp.eta_0_Pa_s = eta0;
  double dv = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double Re = mat::drag_reynolds(dv, 1.0 - phi, rho_f, d, eta0);
    dv = (rho_s - rho_f) * g * d * d / (18.0 * eta0 * mat::drag_F(dp, phi, Re));
  }
  r.u_exact_m_s = (1.0 - phi) * dv;
  r.momentum_y = grains.total_momentum()[1] + fluid.total_momentum()[1];
  r.momentum_scale = (grains.total_mass() + fluid.total_mass()) * r.u_exact_m_s;
  r.max_pressure_Pa = 0.0;
  for (const auto& sg : fluid.stress_Pa) r.max_pressure_Pa = std::max(r.max_pressure_Pa, std::fabs(sg.trace() / 3.0));
  return r;
}

}  // namespace

TEST(SettlingV4, StiffDragPaperGrainSize) {
  // d = 5.85 μm: drag time ρ/C_V ≈ 1e-8 s ≪ Δt = 1e-5 s (the semi-implicit drag never limits Δt).
  for (double phi : {0.1, 0.3, 0.5}) {
    const auto r = run_settling(phi, 5.85e-6, 1e-3, mat::DragLaw::Beetstra, 20, ShapeKind::QuadraticBSpline);
    EXPECT_NEAR(r.u_settle_m_s, r.u_exact_m_s, 1e-6 * r.u_exact_m_s) << "phi " << phi;
    EXPECT_LT(std::fabs(r.momentum_y), 1e-10 * r.momentum_scale);
    EXPECT_LT(r.max_pressure_Pa, 1e-9);
  }
}

TEST(SettlingV4, FiniteReynoldsAndCarmanKozeny) {
  // d = 100 μm: Re ≈ 0.03 and a drag time ≈ 0.2 ms, reached after the transient (1000 steps).
  {
    const auto r = run_settling(0.3, 1e-4, 1e-3, mat::DragLaw::Beetstra, 1500, ShapeKind::CubicBSpline);
    EXPECT_NEAR(r.u_settle_m_s, r.u_exact_m_s, 1e-4 * r.u_exact_m_s);
  }
  {
    const auto r = run_settling(0.4, 5.85e-6, 4.6e-3, mat::DragLaw::CarmanKozeny, 20, ShapeKind::UGimp);
    EXPECT_NEAR(r.u_settle_m_s, r.u_exact_m_s, 1e-6 * r.u_exact_m_s);
  }
}

TEST(SettlingV4, AxisymmetricColumnSameVelocity) {
  // The same balance in axisymmetric mode: a cylinder r ∈ [0, R] (axis + frictionless outer
  // wall), periodic in z, gravity along −z. Masses and volumes are both per radian, so the nodal
  // porosity n_i = 1 − m^s_i/(ρ_s V_i) is right (the authors' code mixes per-radian masses with whole volumes).
  const double phi = 0.3, rho_s = 1620.0, rho_f = 1000.0, g = 9.81, h = 1e-3, d = 5.85e-6, eta0 = 1e-3;
  const int cells = 8;
  Grid<2> grid(Vec<2>(0.0, 0.0), h, {cells, cells}, {false, true});
  SolverOptions<Axisymmetric> opt;
  opt.shape = ShapeKind::QuadraticBSpline;
  opt.threads = 1;
  opt.dt_s = 1e-5;
  opt.gravity_m_s2 = Vec<3>(0.0, -g, 0.0);
  opt.mixture.rho_s_kg_m3 = rho_s;
  opt.mixture.rho_f0_kg_m3 = rho_f;
  opt.mixture.drag.d_m = d;
  opt.mixture.drag.eta_0_Pa_s = eta0;
  opt.mixture.background_pressure_gradient_Pa_m = (phi * rho_s + (1.0 - phi) * rho_f) * opt.gravity_m_s2;
  Solver<Axisymmetric> s(grid, opt);
  s.boundaries()[0].type = WallType::Axis;
  s.boundaries()[1].type = WallType::Slip;
  auto& grains = s.add_body("grains", Phase::Grains);
  auto& fluid = s.add_body("fluid", Phase::Fluid);
  mat::FluidParams fp;
  fp.eta_0_Pa_s = eta0;
  fp.kappa_Pa = 1e6;
  fp.rho_f0_kg_m3 = rho_f;
  fluid.set_law(std::make_unique<FluidLaw<Axisymmetric>>(fp, opt.mixture.min_porosity));
  auto zero = [](const Vec<2>&) { return Vec<3>::Zero(); };
  fill_box(grains, Vec<2>(0, 0), Vec<2>(cells * h, cells * h), h, 2, phi * rho_s, zero);
  fill_box(fluid, Vec<2>(0, 0), Vec<2>(cells * h, cells * h), h, 2, (1.0 - phi) * rho_f, zero);
  for (int i = 0; i < 20; ++i) s.step();
  mat::DragParams dp;
  dp.d_m = d;
  dp.eta_0_Pa_s = eta0;
  double dv = 0.0;
  for (int it = 0; it < 100; ++it)
    dv = (rho_s - rho_f) * g * d * d /
         (18.0 * eta0 * mat::drag_F(dp, phi, mat::drag_reynolds(dv, 1.0 - phi, rho_f, d, eta0)));
  const double u_exact = (1.0 - phi) * dv;
  // Every point (not only the mean) settles at the balance velocity, also next to the axis/wall.
  for (std::int64_t p = 0; p < grains.size(); ++p) {
    const double vs = grains.v_m_s[p][1], vf = fluid.v_m_s[p][1];
    const double j = phi * vs + (1.0 - phi) * vf;
    EXPECT_NEAR(-(vs - j), u_exact, 1e-4 * u_exact) << "r " << grains.x_m[p][0];
    EXPECT_NEAR(grains.v_m_s[p][0], 0.0, 1e-6 * u_exact);
  }
}
