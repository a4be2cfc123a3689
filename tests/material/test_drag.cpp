// E29 drag law and the semi-implicit nodal update (docs/equations.md, fluid phase and coupling).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <iterator>
#include <random>

#include "oobleck/material/drag.hpp"
#include "oobleck/numerics/vector_math.hpp"

namespace m = oobleck::material;

namespace {
// Reference values of Beetstra's F̂(φ, Re) evaluated independently with 30-digit decimal
// arithmetic (Python `decimal`), straight from the formula in Beetstra, van der Hoef & Kuipers,
// AIChE J. 53 (2007) 489, eq. (13) as written in E29 (docs/equations.md).
struct Tab {
  double phi, Re, F;
};
constexpr Tab kBeetstra[] = {
    {0.1, 0, 2.42878463694502599},    {0.1, 0.1, 2.43262526141870441}, {0.1, 10, 3.21806941256954532},
    {0.1, 100, 8.55374630087295108},  {0.3, 0, 7.01502505935813383},   {0.3, 0.1, 7.01574006764984470},
    {0.3, 10, 8.27936128272357000},   {0.3, 100, 19.6882254802125236}, {0.45, 0, 15.4829178112883985},
    {0.45, 0.1, 15.4831305314863153}, {0.45, 10, 17.4000944141601557}, {0.45, 100, 39.0600782389717049},
    {0.6, 0, 37.8459032006179560},    {0.6, 0.1, 37.8459770646392596}, {0.6, 10, 41.1945112762823711},
    {0.6, 100, 89.7894153723584708}};
}  // namespace

TEST(Drag, BeetstraMatchesTabulatedValues) {
  for (const auto& t : kBeetstra) {
    EXPECT_NEAR(m::beetstra_F(t.phi, t.Re), t.F, 1e-12 * t.F) << "phi=" << t.phi << " Re=" << t.Re;
  }
}

TEST(Drag, BeetstraStokesLimitAtZeroRe) {
  // F̂ → 1 as φ → 0 (isolated sphere in Stokes flow); leading correction 1.5√φ.
  EXPECT_DOUBLE_EQ(m::beetstra_F(0.0, 0.0), 1.0);
  for (double phi : {1e-4, 1e-6, 1e-8}) {
    EXPECT_NEAR(m::beetstra_F(phi, 0.0), 1.0, 2.0 * std::sqrt(phi));
  }
  // The Re term vanishes continuously as Re → 0.
  for (double phi : {0.1, 0.4, 0.55}) {
    EXPECT_NEAR(m::beetstra_F(phi, 1e-12), m::beetstra_F(phi, 0.0), 1e-6);
  }
}

TEST(Drag, ReTermOnlyIncreasesDrag) {
  for (double phi : {0.05, 0.2, 0.5}) {
    double prev = m::beetstra_F(phi, 0.0);
    for (double Re : {0.01, 0.1, 1.0, 10.0, 100.0, 1000.0}) {
      const double F = m::beetstra_F(phi, Re);
      EXPECT_GT(F, prev);
      prev = F;
    }
  }
}

TEST(Drag, CarmanKozenyIsDarcyWithKozenyPermeability) {
  // Independent route: Darcy drag per mixture volume η n²/k with k = d² n³/(180 φ²).
  const double d = 5.85e-6, eta = 4.6e-3;
  m::DragParams p;
  p.law = m::DragLaw::CarmanKozeny;
  p.d_m = d;
  p.eta_0_Pa_s = eta;
  for (double phi : {0.2, 0.4, 0.5, 0.58}) {
    const double n = 1.0 - phi;
    const double k = d * d * n * n * n / (180.0 * phi * phi);
    EXPECT_NEAR(m::drag_coefficient_per_volume(p, phi, 0.0), eta * n * n / k, 1e-12 * eta * n * n / k);
  }
}

TEST(Drag, PrefactorIsStokesTimesNumberDensity) {
  // φ → 0: C_V → n_p · 3π η d with n_p = φ/(π d³/6) and the (1−φ) factor → 1.
  m::DragParams p;
  p.d_m = 1e-5;
  p.eta_0_Pa_s = 1e-3;
  const double phi = 1e-9;
  const double stokes = phi / (M_PI * std::pow(p.d_m, 3) / 6.0) * 3.0 * M_PI * p.eta_0_Pa_s * p.d_m;
  EXPECT_NEAR(m::drag_coefficient_per_volume(p, phi, 0.0) / stokes, 1.0, 1e-4);
}

TEST(Drag, ReynoldsNumberDefinition) {
  EXPECT_DOUBLE_EQ(m::drag_reynolds(0.1, 0.5, 1000.0, 1e-4, 1e-3), 0.1 * 0.5 * 1000.0 * 1e-4 / 1e-3);
}

TEST(SemiImplicitDrag, ConservesMomentumAndIsBackwardEuler) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> lg(-8.0, 8.0);
  for (int trial = 0; trial < 1000; ++trial) {
    const double ms = std::pow(10.0, lg(rng) * 0.5), mf = std::pow(10.0, lg(rng) * 0.5);
    const double C = std::pow(10.0, lg(rng)), dt = std::pow(10.0, lg(rng) - 4.0);
    const Eigen::Vector3d vs(u(rng), u(rng), u(rng)), vf(u(rng), u(rng), u(rng));
    const Eigen::Vector3d F = m::semi_implicit_drag_force(ms, mf, vs, vf, C, dt);
    const Eigen::Vector3d vs1 = vs - dt * F / ms, vf1 = vf + dt * F / mf;
    // Momentum: exact up to round-off of the two updates.
    const Eigen::Vector3d p0 = ms * vs + mf * vf, p1 = ms * vs1 + mf * vf1;
    EXPECT_LE((p1 - p0).norm(), 1e-14 * (ms * vs.norm() + mf * vf.norm() + 1e-300) * 4);
    // Backward Euler of d(Δv)/dt = −C (1/m_s + 1/m_f) Δv.
    const double a = C * (1.0 / ms + 1.0 / mf);
    const Eigen::Vector3d rel_expected = (vs - vf) / (1.0 + dt * a);
    EXPECT_LE(((vs1 - vf1) - rel_expected).norm(), 1e-12 * (vs - vf).norm() + 1e-15 * (vs.norm() + vf.norm()));
    // The drag force is C times the *new* relative velocity (checked where C Δv_new is not
    // dominated by round-off, i.e. away from the stiff limit).
    if (dt * a < 1e3) {
      EXPECT_LE((F - C * rel_expected).norm(), 1e-12 * C * (vs - vf).norm());
    }
  }
}

TEST(SemiImplicitDrag, StableForStiffDrag) {
  // Δt C/m up to 1e12: the relative velocity decays monotonically, never changes sign, and the
  // pair moves at the centre-of-mass velocity in the stiff limit.
  const double ms = 2.0, mf = 1.0, dt = 1e-3;
  double vs = 1.0, vf = -0.5;
  const double vcm = (ms * vs + mf * vf) / (ms + mf);
  for (double C : {1e3, 1e6, 1e9, 1e12, 1e15}) {
    double a = vs, b = vf;
    for (int step = 0; step < 50; ++step) {
      const double F = m::semi_implicit_drag_force(ms, mf, a, b, C, dt);
      const double rel_before = a - b;
      a -= dt * F / ms;
      b += dt * F / mf;
      EXPECT_TRUE(std::isfinite(a) && std::isfinite(b));
      EXPECT_GE((a - b) * rel_before, 0.0);
      EXPECT_LE(std::fabs(a - b), std::fabs(rel_before));
    }
    EXPECT_NEAR(ms * a + mf * b, (ms + mf) * vcm, 1e-14);
    if (C >= 1e9) {
      EXPECT_NEAR(a, vcm, 1e-5);
      EXPECT_NEAR(b, vcm, 1e-5);
    }
  }
  // Infinite C: rigid coupling in one step.
  const double F = m::semi_implicit_drag_force(ms, mf, vs, vf, INFINITY, dt);
  EXPECT_NEAR(vs - dt * F / ms, vcm, 1e-14);
  EXPECT_NEAR(vf + dt * F / mf, vcm, 1e-14);
}

TEST(SemiImplicitDrag, NoDragWithoutBothPhases) {
  EXPECT_EQ(m::semi_implicit_drag_force(0.0, 1.0, 1.0, 0.0, 1e3, 1e-3), 0.0);
  EXPECT_EQ(m::semi_implicit_drag_force(1.0, 0.0, 1.0, 0.0, 1e3, 1e-3), 0.0);
}

TEST(SemiImplicitDrag, ExponentialRelaxationRecoveredAsDtShrinks) {
  // Many small steps reproduce the exact exponential decay of the relative velocity.
  const double ms = 1.0, mf = 3.0, C = 50.0, T = 0.05;
  const double a = C * (1.0 / ms + 1.0 / mf);
  double prev_err = 0.0;
  for (int n : {100, 200, 400}) {
    const double dt = T / n;
    double vs = 1.0, vf = 0.0;
    for (int i = 0; i < n; ++i) {
      const double F = m::semi_implicit_drag_force(ms, mf, vs, vf, C, dt);
      vs -= dt * F / ms;
      vf += dt * F / mf;
    }
    const double err = std::fabs((vs - vf) - std::exp(-a * T));
    if (prev_err > 0.0) {
      EXPECT_NEAR(prev_err / err, 2.0, 0.1);  // first order in Δt
    }
    prev_err = err;
  }
}

TEST(Drag, BlockMatchesTabulatedValuesAndScalarLaws) {
  // the solver's nodal call (powers in vector lanes) against the 30-digit table, and the scalar
  // laws where no power is taken (Re = 0, Carman–Kozeny, Re term off) to round-off: the library
  // may run its x86-64-v3 variant, which contracts a*b+c where this file does not
  constexpr int N = oobleck::numerics::kMathBlock;
  m::DragParams p;
  p.d_m = 1e-5;
  p.eta_0_Pa_s = 2e-3;
  const double scale = 18.0 * p.eta_0_Pa_s / (p.d_m * p.d_m);
  double phi[N], Re[N], C[N];
  for (int j = 0; j < N; ++j) {
    const Tab& t = kBeetstra[j % std::size(kBeetstra)];
    phi[j] = t.phi;
    Re[j] = t.Re;
  }
  m::drag_coefficient_per_volume_block(p, phi, Re, C);
  for (int j = 0; j < N; ++j) {
    const Tab& t = kBeetstra[j % std::size(kBeetstra)];
    EXPECT_NEAR(C[j] / (scale * t.phi * (1.0 - t.phi)), t.F, 1e-12 * t.F) << "phi=" << t.phi << " Re=" << t.Re;
    if (t.Re == 0.0) {
      const double ref = m::drag_coefficient_per_volume(p, t.phi, 0.0);
      EXPECT_NEAR(C[j], ref, 1e-14 * ref) << "phi=" << t.phi;
    }
  }
  for (auto law : {m::DragLaw::CarmanKozeny, m::DragLaw::Beetstra}) {
    m::DragParams q = p;
    q.law = law;
    q.use_reynolds = false;
    m::drag_coefficient_per_volume_block(q, phi, Re, C);
    for (int j = 0; j < N; ++j) {
      const double ref = m::drag_coefficient_per_volume(q, phi[j], Re[j]);
      EXPECT_NEAR(C[j], ref, 1e-14 * ref) << "phi=" << phi[j] << " Re=" << Re[j];
    }
  }
}
