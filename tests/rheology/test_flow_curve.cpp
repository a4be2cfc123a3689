// Steady flow curves (docs/equations.md, steady rheology) against the paper's closed forms, written independently in
// paper_tables.hpp: E12/E13 asymptotes at the curve ends, E14 DST rate on the DST branch, and
// E10 (f = H f_m/(H + S)) satisfied by every row.
#include <cmath>

#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"
#include "paper_tables.hpp"

using namespace oobleck;

namespace {
double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

// Several volume fractions spanning CST -> DST for each fit (all < phi_j).
std::vector<double> phis_for(const paper::Fit& f) {
  std::vector<double> out;
  for (double s : {0.5, 0.8, 0.95}) out.push_back(s * f.phi_c);
  for (double s : {0.1, 0.5, 0.9}) out.push_back(f.phi_c + s * (f.phi_j - f.phi_c));
  return out;
}
}  // namespace

TEST(FlowCurve, LowAndHighViscosityAsymptotesE12E13) {
  for (const auto& fit : paper::fits()) {
    const auto p = rheology::load_preset(fit.name);
    for (double phi : phis_for(fit)) {
      SCOPED_TRACE(fit.name + " phi=" + std::to_string(phi));
      const auto c = rheology::flow_curve(p.steady, phi, 200);
      EXPECT_LT(rel(c.front().eta_r, paper::eta_r_low(fit, phi)), 1e-6);
      if (phi < fit.phi_c) {
        EXPECT_LT(rel(c.back().eta_r, paper::eta_r_high(fit, phi)), 1e-6);
      }
    }
  }
}

TEST(FlowCurve, DstBranchTendsToClosedFormRateE14) {
  int checked = 0;
  for (const auto& fit : paper::fits()) {
    if (fit.terms.empty() || fit.Delta != 0.0) continue;  // E14 needs finite eta_B and phi_c <= phi <= phi*
    const auto p = rheology::load_preset(fit.name);
    for (double s : {0.05, 0.3, 0.6, 0.9}) {
      const double phi = fit.phi_c + s * (fit.phi_j - fit.phi_c);
      SCOPED_TRACE(fit.name + " phi=" + std::to_string(phi));
      const double expected = paper::gamma_dot_dst(fit, phi);
      const auto c = rheology::flow_curve(p.steady, phi, 200);
      EXPECT_LT(rel(c.back().shear_rate, expected), 1e-3);
      EXPECT_GT(c.back().shear_stress, 1e3 * c.front().shear_stress);  // stress diverges on the branch
      const auto direct = rheology::shear_rate_dst(p.steady, phi);
      ASSERT_TRUE(direct.has_value());
      EXPECT_LT(rel(*direct, expected), 1e-12);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 24);
}

TEST(FlowCurve, EveryRowIsASteadyStateE10) {
  for (const auto& fit : paper::fits()) {
    const auto p = rheology::load_preset(fit.name);
    for (double phi : phis_for(fit)) {
      SCOPED_TRACE(fit.name + " phi=" + std::to_string(phi));
      const double fm = paper::f_m(fit, phi);
      const double inv_eta_B = 1.0 / paper::eta_B(fit, phi);
      double f_prev = -1.0;
      for (const auto& r : rheology::flow_curve(p.steady, phi, 200)) {
        const double H = std::pow(r.granular_shear_stress / fit.tau_star, 1.5);     // E7
        const double S = 1.0 + r.granular_shear_stress * inv_eta_B / r.shear_rate;  // E7
        ASSERT_LE(rel(r.f, H * fm / (H + S)), 1e-10) << "f=" << r.f;                // E10
        // E3 = fluid (Einstein) + granular; E5 tau_bar = (mu_c + mu_h) p.
        ASSERT_LE(rel(r.shear_stress, fit.eta_0 * r.shear_rate * (1 + 2.5 * phi) + r.granular_shear_stress), 1e-12);
        const double phim = fit.phi_j + (fit.phi_c - fit.phi_j) * r.f;
        const double a = fit.a_0 + (fit.a_inf - fit.a_0) * r.f;
        if (phim - phi > 1e-6) {
          ASSERT_LE(rel(r.granular_pressure, 2 * std::pow(a * phi / (phim - phi), 2) * fit.eta_0 * r.shear_rate), 1e-8);
          ASSERT_LE(rel(r.granular_shear_stress, (fit.mu_c + 1.25 * (phim - phi) / (a * a)) * r.granular_pressure),
                    1e-8);
        }
        ASSERT_GT(r.f, f_prev);  // rows ordered by increasing f
        f_prev = r.f;
        ASSERT_NEAR(r.viscosity, r.shear_stress / r.shear_rate, 1e-12 * r.viscosity);
      }
    }
  }
}

TEST(FlowCurve, CurveEndsSpanZeroToUpperStructure) {
  const auto p = rheology::load_preset("hermes2016");
  for (double phi : {0.40, 0.45, 0.50}) {
    const auto c = rheology::flow_curve(p.steady, phi, 200);
    const double fu = std::min(paper::f_m(paper::fits().back(), phi), (0.535 - phi) / (0.535 - 0.436));
    EXPECT_LE(c.front().f, 1e-6 * fu);
    EXPECT_LE(fu - c.back().f, 1e-6);
    EXPECT_GE(fu - c.back().f, 0.0);
  }
}

TEST(FlowCurve, SinghCurvesAreSShapedBelowPhiCAndShearJamAbove) {
  const auto p = rheology::load_preset("singh2018a");
  // phi = 0.56 < phi_c: gamma_dot decreases along part of the curve while tau increases (S shape).
  const auto s = rheology::flow_curve(p.steady, 0.56, 400);
  bool decreasing = false;
  for (std::size_t i = 1; i < s.size(); ++i) {
    ASSERT_GT(s[i].shear_stress, s[i - 1].shear_stress);
    decreasing = decreasing || s[i].shear_rate < s[i - 1].shear_rate;
  }
  EXPECT_TRUE(decreasing);
  // phi = 0.60 > phi_c with Delta = 1: gamma_dot -> 0 at finite stress as f -> f_jam (shear jamming).
  const auto j = rheology::flow_curve(p.steady, 0.60, 400);
  EXPECT_LT(j.back().shear_rate, 1e-12 * j[j.size() / 2].shear_rate);
  EXPECT_TRUE(std::isfinite(j.back().shear_stress));
  EXPECT_LT(j.back().shear_stress, 10.0);
  EXPECT_FALSE(rheology::shear_rate_dst(p.steady, 0.60).has_value());
}

TEST(FlowCurve, BrownianDecayRateGivesASteadyStateToo) {
  auto p = rheology::load_preset("hermes2016");
  p.steady.xi_dot_eps = 3.0;  // [1/s]
  const auto& fit = paper::fits().back();
  for (double phi : {0.40, 0.47}) {
    const double fm = paper::f_m(fit, phi);
    for (const auto& r : rheology::flow_curve(p.steady, phi, 100)) {
      const double H = std::pow(r.granular_shear_stress / fit.tau_star, 1.5);
      const double S = 1.0 + (r.granular_shear_stress / paper::eta_B(fit, phi) + 3.0) / r.shear_rate;
      ASSERT_LE(rel(r.f, H * fm / (H + S)), 1e-10);
    }
  }
  // Structure decay costs stress: at the same f the shear rate is higher than without it.
  auto q = p;
  q.steady.xi_dot_eps = 0.0;
  EXPECT_GT(rheology::steady_point(p.steady, 0.40, 0.5, 0.5).shear_rate,
            rheology::steady_point(q.steady, 0.40, 0.5, 0.5).shear_rate);
}

TEST(FlowCurve, PhiOutsideTheSteadyRangeIsRejected) {
  const auto p = rheology::load_preset("hermes2016");
  EXPECT_THROW(rheology::flow_curve(p.steady, 0.0, 10), InputError);
  EXPECT_THROW(rheology::flow_curve(p.steady, -0.1, 10), InputError);
  EXPECT_THROW(rheology::flow_curve(p.steady, 0.535, 10), InputError);
  EXPECT_THROW(rheology::flow_curve(p.steady, NAN, 10), InputError);
}

// The fastest steady shear (sup of gamma_dot over the flow curve) against a brute-force scan of
// the closed-form E11 curve written out in paper_tables.hpp: the lower branch's turning point
// where the curve is S-shaped, the E14 DST rate where the upper branch rises to it, no bound for
// CST (phi < phi_c).
TEST(FlowCurve, FastestSteadyShearIsTheSupremumOfTheClosedFormCurve) {
  int humps = 0, asymptotes = 0;
  for (const auto& fit : paper::fits()) {
    if (fit.terms.empty() || fit.Delta != 0.0) continue;  // E11 closed form and E14 need finite eta_B, Delta = 0
    const auto p = rheology::load_preset(fit.name);
    for (double s : {0.05, 0.3, 0.6, 0.9}) {
      const double phi = fit.phi_c + s * (fit.phi_j - fit.phi_c);
      SCOPED_TRACE(fit.name + " phi=" + std::to_string(phi));
      const double fu = paper::f_m(fit, phi);  // Delta = 0: f_u = f_m (phi_m(f_m) = phi)
      double scan = 0.0, f_at = 0.0;
      constexpr int n = 100000;
      for (int k = 1; k < n; ++k) {
        const double f = fu * k / n;
        const double g = paper::gamma_dot_of_f(fit, phi, f);
        if (g > scan) {
          scan = g;
          f_at = f;
        }
      }
      const double dst = paper::gamma_dot_dst(fit, phi);
      const auto lim = rheology::fastest_steady_shear(p.steady, phi);
      ASSERT_TRUE(lim.has_value());
      if (f_at < fu * (1.0 - 1e-3) && scan > dst) {  // an interior maximum: S-shaped curve
        ++humps;
        EXPECT_TRUE(lim->attained);
        EXPECT_LT(rel(lim->shear_rate, scan), 1e-6);
        EXPECT_NEAR(lim->f, f_at, 1e-3 * fu);
        EXPECT_TRUE(std::isfinite(lim->shear_stress));
      } else {  // rising to the DST asymptote
        ++asymptotes;
        EXPECT_FALSE(lim->attained);
        EXPECT_LT(rel(lim->shear_rate, dst), 1e-12);
        EXPECT_TRUE(std::isinf(lim->shear_stress));
      }
      EXPECT_GE(lim->shear_rate, dst * (1.0 - 1e-12));  // the sup is never below the asymptote
    }
    // CST: the flow curve has no upper bound in gamma_dot.
    EXPECT_FALSE(rheology::fastest_steady_shear(p.steady, 0.9 * fit.phi_c).has_value());
  }
  EXPECT_GT(humps, 0);
  EXPECT_GT(asymptotes, 0);
  EXPECT_EQ(humps + asymptotes, 24);
}

// Shear jamming (Delta = 1, the Singh sets, phi > phi_c): the curve ends at f_jam with gamma_dot
// -> 0, so the fastest steady shear is an attained peak (brute-force scan of E11 up to f_jam).
TEST(FlowCurve, FastestSteadyShearOfShearJammingSets) {
  int checked = 0;
  for (const auto& fit : paper::fits()) {
    if (fit.Delta != 1.0) continue;
    const auto p = rheology::load_preset(fit.name);
    for (double s : {0.2, 0.6}) {
      const double phi = fit.phi_c + s * (fit.phi_j - fit.phi_c);
      SCOPED_TRACE(fit.name + " phi=" + std::to_string(phi));
      const double f_jam = (fit.phi_j - phi) / (fit.phi_j - fit.phi_c);
      ASSERT_LT(f_jam, paper::f_m(fit, phi));
      double scan = 0.0;
      for (int k = 1; k < 100000; ++k) scan = std::max(scan, paper::gamma_dot_of_f(fit, phi, f_jam * k / 100000.0));
      const auto lim = rheology::fastest_steady_shear(p.steady, phi);
      ASSERT_TRUE(lim.has_value());
      EXPECT_TRUE(lim->attained);
      EXPECT_LT(rel(lim->shear_rate, scan), 1e-6);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4);
}

// S1 (scenes.md): hermes2016 at the annular cell's phi = 0.505 with its eta_0 = 10 mPa s. The
// curve is S-shaped: its lower branch turns (brute-force scan of the closed form) above the DST
// rate, 0.255 1/s by hand from E14.
TEST(FlowCurve, FastestSteadyShearOfTheAnnularCell) {
  auto p = rheology::load_preset("hermes2016");
  p.steady.eta_0 = 0.010;
  paper::Fit fit = paper::fits().back();
  ASSERT_EQ(fit.name, "hermes2016");
  fit.eta_0 = 0.010;
  const double phi = 0.505;
  const double eta_B = 1.0 / (1.86e4 * std::pow(0.535 - phi, 4) + 9.3e-3 * std::pow(0.535 - phi, 0.1));
  const double dst =
      5.35 / 0.010 * std::pow(2 * 1.19 * std::pow(eta_B / 0.010 * 0.8 * phi / (0.535 - phi), 2), -1.0 / 3.0);
  EXPECT_NEAR(dst, 0.255, 0.001);
  double scan = 0.0;
  const double fu = (phi - 0.535) / (0.436 - 0.535);
  for (int k = 1; k < 100000; ++k) scan = std::max(scan, paper::gamma_dot_of_f(fit, phi, fu * k / 100000.0));
  const auto lim = rheology::fastest_steady_shear(p.steady, phi);
  ASSERT_TRUE(lim.has_value());
  EXPECT_TRUE(lim->attained);
  EXPECT_LT(rel(lim->shear_rate, scan), 1e-6);
  EXPECT_GT(lim->shear_rate, 1.3 * dst);
}
