// The input checks of the point experiments (material::validate for ShearInput and RelaxInput),
// which `oobleck point shear/relax` and oobleck.point_shear/point_relax share: one bad input per
// rule, with the exact message in the CLI's spelling and in Python's; and the options built from
// a good input (the imposed control, the default time step of default_dt).
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/params.hpp"

using namespace oobleck;
using material::ArgStyle;

namespace {

material::ShearInput good_shear() {
  material::ShearInput in;
  in.phi = 0.44;
  in.shear_rate = 10.0;
  in.duration = 1.0;
  return in;
}

material::RelaxInput good_relax() {
  material::RelaxInput in;
  in.phi = 0.44;
  in.shear_rate = 5.0;
  in.duration = 0.01;
  return in;
}

template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST(PointInputs, ShearRulesNameTheArgumentInEachStyle) {
  struct Case {
    void (*bad)(material::ShearInput&);
    const char *cli, *python;
  };
  const Case cases[] = {
      {[](auto& in) { in.phi = 1.2; }, "--phi = 1.2: must lie in (0, 1)", "phi = 1.2: must lie in (0, 1)"},
      {[](auto& in) { in.shear_stress = 3.0; }, "--shear-rate and --shear-stress: give one of them, not both",
       "shear_rate and shear_stress: give one of them, not both"},
      {[](auto& in) { in.shear_rate.reset(); }, "one of --shear-rate R or --shear-stress S is required",
       "one of shear_rate or shear_stress is required"},
      {[](auto& in) { in.shear_rate = -1.0; }, "--shear-rate = -1: must be positive [1/s]",
       "shear_rate = -1: must be positive [1/s]"},
      {[](auto& in) {
         in.shear_rate.reset();
         in.shear_stress = 0.0;
       },
       "--shear-stress = 0: must be positive [Pa]", "shear_stress = 0: must be positive [Pa]"},
      {[](auto& in) { in.duration = 0.0; }, "--duration = 0: must be positive [s]",
       "duration = 0: must be positive [s]"},
      {[](auto& in) { in.dt = 2.0; }, "--dt = 2: must lie in (0, --duration = 1] [s]",
       "dt = 2: must lie in (0, duration = 1] [s]"},
      {[](auto& in) { in.f0 = 1.5; }, "--f0 = 1.5: must lie in [0, 1]", "f0 = 1.5: must lie in [0, 1]"},
      {[](auto& in) { in.samples = 1; }, "--samples = 1: must be >= 2", "samples = 1: must be >= 2"},
  };
  for (const Case& c : cases) {
    material::ShearInput in = good_shear();
    c.bad(in);
    EXPECT_EQ(message_of([&] { material::validate(in, ArgStyle::cli); }), c.cli);
    EXPECT_EQ(message_of([&] { material::validate(in, ArgStyle::python); }), c.python);
  }
  EXPECT_NO_THROW(material::validate(good_shear(), ArgStyle::cli));
}

TEST(PointInputs, RelaxRulesNameTheArgumentInEachStyle) {
  const auto p = rheology::load_preset("hermes2016");  // phi_j = 0.535
  struct Case {
    void (*bad)(material::RelaxInput&);
    const char *cli, *python;
  };
  const Case cases[] = {
      {[](auto& in) { in.phi = -0.1; }, "--phi = -0.1: must lie in (0, 1)", "phi = -0.1: must lie in (0, 1)"},
      {[](auto& in) { in.dt = 0.0; }, "--dt = 0: must lie in (0, --duration = 0.01] [s]",
       "dt = 0: must lie in (0, duration = 0.01] [s]"},
      {[](auto& in) { in.samples = 0; }, "--samples = 0: must be >= 2", "samples = 0: must be >= 2"},
      {[](auto& in) {
         in.G = {1e4, -5.0};
       },
       "--G = -5: must be positive [Pa]", "G = -5: must be positive [Pa]"},
      {[](auto& in) { in.K_0 = {0.0}; }, "--K0 = 0: must be positive", "K0 = 0: must be positive"},
  };
  for (const Case& c : cases) {
    material::RelaxInput in = good_relax();
    c.bad(in);
    EXPECT_EQ(message_of([&] { material::validate(in, p.steady, ArgStyle::cli); }), c.cli);
    EXPECT_EQ(message_of([&] { material::validate(in, p.steady, ArgStyle::python); }), c.python);
  }
  // phi in (0, 1) but not below phi_j, and a pre-shear stress below the flow curve (E11)
  material::RelaxInput in = good_relax();
  in.phi = 0.6;
  EXPECT_NE(message_of([&] { material::validate(in, p.steady, ArgStyle::cli); }).find("--phi = 0.6: must lie in"),
            std::string::npos);
  in = good_relax();
  in.shear_rate.reset();
  in.shear_stress = 1e-12;
  EXPECT_NE(message_of([&] {
              material::validate(in, p.steady, ArgStyle::python);
            }).find("is below the smallest steady stress"),
            std::string::npos);
  EXPECT_NO_THROW(material::validate(good_relax(), p.steady, ArgStyle::python));
}

TEST(PointInputs, OptionsCarryTheControlAndTheDefaultStep) {
  const auto p = rheology::load_preset("hermes2016");
  const material::GranularLaw law(p);
  material::ShearInput in = good_shear();
  material::ShearOptions so = material::shear_options(law, in);
  EXPECT_FALSE(so.stress_controlled);
  EXPECT_EQ(so.shear_rate, 10.0);
  EXPECT_EQ(so.dt, material::default_dt(law, 0.44, 10.0, 1.0));
  in.dt = 0.25;
  EXPECT_EQ(material::shear_options(law, in).dt, 0.25);
  in = good_shear();
  in.shear_rate.reset();
  in.shear_stress = 20.0;
  so = material::shear_options(law, in);
  EXPECT_TRUE(so.stress_controlled);
  EXPECT_EQ(so.shear_rate, 0.0);
  EXPECT_EQ(so.shear_stress, 20.0);
  // the rate scale of a stress-controlled run: stress over the E12 viscosity eta_0 eta_r_low(phi)
  const double phi_j = 0.535, a_0 = 0.8, mu_c = 1.19, eta_0 = 6e-3, phi = 0.44;
  const double eta_r_low = 1 + 2.5 * phi * phi_j / (phi_j - phi) + 2 * mu_c * std::pow(a_0 * phi / (phi_j - phi), 2);
  EXPECT_DOUBLE_EQ(so.dt, material::default_dt(law, phi, 20.0 / (eta_0 * eta_r_low), 1.0));

  material::RelaxInput r = good_relax();
  r.G = {1e4, 1e5};
  const material::RelaxOptions ro = material::relax_options(r);
  EXPECT_EQ(ro.shear_rate, 5.0);
  EXPECT_EQ(ro.dt, 0.0);  // run_relax picks 1/20 of the initial relaxation time
  EXPECT_EQ(ro.samples, 200);
}

TEST(PointInputs, RelaxSweepRunsKZeroOuterGInner) {
  const auto p = rheology::load_preset("hermes2016");
  material::RelaxInput in = good_relax();
  in.samples = 10;
  in.G = {1e4, 1e5};
  in.K_0 = {p.granular.K_0, 2.0 * p.granular.K_0};
  std::vector<material::RelaxCase> started, done;
  material::RelaxSweepHooks hooks;
  hooks.start = [&](const material::RelaxCase& c) -> material::Progress {
    started.push_back(c);
    return {};
  };
  hooks.done = [&](const material::RelaxCase& c, const material::RelaxResult&) { done.push_back(c); };
  const auto results = material::run_relax_sweep(p, in, hooks);
  ASSERT_EQ(results.size(), 4u);
  ASSERT_EQ(started.size(), 4u);
  ASSERT_EQ(done.size(), 4u);
  const double expect[4][2] = {
      {1e4, p.granular.K_0}, {1e5, p.granular.K_0}, {1e4, 2 * p.granular.K_0}, {1e5, 2 * p.granular.K_0}};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(results[k].G, expect[k][0]);
    EXPECT_EQ(results[k].K_0, expect[k][1]);
    EXPECT_EQ(started[k].G, expect[k][0]);
    EXPECT_EQ(done[k].K_0, expect[k][1]);
  }
  // a case is run_relax on the parameter set with that G and K_0
  rheology::Preset q = p;
  q.granular.G = 1e5;
  q.granular.K_0 = 2.0 * p.granular.K_0;
  const auto one = material::run_relax(material::GranularLaw(q), material::relax_options(in));
  ASSERT_EQ(one.samples.size(), results[3].samples.size());
  EXPECT_EQ(one.samples.back().tau_bar, results[3].samples.back().tau_bar);
  // without G and K_0: the parameter set's
  in.G.clear();
  in.K_0.clear();
  const auto base = material::run_relax_sweep(p, in);
  ASSERT_EQ(base.size(), 1u);
  EXPECT_EQ(base[0].G, p.granular.G);
  EXPECT_EQ(base[0].K_0, p.granular.K_0);
}

TEST(PointInputs, RelaxColumnsHoldTheirQuantities) {
  // Each named column of the relaxation table (the CLI's CSV and the Python dict) holds the
  // quantity its name says, with its unit; the text column (regime) has no unit and no number.
  material::RelaxResult r;
  r.G = 1.5e5;
  r.K_0 = 2.5;
  material::RelaxSample x;
  x.time = 0.125;
  x.tau_bar = 11.0;
  x.p = 12.0;
  x.f = 0.3;
  x.gamma_dot_p = 7.0;
  x.ode_tau_bar = 10.5;
  x.ode_f = 0.29;
  const std::vector<std::pair<std::string, double>> expected = {{"case", 3.0},
                                                                {"G", 1.5e5},
                                                                {"K_0", 2.5},
                                                                {"time", 0.125},
                                                                {"granular_shear_stress", 11.0},
                                                                {"granular_pressure", 12.0},
                                                                {"f", 0.3},
                                                                {"gamma_dot_p", 7.0},
                                                                {"ode_granular_shear_stress", 10.5},
                                                                {"ode_f", 0.29}};
  const auto columns = material::relax_columns();
  const auto row = material::relax_row(3, r, x);
  ASSERT_EQ(columns.size(), row.size());
  ASSERT_EQ(columns.size(), expected.size() + 1);
  for (const auto& [name, value] : expected) {
    std::size_t k = 0;
    while (k < columns.size() && columns[k].name != name) ++k;
    ASSERT_LT(k, columns.size()) << name;
    EXPECT_EQ(row[k], value) << name;
    EXPECT_FALSE(columns[k].unit.empty()) << name;
  }
  EXPECT_EQ(columns[8].name, "regime");
  EXPECT_TRUE(columns[8].unit.empty());
  EXPECT_TRUE(std::isnan(row[8]));
  EXPECT_EQ(columns[1].unit, "Pa");  // G
  EXPECT_EQ(columns[2].unit, "1");   // K_0
}
