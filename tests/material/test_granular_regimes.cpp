// Individual regimes of the granular law against hand-derived results (E16–E24, docs/equations.md).
#include <cmath>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/material/point_driver.hpp"
#include "test_helpers.hpp"

using namespace oobleck;
using material::GranularRegime;

// A jammed, pre-compressed state (phi >= phi_m) under a small deformation stays elastic and the
// stress increment is exactly the hypo-elastic one (E16): dt (2G D + (K - 2G/3) tr D 1 + W s - s W).
TEST(GranularRegimes, ElasticIncrementIsHypoelastic) {
  const rheology::Preset P = test::preset("hermes2016");
  const material::GranularLaw law(P);
  material::GranularState st;
  st.f = 0.5;
  st.sigma = -1000.0 * Eigen::Matrix3d::Identity();
  st.sigma(0, 1) = st.sigma(1, 0) = 50.0;
  Eigen::Matrix3d D, W;
  D << 1e-3, 2e-3, 0, 2e-3, -5e-4, 1e-3, 0, 1e-3, 3e-4;
  W << 0, 1e-3, -2e-3, -1e-3, 0, 5e-4, 2e-3, -5e-4, 0;
  const double dt = 1e-4, G = P.granular.G, K = P.granular.K;
  const material::GranularState before = st;
  const auto u = law.update(st, D, W, dt, 0.53);  // phi_m(0.5) = 0.4855 < 0.53
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(u.regime, GranularRegime::kElastic);
  const Eigen::Matrix3d expected =
      before.sigma + dt * (2.0 * G * D + (K - 2.0 * G / 3.0) * D.trace() * Eigen::Matrix3d::Identity() +
                           W * before.sigma - before.sigma * W);
  EXPECT_LT((st.sigma - expected).norm(), 1e-12 * expected.norm());
  // no flow: only the buckling term of E24 acts, f = f_n/(1 + dt K_0 tau_bar/eta_B) (linearly implicit)
  const double inv_eta_B = 1.86e4 * std::pow(0.535 - 0.53, 4.0) + 9.3e-3 * std::pow(0.535 - 0.53, 0.1);  // E8
  EXPECT_NEAR(st.f, 0.5 / (1.0 + dt * P.granular.K_0 * material::tau_bar(st.sigma) * inv_eta_B), 1e-14);
}

// The authors' code's pitfall: a loose state (phi < phi_m) at rest cannot hold pressure (E23 with zeta = 0
// gives f_3 = g(phi) p <= 0 => p = 0); the authors' elastic check misses this.
TEST(GranularRegimes, LooseStateAtRestLosesPressure) {
  const material::GranularLaw law(test::preset("hermes2016"));
  material::GranularState st;
  st.sigma = -500.0 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Z = Eigen::Matrix3d::Zero();
  const auto u = law.update(st, Z, Z, 1e-5, 0.40);  // phi_m(0) = 0.535 > 0.40
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(u.regime, GranularRegime::kCompaction);
  EXPECT_EQ(u.p, 0.0);
  EXPECT_NEAR(u.xi_dot_2, -500.0 / (law.K() * 1e-5), 1e-9 * 500.0 / (law.K() * 1e-5));
  EXPECT_EQ(st.sigma.norm(), 0.0);
}

// Tension: the granular skeleton separates (sigma = 0, xi_dot_1 >= 0) when dilatancy cannot
// create pressure (E22).
TEST(GranularRegimes, TensionSeparates) {
  const material::GranularLaw law(test::preset("hermes2016"));
  material::GranularState st;
  const Eigen::Matrix3d D = 1.0 * Eigen::Matrix3d::Identity(), Z = Eigen::Matrix3d::Zero();
  const auto u = law.update(st, D, Z, 1e-4, 0.45);
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(u.regime, GranularRegime::kSeparated);
  EXPECT_EQ(st.sigma.norm(), 0.0);
  EXPECT_NEAR(u.xi_dot_1, 3.0, 1e-12);  // p_tr = -3 K dt => xi_dot_1 = tr D = 3 1/s
}

// phi >= phi_j: the law stays defined (no compaction, beta > 0); f follows E24 with f_m(phi) = 0
// (default) or is forced to 1 (the authors' choice, option).
TEST(GranularRegimes, JammedStructurePolicies) {
  rheology::Preset P = test::preset("hermes2016");
  for (auto policy : {material::JammedStructure::kEvolve, material::JammedStructure::kForceOne}) {
    material::GranularOptions opt;
    opt.jammed_structure = policy;
    const material::GranularLaw law(P, opt);
    material::GranularState st;
    st.f = 0.5;
    st.sigma = -1e4 * Eigen::Matrix3d::Identity();
    Eigen::Matrix3d D, W;
    material::simple_shear_rates(100.0, D, W);
    material::GranularUpdate u;
    for (int k = 0; k < 2000; ++k) {
      u = law.update(st, D, W, 1e-3, 0.56);
      ASSERT_TRUE(u.ok());
    }
    EXPECT_TRUE(u.jammed);
    EXPECT_GT(u.p, 0.0);
    EXPECT_GT(u.beta, 0.0);
    if (policy == material::JammedStructure::kForceOne) {
      EXPECT_EQ(st.f, 1.0);
    } else {
      EXPECT_LT(st.f, 1e-6);  // f_m(phi >= phi_j) = 0 for Delta = 0 (E9): the structure decays
    }
  }
}

// Non-convergence and bad input are reported, never silent: a NaN input yields ok() == false with
// the state untouched, and require_ok() throws a NumericalError naming the law and the state.
TEST(GranularRegimes, FailuresAreReported) {
  const material::GranularLaw law(test::preset("hermes2016"));
  material::GranularState st;
  st.sigma = -10.0 * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  D(0, 1) = NAN;
  const material::GranularState before = st;
  const auto u = law.update(st, D, Eigen::Matrix3d::Zero(), 1e-5, 0.45);
  EXPECT_FALSE(u.ok());
  EXPECT_EQ(st.sigma, before.sigma);
  try {
    law.require_ok(u, before, D, Eigen::Matrix3d::Zero(), 1e-5, 0.45);
    FAIL() << "no exception";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("granular law"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("phi = 0.45"), std::string::npos);
  }
  rheology::Preset P = test::preset("hermes2016");
  P.granular.K_4 = 0.5;
  EXPECT_THROW(material::GranularLaw{P}, InputError);
}
