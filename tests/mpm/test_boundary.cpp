// Walls: a geostatic column stays at rest on a frictionless floor under gravity; tangential
// momentum along a slip wall is untouched; prescribed-velocity walls carry a block rigidly.
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

using namespace oobleck::mpm;
using oobleck::material::LinearElasticParams;

namespace {
LinearElasticParams soft() {
  LinearElasticParams ep;
  ep.youngs_modulus_Pa = 1e6;
  ep.poisson_ratio = 0.3;
  return ep;
}
}  // namespace

TEST(Boundary, GeostaticColumnStaysAtRest) {
  // Column of height H on a slip floor, periodic in x, initialized with the exact uniaxial-strain
  // geostatic stress σ_yy = −ρ g (H − y), σ_xx = σ_zz = ν/(1−ν) σ_yy. The discrete body must stay
  // (nearly) at rest: max |v| < 2e-3 g T (g T: what free fall would reach in the same time), and the floor
  // carries the weight: σ_yy at the lowest points = −ρ g (H − y) within 1%.
  for (ShapeKind k : {ShapeKind::Linear, ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline, ShapeKind::UGimp}) {
    const double H = 1.0, h = H / 16, rho = 1000.0, g = 9.81;
    const LinearElasticParams ep = soft();
    const double c = std::sqrt(ep.p_wave_modulus_Pa() / rho);
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {4, 24}, {true, false});
    SolverOptions<PlaneStrain> opt;
    opt.shape = k;
    opt.transfer = Transfer::Apic;
    opt.threads = 1;
    opt.dt_s = 0.2 * h / c;
    opt.gravity_m_s2 = Vec<2>(0.0, -g);
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[2].type = WallType::Slip;  // floor (axis 1 lower)
    auto& b = s.add_body("column");
    b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    fill_box(b, Vec<2>(0.0, 0.0), Vec<2>(4 * h, H), h, 2, rho, [](const Vec<2>&) { return Vec<2>::Zero(); });
    const double K0 = ep.poisson_ratio / (1.0 - ep.poisson_ratio);
    for (std::int64_t p = 0; p < b.size(); ++p) {
      const double syy = -rho * g * (H - b.x_m[p][1]);
      b.stress_Pa[p].diagonal() << K0 * syy, syy, K0 * syy;
    }
    const double T = 4.0 * H / c;  // fundamental period of the column
    const int n = static_cast<int>(T / opt.dt_s);
    double vmax = 0.0;
    for (int i = 0; i < n; ++i) {
      s.step();
      for (const auto& v : b.v_m_s) vmax = std::max(vmax, v.norm());
    }
    EXPECT_LT(vmax, 2e-3 * g * T) << "kind " << static_cast<int>(k);
    // Floor reaction: mean σ_yy of the bottom row of points vs −ρ g (H − y).
    double sum = 0.0, ref = 0.0;
    int cnt = 0;
    for (std::int64_t p = 0; p < b.size(); ++p) {
      if (b.x_m[p][1] < h / 2) {
        sum += b.stress_Pa[p](1, 1);
        ref += -rho * g * (H - b.x_m[p][1]);
        ++cnt;
      }
    }
    EXPECT_NEAR(sum / cnt, ref / cnt, 0.01 * std::fabs(ref / cnt)) << "kind " << static_cast<int>(k);
    // Horizontal momentum untouched by the frictionless floor.
    EXPECT_NEAR(b.total_momentum()[0], 0.0, 1e-12 * b.total_mass());
  }
}

TEST(Boundary, SlipWallKeepsTangentialMomentum) {
  // A block pressed against a frictionless wall (x = 0) while sliding along it at 0.3 m/s: the
  // tangential momentum is conserved to round-off, the normal one is absorbed by the wall.
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    const double h = 0.1;
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {12, 12});
    SolverOptions<PlaneStrain> opt;
    opt.shape = k;
    opt.threads = 1;
    const LinearElasticParams ep = soft();
    opt.dt_s = 0.2 * h / std::sqrt(ep.p_wave_modulus_Pa() / 1000.0);
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[0].type = WallType::Slip;
    auto& b = s.add_body("block");
    b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    fill_box(b, Vec<2>(0.0, 0.3), Vec<2>(0.4, 0.7), h, 2, 1000.0, [](const Vec<2>&) { return Vec<2>(-0.05, 0.3); });
    const double Py0 = b.total_momentum()[1];
    for (int i = 0; i < 100; ++i) s.step();
    EXPECT_NEAR(b.total_momentum()[1], Py0, 1e-12 * std::fabs(Py0));
    for (const auto& x : b.x_m) EXPECT_GT(x[0], -0.5 * h / 2);  // no point crosses the wall
  }
}

TEST(Boundary, PrescribedWallsCarryBlockRigidly) {
  // A block filling the gap between two walls prescribed at U = (0, 0.2) m/s, itself moving at U:
  // it must keep moving rigidly (no spurious stress from the walls), to round-off.
  const double h = 0.1;
  Grid<2> grid(Vec<2>(0.0, 0.0), h, {8, 8}, {false, true});
  SolverOptions<PlaneStrain> opt;
  opt.threads = 1;
  const LinearElasticParams ep = soft();
  opt.dt_s = 0.2 * h / std::sqrt(ep.p_wave_modulus_Pa() / 1000.0);
  for (ShapeKind k : {ShapeKind::Linear, ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline, ShapeKind::UGimp}) {
    opt.shape = k;
    Solver<PlaneStrain> s(grid, opt);
    for (int f : {0, 1}) {
      s.boundaries()[f].type = WallType::Prescribed;
      s.boundaries()[f].velocity_m_s = Eigen::Vector3d(0.0, 0.2, 0.0);
    }
    auto& b = s.add_body("block");
    b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    fill_box(b, Vec<2>(0.0, 0.0), Vec<2>(0.8, 0.8), h, 2, 1000.0, [](const Vec<2>&) { return Vec<2>(0.0, 0.2); });
    for (int i = 0; i < 50; ++i) s.step();
    for (std::int64_t p = 0; p < b.size(); ++p) {
      EXPECT_NEAR(b.v_m_s[p][0], 0.0, 1e-14);
      EXPECT_NEAR(b.v_m_s[p][1], 0.2, 1e-14);
      EXPECT_NEAR(b.stress_Pa[p].norm(), 0.0, 1e-9);
    }
  }
}

TEST(Boundary, CoulombFrictionFloorDeceleratesSlidingBlockAtMuG) {
  // An elastic block in geostatic equilibrium on a frictional floor (μ = 0.3), periodic in x,
  // sliding at v0: a rigid-body sliding on Coulomb friction decelerates at μ g until it stops.
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    const double H = 0.5, h = H / 8, rho = 1000.0, g = 9.81, mu = 0.3, v0 = 1.0;
    LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e7;
    ep.poisson_ratio = 0.3;
    const double c = std::sqrt(ep.p_wave_modulus_Pa() / rho);
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {4, 12}, {true, false});
    SolverOptions<PlaneStrain> opt;
    opt.shape = k;
    opt.threads = 1;
    opt.dt_s = 0.3 * h / c;
    opt.gravity_m_s2 = Vec<2>(0.0, -g);
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[2].type = WallType::Friction;
    s.boundaries()[2].friction_coefficient = mu;
    auto& b = s.add_body("block");
    b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    fill_box(b, Vec<2>(0.0, 0.0), Vec<2>(4 * h, H), h, 2, rho, [&](const Vec<2>&) { return Vec<2>(v0, 0.0); });
    const double K0 = ep.poisson_ratio / (1.0 - ep.poisson_ratio);
    for (std::int64_t p = 0; p < b.size(); ++p) {
      const double syy = -rho * g * (H - b.x_m[p][1]);
      b.stress_Pa[p].diagonal() << K0 * syy, syy, K0 * syy;
    }
    const double t1 = 0.2;  // v(t1) = v0 − μ g t1 = 0.41 m/s
    while (s.time_s() < t1) s.step();
    const double v_mean = b.total_momentum()[0] / b.total_mass();
    EXPECT_NEAR(v_mean, v0 - mu * g * s.time_s(), 0.005 * v0) << "kind " << static_cast<int>(k);
    while (s.time_s() < 0.5) s.step();  // stopped at t = v0/(μ g) = 0.34 s, and stays
    EXPECT_NEAR(b.total_momentum()[0] / b.total_mass(), 0.0, 0.02 * v0) << "kind " << static_cast<int>(k);
  }
}
