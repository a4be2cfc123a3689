// Fits of E12/E13/E14 (rheology/fit.hpp): recovery of known parameters from synthetic data with
// 2 % multiplicative noise, generated with the library's closed forms (flow_curve.hpp), which
// the fitting code does not use for its residuals.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/fit.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"

namespace oobleck::rheology {
namespace {

constexpr double kNoise = 0.02;  // 2 % multiplicative scatter

struct Synthetic {
  std::vector<double> phi, values;
};

/// n points of `kind` at phi from `model` on [phi_lo, phi_hi] (for dst: log-spaced in phi_j - phi),
/// each multiplied by (1 + 0.02 N(0, 1)) with a fixed seed.
Synthetic synthesize(FitKind kind, const SteadyParams& truth, double phi_lo, double phi_hi, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Synthetic s;
  for (int k = 0; k < n; ++k) {
    const double t = double(k) / (n - 1);
    double phi = phi_lo + (phi_hi - phi_lo) * t;
    if (kind == FitKind::dst) {  // dense near phi_j, where the shallow eta_B terms dominate
      const double g_hi = truth.phi_j - phi_lo, g_lo = truth.phi_j - phi_hi;
      phi = truth.phi_j - g_hi * std::pow(g_lo / g_hi, t);
    }
    double v = 0.0;
    switch (kind) {
      case FitKind::low: v = eta_r_low(truth, phi); break;               // E12
      case FitKind::high: v = eta_r_high(truth, phi); break;             // E13
      case FitKind::dst: v = shear_rate_dst(truth, phi).value(); break;  // E14
    }
    s.phi.push_back(phi);
    s.values.push_back(v * (1.0 + kNoise * normal(rng)));
  }
  return s;
}

struct Expected {
  std::string name;
  double value;
};

/// Every fitted parameter within 3 standard errors of the truth, and the standard errors
/// sensible: relative error <= `max_rel` (absolute <= max_rel for parameters near 0, alpha).
void expect_recovered(const FitResult& r, const std::vector<Expected>& truth, double max_rel) {
  ASSERT_TRUE(r.covariance_ok);
  ASSERT_EQ(r.parameters.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto& p = r.parameters[i];
    SCOPED_TRACE(p.name);
    EXPECT_EQ(p.name, truth[i].name);
    ASSERT_TRUE(std::isfinite(p.std_error));
    EXPECT_GT(p.std_error, 0.0);
    EXPECT_LT(std::abs(p.value - truth[i].value), 3.0 * p.std_error)
        << "fit " << p.value << " +- " << p.std_error << ", truth " << truth[i].value;
    EXPECT_LT(p.std_error, max_rel * std::max(1.0, std::abs(p.value)));
    std::printf("    %-16s truth %-12.6g fit %-12.6g +- %-10.3g (%.2f sigma)\n", p.name.c_str(), truth[i].value,
                p.value, p.std_error, std::abs(p.value - truth[i].value) / p.std_error);
  }
  // Log residuals with 2 % scatter: RMS ~ 0.02.
  EXPECT_GT(r.rms, 0.5 * kNoise);
  EXPECT_LT(r.rms, 2.0 * kNoise);
  // The Ceres cost (templated residuals) agrees with the library closed forms (rms).
  EXPECT_NEAR(r.rms * r.rms * r.n, 2.0 * r.cost, 1e-9 * (1.0 + 2.0 * r.cost));
}

TEST(Fit, LowRecoversA0PhiJ) {
  for (const std::string name : {"hermes2016", "dhaene1993"}) {
    SCOPED_TRACE(name);
    const SteadyParams truth = load_preset(name).steady;
    const auto d = synthesize(FitKind::low, truth, 0.3 * truth.phi_j, truth.phi_j - 0.02, 25, 11);
    SteadyParams base = truth;  // the fit must not see the answer: perturb the base set
    base.a_0 *= 1.7;
    base.phi_j = std::min(0.99, base.phi_j + 0.05);
    const FitResult r = fit(FitKind::low, d.phi, d.values, base);
    expect_recovered(r, {{"a_0", truth.a_0}, {"phi_j", truth.phi_j}}, 0.05);
    EXPECT_DOUBLE_EQ(r.params.a_0, r.parameters[0].value);
    EXPECT_DOUBLE_EQ(r.params.phi_j, r.parameters[1].value);
    EXPECT_EQ(r.params.mu_c, truth.mu_c);  // never fitted
    EXPECT_EQ(r.n, 25);
    EXPECT_EQ(r.p, 2);
  }
}

TEST(Fit, HighRecoversAInfPhiC) {
  for (const std::string name : {"hermes2016", "dhaene1993", "guy2015b"}) {
    SCOPED_TRACE(name);
    const SteadyParams truth = load_preset(name).steady;
    const auto d = synthesize(FitKind::high, truth, 0.3 * truth.phi_c, truth.phi_c - 0.015, 25, 12);
    SteadyParams base = truth;
    base.a_inf *= 0.6;
    base.phi_c -= 0.01;
    const FitResult r = fit(FitKind::high, d.phi, d.values, base);
    expect_recovered(r, {{"a_inf", truth.a_inf}, {"phi_c", truth.phi_c}}, 0.05);
    EXPECT_DOUBLE_EQ(r.params.phi_c, r.parameters[1].value);
    EXPECT_EQ(r.params.phi_j, base.phi_j);
  }
}

TEST(Fit, DstRecoversEtaBTerms) {
  // hermes2016 (two terms), dhaene1993 (one term), guy2015a (two terms, alpha 5 and 0.1).
  struct Case {
    std::string name;
    double gap_min;
  };
  for (const auto& c : {Case{"hermes2016", 2e-4}, Case{"dhaene1993", 2e-3}, Case{"guy2015a", 2e-4}}) {
    SCOPED_TRACE(c.name);
    const SteadyParams truth = load_preset(c.name).steady;
    const auto d = synthesize(FitKind::dst, truth, truth.phi_c, truth.phi_j - c.gap_min, 40, 13);
    SteadyParams base = truth;
    for (auto& t : base.eta_B_terms) t = {1.0, 1.0};  // the fit must not start from the answer
    const FitResult r = fit(FitKind::dst, d.phi, d.values, base);
    std::vector<Expected> expected;
    for (std::size_t i = 0; i < truth.eta_B_terms.size(); ++i) {
      expected.push_back({"eta_B[" + std::to_string(i) + "].phi_i", truth.eta_B_terms[i].phi_i});
      expected.push_back({"eta_B[" + std::to_string(i) + "].alpha", truth.eta_B_terms[i].alpha});
    }
    ASSERT_EQ(r.parameters.size(), expected.size());
    // phi_i spans decades and is fitted as ln(phi_i): compare in log space (SE of ln phi_i is
    // SE(phi_i)/phi_i), the alphas directly.
    for (std::size_t i = 0; i < expected.size(); i += 2) {
      const auto& phi_i = r.parameters[i];
      const double ln_se = phi_i.std_error / phi_i.value;
      EXPECT_LT(std::abs(std::log(phi_i.value / expected[i].value)), 3.0 * ln_se) << phi_i.name;
      EXPECT_LT(ln_se, 0.3) << phi_i.name;  // phi_i known to better than a factor 1.35
      std::printf("    %-16s truth %-12.6g fit %-12.6g +- %-10.3g (ln: %.2f sigma)\n", phi_i.name.c_str(),
                  expected[i].value, phi_i.value, phi_i.std_error,
                  std::abs(std::log(phi_i.value / expected[i].value)) / ln_se);
      const auto& alpha = r.parameters[i + 1];
      EXPECT_LT(std::abs(alpha.value - expected[i + 1].value), 3.0 * alpha.std_error) << alpha.name;
      EXPECT_LT(alpha.std_error, 0.05 * std::max(1.0, alpha.value)) << alpha.name;
      std::printf("    %-16s truth %-12.6g fit %-12.6g +- %-10.3g (%.2f sigma)\n", alpha.name.c_str(),
                  expected[i + 1].value, alpha.value, alpha.std_error,
                  std::abs(alpha.value - expected[i + 1].value) / alpha.std_error);
    }
    EXPECT_GT(r.rms, 0.5 * kNoise);
    EXPECT_LT(r.rms, 2.0 * kNoise);
    EXPECT_NEAR(r.rms * r.rms * r.n, 2.0 * r.cost, 1e-9 * (1.0 + 2.0 * r.cost));
    // The fitted eta_B reproduces the rates (E14) to the noise level.
    for (std::size_t k = 0; k < d.phi.size(); ++k) {
      EXPECT_NEAR(std::log(fit_model_value(FitKind::dst, r.params, d.phi[k]) / d.values[k]), 0.0, 5 * kNoise);
    }
  }
}

TEST(Fit, DstDefaultsToOneTermWithoutEtaB) {
  SteadyParams truth = load_preset("dhaene1993").steady;
  const auto d = synthesize(FitKind::dst, truth, truth.phi_c, truth.phi_j - 2e-3, 20, 14);
  SteadyParams base = truth;
  base.eta_B_terms.clear();
  EXPECT_EQ(fit_parameter_count(FitKind::dst, base), 2);
  const FitResult r = fit(FitKind::dst, d.phi, d.values, base);
  ASSERT_EQ(r.params.eta_B_terms.size(), 1u);
  EXPECT_NEAR(r.params.eta_B_terms[0].alpha, 6.0, 3 * r.parameters[1].std_error);
  // --terms overrides the base set's count.
  FitOptions two;
  two.terms = 2;
  EXPECT_EQ(fit_parameter_count(FitKind::dst, base, two), 4);
}

TEST(Fit, UnidentifiableTermsGiveNaNStdErrors) {
  // Two eta_B terms fitted to single-power-law data: the terms coincide (or one vanishes), the
  // Jacobian is rank-deficient, and the fit says so instead of printing meaningless errors.
  const SteadyParams truth = load_preset("dhaene1993").steady;
  const auto d = synthesize(FitKind::dst, truth, truth.phi_c, truth.phi_j - 2e-3, 20, 17);
  FitOptions o;
  o.terms = 2;
  const FitResult r = fit(FitKind::dst, d.phi, d.values, truth, o);
  EXPECT_FALSE(r.covariance_ok);
  for (const auto& p : r.parameters) EXPECT_TRUE(std::isnan(p.std_error)) << p.name;
  EXPECT_LT(r.rms, 2.0 * kNoise);  // the curve itself is still fine
}

TEST(Fit, FittedTomlRoundTrips) {
  Preset preset = load_preset("hermes2016");
  const auto d = synthesize(FitKind::low, preset.steady, 0.2, 0.52, 20, 15);
  const FitResult r = fit(FitKind::low, d.phi, d.values, preset.steady);
  preset.steady = r.params;
  const auto dir = std::filesystem::temp_directory_path() / ("oobleck_fit_rt_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "fit.toml").string();
  io::write_file_atomically(path, to_toml(preset));
  const Preset back = load_params_file(path);
  EXPECT_EQ(back.steady.a_0, r.params.a_0);
  EXPECT_EQ(back.steady.phi_j, r.params.phi_j);
  EXPECT_EQ(back.steady.phi_c, preset.steady.phi_c);
  EXPECT_EQ(back.steady.eta_B_terms.size(), preset.steady.eta_B_terms.size());
  std::filesystem::remove_all(dir);
}

TEST(Fit, RejectsBadData) {
  const SteadyParams base = load_preset("hermes2016").steady;
  const std::vector<double> phi = {0.2, 0.3, 0.4}, eta = {2.0, 4.0, 9.0};
  EXPECT_THROW(fit(FitKind::low, {0.2, 0.3}, {2.0, 4.0}, base), InputError);  // n < p + 1
  EXPECT_THROW(fit(FitKind::low, {0.2, 1.3, 0.4}, eta, base), InputError);    // phi outside (0,1)
  EXPECT_THROW(fit(FitKind::low, {0.2, 0.0, 0.4}, eta, base), InputError);
  EXPECT_THROW(fit(FitKind::low, phi, {2.0, -4.0, 9.0}, base), InputError);                // non-positive
  EXPECT_THROW(fit(FitKind::low, phi, {2.0, 4.0}, base), InputError);                      // size mismatch
  EXPECT_THROW(fit(FitKind::high, {0.2, 0.3, 0.6}, eta, base), InputError);                // phi >= base phi_j
  EXPECT_THROW(fit(FitKind::high, {0.2, 0.3, base.phi_j - 1e-8}, eta, base), InputError);  // no room for phi_c
  EXPECT_THROW(fit(FitKind::low, {0.2, 0.3, 1.0 - 1e-8}, eta, base), InputError);          // no room for phi_j
  EXPECT_THROW(fit(FitKind::dst, {0.45, 0.47, 0.3, 0.5, 0.51}, {1, 2, 3, 4, 5}, base), InputError);  // < phi_c
  try {
    FitOptions o;
    o.where = "data.csv";
    fit(FitKind::low, phi, {2.0, 0.0, 9.0}, base, o);
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("data.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("point 2"), std::string::npos) << m;
    EXPECT_NE(m.find("must be positive"), std::string::npos) << m;
  }
}

TEST(Fit, NonConvergenceIsNumericalError) {
  const SteadyParams truth = load_preset("hermes2016").steady;
  const auto d = synthesize(FitKind::low, truth, 0.2, 0.52, 20, 16);
  FitOptions o;
  o.max_iterations = 1;
  o.where = "rheometer.csv";
  try {
    fit(FitKind::low, d.phi, d.values, truth, o);
    FAIL() << "one iteration converged";
  } catch (const NumericalError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("rheometer.csv: the low fit did not converge after 1 iterations (", 0), 0u) << m;
    EXPECT_NE(m.find("check that the data follow the model's asymptote"), std::string::npos) << m;
  }
}

TEST(Fit, ParseKind) {
  EXPECT_EQ(parse_fit_kind("low", "--kind"), FitKind::low);
  EXPECT_EQ(parse_fit_kind("dst", "--kind"), FitKind::dst);
  EXPECT_THROW(parse_fit_kind("medium", "--kind"), InputError);
}

}  // namespace
}  // namespace oobleck::rheology
