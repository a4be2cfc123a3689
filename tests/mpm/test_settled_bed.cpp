// V4, second part: a settled bed. Grains (test-only linear elastic skeleton) and fluid fill a
// column of height H on a frictionless floor, periodic in x, with gravity. The analytic settled
// state is p_f = ρ_f g (H − y) (fluid carries its own weight) and a granular effective stress
// σ̃_yy = −φ (ρ_s − ρ_f) g (H − y) (the skeleton carries the buoyant weight, E28), σ̃_xx = σ̃_zz =
// ν/(1−ν) σ̃_yy, set by set_hydrostatic_bed (mpm/initial_state.hpp). Started there, the discrete
// two-phase system must hold it: velocities stay
// ≪ g T and the stresses at the floor stay at the analytic values. (The test checks that the
// analytic state is an equilibrium of the discrete coupling — buoyancy split, porosity, pressure
// force — not the transient that reaches it.)
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/mpm/initial_state.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

using namespace oobleck::mpm;
namespace mat = oobleck::material;

TEST(SettledBedV4, HydrostaticFluidAndBuoyantWeightOnSkeleton) {
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    const double h = 1e-3, H = 8e-3, g = 9.81, phi = 0.5, rho_s = 2500.0, rho_f = 1000.0;
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {4, 12}, {true, false});
    SolverOptions<PlaneStrain> opt;
    opt.shape = k;
    opt.transfer = Transfer::Apic;
    opt.threads = 1;
    opt.gravity_m_s2 = Vec<2>(0.0, -g);
    opt.mixture.rho_s_kg_m3 = rho_s;
    opt.mixture.rho_f0_kg_m3 = rho_f;
    opt.mixture.drag.d_m = 1e-5;
    opt.mixture.drag.eta_0_Pa_s = 1e-3;
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[2].type = WallType::Slip;
    auto& grains = s.add_body("grains", Phase::Grains);
    auto& fluid = s.add_body("fluid", Phase::Fluid);
    mat::LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e5;
    ep.poisson_ratio = 0.3;
    grains.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    mat::FluidParams fp;
    fp.eta_0_Pa_s = 1e-3;
    fp.kappa_Pa = 1e6;
    fp.rho_f0_kg_m3 = rho_f;
    fluid.set_law(std::make_unique<FluidLaw<PlaneStrain>>(fp, 0.01));
    auto zero = [](const Vec<2>&) { return Vec<2>::Zero(); };
    fill_box(grains, Vec<2>(0, 0), Vec<2>(4 * h, H), h, 2, phi * rho_s, zero);
    fill_box(fluid, Vec<2>(0, 0), Vec<2>(4 * h, H), h, 2, (1.0 - phi) * rho_f, zero);
    HydrostaticBed bed;
    bed.surface_m = H;
    bed.g_m_s2 = g;
    bed.rho_s_kg_m3 = rho_s;
    bed.rho_f0_kg_m3 = rho_f;
    bed.K0 = ep.poisson_ratio / (1.0 - ep.poisson_ratio);  // uniaxial-strain elastic skeleton
    bed.phi_bed = phi;
    set_hydrostatic_bed(bed, &grains, &fluid);
    opt.dt_s = s.stable_dt(0.3);
    s.options().dt_s = opt.dt_s;
    const double c_skel = std::sqrt(ep.p_wave_modulus_Pa() / (phi * rho_s));
    const double T = 4.0 * H / c_skel;
    double vmax = 0.0;
    while (s.time_s() < T) {
      s.step();
      for (const auto& v : grains.v_m_s) vmax = std::max(vmax, v.norm());
      for (const auto& v : fluid.v_m_s) vmax = std::max(vmax, v.norm());
    }
    EXPECT_LT(vmax, 2e-3 * g * T) << "kind " << static_cast<int>(k);
    double pf = 0.0, pf_ref = 0.0, sg = 0.0, sg_ref = 0.0;
    for (std::int64_t p = 0; p < fluid.size(); ++p)
      if (fluid.x_m[p][1] < h / 2) {
        pf += -fluid.stress_Pa[p].trace() / 3.0;
        pf_ref += rho_f * g * (H - fluid.x_m[p][1]);
      }
    for (std::int64_t p = 0; p < grains.size(); ++p)
      if (grains.x_m[p][1] < h / 2) {
        sg += grains.stress_Pa[p](1, 1);
        sg_ref += -phi * (rho_s - rho_f) * g * (H - grains.x_m[p][1]);
      }
    // p_f carries the fluid's own pressure waves (κ = 1e6 Pa): 2% at the floor row.
    EXPECT_NEAR(pf / pf_ref, 1.0, 0.02) << "kind " << static_cast<int>(k);
    EXPECT_NEAR(sg / sg_ref, 1.0, 0.01) << "kind " << static_cast<int>(k);
  }
}
