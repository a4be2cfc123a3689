// The granular law's scalar reference: one point at a time (update, advance, and the return map
// that advance_batch also calls where its lane solves fail), with the point kernels and the end
// of step (finish) of granular_kernels.hpp. The batched lanes are in granular_batch.cpp.
// Algorithm: docs/granular.md.
#include "oobleck/material/granular.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/granular_kernels.hpp"
#include "oobleck/numerics/vector_math.hpp"
#include "oobleck/rheology/f_max.hpp"

namespace oobleck::material {

using namespace granular_kernels;

const char* regime_name(GranularRegime r) {
  switch (r) {
    case GranularRegime::kElastic: return "elastic";
    case GranularRegime::kSeparated: return "separated";
    case GranularRegime::kShear: return "shear";
    case GranularRegime::kShearCompaction: return "shear+compaction";
    case GranularRegime::kCompaction: return "compaction";
  }
  return "unknown";
}

GranularLaw::GranularLaw(const rheology::Preset& preset, GranularOptions options)
    : steady_(preset.steady), granular_(preset.granular), options_(options) {
  if (granular_.K_4 != 0.0) {
    throw InputError(
        fmt::format("{}: key 'granular.K_4' = {}: the granular return map supports only K_4 = 0 (the value of every "
                    "paper preset; see docs/granular.md)",
                    preset.file.empty() ? preset.name : preset.file, granular_.K_4));
  }
  if (!(options_.rel_tol > 0.0 && options_.rel_tol < 1e-3) || options_.max_iter < 5) {
    throw InputError(fmt::format("granular law options: rel_tol = {} must lie in (0, 1e-3) and max_iter = {} >= 5",
                                 options_.rel_tol, options_.max_iter));
  }
  eta_0_ = steady_.eta_0;
  G_ = granular_.G;
  K_ = granular_.K;
  mu_1_ = steady_.mu_c;
  mu_2_ = granular_.mu_2 < 0.0 ? steady_.mu_c : granular_.mu_2;  // mu_2 < 0 means mu_2 = mu_c
  b_ = granular_.b;
  K_3_ = granular_.K_3;
  K_0_ = granular_.K_0;
  d2_rho_s_ = granular_.d * granular_.d * granular_.rho_s;
  tau_star_ = steady_.tau_star;
  xi_dot_eps_ = steady_.xi_dot_eps;
  phi_c_ = steady_.phi_c;
  phi_j_ = steady_.phi_j;
  a_0_ = steady_.a_0;
  a_inf_ = steady_.a_inf;
  for (const rheology::EtaBTerm& t : steady_.eta_B_terms) {
    const double r = std::nearbyint(t.alpha);
    // (a whole alpha < 0, which validation rejects, gives 1 as before: no multiplication)
    eta_B_int_alpha_.push_back(r == t.alpha && r <= 8.0 ? static_cast<int>(std::max(r, 0.0)) : kNonInteger);
  }
}

double GranularLaw::mu_q(double I_m) const {
  // E20 without the viscous term: mu_1 + (mu_2 - mu_1)/(1 + b/I_m) = mu_1 + (mu_2 - mu_1) I_m/(I_m + b).
  if (b_ == 0.0) return mu_2_;  // limit I_m -> 0+ as well
  return mu_1_ + (mu_2_ - mu_1_) * I_m / (I_m + b_);
}

// ---- The return map (E17–E23), one function per regime: elastic trial, f_1 shear yield (E21),
// separation (E22), the f_1 + f_3 closed form (E21, E23), the p_tr <= 0 fast path and the nested
// solve in gamma_dot that backs up both Newton solves (docs/granular.md). Inlined into return_map
// (the solve in gamma_dot's residual stays a call, as the lambda it was), so that the compiled
// code, and its arithmetic operation by operation, is that of the single function it was.
namespace {

#if defined(__GNUC__)
#define OOBLECK_RM_INLINE [[gnu::always_inline]] inline
#else
#define OOBLECK_RM_INLINE inline
#endif

/// What every regime of the return map needs: E1, E2 at the structure f it is called with, the
/// trial (p_tr, tau_tr) and the constants derived from them.
struct MapSetup {
  const GranularLaw& law;  // mu_q: E20 without the viscous term
  F1Consts c;              // K dt, G dt, 2 eta_0, d^2 rho_s, K_3, mu_1, mu_2, b
  double tol;              // options.rel_tol
  int cap;                 // options.max_iter
  double phi, phi_m, a;    // phi and E1, E2 (f_n when staggered)
  double visc;             // E20 viscous friction times p: visc * gamma_dot/I_m
  double p_tr, tau_tr;
  double u_eq;   // I_m at which beta = 0
  double g_max;  // gamma_dot^p at which tau_bar = 0 (radial return)
  double dil;    // d p/d gamma_dot at p -> 0 (I_m -> infinity: beta -> K_3 phi)
};

/// The return map's result while it is built (ReturnMap, private to GranularLaw, plus I_m = u).
struct MapResult {
  double tau = 0.0, p = 0.0, g = 0.0, u = 0.0, xi1 = 0.0, xi2 = 0.0;
  GranularRegime regime = GranularRegime::kElastic;
  bool converged = true;
  int iterations = 0;
  double residual = 0.0;
};

// E18 dilation as a function of I_m (u) and its derivative.
OOBLECK_RM_INLINE double beta_of(const MapSetup& s, double u) { return s.c.K_3 * (s.phi - s.phi_m / (1.0 + s.a * u)); }
OOBLECK_RM_INLINE double dbeta_of(const MapSetup& s, double u) {
  const double q = 1.0 + s.a * u;
  return s.c.K_3 * s.phi_m * s.a / (q * q);
}
// E19 I_m from (gamma_dot, p): I_m^2 = Q(gamma_dot)/p with Q = gamma_dot (gamma_dot d^2 rho_s + 2 eta_0).
OOBLECK_RM_INLINE double Q_of(const MapSetup& s, double g) { return g * (g * s.c.d2_rho_s + s.c.two_eta); }

// Friction side of E21 at (gamma_dot, p, I_m): max((mu_p + beta) p, 0), with E20 written as
// mu_p p = mu_q(I_m) p + (5/2)(phi/a) eta_0 gamma_dot/I_m.
OOBLECK_RM_INLINE double friction(const MapSetup& s, double gg, double pp, double uu) {
  return friction_of(s.c, s.phi, s.phi_m, s.a, s.visc, gg, pp, uu);
}

/// The pressure balance (E17 with E18, E19) for fixed gamma_dot: p, I_m and their derivatives in gamma_dot.
struct Inner {
  double p, u, du, dp;  // p, I_m and their derivatives in gamma_dot
  bool ok;
};

// Inner solve of the general shear solve in gamma_dot (used for p_tr <= 0 and as the fallback of
// the fast paths). For fixed gamma_dot the pressure balance, written in u = I_m with p =
// Q(gamma_dot)/u^2, h(u) = Q/u^2 - p_tr - K dt gamma_dot beta(u), is strictly decreasing and convex
// in u (Q/u^2 and -beta(u) are). Newton started left of the root (h >= 0) therefore increases
// monotonically to it without overshooting. Start: the larger of u at p = p_tr + K dt K_3 phi
// gamma_dot (the largest possible p) and, for p_tr < 0, the u at which p_tr + K dt gamma_dot beta(u)
// = 0 (p -> 0+); both have h >= 0. Also returns du/dgamma_dot (implicit derivative) for the outer
// Newton.
OOBLECK_RM_INLINE Inner pressure_balance(const MapSetup& s, double gg, int& iterations) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double p_tr = s.p_tr, Kdt = s.c.Kdt;
  Inner in{0.0, kInf, 0.0, 0.0, true};
  if (!(gg > 0.0)) {
    in.u = 0.0;
    in.p = std::max(p_tr, 0.0);
    return in;
  }
  const double S = p_tr + s.dil * gg;  // p at beta = K_3 phi (u -> infinity): the largest possible p
  if (S <= 0.0) return in;             // no contact pressure even with full dilatancy
  const double Q = Q_of(s, gg), ck = Kdt * gg;
  double x = std::sqrt(Q / S);
  if (p_tr < 0.0) {
    const double u0 = (s.phi_m * ck * s.c.K_3 / S - 1.0) / s.a;  // beta(u0) = -p_tr/(K dt gamma_dot)
    if (u0 > x) x = u0;
  }
  in.ok = false;
  for (int k = 1; k <= s.cap; ++k) {
    ++iterations;
    const double hv = Q / (x * x) - p_tr - ck * beta_of(s, x);
    if (hv <= 0.0) {  // at the root (or past it by round-off)
      in.ok = true;
      break;
    }
    const double dh = -2.0 * Q / (x * x * x) - ck * dbeta_of(s, x);
    const double step = -hv / dh;
    x += step;
    if (!(step > 0.25 * s.tol * x)) {
      in.ok = std::isfinite(x);
      break;
    }
  }
  in.u = x;
  in.p = Q / (x * x);
  // implicit derivatives: h(u(g), g) = 0
  const double Qp = 2.0 * gg * s.c.d2_rho_s + s.c.two_eta;
  const double hu = -2.0 * in.p / x - ck * dbeta_of(s, x);
  const double hg = Qp / (x * x) - Kdt * beta_of(s, x);
  in.du = hu < 0.0 ? -hg / hu : 0.0;
  in.dp = Qp / (x * x) - 2.0 * in.p / x * in.du;
  return in;
}

/// The outer residual of the solve in gamma_dot: E21 R(gamma_dot) = tau_tr - G dt gamma_dot - friction
/// (E20 with the E18 beta) at the pressure balance's (p, I_m), and dR/dgamma_dot. Out of line, as
/// GCC compiled the lambda it was (a fallback path; return_map stays the size it was).
#if defined(__GNUC__)
[[gnu::noinline]]
#endif
double
shear_residual_g(const MapSetup& s, double gg, double& dR, bool& all_ok, double& pp, double& uu, int& iterations) {
  const Inner in = pressure_balance(s, gg, iterations);
  all_ok = all_ok && in.ok;
  pp = in.p;
  uu = in.u;
  const double b = s.c.b, mu_1 = s.c.mu_1, mu_2 = s.c.mu_2, visc = s.visc;
  double F = 0.0, dF = 0.0;
  if (in.p > 0.0 && in.u > 0.0 && std::isfinite(in.u)) {
    const double be = beta_of(s, in.u), dbe = dbeta_of(s, in.u);
    const double mq = s.law.mu_q(in.u);
    const double dmq = b == 0.0 ? 0.0 : (mu_2 - mu_1) * b / ((in.u + b) * (in.u + b));
    F = (mq + be) * in.p + visc * gg / in.u;
    dF = (dmq + dbe) * in.du * in.p + (mq + be) * in.dp + visc / in.u - visc * gg / (in.u * in.u) * in.du;
    if (F < 0.0) F = dF = 0.0;
  }
  dR = -s.c.Gdt - dF;
  return s.tau_tr - s.c.Gdt * gg - F;
}

/// E21 shear yield solved in gamma_dot (the nested solve): R(gamma_dot) on [glo, ghi] with
/// R(glo) > 0 >= R(ghi): Newton with the analytic dR/dgamma_dot, started at ghi and kept inside the
/// shrinking bracket (bisection when a step leaves it). Sets g, p, u, residual, converged.
OOBLECK_RM_INLINE void solve_shear_in_g(const MapSetup& s, double glo, double ghi, MapResult& m) {
  const double tau_tr = s.tau_tr, tol = s.tol;
  int iterations = m.iterations;
  bool all_ok = true;
  double pp = 0.0, uu = 0.0;
  double gg = ghi, dR = 0.0;
  double R = shear_residual_g(s, gg, dR, all_ok, pp, uu, iterations);
  bool done = std::fabs(R) <= 1e-14 * tau_tr;
  for (int k = 1; k <= s.cap && !done; ++k) {
    ++iterations;
    if (R > 0.0)
      glo = gg;
    else
      ghi = gg;
    double next = dR < 0.0 ? gg - R / dR : -1.0;
    const bool newton = next > glo && next < ghi;
    if (!newton) next = 0.5 * (glo + ghi);
    done = (newton && std::fabs(next - gg) <= tol * gg) || (ghi - glo) <= tol * ghi;
    gg = next;
    R = shear_residual_g(s, gg, dR, all_ok, pp, uu, iterations);
    done = done || std::fabs(R) <= 1e-14 * tau_tr;
  }
  m.iterations = iterations;
  m.g = gg;
  m.p = pp;
  m.u = uu;
  m.residual = std::fabs(R) / tau_tr;
  m.converged = all_ok && m.residual <= 1e-9;
}

/// E21 shear yield alone (f_1, beta >= 0, xi_dot_2 = 0) for p_tr > 0: the root of R(u) on
/// [u_eq, u_hi] in u = I_m (f1_value: R(u) decreasing, docs/granular.md), the nested solve in
/// gamma_dot where u is ill-conditioned; tau_bar from the friction side of E21.
OOBLECK_RM_INLINE void shear_yield(const MapSetup& s, double mu0, const F1Value& e_lo, MapResult& m) {
  const F1Consts& c = s.c;
  const double phi = s.phi, phi_m = s.phi_m, a = s.a, visc = s.visc, p_tr = s.p_tr, tau_tr = s.tau_tr;
  double lo = s.u_eq, hi, x;
  f1_start(c, mu0, phi, phi_m, a, visc, p_tr, tau_tr, s.u_eq, s.g_max, e_lo, x, hi);
  F1Value e{};
  bool converged = false;
  int iterations;
  for (iterations = 1; iterations <= s.cap; ++iterations) {
    f1_value(c, phi, phi_m, a, visc, p_tr, tau_tr, x, e);
    const double dR = f1_slope(c, phi_m, a, visc, p_tr, x, e);
    const int st = f1_step(e.R, dR, tau_tr, s.tol, x, lo, hi);
    if (st == 1) {
      converged = true;
      break;
    }
    if (st == 2) {
      f1_value(c, phi, phi_m, a, visc, p_tr, tau_tr, x, e);
      converged = true;
      break;
    }
  }
  m.iterations = iterations;
  m.converged = converged;
  m.residual = std::fabs(e.R) / tau_tr;
  if (converged && m.residual <= 1e-10) {
    m.u = x;
    m.g = e.g;
    m.p = e.p;
  } else {
    // u is ill-conditioned here (gamma_dot(u) steep where dilatancy dominates p_tr): solve in gamma_dot
    solve_shear_in_g(s, e_lo.g, s.g_max, m);
  }
  // tau_bar from the friction side of E21: accurate even when G dt g >> tau_bar
  m.tau = std::min(friction(s, m.g, m.p, m.u), tau_tr);
  m.regime = GranularRegime::kShear;
}

/// Compressive trial (p_tr > 0): elastic, E21 shear yield (f_1), or shear with compaction (f_1 + f_3,
/// E21 and E23 with K_4 = 0, closed form).
OOBLECK_RM_INLINE void compressive_trial(const MapSetup& s, MapResult& m) {
  const double mu0 = s.law.mu_q(0.0);
  const bool f3_trial_active = s.phi < s.phi_m;                                        // E23: g(phi) p_tr > 0
  const double f1_trial = s.tau_tr - std::max((mu0 + beta_of(s, 0.0)) * s.p_tr, 0.0);  // E21 at gamma_dot = 0
  if (!f3_trial_active && f1_trial <= 0.0) {
    m.regime = GranularRegime::kElastic;
    m.tau = s.tau_tr;
    m.p = s.p_tr;
    return;
  }
  // Fast path, parametrised by u = I_m >= u_eq (beta >= 0, xi_dot_2 = 0): f1_value, R(u)
  // decreasing in u (docs/granular.md). Its value at u_eq decides between f_1 + f_3 and f_1.
  // (compressive(): that value and the f_1 + f_3 closed form below)
  Compressive cm;
  compressive(s.c, s.phi, s.phi_m, s.a, s.visc, s.p_tr, s.tau_tr, s.u_eq, cm.e_lo, cm.g, cm.p, cm.tau, cm.xi2);
  if (cm.e_lo.R <= 0.0 && s.u_eq > 0.0) {
    // f_1 + f_3 (E21, E23 with K_4 = 0): beta = 0, I_m = u_eq; closed form
    m.g = cm.g;
    m.p = cm.p;
    m.tau = cm.tau;
    m.u = s.u_eq;
    m.xi2 = cm.xi2;
    m.regime = m.g > 0.0 ? GranularRegime::kShearCompaction : GranularRegime::kCompaction;
  } else {
    shear_yield(s, mu0, cm.e_lo, m);  // f_1 only
  }
}

/// Fast path of the p_tr <= 0 flow with p > 0 created by dilatancy (a loose bed that dilates
/// slightly, or a stress-free dense state that is sheared): Newton on the pair (gamma_dot, u = I_m)
/// for the pressure balance h = Q(gamma_dot)/u^2 - p_tr - K dt gamma_dot beta(u) = 0 (E17–E19) and
/// E21 R = tau_tr - G dt gamma_dot - (mu_q(u) + beta(u)) p - visc gamma_dot/u = 0 with p = Q/u^2,
/// started at gamma_dot_max and the inner start of the nested solve (h >= 0). Accepted (true; g, u,
/// p, residual set) only when the last Newton step is below rel_tol in both unknowns and both
/// residuals are at round-off level; otherwise (far from the root, ill-conditioned) false, for the
/// bracketed nested solve in gamma_dot.
template <int kTensionIterations>
OOBLECK_RM_INLINE bool tension_fast_path(const MapSetup& s, MapResult& m) {
  const F1Consts& c = s.c;
  const double phi = s.phi, phi_m = s.phi_m, a = s.a, visc = s.visc, p_tr = s.p_tr, tau_tr = s.tau_tr;
  bool fast = false;
  double gg = s.g_max, uu = tension_start(c, phi_m, a, p_tr, s.dil, s.g_max);
  bool step_ok = false;
  for (int k = 1; k <= kTensionIterations; ++k) {
    ++m.iterations;
    double pp, Rr;
    const double st = tension_step(c, phi, phi_m, a, visc, p_tr, tau_tr, s.g_max, s.tol, gg, uu, pp, Rr);
    if (st == 1.0) {
      fast = true;
      m.g = gg;
      m.u = uu;
      m.p = pp;
      m.residual = std::fabs(Rr) / tau_tr;
      break;
    }
    if (st == 2.0) break;
    if (st == 3.0) {
      step_ok = true;
      break;
    }
  }
  double pp = 0.0, res = 0.0;
  if (step_ok && !fast) {
    if (tension_accept(c, phi, phi_m, a, visc, p_tr, tau_tr, gg, uu, pp, res)) {
      fast = true;
      m.g = gg;
      m.u = uu;
      m.p = pp;
      m.residual = res;
    }
  }
  return fast;
}

/// Tensile or zero trial pressure (p_tr <= 0): separated (E22, f_2 active) unless shear dilatancy
/// builds pressure, then E21 shear yield at p > 0 (fast path, else the nested solve in gamma_dot).
template <int kTensionIterations>
OOBLECK_RM_INLINE void tensile_trial(const MapSetup& s, MapResult& m) {
  const double p_tr = s.p_tr, tau_tr = s.tau_tr;
  if (!(tau_tr > 0.0) || !(p_tr + s.dil * s.g_max > 0.0)) {
    m.regime = (tau_tr > 0.0 || p_tr < 0.0) ? GranularRegime::kSeparated : GranularRegime::kElastic;
    m.g = tau_tr > 0.0 ? s.g_max : 0.0;
    m.tau = 0.0;
    m.p = 0.0;
    m.xi1 = separated_xi1(s.c, s.phi, p_tr, m.g);  // E22
    return;
  }
  if (!tension_fast_path<kTensionIterations>(s, m)) solve_shear_in_g(s, std::max(-p_tr / s.dil, 0.0), s.g_max, m);
  m.tau = std::min(friction(s, m.g, m.p, m.u), tau_tr);
  m.regime = m.p > 0.0 ? GranularRegime::kShear : GranularRegime::kSeparated;
  if (m.p <= 0.0) m.xi1 = separated_xi1(s.c, s.phi, p_tr, m.g);
}

#undef OOBLECK_RM_INLINE

}  // namespace

GranularLaw::ReturnMap GranularLaw::return_map(double f, double phi, double eta_0, double dt, double p_tr,
                                               double tau_tr) const {
  // ---- E1, E2 with the structure used by this return map (f_n when staggered) ----
  const double phi_m = phi_j_ + (phi_c_ - phi_j_) * f;  // E1
  const double a = a_0_ + (a_inf_ - a_0_) * f;          // E2
  const double Gdt = G_ * dt;
  const double Kdt = K_ * dt;
  const double visc = 2.5 * phi / a * eta_0;  // E20 viscous friction times p: visc * gamma_dot/I_m
  const double two_eta = 2.0 * eta_0;
  const double u_eq = phi < phi_m ? (phi_m - phi) / (a * phi) : 0.0;  // I_m at which beta = 0 (E18)
  const double g_max = tau_tr / Gdt;                                  // gamma_dot^p at which tau_bar = 0
  const double dil = Kdt * K_3_ * phi;  // d p/d gamma_dot at p -> 0 (I_m -> infinity: beta -> K_3 phi)
  const MapSetup s{*this,
                   F1Consts{Kdt, Gdt, two_eta, d2_rho_s_, K_3_, mu_1_, mu_2_, b_},
                   options_.rel_tol,
                   options_.max_iter,
                   phi,
                   phi_m,
                   a,
                   visc,
                   p_tr,
                   tau_tr,
                   u_eq,
                   g_max,
                   dil};
  MapResult m;
  if (p_tr > 0.0) {
    compressive_trial(s, m);  // elastic, E21 (f_1), or E21 + E23 (f_1 + f_3)
  } else {
    tensile_trial<kTensionIterations>(s, m);  // E22 (f_2), or E21 at a pressure built by dilatancy
  }
  ReturnMap r;
  r.tau = m.tau;
  r.p = m.p;
  r.g = m.g;
  r.xi1 = m.xi1;
  r.xi2 = m.xi2;
  r.residual = m.residual;
  r.regime = m.regime;
  r.converged = m.converged;
  r.iterations = m.iterations;
  return r;
}

GranularUpdate GranularLaw::update(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                                   double phi, double eta_0) const {
  return update_impl<true>(state, D, W, dt, phi, eta_0);
}

GranularStep GranularLaw::advance(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                                  double phi) const {
  const GranularUpdate u = update_impl<false>(state, D, W, dt, phi, eta_0_);
  return GranularStep{u.regime, u.ok(), u.gamma_dot_p};
}

// Inlined into update() and advance(), so that advance() drops the stores of what it does not return.
template <bool kDiagnostics>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline GranularUpdate
GranularLaw::update_impl(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                         double phi, double eta_0) const {
  GranularUpdate out;
  Trial t;
  if (!begin(state, D, W, dt, phi, eta_0, t, out)) return out;
  finish<kDiagnostics>(state, t, return_map(state.f, phi, eta_0, dt, t.p_tr, t.tau_tr), dt, phi, eta_0, out);
  return out;
}

#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline bool
GranularLaw::begin(const GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                   double phi, double eta_0, Trial& t, GranularUpdate& out) const {
  // ---- input checks (never throw in the hot loop; report instead) ----
  const T9 S = to9(state.sigma), D9 = to9(D), W9 = to9(W);
  if (!step_inputs_valid(dt, eta_0) || !point_inputs_valid(phi, state.f, S, D9, W9)) {
    out.f_old = state.f;
    out.finite = false;
    out.converged = false;
    out.message = "invalid input: need dt > 0, 0 < phi < 1, eta_0 > 0, f in [0, 1] and finite sigma, D, W";
    return false;
  }
  // ---- E16: elastic trial (D^p = 0), explicit Jaumann rotation with sigma_n ----
  T9 s;
  elastic_trial(S, D9, W9, dt, G_, K_, s, t.p_tr, t.tau_tr);
  for (int k = 0; k < 9; ++k) t.s.data()[k] = s.v[k];

  // ---- E24 ingredients that depend on phi only: f_m (E9), 1/eta_B (E8) ----
  t.fm = rheology::f_m(steady_, phi);
  t.inv_eta_B = inv_eta_B(phi);
  return true;
}

double GranularLaw::inv_eta_B(double phi) const {
  double x[numerics::kMathBlock], r[numerics::kMathBlock];
  for (double& v : x) v = phi;
  inv_eta_B_block(x, r);
  return r[0];
}

void GranularLaw::inv_eta_B_block(const double* phi, double* r) const {
  // E8: 1/eta_B = sum_i phi_i (phi_j - phi)^alpha_i, summed in the order of the terms; whole
  // alpha <= 8 by multiplication, the others as exp(alpha log(phi_j - phi)).
  constexpr int N = numerics::kMathBlock;
  double gap[N], lg[N], arg[N], e[N];
  for (int j = 0; j < N; ++j) {
    const double g = phi_j_ - phi[j];
    gap[j] = g > 0.0 ? g : 1.0;  // (a finite stand-in where the result is 0)
    r[j] = 0.0;
  }
  if (std::find(eta_B_int_alpha_.begin(), eta_B_int_alpha_.end(), kNonInteger) != eta_B_int_alpha_.end())
    numerics::log_block(gap, lg);
  for (std::size_t t = 0; t < steady_.eta_B_terms.size(); ++t) {
    const rheology::EtaBTerm& term = steady_.eta_B_terms[t];
    if (const int k = eta_B_int_alpha_[t]; k != kNonInteger) {
      for (int j = 0; j < N; ++j) {
        double y = 1.0;
        for (int q = 0; q < k; ++q) y *= gap[j];
        r[j] += term.phi_i * y;
      }
    } else {
      for (int j = 0; j < N; ++j) arg[j] = term.alpha * lg[j];
      numerics::exp_block(arg, e);
      for (int j = 0; j < N; ++j) r[j] += term.phi_i * e[j];
    }
  }
  for (int j = 0; j < N; ++j)
    if (!(phi_j_ - phi[j] > 0.0)) r[j] = 0.0;
}

std::string GranularLaw::describe(const GranularUpdate& u, const GranularState& before, const Eigen::Matrix3d& D,
                                  const Eigen::Matrix3d& W, double dt, double phi) const {
  auto mat = [](const Eigen::Matrix3d& m) {
    return fmt::format("[[{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}]]",
                       m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2));
  };
  return fmt::format(
      "granular law (E16-E24, preset parameters: G = {} Pa, K = {} Pa, K_0 = {}, d = {} m, rho_s = {} kg/m^3): {}; "
      "regime {}, iterations {}, relative residual {:.3g}; state before: f = {:.17g}, sigma = {} Pa; "
      "inputs: phi = {:.17g}, dt = {:.17g} s, D = {} 1/s, W = {} 1/s; trial tau_bar = {:.6g} Pa, p = {:.6g} Pa; "
      "result tau_bar = {:.6g} Pa, p = {:.6g} Pa, gamma_dot_p = {:.6g} 1/s",
      G_, K_, K_0_, granular_.d, granular_.rho_s, u.message ? u.message : "ok", regime_name(u.regime), u.iterations,
      u.residual, before.f, mat(before.sigma), phi, dt, mat(D), mat(W), u.tau_trial, u.p_trial, u.tau_bar, u.p,
      u.gamma_dot_p);
}

void GranularLaw::require_ok(const GranularUpdate& u, const GranularState& before, const Eigen::Matrix3d& D,
                             const Eigen::Matrix3d& W, double dt, double phi) const {
  if (!u.ok()) throw NumericalError(describe(u, before, D, W, dt, phi));
}

}  // namespace oobleck::material
