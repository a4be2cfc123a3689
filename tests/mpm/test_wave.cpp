// V2: elastic standing waves (scenes.md V2). Period within 1% of the analytic value (L/c periodic,
// 2L/c between frictionless walls), agreement with the semi-discrete lumped-mass dispersion
// relation of each kernel, and second-order convergence in h for B-splines, also with walls.
#include <gtest/gtest.h>

#include <cmath>

#include "wave_problem.hpp"

using namespace oobleck::mpm;
using oobleck::mpm::testing::run_standing_wave;

namespace {
// Independent reference: the semi-discrete (continuous time) relative period error of a standing
// wave with θ = k h for the lumped-mass Galerkin discretization on a uniform grid. The stiffness
// symbol is K(θ) = ∑_j S_j cos(jθ), S_j = h ∫ N'(x) N'(x − j h) dx, the consistent-mass symbol
// M(θ) = ∑_j m_j cos(jθ), m_j = (1/h) ∫ N(x) N(x − j h) dx; the integrals of the splines are the
// classical values below. APIC/PIC see the lumped mass (M_l = 1): ω h/c = √K. FLIP's update
// P2G ∘ G2P applies the consistent mass to the velocity increment, so its effective mass is
// M_l²/M_c and ω h/c = √(K M_c). Then T_h/T − 1 = θ/(ω h/c) − 1.
double kernel_period_error(ShapeKind k, double theta, bool flip) {
  double K = 0.0, Mc = 0.0;
  auto c = [&](int j) { return std::cos(j * theta); };
  switch (k) {
    case ShapeKind::Linear:
    case ShapeKind::UGimp:  // at the lattice positions of 2 points per cell, uGIMP (ℓ = 1/4) = linear
      K = 2.0 - 2.0 * c(1);
      Mc = 2.0 / 3.0 + 1.0 / 3.0 * c(1);
      break;
    case ShapeKind::QuadraticBSpline:
      K = 1.0 - 2.0 / 3.0 * c(1) - 1.0 / 3.0 * c(2);
      Mc = 11.0 / 20.0 + 13.0 / 30.0 * c(1) + 1.0 / 60.0 * c(2);
      break;
    case ShapeKind::CubicBSpline:
      K = 2.0 / 3.0 - 1.0 / 4.0 * c(1) - 2.0 / 5.0 * c(2) - 1.0 / 60.0 * c(3);
      Mc = 151.0 / 315.0 + 397.0 / 840.0 * c(1) + 1.0 / 21.0 * c(2) + 1.0 / 2520.0 * c(3);
      break;
  }
  const double omega_h_over_c = std::sqrt(flip ? K * Mc : K);
  return theta / omega_h_over_c - 1.0;
}
}  // namespace

TEST(WaveV2, PeriodWithinOnePercentEveryKernel) {
  // 32 cells per wavelength: periodic column of 32 cells, or 16 cells between walls.
  for (ShapeKind k : {ShapeKind::Linear, ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline, ShapeKind::UGimp}) {
    for (bool fixed : {false, true}) {
      const auto r = run_standing_wave(k, Transfer::Apic, 0.0, fixed ? 16 : 32, fixed);
      EXPECT_LT(r.rel_period_error, 0.01) << "kind " << static_cast<int>(k) << " fixed " << fixed;
      EXPECT_GT(r.amplitude_ratio, 0.95);
    }
  }
}

TEST(WaveV2, PeriodMatchesSemiDiscreteDispersion) {
  // The measured period error is the spatial dispersion error of the kernel (time stepping adds
  // (ωΔt)²/24 ≈ 1e-4 of it at CFL 0.1): within 10% of the prediction, for APIC and pure FLIP.
  for (ShapeKind k : {ShapeKind::Linear, ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    for (bool flip : {false, true}) {
      const int n = 16;
      const auto r = run_standing_wave(k, flip ? Transfer::FlipPicBlend : Transfer::Apic, 1.0, n, false);
      const double predicted = kernel_period_error(k, 2.0 * M_PI / n, flip);
      EXPECT_NEAR(r.rel_period_error, predicted, 0.1 * predicted) << "kind " << static_cast<int>(k) << " flip " << flip;
    }
  }
}

TEST(WaveV2, FlipIsNonDissipativeApicDampsLittle) {
  const auto f = run_standing_wave(ShapeKind::QuadraticBSpline, Transfer::FlipPicBlend, 1.0, 48, false);
  EXPECT_LT(f.rel_period_error, 0.01);
  EXPECT_GT(f.amplitude_ratio, 0.999);
  const auto a = run_standing_wave(ShapeKind::QuadraticBSpline, Transfer::Apic, 0.0, 48, false);
  EXPECT_GT(a.amplitude_ratio, 0.99);
  // PIC is strongly dissipative at the same resolution.
  const auto p = run_standing_wave(ShapeKind::QuadraticBSpline, Transfer::FlipPicBlend, 0.0, 48, false);
  EXPECT_LT(p.amplitude_ratio, a.amplitude_ratio);
}

TEST(WaveV2, SecondOrderConvergenceForBSplines) {
  for (ShapeKind k : {ShapeKind::QuadraticBSpline, ShapeKind::CubicBSpline}) {
    for (bool fixed : {false, true}) {
      double prev = 0.0;
      for (int n : {8, 16, 32}) {
        const int cells = fixed ? n / 2 : n;  // same cells per wavelength
        const auto r = run_standing_wave(k, Transfer::Apic, 0.0, cells, fixed);
        if (prev > 0.0) {
          const double order = std::log2(prev / r.rel_period_error);
          EXPECT_GT(order, 1.9) << "kind " << static_cast<int>(k) << " cells " << cells << " fixed " << fixed;
          EXPECT_LT(order, 2.2);
        }
        prev = r.rel_period_error;
      }
    }
  }
}
