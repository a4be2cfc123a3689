#pragma once
// The granular law's point kernels (E16–E24): the inline, branch-free functions of one material
// point that both forms of GranularLaw use, the scalar reference (granular.cpp: update, advance,
// return_map) and the batched lanes (granular_batch.cpp: advance_batch, which runs them across
// points in vector lanes), and GranularLaw::finish, the end of a point's step, which both inline. Because both call
// these same functions, in the same order and compiled with the same flags (CMakeLists.txt: no FMA contraction, no
// errno, no traps), advance_batch gives the results of advance() bit for bit; the contract is the test
// GranularBatchContract (tests/material/test_granular_batch_contract.cpp). Algorithm: docs/granular.md.
//
// Internal to those two files (not part of the law's interface).
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "oobleck/material/granular.hpp"

namespace oobleck::material::granular_kernels {

/// A 3x3 tensor as nine numbers, column-major (Eigen's order), for the functions below that also
/// run in lanes across points: GCC 12 vectorises an `omp simd` loop that passes these by reference
/// to always_inline functions, but not one that passes pointers to local arrays or calls a function
/// the early inliner leaves out of line (the loop's locals then become per-lane arrays).
struct T9 {
  double v[9];
};
inline T9 to9(const Eigen::Matrix3d& m) {
  T9 t;
  for (int k = 0; k < 9; ++k) t.v[k] = m.data()[k];
  return t;
}

/// All nine entries finite, without branches: x * 0 is NaN exactly when x is infinite or NaN.
inline bool finite9(const T9& x) {
  double z = 0.0;
  for (int i = 0; i < 9; ++i) z += x.v[i] * 0.0;
  return z == 0.0;
}
inline bool finite3(const Eigen::Matrix3d& m) { return finite9(to9(m)); }

/// The law's input checks (GranularLaw::update): those of the step, dt > 0 and eta_0 > 0 finite, and
/// those of a point, 0 < phi < 1, f in [0, 1], finite sigma, D, W (branch-free, so that the lanes of
/// advance_batch vectorise).
inline bool step_inputs_valid(double dt, double eta_0) {
  return dt > 0.0 && std::isfinite(dt) && eta_0 > 0.0 && std::isfinite(eta_0);
}
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline bool
point_inputs_valid(double phi, double f, const T9& S, const T9& D, const T9& W) {
  return (phi > 0.0) & (phi < 1.0) & (f >= 0.0) & (f <= 1.0) & finite9(S) & finite9(D) & finite9(W);
}

/// E16 trial sig + dt (2 G D + W sig - sig W) + dt (K - 2G/3) tr(D) 1, written out so that it
/// inlines and vectorises across points. Every sum is formed in the order of the Eigen 3.4
/// expression it replaces (the SSE2 lazy product sums rows 0-1 as (k0 + k1) + k2 and row 2 as
/// k0 + (k1 + k2); the trace is d00 + (d11 + d22)), so the result is the same bit for bit. (For
/// W = skew(L), with its zero diagonal, the order is moot.)
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
jaumann_trial(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& r) {
  const double two_G = 2.0 * G;
  auto at = [](const T9& m, int i, int j) { return m.v[i + 3 * j]; };
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      double ws, sw;
      if (i < 2) {
        ws = (at(W, i, 0) * at(S, 0, j) + at(W, i, 1) * at(S, 1, j)) + at(W, i, 2) * at(S, 2, j);
        sw = (at(S, i, 0) * at(W, 0, j) + at(S, i, 1) * at(W, 1, j)) + at(S, i, 2) * at(W, 2, j);
      } else {
        ws = at(W, i, 0) * at(S, 0, j) + (at(W, i, 1) * at(S, 1, j) + at(W, i, 2) * at(S, 2, j));
        sw = at(S, i, 0) * at(W, 0, j) + (at(S, i, 1) * at(W, 1, j) + at(S, i, 2) * at(W, 2, j));
      }
      r.v[i + 3 * j] = at(S, i, j) + dt * ((two_G * at(D, i, j) + ws) - sw);
    }
  }
  const double trD = D.v[0] + (D.v[4] + D.v[8]);
  const double vol = dt * (K - two_G / 3.0) * trD;
  for (int i = 0; i < 3; ++i) r.v[4 * i] += vol;
}

/// jaumann_trial for a point in plane motion: the xz and yz entries of S, D and W (T9 indices 2, 5,
/// 6, 7) are zero, D_zz = D.v[8] is any value (plane strain: 0). jaumann_trial's sums without
/// their zero products, in the same order: the in-plane entries and zz are the same values (a sum
/// with a zero product changes at most the sign of a zero), and the four out-of-plane entries are
/// +0.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
jaumann_trial_plane(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& r) {
  const double two_G = 2.0 * G;
  auto at = [](const T9& m, int i, int j) { return m.v[i + 3 * j]; };
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const double ws = at(W, i, 0) * at(S, 0, j) + at(W, i, 1) * at(S, 1, j);
      const double sw = at(S, i, 0) * at(W, 0, j) + at(S, i, 1) * at(W, 1, j);
      r.v[i + 3 * j] = at(S, i, j) + dt * ((two_G * at(D, i, j) + ws) - sw);
    }
  }
  r.v[2] = 0.0;
  r.v[5] = 0.0;
  r.v[6] = 0.0;
  r.v[7] = 0.0;
  r.v[8] = S.v[8] + dt * (two_G * D.v[8]);
  const double trD = D.v[0] + (D.v[4] + D.v[8]);
  const double vol = dt * (K - two_G / 3.0) * trD;
  r.v[0] += vol;
  r.v[4] += vol;
  r.v[8] += vol;
}

/// The E16 trial of one point: s = the deviator of the trial stress, p_tr = -tr/3 and
/// tau_tr = sqrt(|dev|^2/2). (Results through references: a returned T9 is copied as an aggregate
/// in the portable build, which stops the vectorisation.) The sums in the order of Eigen's trace() (d00 + (d11 + d22))
/// and squaredNorm() (SSE2 pairs summed as two lanes, then the ninth entry), which GCC's Eigen 3.4 uses for a Matrix3d
/// with or without AVX (with -ffp-contract=off): bit for bit as before.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
elastic_trial(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& s, double& p_tr,
              double& tau_tr) {
  jaumann_trial(S, D, W, dt, G, K, s);
  p_tr = -(s.v[0] + (s.v[4] + s.v[8])) / 3.0;
  for (int i = 0; i < 3; ++i) s.v[4 * i] += p_tr;  // dev sigma_tr
  double q[9];
  for (int k = 0; k < 9; ++k) q[k] = s.v[k] * s.v[k];
  const double sq = (((q[0] + q[2]) + (q[4] + q[6])) + ((q[1] + q[3]) + (q[5] + q[7]))) + q[8];
  tau_tr = std::sqrt(0.5 * sq);
}

/// elastic_trial for a point in plane motion (jaumann_trial_plane): |s|^2 without the four zero
/// squares, whose sums with them were exact.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
elastic_trial_plane(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& s, double& p_tr,
                    double& tau_tr) {
  jaumann_trial_plane(S, D, W, dt, G, K, s);
  p_tr = -(s.v[0] + (s.v[4] + s.v[8])) / 3.0;
  s.v[0] += p_tr;
  s.v[4] += p_tr;
  s.v[8] += p_tr;
  const double q0 = s.v[0] * s.v[0], q1 = s.v[1] * s.v[1], q3 = s.v[3] * s.v[3], q4 = s.v[4] * s.v[4];
  const double sq = ((q0 + q4) + (q1 + q3)) + s.v[8] * s.v[8];
  tau_tr = std::sqrt(0.5 * sq);
}

// ---- The f_1-only branch of the return map in u = I_m (docs/granular.md), shared by the scalar
// solve and the lanes of advance_batch so that both do the same arithmetic. Both sides of every
// select are computed (no division under a condition), so the lane loop vectorises.
struct F1Consts {
  double Kdt, Gdt, two_eta, d2_rho_s, K_3, mu_1, mu_2, b;
};
struct F1Value {
  double g, p, R, be, mq, disc;
};
/// The p_tr > 0 branch's value at u = u_eq (e_lo: decides between f_1 + f_3 and f_1) and the f_1 +
/// f_3 closed form (E21, E23 with K_4 = 0; beta = 0, I_m = u_eq).
struct Compressive {
  F1Value e_lo;
  double g, p, tau, xi2;
};

/// E20 mu_q(I_m) = mu_1 + (mu_2 - mu_1) I_m/(I_m + b) (GranularLaw::mu_q, mu_2 for b = 0) and its
/// derivative, without branches (both sides computed) so that the lane loops vectorise.
inline double f1_mu_q(const F1Consts& c, double uu) {
  const double mq_b = c.mu_1 + (c.mu_2 - c.mu_1) * uu / (uu + c.b);
  return c.b == 0.0 ? c.mu_2 : mq_b;
}
inline double f1_dmu_q(const F1Consts& c, double uu) {
  const double dmq_b = (c.mu_2 - c.mu_1) * c.b / ((uu + c.b) * (uu + c.b));
  return c.b == 0.0 ? 0.0 : dmq_b;
}

/// For given u the pressure balance p = p_tr + K dt beta(u) gamma_dot with p = Q(gamma_dot)/u^2 (E18,
/// E19) is a quadratic in gamma_dot with one positive root; R(u) = tau_tr - G dt gamma_dot - mu_p p
/// is the E21 residual, mu_p from E20.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
f1_value(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr, double tau_tr, double uu,
         F1Value& e) {
  e.be = c.K_3 * (phi - phi_m / (1.0 + a * uu));  // E18 beta
  const double A2 = c.d2_rho_s;
  const double B2 = c.two_eta - c.Kdt * e.be * uu * uu;
  const double C2 = p_tr * uu * uu;
  e.disc = std::sqrt(B2 * B2 + 4.0 * A2 * C2);
  // g_+ = 2 C2/(B2 + disc) for B2 >= 0, g_- = (disc - B2)/(2 A2) otherwise: the operands selected
  // before the one division (in the lanes both quotients were computed; the divider bounds them)
  const bool plus = B2 >= 0.0;
  e.g = (plus ? 2.0 * C2 : e.disc - B2) / (plus ? B2 + e.disc : 2.0 * A2);
  e.p = p_tr + c.Kdt * e.be * e.g;
  e.mq = f1_mu_q(c, uu);  // E20 mu_q
  // viscous friction term of E20 times p: (5/2) phi/a * I_v/I_m * p = visc * g/u
  const double g_over_u = e.g / uu;
  const double gv = uu > 0.0 ? g_over_u : 0.0;
  e.R = tau_tr - c.Gdt * e.g - (e.mq + e.be) * e.p - visc * gv;
}

/// dR/du at the value e (implicit derivatives of the quadratic's root).
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline double
f1_slope(const F1Consts& c, double phi_m, double a, double visc, double p_tr, double uu, const F1Value& e) {
  const double q = 1.0 + a * uu;
  const double be = e.be, dbe = c.K_3 * phi_m * a / (q * q);
  const double dB2 = -c.Kdt * (dbe * uu * uu + 2.0 * be * uu);
  const double dC2 = 2.0 * p_tr * uu;
  const double dg_d = (dC2 - dB2 * e.g) / e.disc;
  const double dg = e.disc > 0.0 ? dg_d : 0.0;
  const double dp = c.Kdt * (dbe * e.g + be * dg);
  const double dmq = f1_dmu_q(c, uu);
  const double dgv_u = dg / uu - e.g / (uu * uu);
  const double dgv = uu > 0.0 ? dgv_u : p_tr / c.two_eta;  // g ~ p_tr u^2/(2 eta_0) as u -> 0
  return -c.Gdt * dg - (dmq + dbe) * e.p - (e.mq + be) * dp - visc * dgv;
}

/// One Newton/bracketing step of the f_1 solve after the value R and slope dR at x (in the order of
/// the scalar loop): 0 = continue at x, 1 = converged at x (|R| small), 2 = step converged: x is the
/// new point, evaluate once more and stop.
inline int f1_step(double R, double dR, double tau_tr, double tol, double& x, double& lo, double& hi) {
  if (std::fabs(R) <= 1e-14 * tau_tr) return 1;
  if (R > 0.0)
    lo = x;
  else
    hi = x;
  double next = (dR < 0.0) ? x - R / dR : -1.0;
  const bool newton = next > lo && next < hi;
  if (!newton) next = (lo > 0.0 && hi > 4.0 * lo) ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
  const bool step_done = (newton && std::fabs(next - x) <= tol * x) || (hi - lo) <= tol * hi;
  x = next;
  return step_done ? 2 : 0;
}

/// Compressive: the value at u_eq and the f_1 + f_3 closed form, tau_tr - G dt g = mu_q p + visc g/u_eq
/// with p = Q(g)/u_eq^2, a quadratic A g^2 + B g - C = 0. Branch-free (computed where unused too),
/// so that advance_batch evaluates it for a block of points in lanes.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
compressive(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr, double tau_tr, double u_eq,
            F1Value& e_lo, double& g, double& p, double& tau, double& xi2) {
  f1_value(c, phi, phi_m, a, visc, p_tr, tau_tr, u_eq, e_lo);
  const double mq = f1_mu_q(c, u_eq);
  const double u2 = u_eq * u_eq;
  const double A = mq * c.d2_rho_s;
  const double B = c.Gdt * u2 + mq * c.two_eta + visc * u_eq;
  const double C = tau_tr * u2;
  g = 2.0 * C / (B + std::sqrt(B * B + 4.0 * A * C));
  p = std::min((g * (g * c.d2_rho_s + c.two_eta)) / u2, p_tr);  // <= p_tr by construction; min guards round-off
  // tau_bar from the friction side of E21 (tau_tr - G dt g cancels when G dt g >> tau_bar)
  tau = std::min(mq * p + visc * g / u_eq, tau_tr);
  xi2 = std::min((p - p_tr) / c.Kdt, 0.0);  // E23: xi_dot_2 <= 0
}

/// Start of the f_1-only Newton solve in u (return_map): the bracket's upper end hi and the first
/// iterate x in (u_eq, hi). Upper end: with beta >= 0, gamma_dot(u) >= the beta = 0 root, so
/// gamma_dot(u_hi) >= gamma_max = tau_tr/(G dt) when Q(gamma_max)/u_hi^2 <= p_tr; there
/// R <= -(mu_p + beta) p < 0. First iterate: the rigid-plastic, viscous balance
/// tau_tr/p_tr = mu_q + beta(u) + (5/4)(phi/a) u (G dt, K dt dropped), a quadratic
/// c1 a u^2 + (c1 - r a) u - (r + K_3 phi_m) = 0; near a steady state (the root just above u_eq) a
/// Newton step from u_eq when it lands lower. Both sides of every select computed (lanes).
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
f1_start(const F1Consts& c, double mu0, double phi, double phi_m, double a, double visc, double p_tr, double tau_tr,
         double u_eq, double g_max, const F1Value& e_lo, double& x, double& hi) {
  const double e_lo_dR = f1_slope(c, phi_m, a, visc, p_tr, u_eq, e_lo);
  const double lo = u_eq;
  const double Q_max = g_max * (g_max * c.d2_rho_s + c.two_eta);  // E19 Q(gamma_max)
  const double u_max = std::sqrt(Q_max / p_tr);
  hi = (u_eq < u_max ? u_max : u_eq) * (1.0 + 1e-12) + 1e-300;  // std::max(u_eq, u_max)
  const double c1 = 1.25 * phi / a;
  const double r = tau_tr / p_tr - mu0 - c.K_3 * phi;
  const double qa = c1 * a, qb = c1 - r * a, qc = -(r + c.K_3 * phi_m);
  const double disc = qb * qb - 4.0 * qa * qc;
  const double sq = std::sqrt(disc);
  // the positive root, stably: (-qb + sq)/(2 qa) for qb <= 0, else -2 qc/(qb + sq) (operands
  // selected before the one division)
  const bool ra = qb <= 0.0;
  const double x_ab = (ra ? -qb + sq : -2.0 * qc) / (ra ? 2.0 * qa : qb + sq);
  const double mid = 0.5 * (lo + hi);
  const double x_q = ((qc < 0.0) & (disc >= 0.0)) ? x_ab : mid;
  const double x_in = ((x_q > lo) & (x_q < hi)) ? x_q : mid;
  const double xn = lo - e_lo.R / e_lo_dR;
  x = ((e_lo_dR < 0.0) & (xn > lo) & (xn < x_in)) ? xn : x_in;
}

/// Start of the p_tr <= 0 fast path's Newton solve on (gamma_dot, u) (return_map), at gamma_dot_max:
/// the inner start of the nested solve's pressure balance there (h >= 0): u at the largest possible
/// p = p_tr + K dt K_3 phi gamma_dot and, for p_tr < 0, the u at which p -> 0+.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline double
tension_start(const F1Consts& c, double phi_m, double a, double p_tr, double dil, double g_max) {
  const double S = p_tr + dil * g_max, ck = c.Kdt * g_max;
  const double u_q = std::sqrt((g_max * (g_max * c.d2_rho_s + c.two_eta)) / S);
  const double u_0 = (phi_m * ck * c.K_3 / S - 1.0) / a;
  return p_tr < 0.0 && u_q < u_0 ? u_0 : u_q;  // std::max(u_q, u_0) for p_tr < 0
}

/// E22 for a separated point (p = 0): p = p_tr + K dt (beta gamma_dot + xi_1) = 0 with beta = K_3 phi,
/// xi_1 = max(-p_tr/(K dt) - K_3 phi gamma_dot, 0). Branch-free (return_map and the lanes).
inline double separated_xi1(const F1Consts& c, double phi, double p_tr, double g) {
  const double xi1 = -p_tr / c.Kdt - c.K_3 * phi * g;
  return xi1 < 0.0 ? 0.0 : xi1;  // std::max(xi1, 0.0)
}

/// E24 linearly implicit with the end-of-step tau_bar, gamma_dot^p: f = (f_n + dt H' f_m)/(1 + dt (H' + S')),
/// H' = K_0 gamma_dot^p (tau_bar/tau*)^{3/2}, S' = K_0 (gamma_dot^p + tau_bar/eta_B + xi_dot_eps);
/// `stiff` = dt (H' + S'). Branch-free (GranularLaw::finish and the lanes of advance_batch).
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline double
structure_step(double K_0, double tau_star, double xi_dot_eps, double dt, double fn, double fm, double inv_eta_B,
               double tau, double g, double& stiff) {
  const double x = tau / tau_star;
  const double Hp = K_0 * g * x * std::sqrt(x);
  const double Sp = K_0 * (g + tau * inv_eta_B + xi_dot_eps);
  stiff = dt * (Hp + Sp);
  const double v = (fn + dt * Hp * fm) / (1.0 + stiff);
  return v < 0.0 ? 0.0 : (1.0 < v ? 1.0 : v);  // std::clamp(v, 0, 1)
}

/// Friction side of E21 at (gamma_dot, p, I_m): max((mu_p + beta) p, 0), with E20 written as
/// mu_p p = mu_q(I_m) p + (5/2)(phi/a) eta_0 gamma_dot/I_m; beta from E18.
inline double friction_of(const F1Consts& c, double phi, double phi_m, double a, double visc, double gg, double pp,
                          double uu) {
  if (!(pp > 0.0)) return 0.0;
  if (!(uu > 0.0)) return std::max((f1_mu_q(c, 0.0) + c.K_3 * (phi - phi_m / (1.0 + a * 0.0))) * pp, 0.0);
  return std::max((f1_mu_q(c, uu) + c.K_3 * (phi - phi_m / (1.0 + a * uu))) * pp + visc * gg / uu, 0.0);
}

/// One Newton step of the p_tr <= 0 fast path on the pair (gamma_dot, u = I_m) (return_map), shared
/// by the scalar loop and the lanes of advance_batch; computed without branches. Returns 1 when the
/// residuals at (gg, uu) are at round-off level (pp, Rr are the values there; gg, uu unchanged),
/// 2 when the step fails (singular Jacobian: unchanged; or the update leaves the admissible range),
/// 3 when the update is below rel_tol in both unknowns, 0 to continue from the updated (gg, uu).
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline double
tension_step(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr, double tau_tr,
             double g_max, double tol, double& gg, double& uu, double& pp_out, double& Rr_out) {
  const double iu = 1.0 / uu;
  const double Qp = 2.0 * gg * c.d2_rho_s + c.two_eta;
  const double pp = (gg * (gg * c.d2_rho_s + c.two_eta)) * iu * iu;
  const double iq = 1.0 / (1.0 + a * uu);
  const double be = c.K_3 * (phi - phi_m * iq), dbe = c.K_3 * phi_m * a * iq * iq;
  const double mq = f1_mu_q(c, uu), dmq = f1_dmu_q(c, uu);
  const double h = pp - p_tr - c.Kdt * gg * be;
  const double Rr = tau_tr - c.Gdt * gg - (mq + be) * pp - visc * gg * iu;
  // residual exit with the tolerances of the nested solve (|R| <= 1e-14 tau_tr, pressure balance to
  // 1e-15 of its terms)
  const bool fast = (std::fabs(Rr) <= 1e-14 * tau_tr) & (std::fabs(h) <= 1e-15 * (std::fabs(p_tr) + pp)) & (be >= 0.0);
  const double hg = Qp * iu * iu - c.Kdt * be, hu = -2.0 * pp * iu - c.Kdt * gg * dbe;
  const double Rg = -c.Gdt - (mq + be) * Qp * iu * iu - visc * iu;
  const double Ru = -(dmq + dbe) * pp + 2.0 * (mq + be) * pp * iu + visc * gg * iu * iu;
  const double det = hg * Ru - hu * Rg;
  const bool singular = !(std::fabs(det) > 0.0);
  const double dg = (hu * Rr - h * Ru) / det;
  const double du = (h * Rg - hg * Rr) / det;
  const double g1 = gg + dg, u1 = uu + du;
  const bool in_range = (g1 > 0.0) & (g1 <= g_max) & (u1 > 0.0) & (std::fabs(u1) <= std::numeric_limits<double>::max());
  const bool small = (std::fabs(dg) <= tol * g1) & (std::fabs(du) <= tol * u1);
  pp_out = pp;
  Rr_out = Rr;
  const bool keep = fast | singular;
  gg = keep ? gg : g1;
  uu = keep ? uu : u1;
  // (a double, so that the lane loop has one element width)
  const double st = small ? 3.0 : 0.0;
  const double st2 = (singular | !in_range) ? 2.0 : st;
  return fast ? 1.0 : st2;
}

/// The p_tr <= 0 fast path's acceptance of a converged Newton step at (gg, uu): the pressure pp and
/// the relative E21 residual res there, and whether both residuals are small (else the nested solve).
inline bool tension_accept(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr,
                           double tau_tr, double gg, double uu, double& pp, double& res) {
  pp = (gg * (gg * c.d2_rho_s + c.two_eta)) / (uu * uu);
  const double be = c.K_3 * (phi - phi_m / (1.0 + a * uu));
  const double h = pp - p_tr - c.Kdt * gg * be;
  const double Rr = tau_tr - c.Gdt * gg - (f1_mu_q(c, uu) + be) * pp - visc * gg / uu;
  res = std::fabs(Rr) / tau_tr;
  return pp > 0.0 && be >= 0.0 && res <= 1e-10 && std::fabs(h) <= 1e-12 * (std::fabs(p_tr) + pp + c.Kdt * gg * be);
}

}  // namespace oobleck::material::granular_kernels

namespace oobleck::material::granular_kernels {

/// E24 monolithic backward Euler in f (StructureUpdate::kImplicit, or kAuto when the staggered step
/// is stiff): find f with f = f_next(return_map(f)), i.e. phi_m, a of the return map (E1, E2) and the
/// E24 rates all at the end of the step. Z(f) = f - f_next(return_map(f)) has Z(0) <= 0 and
/// Z(max(f_n, f_m)) >= 0 (f_next <= max(f_n, f_m)); the bracket starts at [f_n, staggered f] so that
/// the root nearest the staggered prediction is found; Illinois iteration. `map(f)` is the return
/// map at structure f, `f_next(r, stiff)` the linearly implicit E24 step after it (structure_step).
/// On entry r is the return map at f_n and f_new the staggered f; on exit r, f_used (the structure
/// of r) and f_new are those of the root, structure_iterations counts the return maps. Returns
/// whether it converged. (GranularLaw::finish; inlined as the block of finish it was.)
template <class Map, class FNext, class ReturnMap>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline bool
structure_implicit(const Map& map, const FNext& f_next, double fn, double fm, int max_iter, ReturnMap& r,
                   double& f_used, double& f_new, int& structure_iterations) {
  ReturnMap rz;
  double dummy = 0.0;
  auto Z = [&](double ff, ReturnMap& rr, double& fnext) {
    rr = map(ff);
    fnext = f_next(rr, dummy);
    structure_iterations++;
    return ff - fnext;
  };
  double a_f = fn, Za = fn - f_new;  // Z(f_n) from the staggered solve
  ReturnMap ra = r;
  double fa_next = f_new;
  double b_f = f_new, fb_next = 0.0;
  ReturnMap rb;
  double Zb = Z(b_f, rb, fb_next);
  if (Za != 0.0 && (Zb > 0.0) == (Za > 0.0) && Zb != 0.0) {  // no sign change: widen to the safe end
    b_f = f_new > fn ? std::max(fn, fm) : 0.0;
    Zb = Z(b_f, rb, fb_next);
  }
  bool ok = true;
  if (Za == 0.0) {
    rz = ra;
    f_used = a_f;
    f_new = fa_next;
  } else if (Zb == 0.0 || (Zb > 0.0) == (Za > 0.0)) {
    rz = rb;  // Zb == 0, or (only by round-off) no bracket: take the end point
    f_used = b_f;
    f_new = fb_next;
    ok = std::fabs(Zb) <= 1e-12;
  } else {
    int side = 0;
    ok = false;
    for (int k = 0; k < max_iter; ++k) {
      double fc = (Za - Zb) != 0.0 ? (a_f * Zb - b_f * Za) / (Zb - Za) : 0.5 * (a_f + b_f);
      if (!(fc > std::min(a_f, b_f) && fc < std::max(a_f, b_f))) fc = 0.5 * (a_f + b_f);
      double fc_next = 0.0;
      const double Zc = Z(fc, rz, fc_next);
      f_used = fc;
      f_new = fc_next;
      if (std::fabs(Zc) <= 1e-13 || std::fabs(b_f - a_f) <= 1e-14) {
        ok = true;
        break;
      }
      if ((Zc > 0.0) == (Za > 0.0)) {
        a_f = fc;
        Za = Zc;
        if (side == 1) Zb *= 0.5;
        side = 1;
      } else {
        b_f = fc;
        Zb = Zc;
        if (side == -1) Za *= 0.5;
        side = -1;
      }
    }
  }
  r = rz;
  return ok;
}

/// Diagnostics E18–E20 of the end state (update() only: kDiagnostics) at (tau_bar, p, gamma_dot^p)
/// = (p, g) with E1, E2's phi_m, a of the structure the return map used: I_v, I, I_m (E19), phi_eq,
/// beta (E18), mu_p (E20). (GranularLaw::finish.)
template <bool kDiagnostics>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
end_state_diagnostics(const GranularLaw& law, double phi, double eta_0, double phi_m, double a, double p, double g,
                      GranularRegime regime, GranularUpdate& out) {
  const rheology::GranularParams& gp = law.granular();
  if constexpr (!kDiagnostics) {
    (void)gp;
    (void)phi;
    (void)eta_0;
    (void)phi_m;
    (void)a;
    (void)p;
    (void)g;
    (void)regime;
    (void)out;
  } else if (p > 0.0 && g > 0.0) {
    out.I_v = eta_0 * g / p;  // E19
    out.I = g * gp.d * std::sqrt(gp.rho_s / p);
    out.I_m = std::sqrt(out.I * out.I + 2.0 * out.I_v);
    out.phi_eq = phi_m / (1.0 + a * out.I_m);  // E18
    out.beta = gp.K_3 * (phi - out.phi_eq);
    out.mu_p = law.mu_q(out.I_m) + 2.5 * phi * out.I_v / (a * out.I_m);  // E20
  } else if (p > 0.0 || regime == GranularRegime::kElastic) {
    out.phi_eq = phi_m;
    out.beta = gp.K_3 * (phi - phi_m);
    out.mu_p = law.mu_q(0.0);
  } else {  // p = 0: I_m -> infinity while flowing (reported as 0), phi_eq -> 0
    out.phi_eq = g > 0.0 ? 0.0 : phi_m;
    out.beta = g > 0.0 ? gp.K_3 * phi : gp.K_3 * (phi - phi_m);
    out.mu_p = law.mu_q(0.0);
  }
}

/// The final stress (E17: radial return in deviatoric space, sigma = (tau_bar/tau_tr) s_tr - p I)
/// and f_new, written to state only when finite (else out.finite = false); out.message when the
/// return map did not converge. (GranularLaw::finish.)
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
radial_return(const Eigen::Matrix3d& s_tr, double tau_tr, double tau, double p, double g, double f_new,
              GranularState& state, GranularUpdate& out) {
  // (element by element: the Eigen expression did not inline; same operations)
  const double scale = tau_tr > 0.0 ? tau / tau_tr : 0.0;
  Eigen::Matrix3d sig;
  for (int i = 0; i < 9; ++i) sig.data()[i] = scale * s_tr.data()[i];
  for (int i = 0; i < 3; ++i) sig(i, i) -= p;

  if (!finite3(sig) || !std::isfinite(f_new) || !std::isfinite(g) || !std::isfinite(p)) {
    out.finite = false;
    out.message = "non-finite result (state left unchanged)";
    return;
  }
  if (!out.converged && out.message == nullptr) out.message = "return map did not converge within the iteration cap";
  for (int i = 0; i < 9; ++i) state.sigma.data()[i] = sig.data()[i];
  state.f = f_new;
}

}  // namespace oobleck::material::granular_kernels

namespace oobleck::material {

// The end of a point's step, after its return map: inline in both files, so that advance_batch's
// points that its lanes cannot finish (a failed solve, the implicit structure update, the forced
// f = 1) take the very code of advance(), inlined as in update() and advance(). The E24 structure
// update (staggered, forced f = 1, or structure_implicit), then end_state_diagnostics and radial_return.
template <bool kDiagnostics>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
GranularLaw::finish(GranularState& state, const Trial& t, ReturnMap r, double dt, double phi, double eta_0,
                    GranularUpdate& out) const {
  out.f_old = state.f;
  const double fn = state.f;
  out.jammed = phi >= phi_j_;
  const double p_tr = t.p_tr, tau_tr = t.tau_tr, fm = t.fm, inv_eta_B = t.inv_eta_B;
  out.tau_trial = tau_tr;
  out.p_trial = p_tr;
  // Linearly implicit E24 step with end-of-step tau_bar, gamma_dot^p: f = (f_n + dt H' f_m)/(1 + dt (H' + S')),
  // H' = K_0 gamma_dot^p (tau_bar/tau*)^{3/2}, S' = K_0 (gamma_dot^p + tau_bar/eta_B + xi_dot_eps); `stiff` = dt (H' +
  // S').
  auto f_next = [&](const ReturnMap& rr, double& stiff) {
    return granular_kernels::structure_step(K_0_, tau_star_, xi_dot_eps_, dt, fn, fm, inv_eta_B, rr.tau, rr.g, stiff);
  };

  // ---- the return map r with f_n (given), then the E24 structure update ----
  double stiff = 0.0;
  double f_used = fn;
  double f_new = f_next(r, stiff);
  const bool forced = out.jammed && options_.jammed_structure == JammedStructure::kForceOne;
  if (forced) {
    f_new = 1.0;
  } else if (options_.structure_update == StructureUpdate::kImplicit ||
             (options_.structure_update == StructureUpdate::kAuto && stiff > options_.stiff_structure)) {
    // backward Euler in f: the return map at the end-of-step structure
    int structure_iterations = 0;  // a local, not out
    auto map = [&](double ff) { return return_map(ff, phi, eta_0, dt, p_tr, tau_tr); };
    const bool ok = granular_kernels::structure_implicit(map, f_next, fn, fm, options_.max_iter, r, f_used, f_new,
                                                         structure_iterations);
    out.structure_iterations = structure_iterations;
    r.converged = r.converged && ok;
    if (!ok) out.message = "implicit structure update did not converge within the iteration cap";
  }
  const double phi_m = phi_j_ + (phi_c_ - phi_j_) * f_used;  // E1 as used by the return map
  const double a = a_0_ + (a_inf_ - a_0_) * f_used;          // E2
  out.phi_m = phi_m;
  const double tau = r.tau, p = r.p, g = r.g;

  // ---- diagnostics E18–E20 at the end state ----
  out.regime = r.regime;
  out.gamma_dot_p = g;
  out.xi_dot_1 = r.xi1;
  out.xi_dot_2 = r.xi2;
  granular_kernels::end_state_diagnostics<kDiagnostics>(*this, phi, eta_0, phi_m, a, p, g, r.regime, out);
  out.tau_bar = tau;
  out.p = p;
  out.iterations = r.iterations;
  out.residual = r.residual;
  out.converged = r.converged;

  // ---- final stress: radial return in deviatoric space ----
  granular_kernels::radial_return(t.s, tau_tr, tau, p, g, f_new, state, out);
}

}  // namespace oobleck::material
