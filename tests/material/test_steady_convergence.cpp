// V1: rate- and stress-controlled homogeneous shear at fixed phi converges to the closed-form
// steady flow curve (E3–E5, E10, E11 of docs/equations.md), evaluated independently by rheology::.
#include <cstdio>

#include <gtest/gtest.h>

#include "oobleck/material/point_driver.hpp"
#include "test_helpers.hpp"

using namespace oobleck;

namespace {

struct Case {
  const char* preset;
  double phi;
  double rate;
};

material::ShearResult shear_rate_run(const material::GranularLaw& law, double phi, double rate, double strain,
                                     double dstrain = 0.02, double f0 = 0.0) {
  material::ShearOptions o;
  o.phi = phi;
  o.shear_rate = rate;
  o.duration = strain / rate;
  o.dt = dstrain / rate;
  o.f0 = f0;
  o.samples = 10;
  return material::run_shear(law, o);
}

}  // namespace

TEST(SteadyConvergence, RateControlledMatchesClosedForm) {
  const Case cases[] = {
      {"hermes2016", 0.40, 1e-2},  {"hermes2016", 0.40, 1e-1}, {"hermes2016", 0.40, 1.0},  {"hermes2016", 0.40, 10.0},
      {"hermes2016", 0.40, 100.0}, {"hermes2016", 0.44, 1e-3}, {"hermes2016", 0.44, 1e-2}, {"hermes2016", 0.44, 1e-1},
      {"hermes2016", 0.44, 1.0},   {"hermes2016", 0.44, 10.0}, {"hermes2016", 0.48, 1e-3}, {"hermes2016", 0.48, 1e-2},
      {"hermes2016", 0.48, 1e-1},  {"hermes2016", 0.48, 1.0},  {"hermes2016", 0.48, 2.0},  {"singh2018b", 0.50, 1e-2},
      {"singh2018b", 0.56, 1.0},   {"singh2018b", 0.60, 1e-3}, {"dhaene1993", 0.58, 3.0},  {"dhaene1993", 0.50, 1.0},
      {"dhaene1993", 0.55, 10.0},  {"dhaene1993", 0.58, 0.1},
  };
  for (const Case& c : cases) {
    const material::GranularLaw law(test::preset(c.preset, 1e-8));
    const auto r = shear_rate_run(law, c.phi, c.rate, 60.0);
    const auto& last = r.samples.back();
    const double f_cf = test::steady_f_at_rate(law.steady(), c.phi, c.rate, last.f);
    const auto cf = test::steady_at_f(law.steady(), c.phi, f_cf);
    std::printf("%s phi=%.2f rate=%g: f %.6g/%.6g tau %.6g/%.6g p %.6g/%.6g regime %s\n", c.preset, c.phi, c.rate,
                last.f, f_cf, last.granular_shear_stress, cf.granular_shear_stress, last.granular_pressure,
                cf.granular_pressure, material::regime_name(last.regime));
    EXPECT_LT(test::rel(last.f, f_cf), 0.01) << c.preset << " phi " << c.phi << " rate " << c.rate;
    EXPECT_LT(test::rel(last.granular_shear_stress, cf.granular_shear_stress), 0.01) << c.preset << " " << c.rate;
    EXPECT_LT(test::rel(last.granular_pressure, cf.granular_pressure), 0.01) << c.preset << " " << c.rate;
  }
}

namespace {
material::ShearResult shear_stress_run(const material::GranularLaw& law, double phi, double stress, double duration,
                                       double dt) {
  material::ShearOptions o;
  o.phi = phi;
  o.stress_controlled = true;
  o.shear_stress = stress;
  o.duration = duration;
  o.dt = dt;
  o.samples = 10;
  return material::run_shear(law, o);
}
}  // namespace

// Stress control lands on the same closed-form curve, including the unstable-under-rate-control
// DST branch (d gamma_dot/d tau < 0) of hermes2016 at phi = 0.48 (phi_c < phi < phi_j, Delta = 0).
TEST(SteadyConvergence, StressControlledMatchesClosedFormIncludingDstBranch) {
  struct SCase {
    const char* preset;
    double phi, stress, duration, dt;
    bool dst_branch;
  };
  const SCase cases[] = {
      {"hermes2016", 0.48, 1.0, 100.0, 0.02, false},
      {"hermes2016", 0.48, 50.0, 200.0, 0.02, true},
      {"hermes2016", 0.40, 20.0, 10.0, 1e-3, false},
      {"dhaene1993", 0.55, 10.0, 20.0, 2e-3, false},
  };
  for (const SCase& c : cases) {
    const material::GranularLaw law(test::preset(c.preset, 1e-8));
    const auto r = shear_stress_run(law, c.phi, c.stress, c.duration, c.dt);
    const auto& last = r.samples.back();
    const auto cf = test::steady_at_f(law.steady(), c.phi, last.f);  // closed form at the reached f
    std::printf("%s phi=%.2f S=%g: rate %.6g/%.6g tau %.6g/%.6g taub %.6g/%.6g p %.6g/%.6g f %.6g\n", c.preset, c.phi,
                c.stress, last.shear_rate, cf.shear_rate, c.stress, cf.shear_stress, last.granular_shear_stress,
                cf.granular_shear_stress, last.granular_pressure, cf.granular_pressure, last.f);
    EXPECT_LT(test::rel(cf.shear_stress, c.stress), 0.01) << c.preset << " S " << c.stress;
    EXPECT_LT(test::rel(last.shear_rate, cf.shear_rate), 0.01) << c.preset << " S " << c.stress;
    EXPECT_LT(test::rel(last.granular_shear_stress, cf.granular_shear_stress), 0.01) << c.preset;
    EXPECT_LT(test::rel(last.granular_pressure, cf.granular_pressure), 0.01) << c.preset;
    // the f reached is the closed-form f at this stress (E11 swept in f; tau(f) is increasing)
    {
      double lo = 0.0, hi = rheology::f_upper(law.steady(), c.phi);
      for (int k = 0; k < 200; ++k) {
        const double m = 0.5 * (lo + hi);
        (test::steady_at_f(law.steady(), c.phi, m).shear_stress < c.stress ? lo : hi) = m;
      }
      EXPECT_LT(test::rel(last.f, 0.5 * (lo + hi)), 0.01) << c.preset << " S " << c.stress;
    }
    const auto cf2 = test::steady_at_f(law.steady(), c.phi, last.f * 1.001);
    const bool negative_slope = cf2.shear_rate < cf.shear_rate && cf2.shear_stress > cf.shear_stress;
    EXPECT_EQ(negative_slope, c.dst_branch) << c.preset << " S " << c.stress;
  }
}

// xi_dot_eps > 0 (Brownian/electrostatic structure decay, E7/E24) shifts the steady structure; the
// run follows the closed form, whose E10 root rheology::steady_point solves separately.
TEST(SteadyConvergence, RateControlledWithStructureDecay) {
  rheology::Preset P = test::preset("hermes2016", 1e-8);
  P.steady.xi_dot_eps = 2.0;
  const material::GranularLaw law(P);
  for (double rate : {1.0, 10.0}) {
    const auto r = shear_rate_run(law, 0.44, rate, 60.0);
    const auto& last = r.samples.back();
    const double f_cf = test::steady_f_at_rate(law.steady(), 0.44, rate, last.f);
    const auto cf = test::steady_at_f(law.steady(), 0.44, f_cf);
    EXPECT_LT(test::rel(last.f, f_cf), 0.01) << rate;
    EXPECT_LT(test::rel(last.granular_shear_stress, cf.granular_shear_stress), 0.01) << rate;
    EXPECT_LT(test::rel(last.granular_pressure, cf.granular_pressure), 0.01) << rate;
    // and the decay matters: f is below the xi_dot_eps = 0 value
    const rheology::Preset P0 = test::preset("hermes2016", 1e-8);
    EXPECT_LT(f_cf, 0.99 * test::steady_f_at_rate(P0.steady, 0.44, rate, last.f)) << rate;
  }
}
