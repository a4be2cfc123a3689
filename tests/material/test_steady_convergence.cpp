// V1: rate- and stress-controlled homogeneous shear at fixed phi converges to the closed-form
// steady flow curve of model.md §2 (E3–E5, E10, E11), evaluated independently by rheology::.
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
      {"hermes2016", 0.40, 1e-2}, {"hermes2016", 0.40, 1e-1}, {"hermes2016", 0.40, 1.0},
      {"hermes2016", 0.40, 10.0}, {"hermes2016", 0.40, 100.0}, {"hermes2016", 0.44, 1e-3},
      {"hermes2016", 0.44, 1e-2}, {"hermes2016", 0.44, 1e-1}, {"hermes2016", 0.44, 1.0},
      {"hermes2016", 0.44, 10.0}, {"hermes2016", 0.48, 1e-3}, {"hermes2016", 0.48, 1e-2},
      {"hermes2016", 0.48, 1e-1}, {"hermes2016", 0.48, 1.0},  {"hermes2016", 0.48, 2.0},
      {"singh2018b", 0.50, 1e-2}, {"singh2018b", 0.56, 1.0},  {"singh2018b", 0.60, 1e-3}, {"dhaene1993", 0.58, 3.0},
      {"dhaene1993", 0.50, 1.0},  {"dhaene1993", 0.55, 10.0}, {"dhaene1993", 0.58, 0.1},
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
