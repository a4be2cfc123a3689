// The joint flow-curve fit (rheology/fit_curves.hpp) on a user's first call: rate-controlled flow
// curves below DST, fitted with the default parameter set, hold the parameters the data do not
// determine at the base set's values and recover the rest; strict keeps the error.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/fit_curves.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/steady_states.hpp"

namespace {
using namespace oobleck::rheology;

struct Curves {
  std::vector<double> phi, rate, stress;
};

/// Rate-controlled flow curves of `p` at five phi from 0.40 to 0.49: 12 rates per curve, log-spaced
/// from 1e-3 1/s to 0.8 gamma_dot_DST (10 1/s where there is no DST), the stress of the
/// low-viscosity branch times exp(noise * N(0, 1)) (Box-Muller on std::mt19937, whose output the
/// standard fixes, so the data are the same everywhere).
Curves rate_controlled_below_dst(const SteadyParams& p, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  auto uniform = [&rng] { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; };
  Curves c;
  for (double phi : {0.40, 0.4225, 0.445, 0.4675, 0.49}) {
    const auto dst = shear_rate_dst(p, phi);
    const double hi = dst ? 0.8 * *dst : 10.0;
    for (int k = 0; k < 12; ++k) {
      const double rate = 1e-3 * std::pow(hi / 1e-3, k / 11.0);
      const auto states = steady_states_at(p, phi, Control::shear_rate, rate);
      const double gauss = std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * M_PI * uniform());
      c.phi.push_back(phi);
      c.rate.push_back(rate);
      c.stress.push_back(states.at(0).shear_stress * std::exp(noise * gauss));
    }
  }
  return c;
}

double value_of(const SteadyParams& p, const std::string& name) {
  if (name == "a_0") return p.a_0;
  if (name == "phi_j") return p.phi_j;
  if (name == "a_inf") return p.a_inf;
  if (name == "phi_c") return p.phi_c;
  if (name == "tau_star") return p.tau_star;
  const auto& t = p.eta_B_terms.at(static_cast<std::size_t>(name.at(6) - '0'));
  return name.ends_with("phi_i") ? t.phi_i : t.alpha;
}

TEST(FitCurves, RateControlledCurvesBelowDstHoldTheEtaBTermsAndRecoverTheRest) {
  // The truth is hermes2016 (a_0 = a_inf = 0.8, phi_j = 0.535, phi_c = 0.436, tau* = 5.35 Pa, eta_B
  // terms (1.86e4, 4) and (9.3e-3, 0.1)), which is also the default base set: held parameters sit at
  // the truth, and the fitted ones must come back within 3 standard errors of it.
  const Preset truth = load_preset("hermes2016");
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const Curves d = rate_controlled_below_dst(truth.steady, 0.02, seed);
    const CurvesFitResult r = fit_curves(d.phi, d.rate, d.stress, truth);  // the default parameters
    ASSERT_FALSE(r.held.empty());
    std::vector<std::string> held;
    for (const HeldParameter& h : r.held) {
      held.push_back(h.name);
      EXPECT_TRUE(h.name.starts_with("eta_B[")) << h.name << ": " << h.reason;
      EXPECT_FALSE(h.reason.empty());
      EXPECT_EQ(h.value, value_of(truth.steady, h.name)) << h.name;
      EXPECT_EQ(value_of(r.fitted.steady, h.name), value_of(truth.steady, h.name)) << h.name;
    }
    // The second term (alpha = 0.1) changes 1/eta_B by a constant below DST: never determined.
    for (const char* name : {"eta_B[1].phi_i", "eta_B[1].alpha"})
      EXPECT_NE(std::find(held.begin(), held.end(), name), held.end()) << name;
    EXPECT_EQ(r.parameters.size() + r.held.size(), 9u);
    EXPECT_EQ(r.p, static_cast<int>(r.parameters.size()));
    EXPECT_EQ(r.correlation.size(), r.parameters.size() * r.parameters.size());
    for (const char* name : {"a_0", "phi_j", "phi_c", "tau_star", "a_inf"}) {
      const auto it = std::find_if(r.parameters.begin(), r.parameters.end(),
                                   [&](const FittedParameter& q) { return q.name == name; });
      ASSERT_NE(it, r.parameters.end()) << name << " was held";
      const double z = (it->value - value_of(truth.steady, name)) / it->std_error;
      EXPECT_LT(std::fabs(z), 3.0) << name << " = " << it->value << " +- " << it->std_error;
    }
    EXPECT_GT(r.rms, 0.01);  // the 2 % noise
    EXPECT_LT(r.rms, 0.03);
  }
}

TEST(FitCurves, StrictKeepsTheError) {
  const Preset truth = load_preset("hermes2016");
  const Curves d = rate_controlled_below_dst(truth.steady, 0.02, 1);
  CurvesFitOptions o;
  o.parameters = {"a_0", "phi_j", "eta_B[1].phi_i", "eta_B[1].alpha"};
  const CurvesFitResult r = fit_curves(d.phi, d.rate, d.stress, truth, o);
  ASSERT_EQ(r.held.size(), 2u);
  EXPECT_EQ(r.held[0].name, "eta_B[1].phi_i");
  EXPECT_EQ(r.held[1].name, "eta_B[1].alpha");
  o.strict = true;
  try {
    (void)fit_curves(d.phi, d.rate, d.stress, truth, o);
    FAIL() << "no error";
  } catch (const oobleck::InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("data: the data do not determine eta_B[1].phi_i, eta_B[1].alpha", 0), 0u)
        << e.what();
  }
}

TEST(FitCurves, NamedParametersTheDataDetermineHoldNothing) {
  const Preset truth = load_preset("hermes2016");
  const Curves d = rate_controlled_below_dst(truth.steady, 0.02, 1);
  CurvesFitOptions o;
  o.parameters = {"a_0", "phi_j", "a_inf", "phi_c", "tau_star"};
  const CurvesFitResult r = fit_curves(d.phi, d.rate, d.stress, truth, o);
  EXPECT_TRUE(r.held.empty());
  EXPECT_EQ(r.p, 5);
}

TEST(FitCurves, NothingLeftToFitIsStillAnError) {
  // Low stresses below phi_c (3 % deterministic scatter): the second eta_B term is not determined;
  // held one at a time, nothing is left, and the error is that of the first fit.
  const Preset truth = load_preset("hermes2016");
  std::vector<double> phi, rate, stress;
  for (double x : {0.30, 0.34, 0.38}) {
    for (int k = 0; k < 5; ++k) {
      const double tau = 1e-3 * std::pow(10.0, k / 4.0);
      phi.push_back(x);
      stress.push_back(tau);
      rate.push_back(steady_states_at(truth.steady, x, Control::shear_stress, tau).at(0).shear_rate *
                     (1.0 + 0.03 * std::sin(7.0 * static_cast<double>(rate.size()))));
    }
  }
  CurvesFitOptions o;
  o.parameters = {"eta_B[1].phi_i", "eta_B[1].alpha"};
  for (bool strict : {false, true}) {
    o.strict = strict;
    try {
      (void)fit_curves(phi, rate, stress, truth, o);
      FAIL() << "no error, strict = " << strict;
    } catch (const oobleck::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the data do not determine eta_B[1].phi_i"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
