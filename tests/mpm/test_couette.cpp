// V3 (planar part, scenes.md V3): Newtonian fluid phase alone between a fixed no-slip floor and a
// lid moving at U, periodic in x. Steady state: v_x = U y/H and τ_xy = η_0 U/H (E25 with φ = 0).
// Also: the stable Δt reports the viscous limit ρ h²/(2η) when it is the smaller one.
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

using namespace oobleck::mpm;

TEST(CouetteV3, PlanarSteadyProfileAndStress) {
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline, ShapeKind::UGimp}) {
    const double H = 8e-3, h = H / 8, U = 0.01, eta = 1.0, rho = 1000.0;
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {4, 8}, {true, false});
    SolverOptions<PlaneStrain> opt;
    opt.shape = k;
    opt.transfer = Transfer::Apic;
    opt.threads = 1;
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[2].type = WallType::NoSlip;
    s.boundaries()[3].type = WallType::Prescribed;
    s.boundaries()[3].velocity_m_s = Eigen::Vector3d(U, 0.0, 0.0);
    auto& f = s.add_body("fluid", Phase::Fluid);
    oobleck::material::FluidParams fp;
    fp.eta_0_Pa_s = eta;
    fp.kappa_Pa = 500.0;  // c = 0.71 m/s: the viscous limit is the binding one
    fp.rho_f0_kg_m3 = rho;
    f.set_law(std::make_unique<FluidLaw<PlaneStrain>>(fp, 0.01));
    fill_box(f, Vec<2>(0.0, 0.0), Vec<2>(4 * h, H), h, 2, rho, [](const Vec<2>&) { return Vec<2>::Zero(); });
    const double dt_visc = rho * h * h / (2.0 * eta);
    EXPECT_NEAR(s.stable_dt(0.5), dt_visc, 1e-12 * dt_visc);  // 5e-4 s < 0.5 h/√(κ/ρ) = 7.1e-4 s
    s.options().dt_s = 1.01 * dt_visc;
    EXPECT_THROW(s.check_time_step(0.5), oobleck::InputError);  // refused with the numbers
    s.options().dt_s = 0.5 * s.stable_dt(0.5);
    EXPECT_NO_THROW(s.check_time_step(0.5));
    const double t_end = 3.0 * H * H * rho / eta;  // ≈ 3 diffusion times: e^{−π² 3} ≈ 1e-13
    while (s.time_s() < t_end) s.step();
    for (std::int64_t p = 0; p < f.size(); ++p) {
      const double y = f.x_m[p][1];
      EXPECT_NEAR(f.v_m_s[p][0], U * y / H, 1e-3 * U) << "kind " << static_cast<int>(k) << " y " << y;
      EXPECT_NEAR(f.v_m_s[p][1], 0.0, 1e-6 * U);
      EXPECT_NEAR(f.stress_Pa[p](0, 1), eta * U / H, 1e-3 * eta * U / H);
    }
  }
}
