// Robustness of the granular return map (E16–E24, docs/granular.md) over >= 1e5 random states: phi across
// [0.3, 0.6] (through phi_m and beyond phi_j), strain rates +-1e-3..1e4 1/s in all tensor
// directions, stresses 0..1e6 Pa including tension, dt 1e-7..1e-3 s. Every result must be finite
// and converged, keep p >= 0, 0 <= tau_bar <= tau_bar^tr, f in [0, 1], and satisfy the active
// yield conditions, which are re-evaluated here from E18–E23 independently of the law's code.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/material/granular.hpp"
#include "test_helpers.hpp"

using namespace oobleck;
using material::GranularRegime;
using test::log_uniform;
using test::random_tensor;

namespace {

struct Checker {
  const rheology::Preset& P;
  double mu1, mu2;
  // E19, E20 independently
  double mu_p(double gdp, double p, double a, double phi) const {
    const double Iv = P.steady.eta_0 * gdp / p;
    const double I = gdp * P.granular.d * std::sqrt(P.granular.rho_s / p);
    const double Im = std::sqrt(I * I + 2.0 * Iv);
    const double b = P.granular.b;
    const double mq = b == 0.0 ? mu2 : mu1 + (mu2 - mu1) / (1.0 + b / Im);
    return mq + 2.5 * phi * Iv / (a * Im);
  }
  double beta(double gdp, double p, double a, double phim, double phi) const {
    const double Iv = P.steady.eta_0 * gdp / p;
    const double I = gdp * P.granular.d * std::sqrt(P.granular.rho_s / p);
    const double Im = std::sqrt(I * I + 2.0 * Iv);
    return P.granular.K_3 * (phi - phim / (1.0 + a * Im));  // E18
  }
};

void sweep(const std::string& preset_name, int n, std::uint64_t seed, double K_0 = 1.0) {
  rheology::Preset P = test::preset(preset_name);
  P.granular.K_0 = K_0;
  const material::GranularLaw law(P);
  const Checker ck{P, law.mu_1(), law.mu_2()};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  int counts[5] = {0, 0, 0, 0, 0};
  int failures = 0, implicit = 0;
  for (int k = 0; k < n; ++k) {
    const double phi = 0.3 + 0.3 * U(rng);
    material::GranularState st;
    st.f = U(rng) < 0.1 ? (U(rng) < 0.5 ? 0.0 : 1.0) : U(rng);
    // stress: pressure (20% tensile) plus a deviator of random direction
    const double r = U(rng);
    if (r > 0.05) {
      const double p = (U(rng) < 0.2 ? -1.0 : 1.0) * log_uniform(rng, 1e-3, 1e6);
      Eigen::Matrix3d s = random_tensor(rng, 1.0);
      s = 0.5 * (s + s.transpose()).eval();
      s.diagonal().array() -= s.trace() / 3.0;
      const double tau = U(rng) < 0.1 ? 0.0 : log_uniform(rng, 1e-3, 1e6);
      st.sigma = std::sqrt(2.0) * tau * s / s.norm();
      st.sigma.diagonal().array() -= p;
    }
    const double rate = U(rng) < 0.05 ? 0.0 : log_uniform(rng, 1e-3, 1e4);
    const Eigen::Matrix3d L = random_tensor(rng, rate);
    Eigen::Matrix3d D = 0.5 * (L + L.transpose());
    Eigen::Matrix3d W = 0.5 * (L - L.transpose());
    if (U(rng) < 0.2) D.diagonal().array() -= D.trace() / 3.0;  // isochoric
    const double dt = log_uniform(rng, 1e-7, 1e-3);
    const material::GranularState before = st;
    const material::GranularUpdate u = law.update(st, D, W, dt, phi);
    counts[static_cast<int>(u.regime)]++;
    implicit += u.structure_iterations > 0 ? 1 : 0;
    bool ok = true;
    auto fail = [&](const char* what) {
      if (failures < 10) ADD_FAILURE() << what << ": " << law.describe(u, before, D, W, dt, phi);
      ok = false;
    };
    if (!u.ok()) fail("not ok (non-finite or not converged)");
    if (!st.sigma.allFinite() || !std::isfinite(st.f)) fail("non-finite state");
    if (!(u.p >= 0.0)) fail("p < 0");
    if (!(u.tau_bar >= 0.0 && u.tau_bar <= u.tau_trial * (1.0 + 1e-12))) fail("tau_bar outside [0, tau_trial]");
    if (!(st.f >= 0.0 && st.f <= 1.0)) fail("f outside [0, 1]");
    // the returned stress carries the reported invariants
    const double scale = std::max({u.tau_trial, std::fabs(u.p_trial), 1e-300});
    if (std::fabs(material::pressure(st.sigma) - u.p) > 1e-10 * scale) fail("p(sigma) != p");
    if (std::fabs(material::tau_bar(st.sigma) - u.tau_bar) > 1e-10 * scale) fail("tau_bar(sigma) != tau_bar");
    // structure used by the return map: f_n (staggered) or f_{n+1} (implicit update), recovered from phi_m
    const double fo = (P.steady.phi_j - u.phi_m) / (P.steady.phi_j - P.steady.phi_c);
    if (u.structure_iterations == 0 && std::fabs(fo - before.f) > 1e-12)
      fail("staggered update with phi_m != phi_m(f_n)");
    if (u.structure_iterations > 0 && std::fabs(fo - st.f) > 1e-9) fail("implicit update: phi_m != phi_m(f_{n+1})");
    const double phim = u.phi_m;                                           // E1
    const double a = P.steady.a_0 + (P.steady.a_inf - P.steady.a_0) * fo;  // E2
    const double Gdt = P.granular.G * dt, Kdt = P.granular.K * dt;
    switch (u.regime) {
      case GranularRegime::kElastic: {
        if (u.gamma_dot_p != 0.0) fail("elastic with flow");
        if (u.p > 0.0 && phi < phim) fail("elastic loose state holds pressure (f_3 > 0)");
        const double mu0 = P.granular.b == 0.0 ? ck.mu2 : ck.mu1;
        if (u.tau_bar > std::max((mu0 + P.granular.K_3 * (phi - phim)) * u.p, 0.0) * (1 + 1e-12) + 1e-300)
          fail("elastic with f_1 > 0");
        break;
      }
      case GranularRegime::kSeparated:
        if (u.p != 0.0 || u.tau_bar != 0.0) fail("separated with stress");
        if (u.xi_dot_1 < 0.0) fail("xi_dot_1 < 0");
        if (u.p_trial + Kdt * P.granular.K_3 * phi * u.gamma_dot_p > 1e-10 * scale)
          fail("separation against dilatancy");
        break;
      case GranularRegime::kShear:
      case GranularRegime::kShearCompaction:
      case GranularRegime::kCompaction: {
        // flow rule: gamma_dot_p = (tau_tr - tau_bar)/(G dt)  (radial return)
        if (std::fabs(Gdt * u.gamma_dot_p - (u.tau_trial - u.tau_bar)) > 1e-8 * scale) fail("flow rule");
        if (u.p > 0.0 && u.gamma_dot_p > 0.0) {
          const double be = ck.beta(u.gamma_dot_p, u.p, a, phim, phi);
          const double mp = ck.mu_p(u.gamma_dot_p, u.p, a, phi);
          // f_1 = 0 (E21)
          if (std::fabs(u.tau_bar - std::max((mp + be) * u.p, 0.0)) > 1e-8 * scale) fail("f_1 != 0");
          if (u.regime == GranularRegime::kShear) {
            // f_3 <= 0 (E23 with xi_dot_2 = 0 <=> beta >= 0 for phi < phi_m), pressure balance
            if (phi < phim && be < -1e-8) fail("shear regime with f_3 > 0");
            if (std::fabs(u.p - (u.p_trial + Kdt * be * u.gamma_dot_p)) > 1e-8 * scale) fail("pressure balance");
          } else {
            // f_3 = 0 (E23): (phi_m - phi)^2 p = (a phi)^2 (gdp^2 d^2 rho_s + 2 eta_0 gdp)
            const double g = u.gamma_dot_p;
            const double lhs = (phim - phi) * (phim - phi) * u.p;
            const double rhs =
                a * phi * a * phi * (g * g * P.granular.d * P.granular.d * P.granular.rho_s + 2.0 * P.steady.eta_0 * g);
            if (std::fabs(lhs - rhs) > 1e-8 * std::max(lhs, rhs)) fail("f_3 != 0");
            if (u.xi_dot_2 > 0.0) fail("xi_dot_2 > 0");
            if (std::fabs(u.p - (u.p_trial + Kdt * u.xi_dot_2)) > 1e-8 * scale) fail("compaction pressure balance");
          }
        } else if (u.regime != GranularRegime::kCompaction) {
          fail("flowing regime without pressure");
        }
        break;
      }
    }
    if (!ok) ++failures;
  }
  EXPECT_EQ(failures, 0);
  // the sweep must visit every regime (else it tests nothing)
  EXPECT_GT(counts[0], n / 1000);
  EXPECT_GT(counts[1], n / 1000);
  EXPECT_GT(counts[2], n / 1000);
  EXPECT_GT(counts[3], n / 1000);
  EXPECT_GT(implicit, n / 100);  // the implicit structure update is exercised too
  std::printf("%s: elastic %d separated %d shear %d shear+compaction %d compaction %d (implicit f: %d)\n",
              preset_name.c_str(), counts[0], counts[1], counts[2], counts[3], counts[4], implicit);
}

}  // namespace

TEST(GranularRobustness, RandomSweepHermes) { sweep("hermes2016", 100000, 12345); }
TEST(GranularRobustness, RandomSweepDhaeneFastStructure) { sweep("dhaene1993", 20000, 777, 50.0); }
