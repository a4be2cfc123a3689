// Shear of a loose bed nearly at rest (the states of bench/scenes/*_authors_setup.toml): phi < phi_m,
// tiny stresses, small strain rates, mostly dilating (p_tr <= 0, the pressure is created by
// dilatancy: the general path in gamma_dot of docs/granular.md). The law's (gamma_dot^p, p, tau_bar)
// are compared with an independent long-double reference: nested bisection on E16–E21 written in
// (gamma_dot, p), far tighter than the law's own residual checks (which are relative to the trial).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "oobleck/material/granular.hpp"
#include "test_helpers.hpp"

using namespace oobleck;
using material::GranularRegime;

namespace {

using LD = long double;

struct Reference {
  LD G, K, K3, mu, d2rho, eta, phi, phim, a;
  LD p_tr, tau_tr, dt;
  LD beta(LD Im) const { return K3 * (phi - phim / (1 + a * Im)); }  // E18
  LD Q(LD g) const { return g * (g * d2rho + 2 * eta); }             // I_m^2 p (E19)
  // pressure balance p = p_tr + K dt beta(I_m(g, p)) g: increasing in p, bisection on (0, S]
  LD p_of(LD g) const {
    const LD S = p_tr + K * dt * K3 * phi * g;
    if (!(S > 0)) return 0;
    LD lo = 0, hi = S;
    for (int k = 0; k < 400; ++k) {
      const LD x = (lo > 0 && hi > 4 * lo) ? std::sqrt(lo * hi) : 0.5L * (lo + hi);
      if (!(x > lo && x < hi)) break;
      const LD Ra = x - p_tr - K * dt * g * beta(std::sqrt(Q(g) / x));
      (Ra > 0 ? hi : lo) = x;
    }
    return 0.5L * (lo + hi);
  }
  LD friction(LD g, LD p) const {  // (mu_p + beta) p with E20 (b = 0: mu_q = mu_2)
    if (!(p > 0)) return 0;
    const LD Im = std::sqrt(Q(g) / p), Iv = eta * g / p;
    return std::max((mu + 2.5L * phi * Iv / (a * Im) + beta(Im)) * p, LD(0));
  }
  // E21 residual tau_tr - G dt g - friction, decreasing in g: bisection on [g_lo, tau_tr/(G dt)]
  LD solve_g() const {
    LD lo = std::max(-p_tr / (K * dt * K3 * phi), LD(0)), hi = tau_tr / (G * dt);
    for (int k = 0; k < 400; ++k) {
      const LD x = 0.5L * (lo + hi);
      if (!(x > lo && x < hi)) break;
      const LD R = tau_tr - G * dt * x - friction(x, p_of(x));
      (R > 0 ? lo : hi) = x;
    }
    return 0.5L * (lo + hi);
  }
};

double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}

void sweep(double G, double K, double K_0, double eta_0, double phi, double dt, std::uint64_t seed) {
  rheology::Preset P = test::preset("hermes2016");
  P.granular.G = G;
  P.granular.K = K;
  P.granular.K_0 = K_0;
  P.steady.eta_0 = eta_0;
  ASSERT_EQ(P.granular.b, 0.0);
  const material::GranularLaw law(P);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  auto random_sym = [&] {
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = N(rng);
    return Eigen::Matrix3d(0.5 * (m + m.transpose()));
  };
  int tension = 0, positive = 0, compaction = 0, failures = 0;
  for (int k = 0; k < 3000; ++k) {
    material::GranularState st;
    st.f = U(rng) < 0.2 ? 0.0 : log_uniform(rng, 1e-22, 1e-3);
    const double p0 = log_uniform(rng, 1e-12, 1e-2);
    Eigen::Matrix3d s = random_sym();
    s.diagonal().array() -= s.trace() / 3.0;
    st.sigma = std::sqrt(2.0) * (0.3 + 3.0 * U(rng)) * p0 * s / s.norm();
    st.sigma.diagonal().array() -= p0;
    const double rate = log_uniform(rng, 1e-5, 1e-2);
    Eigen::Vector3d n(N(rng), N(rng), N(rng));
    n.normalize();
    const Eigen::Matrix3d R = random_sym();
    const Eigen::Matrix3d D = rate * ((U(rng) < 0.7 ? 1.0 : -1.0) * n * n.transpose() + 0.3 * R / R.norm());
    Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
    W(0, 1) = 0.5 * rate * N(rng);
    W(1, 0) = -W(0, 1);
    const material::GranularState before = st;
    const material::GranularUpdate u = law.update(st, D, W, dt, phi);
    ASSERT_TRUE(u.ok()) << law.describe(u, before, D, W, dt, phi);
    if (u.regime == GranularRegime::kShearCompaction) ++compaction;
    if (u.regime != GranularRegime::kShear) continue;
    ASSERT_EQ(u.structure_iterations, 0);
    (u.p_trial <= 0.0 ? tension : positive)++;
    const LD f = before.f;
    const Reference ref{G,
                        K,
                        P.granular.K_3,
                        law.mu_2(),
                        LD(P.granular.d) * P.granular.d * P.granular.rho_s,
                        eta_0,
                        phi,
                        P.steady.phi_j + (P.steady.phi_c - P.steady.phi_j) * f,
                        P.steady.a_0 + (P.steady.a_inf - P.steady.a_0) * f,
                        u.p_trial,
                        u.tau_trial,
                        dt};
    const LD g = ref.solve_g(), p = ref.p_of(g), tau = ref.friction(g, p);
    const bool ok = std::fabs(u.gamma_dot_p - g) <= 1e-10L * g && std::fabs(u.p - p) <= 1e-9L * p &&
                    std::fabs(u.tau_bar - tau) <= 1e-9L * tau;
    if (!ok && ++failures <= 5) {
      ADD_FAILURE() << "reference gamma_dot " << static_cast<double>(g) << " p " << static_cast<double>(p)
                    << " tau_bar " << static_cast<double>(tau) << "; " << law.describe(u, before, D, W, dt, phi);
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(tension, 1000);    // the p_tr <= 0 path is what these states exercise
  EXPECT_GT(compaction, 300);  // and the closed-form f_1 + f_3 regime
  std::printf("shear with p_tr <= 0: %d, with p_tr > 0: %d, shear+compaction: %d\n", tension, positive, compaction);
}

}  // namespace

// intruder bed (bench/scenes/intruder_authors_setup.toml)
TEST(GranularLooseBed, ShearMatchesReferenceIntruderBed) { sweep(3.8e7, 8.3e7, 0.2, 4.6e-3, 0.47, 1e-6, 11); }
// wheel bed (bench/scenes/wheel_authors_setup.toml)
TEST(GranularLooseBed, ShearMatchesReferenceWheelBed) { sweep(3.8e5, 8.3e5, 1.0, 1e-3, 0.482, 2e-5, 12); }
// same beds at a 20x larger step (structure and dilatancy terms larger)
TEST(GranularLooseBed, ShearMatchesReferenceLargeStep) { sweep(3.8e5, 8.3e5, 1.0, 1e-3, 0.47, 4e-4, 13); }
