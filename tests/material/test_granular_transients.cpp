// Start-up and relaxation transients of the granular law (E24, SI "A Method for
// Determining G and K_0"), against independent quasi-steady ODE references written here.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/eta_b.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/viscosity.hpp"
#include "test_helpers.hpp"

using namespace oobleck;

namespace {

/// c(f) = tau_bar/(eta_0 gamma_dot^p) at beta = 0 (E3–E5), from the steady formulas.
double c_of_f(const rheology::SteadyParams& s, double phi, double f) {
  const double phim = s.phi_j + (s.phi_c - s.phi_j) * f;
  const double a = s.a_0 + (s.a_inf - s.a_0) * f;
  return s.mu_c * 2.0 * std::pow(a * phi / (phim - phi), 2) + 2.5 * phi * phi / (phim - phi);
}

/// Quasi-steady start-up reference: the stress follows f instantly (tau_bar = c(f) eta_0 gamma_dot),
/// df/dgamma = K_0 [H (f_m - f) - S f] (E6, E7); RK4 in strain.
double startup_reference(const rheology::SteadyParams& s, double phi, double rate, double K_0, double strain) {
  const double fm = rheology::f_m(s, phi);
  const double ieb = rheology::inverse_eta_B(s, phi);
  auto rhs = [&](double f) {
    const double tau = c_of_f(s, phi, f) * s.eta_0 * rate;
    const double H = std::pow(tau / s.tau_star, 1.5);
    const double S = 1.0 + tau * ieb / rate;
    return K_0 * (H * (fm - f) - S * f);
  };
  const int n = 20000;
  const double h = strain / n;
  double f = 0.0;
  for (int i = 0; i < n; ++i) {
    const double k1 = rhs(f), k2 = rhs(f + 0.5 * h * k1), k3 = rhs(f + 0.5 * h * k2), k4 = rhs(f + h * k3);
    f += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return f;
}

material::ShearResult startup(double K_0, double strain, double dstrain) {
  rheology::Preset P = test::preset("hermes2016", 1e-8);
  P.granular.K_0 = K_0;
  const material::GranularLaw law(P);
  material::ShearOptions o;
  o.phi = 0.44;
  o.shear_rate = 10.0;
  o.duration = strain / o.shear_rate;
  o.dt = dstrain / o.shear_rate;
  o.samples = static_cast<int>(std::lround(strain / dstrain));
  return material::run_shear(law, o);
}

double strain_to_fraction(const material::ShearResult& r, double frac) {
  const double target = frac * r.samples.back().f;
  for (std::size_t i = 1; i < r.samples.size(); ++i) {
    const auto& a = r.samples[i - 1];
    const auto& b = r.samples[i];
    if (a.f < target && b.f >= target) return a.strain + (b.strain - a.strain) * (target - a.f) / (b.f - a.f);
  }
  return NAN;
}

}  // namespace

// f rises from 0 on a strain scale proportional to 1/K_0 and follows the quasi-steady E6 reference.
TEST(GranularTransients, StartupStrainScalesWithInverseK0) {
  const auto r1 = startup(1.0, 12.0, 2e-3);
  const auto r4 = startup(4.0, 3.0, 5e-4);
  EXPECT_NEAR(r1.samples.back().f, r4.samples.back().f, 1e-3 * r1.samples.back().f);  // same steady f
  const double g1 = strain_to_fraction(r1, 0.5), g4 = strain_to_fraction(r4, 0.5);
  std::printf("half-rise strain: K_0 = 1: %.5g, K_0 = 4: %.5g, ratio %.4f\n", g1, g4, g1 / g4);
  EXPECT_NEAR(g1 / g4, 4.0, 0.08);
  const rheology::SteadyParams s = test::preset("hermes2016").steady;
  for (double gam : {0.25, 0.5, 1.0, 2.0, 4.0}) {
    const double ref = startup_reference(s, 0.44, 10.0, 1.0, gam);
    double f_run = NAN;
    for (const auto& smp : r1.samples)
      if (std::fabs(smp.strain - gam) < 1e-3) f_run = smp.f;
    std::printf("strain %.2f: f %.6g reference %.6g\n", gam, f_run, ref);
    EXPECT_LT(test::rel(f_run, ref), 0.02) << "strain " << gam;
  }
}

namespace {

/// Independent reduced relaxation ODE (SI): tau' = -G tau/(c(f) eta_0), f' from E24; RK4 in time.
void relax_reference(const rheology::SteadyParams& s, double phi, double G, double K_0, double t_end, double& tau,
                     double& f) {
  const double fm = rheology::f_m(s, phi), ieb = rheology::inverse_eta_B(s, phi);
  auto rhs = [&](double ta, double ff, double& dta, double& dff) {
    const double gdp = ta / (c_of_f(s, phi, ff) * s.eta_0);
    dta = -G * gdp;
    dff = K_0 * gdp * std::pow(ta / s.tau_star, 1.5) * (fm - ff) - K_0 * (gdp + ta * ieb) * ff;
  };
  const int n = 20000;
  const double h = t_end / n;
  for (int i = 0; i < n; ++i) {
    double a1, b1, a2, b2, a3, b3, a4, b4;
    rhs(tau, f, a1, b1);
    rhs(tau + 0.5 * h * a1, f + 0.5 * h * b1, a2, b2);
    rhs(tau + 0.5 * h * a2, f + 0.5 * h * b2, a3, b3);
    rhs(tau + h * a3, f + h * b3, a4, b4);
    tau += h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
    f += h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4);
  }
}

material::RelaxResult relax(double G, double K_0, double duration, double rate = 0.08) {
  rheology::Preset P = test::preset("hermes2016", 1e-8);
  P.granular.G = G;
  P.granular.K_0 = K_0;
  const material::GranularLaw law(P);
  material::RelaxOptions o;
  o.phi = 0.52;
  o.shear_rate = rate;
  o.duration = duration;
  o.samples = 60;
  o.growth = 0.005;
  return material::run_relax(law, o);
}

double tau_at(const material::RelaxResult& r, double t) {
  for (std::size_t i = 1; i < r.samples.size(); ++i)
    if (r.samples[i].time >= t) {
      const auto& a = r.samples[i - 1];
      const auto& b = r.samples[i];
      return a.tau_bar + (b.tau_bar - a.tau_bar) * (t - a.time) / (b.time - a.time);
    }
  return NAN;
}

}  // namespace

// After cessation tau_bar decays monotonically, faster for larger G, and follows the SI reduced
// ODE (whose assumptions — beta = 0, viscous regime — the return map's compaction branch meets).
TEST(GranularTransients, RelaxationMonotoneFasterForStiffer) {
  const rheology::SteadyParams s = test::preset("hermes2016").steady;
  const auto soft = relax(1e4, 1.0, 1.0);
  const auto stiff = relax(1e5, 1.0, 1.0);
  const auto fastf = relax(1e4, 20.0, 1.0);
  std::printf("tau_0 %.5g Pa, f_0 %.5g, T_0 %.4g s (G = 1e4)\n", soft.tau_bar_0, soft.f_0, soft.relaxation_time_0);
  EXPECT_NEAR(soft.tau_bar_0, stiff.tau_bar_0, 1e-6 * soft.tau_bar_0);  // same steady pre-shear state
  for (const auto* r : {&soft, &stiff, &fastf}) {
    for (std::size_t i = 1; i < r->samples.size(); ++i) {
      EXPECT_LE(r->samples[i].tau_bar, r->samples[i - 1].tau_bar) << "G " << r->G << " sample " << i;
      EXPECT_NE(r->samples[i].regime, material::GranularRegime::kShear);  // beta = 0 (compacting) branch
    }
    EXPECT_LT(r->samples.back().tau_bar, 0.5 * r->tau_bar_0);
  }
  for (double t : {0.3 * soft.relaxation_time_0, soft.relaxation_time_0, 3.0 * soft.relaxation_time_0}) {
    EXPECT_LT(tau_at(stiff, t), tau_at(soft, t)) << "t " << t;
  }
  // agreement with the reduced ODE (integrated here) at a few times
  for (const auto* r : {&soft, &stiff, &fastf}) {
    for (std::size_t i = 10; i < r->samples.size(); i += 10) {
      double tau = r->tau_bar_0, f = r->f_0;
      relax_reference(s, 0.52, r->G, r->K_0, r->samples[i].time, tau, f);
      std::printf("G %.0e K0 %g t %.4g: tau %.6g ode %.6g | f %.6g ode %.6g\n", r->G, r->K_0, r->samples[i].time,
                  r->samples[i].tau_bar, tau, r->samples[i].f, f);
      EXPECT_NEAR(r->samples[i].tau_bar, tau, 0.01 * r->tau_bar_0 + 0.02 * tau);
      EXPECT_NEAR(r->samples[i].f, f, 0.01 * r->f_0 + 0.02 * f);
    }
  }
}

// Near the DST asymptote with a stiff structure (dt K_0 gamma_dot H >> 1) the staggered f update
// oscillates with period 2 under stress control; the implicit (monolithic) update selected by
// StructureUpdate::kAuto converges to the closed-form steady state (E11) instead.
TEST(GranularTransients, StiffStructureImplicitUpdateIsStable) {
  const rheology::Preset P = test::preset("hermes2016", 1e-8);
  const double phi = 0.52, S = 1e4, dt = 0.1;
  auto run = [&](material::StructureUpdate mode, double f_last[3], material::GranularUpdate& u) {
    material::GranularOptions opt;
    opt.structure_update = mode;
    const material::GranularLaw law(P, opt);
    material::GranularState st;
    double rate = 0.0;
    for (int k = 0; k < 1500; ++k) {
      rate = material::stress_controlled_step(law, st, phi, dt, S, u);
      if (k >= 1497) f_last[k - 1497] = st.f;
    }
    return rate;
  };
  double fs[3], fi[3];
  material::GranularUpdate us, ui;
  run(material::StructureUpdate::kStaggered, fs, us);
  const double rate = run(material::StructureUpdate::kAuto, fi, ui);
  std::printf("staggered f: %.9g %.9g %.9g | implicit f: %.12g %.12g %.12g (structure iterations %d)\n", fs[0], fs[1],
              fs[2], fi[0], fi[1], fi[2], ui.structure_iterations);
  EXPECT_GT(std::fabs(fs[2] - fs[1]), 1e-5);  // the staggered scheme's 2-cycle
  EXPECT_NEAR(fs[2], fs[0], 1e-9);
  EXPECT_GT(ui.structure_iterations, 0);
  EXPECT_LT(std::fabs(fi[2] - fi[1]), 1e-12);
  const auto cf = test::steady_at_f(P.steady, phi, fi[2]);
  std::printf("implicit: rate %.8g gdp %.8g vs closed form %.8g; tau_bar %.8g vs %.8g; p %.8g vs %.8g\n", rate,
              ui.gamma_dot_p, cf.shear_rate, ui.tau_bar, cf.granular_shear_stress, ui.p, cf.granular_pressure);
  EXPECT_LT(test::rel(cf.shear_stress, S), 0.01);
  EXPECT_LT(test::rel(ui.gamma_dot_p, cf.shear_rate), 0.01);
  EXPECT_LT(test::rel(rate, cf.shear_rate), 0.01);
  EXPECT_LT(test::rel(ui.tau_bar, cf.granular_shear_stress), 0.01);
  EXPECT_LT(test::rel(ui.p, cf.granular_pressure), 0.01);
}
