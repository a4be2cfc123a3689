// Conservation in a free-flying, spinning elastic body without boundaries: mass exactly, linear
// momentum to round-off for every kernel and transfer; angular momentum to round-off for APIC;
// bitwise determinism for a fixed thread count.
#include <gtest/gtest.h>

#include <omp.h>

#include <Eigen/Geometry>
#include <cmath>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"

using namespace oobleck::mpm;
using oobleck::material::LinearElasticParams;

namespace {

struct DiskRun {
  double mass0, mass1;
  Vec<2> P0, P1;
  double Lz0, Lz1;  // angular momentum about the origin (APIC: includes the affine part)
  std::vector<Vec<2>> x;
};

double angular_momentum(const Body<PlaneStrain>& b, bool apic, double D_inertia_scale) {
  // Point angular momentum x × m v plus, for APIC, the affine contribution m (D_p C_pᵀ) skew part;
  // with constant D_p = d I (B-splines) it is m d (C_yx − C_xy).
  double L = 0.0;
  for (std::int64_t p = 0; p < b.size(); ++p) {
    const auto& x = b.x_m[p];
    const auto& v = b.v_m_s[p];
    L += b.mass_kg[p] * (x[0] * v[1] - x[1] * v[0]);
    if (apic) L += b.mass_kg[p] * D_inertia_scale * (b.C_1_s[p](1, 0) - b.C_1_s[p](0, 1));
  }
  return L;
}

DiskRun run_disk(ShapeKind shape, Transfer transfer, double flip, int steps, int threads) {
  const double h = 0.05;
  Grid<2> grid(Vec<2>(-1.0, -1.0), h, {40, 40});
  SolverOptions<PlaneStrain> opt;
  opt.shape = shape;
  opt.transfer = transfer;
  opt.flip_fraction = flip;
  opt.gimp_half_width_cells = 0.25;
  opt.threads = threads;
  LinearElasticParams ep;
  ep.youngs_modulus_Pa = 1e5;
  ep.poisson_ratio = 0.3;
  const double rho = 1000.0;
  opt.dt_s = 0.2 * h / std::sqrt(ep.p_wave_modulus_Pa() / rho);
  Solver<PlaneStrain> s(grid, opt);
  auto& b = s.add_body("disk");
  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
  // Disk of radius 0.3 m, translating and spinning (ω = 2 rad/s), plus a compressive pulse.
  const Vec<2> c(0.05, -0.02);
  const double dx = h / 2.0;  // 2 × 2 points per cell
  for (int i = -12; i < 12; ++i)
    for (int j = -12; j < 12; ++j) {
      const Vec<2> r((i + 0.5) * dx, (j + 0.5) * dx);
      if (r.norm() > 0.3) continue;
      b.add_point(c + r, dx * dx, rho, Vec<2>(0.1 - 2.0 * r[1] + 0.3 * r[0], 0.05 + 2.0 * r[0]));
    }
  const bool apic = transfer == Transfer::Apic;
  const double d = shape == ShapeKind::CubicBSpline ? h * h / 3.0 : h * h / 4.0;
  DiskRun r;
  r.mass0 = b.total_mass();
  r.P0 = b.total_momentum();
  r.Lz0 = angular_momentum(b, false, d);  // C = 0 initially
  for (int i = 0; i < steps; ++i) s.step();
  r.mass1 = b.total_mass();
  r.P1 = b.total_momentum();
  r.Lz1 = angular_momentum(b, apic, d);
  r.x = b.x_m;
  return r;
}

}  // namespace

TEST(Conservation, MassAndMomentumEveryKernelAndTransfer) {
  for (ShapeKind k : {ShapeKind::Linear, ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline, ShapeKind::UGimp}) {
    for (auto [tr, a] : {std::pair{Transfer::Apic, 0.0}, std::pair{Transfer::FlipPicBlend, 1.0},
                         std::pair{Transfer::FlipPicBlend, 0.0}, std::pair{Transfer::FlipPicBlend, 0.95}}) {
      const DiskRun r = run_disk(k, tr, a, 100, 1);
      EXPECT_EQ(r.mass0, r.mass1);
      const double scale = r.mass0 * 1.0;  // momentum scale: mass × 1 m/s
      EXPECT_LT((r.P1 - r.P0).norm(), 1e-13 * scale)
          << "kind " << static_cast<int>(k) << " transfer " << static_cast<int>(tr) << " alpha " << a;
    }
  }
}

TEST(Conservation, ApicConservesAngularMomentum) {
  // The disk spins for 100 steps; APIC with B-spline weights (constant D_p) conserves the total
  // angular momentum (points + affine part) up to round-off; the hypo-elastic stress is symmetric.
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    const DiskRun r = run_disk(k, Transfer::Apic, 0.0, 100, 1);
    EXPECT_NEAR(r.Lz1, r.Lz0, 1e-12 * std::fabs(r.Lz0)) << static_cast<int>(k);
  }
}

TEST(Conservation, DeterministicForFixedThreadCount) {
  const DiskRun a = run_disk(ShapeKind::QuadraticBSpline, Transfer::Apic, 0.0, 30, 2);
  const DiskRun b = run_disk(ShapeKind::QuadraticBSpline, Transfer::Apic, 0.0, 30, 2);
  ASSERT_EQ(a.x.size(), b.x.size());
  for (std::size_t p = 0; p < a.x.size(); ++p) {
    EXPECT_EQ(a.x[p][0], b.x[p][0]);
    EXPECT_EQ(a.x[p][1], b.x[p][1]);
  }
  // One thread and two threads agree to round-off (different summation order only).
  const DiskRun c = run_disk(ShapeKind::QuadraticBSpline, Transfer::Apic, 0.0, 30, 1);
  for (std::size_t p = 0; p < a.x.size(); ++p) EXPECT_NEAR((a.x[p] - c.x[p]).norm(), 0.0, 1e-12);
}

TEST(Conservation, ThreeDimensionalSpinningBlock) {
  // 3D: a spinning, translating elastic block without boundaries; mass exact, momentum to
  // round-off, APIC angular momentum (points + affine part m D C skew) to round-off.
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    const double h = 0.1, rho = 1000.0;
    Grid<3> grid(Vec<3>(-1.0, -1.0, -1.0), h, {20, 20, 20});
    SolverOptions<ThreeD> opt;
    opt.shape = k;
    opt.threads = 1;
    LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e5;
    opt.dt_s = 0.2 * h / std::sqrt(ep.p_wave_modulus_Pa() / rho);
    Solver<ThreeD> s(grid, opt);
    auto& b = s.add_body("block");
    b.set_law(std::make_unique<LinearElasticLaw<ThreeD>>(ep));
    const Vec<3> w(0.5, -1.0, 2.0);
    fill_box(b, Vec<3>(-0.3, -0.3, -0.3), Vec<3>(0.3, 0.3, 0.3), h, 2, rho, [&](const Vec<3>& x) {
      Vec<3> v = w.cross(x);
      v[0] += 0.1 + 0.2 * x[0];
      v[2] -= 0.05;
      return v;
    });
    const double d = k == ShapeKind::CubicBSpline ? h * h / 3.0 : h * h / 4.0;
    auto ang = [&]() {
      Vec<3> L = Vec<3>::Zero();
      for (std::int64_t p = 0; p < b.size(); ++p) {
        L += b.mass_kg[p] * b.x_m[p].cross(b.v_m_s[p]);
        const Mat<3, 3> S = b.mass_kg[p] * d * b.C_1_s[p].transpose();  // m D Cᵀ, D = d I
        L += Vec<3>(S(1, 2) - S(2, 1), S(2, 0) - S(0, 2), S(0, 1) - S(1, 0));
      }
      return L;
    };
    const double m0 = b.total_mass();
    const Vec<3> P0 = b.total_momentum(), L0 = ang();
    for (int i = 0; i < 20; ++i) s.step();
    EXPECT_EQ(b.total_mass(), m0);
    EXPECT_LT((b.total_momentum() - P0).norm(), 1e-13 * m0);
    EXPECT_LT((ang() - L0).norm(), 1e-12 * L0.norm()) << static_cast<int>(k);
  }
}

// A point more than one cell outside the domain stops the step with the body's name, the count of
// such points (summed over the threads' shares and over the bodies' scatters) and the step; a body
// with every point inside is not named.
TEST(Conservation, PointsOutsideTheGridStopTheStepWithTheBodyNamed) {
  for (int threads : {1, 2}) {
    SCOPED_TRACE(::testing::Message() << "threads " << threads);
    const double h = 0.05;
    Grid<2> grid(Vec<2>(-1.0, -1.0), h, {40, 40});
    SolverOptions<PlaneStrain> opt;
    opt.threads = threads;
    LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e5;
    ep.poisson_ratio = 0.3;
    opt.dt_s = 1e-4;
    Solver<PlaneStrain> s(grid, opt);
    auto& inside = s.add_body("inside");
    auto& lost = s.add_body("lost");
    for (Body<PlaneStrain>* b : {&inside, &lost}) {
      b->set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
      for (int i = 0; i < 100; ++i) b->add_point(Vec<2>(-0.5 + 0.01 * i, 0.0), h * h / 4.0, 1000.0);
    }
    // Three points of the second body (one in each thread's half) 3 cells beyond the right face.
    for (std::int64_t p : {5, 60, 99}) lost.x_m[p] = Vec<2>(1.0 + 3.0 * h, 0.1);
    try {
      s.step();
      FAIL() << "no error";
    } catch (const oobleck::NumericalError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("3 point(s) of body 'lost' left the grid"), std::string::npos) << m;
      EXPECT_NE(m.find("step 0"), std::string::npos) << m;
    }
  }
}
