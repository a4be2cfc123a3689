// Fluid law E25–E27.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "oobleck/material/fluid.hpp"

namespace m = oobleck::material;

TEST(Fluid, SimpleShearViscousStress) {
  // v_x = γ̇ y: τ_xy = η_0 (1 + 5φ/2) γ̇, all other components zero (E25).
  const double gdot = 3.0, phi = 0.4, eta0 = 2e-3;
  Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
  L(0, 1) = gdot;
  const Eigen::Matrix3d tau = m::fluid_viscous_stress(L, phi, eta0);
  EXPECT_NEAR(tau(0, 1), eta0 * 2.0 * gdot, 1e-15);
  EXPECT_NEAR(tau(1, 0), tau(0, 1), 0.0);
  EXPECT_NEAR(tau(0, 0), 0.0, 1e-18);
  EXPECT_NEAR(tau(2, 2), 0.0, 1e-18);
}

TEST(Fluid, ViscousStressIsDeviatoricSymmetricAndIgnoresSpin) {
  Eigen::Matrix3d L;
  L << 1.0, 2.0, -0.5, 0.3, -4.0, 1.5, 2.0, 0.7, 0.9;
  const double phi = 0.3, eta0 = 1e-3;
  const Eigen::Matrix3d tau = m::fluid_viscous_stress(L, phi, eta0);
  EXPECT_NEAR(tau.trace(), 0.0, 1e-17);
  EXPECT_NEAR((tau - tau.transpose()).norm(), 0.0, 1e-18);
  const Eigen::Matrix3d W = 0.5 * (L - L.transpose());
  EXPECT_NEAR((m::fluid_viscous_stress(L + 7.0 * W, phi, eta0) - tau).norm(), 0.0, 1e-15);
  // Uniaxial extension v_x = ε̇ x: τ_xx = (4/3) η ε̇, τ_yy = τ_zz = −(2/3) η ε̇.
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  E(0, 0) = 2.0;
  const Eigen::Matrix3d t2 = m::fluid_viscous_stress(E, 0.0, eta0);
  EXPECT_NEAR(t2(0, 0), 4.0 / 3.0 * eta0 * 2.0, 1e-18);
  EXPECT_NEAR(t2(1, 1), -2.0 / 3.0 * eta0 * 2.0, 1e-18);
}

TEST(Fluid, PressureFromDensityAndVolumeRatio) {
  const double kappa = 1e6, rho0 = 1000.0;
  EXPECT_EQ(m::fluid_pressure(1.0, kappa), 0.0);
  // 1% compression: ρ_f = ρ_f0/0.99, p_f = κ ln(1/0.99).
  EXPECT_NEAR(m::fluid_pressure(0.99, kappa), kappa * std::log(1.0 / 0.99), 1e-9);
  EXPECT_NEAR(m::fluid_pressure_from_density(rho0 / 0.99, rho0, kappa), m::fluid_pressure(0.99, kappa), 1e-9);
  EXPECT_LT(m::fluid_pressure(1.01, kappa), 0.0);  // expansion → tension
  // Linearization: p ≈ κ (1 − J) for small strains.
  EXPECT_NEAR(m::fluid_pressure(1.0 - 1e-6, kappa), kappa * 1e-6, 1e-6);
}

TEST(Fluid, ExponentialVolumeUpdateIsExactForConstantRate) {
  // Dn/Dt constant-rate expansion: J(t) = J0 exp(t div q / n) for any number of steps.
  const double divq = -3.0, n = 0.5, T = 0.1;
  for (int steps : {1, 7, 1000}) {
    double J = 1.0;
    for (int i = 0; i < steps; ++i) J = m::update_fluid_volume_ratio(J, divq, n, T / steps);
    EXPECT_NEAR(J, std::exp(T * divq / n), 1e-13);  // round-off of 1000 products
  }
  // Fluid-only flow (n = 1, q = v_f): J tracks the volume of a fluid parcel, and ρ_f J = ρ_f0.
  double J = 1.0;
  J = m::update_fluid_volume_ratio(J, 0.2, 1.0, 0.5);
  EXPECT_NEAR(J, std::exp(0.1), 1e-15);
}

TEST(Fluid, LogarithmicVolumeUpdateIsTheLogOfTheExponentialOne) {
  // E27 in logarithms: ln J(t) = ln J0 + t div q / n, exactly the logarithm of the exponential
  // update, and E26 from it: p_f = −κ ln J.
  const double divq = -3.0, n = 0.5, T = 0.1, kappa = 2e6;
  for (int steps : {1, 7, 1000}) {
    double lnJ = 0.0, J = 1.0;
    for (int i = 0; i < steps; ++i) {
      lnJ = m::update_fluid_log_volume_ratio(lnJ, divq, n, T / steps);
      J = m::update_fluid_volume_ratio(J, divq, n, T / steps);
    }
    EXPECT_NEAR(lnJ, T * divq / n, 1e-14);
    EXPECT_NEAR(lnJ, std::log(J), 1e-13);
    EXPECT_NEAR(m::fluid_pressure_from_log_volume_ratio(lnJ, kappa), m::fluid_pressure(J, kappa), 1e-6);
  }
  // 1% compression (J = 0.99): p_f = κ ln(1/0.99) > 0.
  EXPECT_NEAR(m::fluid_pressure_from_log_volume_ratio(std::log(0.99), kappa), kappa * std::log(1.0 / 0.99), 1e-9);
}

TEST(Fluid, CauchyStressCombinesViscousAndPressure) {
  m::FluidParams p;
  p.eta_0_Pa_s = 1e-3;
  p.kappa_Pa = 2e6;
  Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
  L(0, 1) = 10.0;
  const double J = 0.995;
  const Eigen::Matrix3d s = m::fluid_cauchy_stress(L, 0.2, J, p);
  EXPECT_NEAR(-s.trace() / 3.0, p.kappa_Pa * std::log(1.0 / J), 1e-9);
  EXPECT_NEAR(s(0, 1), 1e-3 * 1.5 * 10.0, 1e-15);
  EXPECT_NEAR(m::fluid_wave_speed(1e6, 1000.0), std::sqrt(1000.0), 1e-12);
}
