#include "oobleck/material/granular.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "oobleck/core/error.hpp"
#include "oobleck/numerics/vector_math.hpp"
#include "oobleck/rheology/f_max.hpp"

namespace oobleck::material {

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
    throw InputError(fmt::format(
        "{}: key 'granular.K_4' = {}: the granular return map supports only K_4 = 0 (the value of every "
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

namespace {

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
inline bool point_inputs_valid(double phi, double f, const T9& S, const T9& D, const T9& W) {
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
inline void jaumann_trial(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& r) {
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
inline void jaumann_trial_plane(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& r) {
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
/// in the portable build, which stops the vectorisation.) The sums in the order of Eigen's trace() (d00 + (d11 + d22)) and
/// squaredNorm() (SSE2 pairs summed as two lanes, then the ninth entry), which GCC's Eigen 3.4 uses
/// for a Matrix3d with or without AVX (with -ffp-contract=off): bit for bit as before.
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void elastic_trial(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& s,
                          double& p_tr, double& tau_tr) {
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
inline void elastic_trial_plane(const T9& S, const T9& D, const T9& W, double dt, double G, double K, T9& s,
                                double& p_tr, double& tau_tr) {
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
inline void f1_value(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr, double tau_tr,
                     double uu, F1Value& e) {
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
inline double f1_slope(const F1Consts& c, double phi_m, double a, double visc, double p_tr, double uu,
                       const F1Value& e) {
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
  if (R > 0.0) lo = x; else hi = x;
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
inline void compressive(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr,
                        double tau_tr, double u_eq, F1Value& e_lo, double& g, double& p, double& tau, double& xi2) {
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
inline void f1_start(const F1Consts& c, double mu0, double phi, double phi_m, double a, double visc, double p_tr,
                     double tau_tr, double u_eq, double g_max, const F1Value& e_lo, double& x, double& hi) {
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
inline double tension_start(const F1Consts& c, double phi_m, double a, double p_tr, double dil, double g_max) {
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
inline double structure_step(double K_0, double tau_star, double xi_dot_eps, double dt, double fn, double fm,
                             double inv_eta_B, double tau, double g, double& stiff) {
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
inline double tension_step(const F1Consts& c, double phi, double phi_m, double a, double visc, double p_tr,
                        double tau_tr, double g_max, double tol, double& gg, double& uu, double& pp_out,
                        double& Rr_out) {
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
  const bool in_range =
      (g1 > 0.0) & (g1 <= g_max) & (u1 > 0.0) & (std::fabs(u1) <= std::numeric_limits<double>::max());
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

}  // namespace

GranularLaw::ReturnMap GranularLaw::return_map(double f, double phi, double eta_0, double dt, double p_tr,
                                               double tau_tr) const {
  const double tol = options_.rel_tol;
  const int cap = options_.max_iter;
  // ---- E1, E2 with the structure used by this return map (f_n when staggered) ----
  const double phi_m = phi_j_ + (phi_c_ - phi_j_) * f;  // E1
  const double a = a_0_ + (a_inf_ - a_0_) * f;          // E2
  const double Gdt = G_ * dt;
  const double Kdt = K_ * dt;
  const double visc = 2.5 * phi / a * eta_0;  // E20 viscous friction times p: visc * gamma_dot/I_m
  const double two_eta = 2.0 * eta_0;

  // E18 dilation as a function of I_m (u) and its derivative.
  auto beta_of = [&](double u) { return K_3_ * (phi - phi_m / (1.0 + a * u)); };
  auto dbeta_of = [&](double u) {
    const double q = 1.0 + a * u;
    return K_3_ * phi_m * a / (q * q);
  };
  // E19 I_m from (gamma_dot, p): I_m^2 = Q(gamma_dot)/p with Q = gamma_dot (gamma_dot d^2 rho_s + 2 eta_0).
  auto Q_of = [&](double g) { return g * (g * d2_rho_s_ + two_eta); };
  const double u_eq = phi < phi_m ? (phi_m - phi) / (a * phi) : 0.0;  // I_m at which beta = 0

  double tau = 0.0, p = 0.0, g = 0.0, u = 0.0, xi1 = 0.0, xi2 = 0.0;
  GranularRegime regime = GranularRegime::kElastic;
  bool converged = true;
  int iterations = 0;
  double residual = 0.0;
  const double g_max = tau_tr / Gdt;   // gamma_dot^p at which tau_bar = 0 (radial return)
  const double dil = Kdt * K_3_ * phi;  // d p/d gamma_dot at p -> 0 (I_m -> infinity: beta -> K_3 phi)
  constexpr double kInf = std::numeric_limits<double>::infinity();

  // Friction side of E21 at (gamma_dot, p, I_m): max((mu_p + beta) p, 0), with E20 written as
  // mu_p p = mu_q(I_m) p + (5/2)(phi/a) eta_0 gamma_dot/I_m.
  const F1Consts c{Kdt, Gdt, two_eta, d2_rho_s_, K_3_, mu_1_, mu_2_, b_};
  auto friction = [&](double gg, double pp, double uu) { return friction_of(c, phi, phi_m, a, visc, gg, pp, uu); };

  // ---- General shear solve in gamma_dot (used for p_tr <= 0 and as the fallback of the fast path).
  // Inner: for fixed gamma_dot the pressure balance, written in u = I_m with p = Q(gamma_dot)/u^2,
  // h(u) = Q/u^2 - p_tr - K dt gamma_dot beta(u), is strictly decreasing and convex in u (Q/u^2 and
  // -beta(u) are). Newton started left of the root (h >= 0) therefore increases monotonically to it
  // without overshooting. Start: the larger of u at p = p_tr + K dt K_3 phi gamma_dot (the largest
  // possible p) and, for p_tr < 0, the u at which p_tr + K dt gamma_dot beta(u) = 0 (p -> 0+); both
  // have h >= 0. Also returns du/dgamma_dot (implicit derivative) for the outer Newton.
  struct Inner {
    double p, u, du, dp;  // p, I_m and their derivatives in gamma_dot
    bool ok;
  };
  auto p_of = [&](double gg) -> Inner {
    Inner in{0.0, kInf, 0.0, 0.0, true};
    if (!(gg > 0.0)) {
      in.u = 0.0;
      in.p = std::max(p_tr, 0.0);
      return in;
    }
    const double S = p_tr + dil * gg;  // p at beta = K_3 phi (u -> infinity): the largest possible p
    if (S <= 0.0) return in;            // no contact pressure even with full dilatancy
    const double Q = Q_of(gg), ck = Kdt * gg;
    double x = std::sqrt(Q / S);
    if (p_tr < 0.0) {
      const double u0 = (phi_m * ck * K_3_ / S - 1.0) / a;  // beta(u0) = -p_tr/(K dt gamma_dot)
      if (u0 > x) x = u0;
    }
    in.ok = false;
    for (int k = 1; k <= cap; ++k) {
      ++iterations;
      const double hv = Q / (x * x) - p_tr - ck * beta_of(x);
      if (hv <= 0.0) {  // at the root (or past it by round-off)
        in.ok = true;
        break;
      }
      const double dh = -2.0 * Q / (x * x * x) - ck * dbeta_of(x);
      const double step = -hv / dh;
      x += step;
      if (!(step > 0.25 * tol * x)) {
        in.ok = std::isfinite(x);
        break;
      }
    }
    in.u = x;
    in.p = Q / (x * x);
    // implicit derivatives: h(u(g), g) = 0
    const double Qp = 2.0 * gg * d2_rho_s_ + two_eta;
    const double hu = -2.0 * in.p / x - ck * dbeta_of(x);
    const double hg = Qp / (x * x) - Kdt * beta_of(x);
    in.du = hu < 0.0 ? -hg / hu : 0.0;
    in.dp = Qp / (x * x) - 2.0 * in.p / x * in.du;
    return in;
  };
  // Outer: R(gamma_dot) = tau_tr - G dt gamma_dot - friction on [glo, ghi] with R(glo) > 0 >= R(ghi):
  // Newton with the analytic dR/dgamma_dot, started at ghi and kept inside the shrinking bracket
  // (bisection when a step leaves it).
  auto solve_g = [&](double glo, double ghi) {
    bool all_ok = true;
    double pp = 0.0, uu = 0.0;
    auto R_g = [&](double gg, double& dR) {
      const Inner in = p_of(gg);
      all_ok = all_ok && in.ok;
      pp = in.p;
      uu = in.u;
      double F = 0.0, dF = 0.0;
      if (in.p > 0.0 && in.u > 0.0 && std::isfinite(in.u)) {
        const double be = beta_of(in.u), dbe = dbeta_of(in.u);
        const double mq = mu_q(in.u);
        const double dmq = b_ == 0.0 ? 0.0 : (mu_2_ - mu_1_) * b_ / ((in.u + b_) * (in.u + b_));
        F = (mq + be) * in.p + visc * gg / in.u;
        dF = (dmq + dbe) * in.du * in.p + (mq + be) * in.dp + visc / in.u - visc * gg / (in.u * in.u) * in.du;
        if (F < 0.0) F = dF = 0.0;
      }
      dR = -Gdt - dF;
      return tau_tr - Gdt * gg - F;
    };
    double gg = ghi, dR = 0.0;
    double R = R_g(gg, dR);
    bool done = std::fabs(R) <= 1e-14 * tau_tr;
    for (int k = 1; k <= cap && !done; ++k) {
      ++iterations;
      if (R > 0.0) glo = gg; else ghi = gg;
      double next = dR < 0.0 ? gg - R / dR : -1.0;
      const bool newton = next > glo && next < ghi;
      if (!newton) next = 0.5 * (glo + ghi);
      done = (newton && std::fabs(next - gg) <= tol * gg) || (ghi - glo) <= tol * ghi;
      gg = next;
      R = R_g(gg, dR);
      done = done || std::fabs(R) <= 1e-14 * tau_tr;
    }
    g = gg;
    p = pp;
    u = uu;
    residual = std::fabs(R) / tau_tr;
    converged = all_ok && residual <= 1e-9;
  };

  if (p_tr > 0.0) {
    // -------- compressive trial: elastic, shear (f_1), or compaction (f_1 + f_3) --------
    const double mu0 = mu_q(0.0);
    const bool f3_trial_active = phi < phi_m;                                      // E23: g(phi) p_tr > 0
    const double f1_trial = tau_tr - std::max((mu0 + beta_of(0.0)) * p_tr, 0.0);  // E21 at gamma_dot = 0
    if (!f3_trial_active && f1_trial <= 0.0) {
      regime = GranularRegime::kElastic;
      tau = tau_tr;
      p = p_tr;
    } else {
      // Fast path, parametrised by u = I_m >= u_eq (beta >= 0, xi_dot_2 = 0): f1_value, R(u)
      // decreasing in u (docs/granular.md). Its value at u_eq decides between f_1 + f_3 and f_1.
      // (compressive(): that value and the f_1 + f_3 closed form below)
      Compressive cm;
      compressive(c, phi, phi_m, a, visc, p_tr, tau_tr, u_eq, cm.e_lo, cm.g, cm.p, cm.tau, cm.xi2);
      const F1Value& e_lo = cm.e_lo;
      if (e_lo.R <= 0.0 && u_eq > 0.0) {
        // -------- f_1 + f_3 (E21, E23 with K_4 = 0): beta = 0, I_m = u_eq; closed form ----------
        g = cm.g;
        p = cm.p;
        tau = cm.tau;
        u = u_eq;
        xi2 = cm.xi2;
        regime = g > 0.0 ? GranularRegime::kShearCompaction : GranularRegime::kCompaction;
      } else {
        // -------- f_1 only: root of R(u) on [u_lo, u_hi] --------
        double lo = u_eq, hi, x;
        f1_start(c, mu0, phi, phi_m, a, visc, p_tr, tau_tr, u_eq, g_max, e_lo, x, hi);
        F1Value e{};
        converged = false;
        for (iterations = 1; iterations <= cap; ++iterations) {
          f1_value(c, phi, phi_m, a, visc, p_tr, tau_tr, x, e);
          const double dR = f1_slope(c, phi_m, a, visc, p_tr, x, e);
          const int st = f1_step(e.R, dR, tau_tr, tol, x, lo, hi);
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
        residual = std::fabs(e.R) / tau_tr;
        if (converged && residual <= 1e-10) {
          u = x;
          g = e.g;
          p = e.p;
        } else {
          // u is ill-conditioned here (gamma_dot(u) steep where dilatancy dominates p_tr): solve in gamma_dot
          solve_g(e_lo.g, g_max);
        }
        // tau_bar from the friction side of E21: accurate even when G dt g >> tau_bar
        tau = std::min(friction(g, p, u), tau_tr);
        regime = GranularRegime::kShear;
      }
    }
  } else {
    // -------- p_tr <= 0: separated (f_2 active) unless shear dilatancy builds pressure --------
    if (!(tau_tr > 0.0) || !(p_tr + dil * g_max > 0.0)) {
      regime = (tau_tr > 0.0 || p_tr < 0.0) ? GranularRegime::kSeparated : GranularRegime::kElastic;
      g = tau_tr > 0.0 ? g_max : 0.0;
      tau = 0.0;
      p = 0.0;
      xi1 = separated_xi1(c, phi, p_tr, g);  // E22
    } else {
      // flow with p > 0 created by dilatancy (a loose bed that dilates slightly, or a stress-free
      // dense state that is sheared). Fast path: Newton on the pair (gamma_dot, u = I_m) for the
      // pressure balance h = Q(gamma_dot)/u^2 - p_tr - K dt gamma_dot beta(u) = 0 and E21
      // R = tau_tr - G dt gamma_dot - (mu_q(u) + beta(u)) p - visc gamma_dot/u = 0 with p = Q/u^2,
      // started at gamma_dot_max and the inner start of p_of (h >= 0). Accepted only when the last
      // Newton step is below rel_tol in both unknowns and both residuals are at round-off level;
      // otherwise (far from the root, ill-conditioned) the bracketed nested solve in gamma_dot.
      bool fast = false;
      {
        double gg = g_max, uu = tension_start(c, phi_m, a, p_tr, dil, g_max);
        bool step_ok = false;
        for (int k = 1; k <= kTensionIterations; ++k) {
          ++iterations;
          double pp, Rr;
          const double st = tension_step(c, phi, phi_m, a, visc, p_tr, tau_tr, g_max, tol, gg, uu, pp, Rr);
          if (st == 1.0) {
            fast = true;
            g = gg;
            u = uu;
            p = pp;
            residual = std::fabs(Rr) / tau_tr;
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
            g = gg;
            u = uu;
            p = pp;
            residual = res;
          }
        }
      }
      if (!fast) solve_g(std::max(-p_tr / dil, 0.0), g_max);
      tau = std::min(friction(g, p, u), tau_tr);
      regime = p > 0.0 ? GranularRegime::kShear : GranularRegime::kSeparated;
      if (p <= 0.0) xi1 = separated_xi1(c, phi, p_tr, g);
    }
  }

  ReturnMap r;
  r.tau = tau;
  r.p = p;
  r.g = g;
  r.xi1 = xi1;
  r.xi2 = xi2;
  r.residual = residual;
  r.regime = regime;
  r.converged = converged;
  r.iterations = iterations;
  (void)u;
  return r;
}

GranularUpdate GranularLaw::update(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W,
                                   double dt, double phi, double eta_0) const {
  return update_impl<true>(state, D, W, dt, phi, eta_0);
}

GranularStep GranularLaw::advance(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W,
                                  double dt, double phi) const {
  const GranularUpdate u = update_impl<false>(state, D, W, dt, phi, eta_0_);
  return GranularStep{u.regime, u.ok(), u.gamma_dot_p};
}

// Inlined into update() and advance(), so that advance() drops the stores of what it does not return.
template <bool kDiagnostics>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline GranularUpdate GranularLaw::update_impl(GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W,
                                        double dt, double phi, double eta_0) const {
  GranularUpdate out;
  Trial t;
  if (!begin(state, D, W, dt, phi, eta_0, t, out)) return out;
  finish<kDiagnostics>(state, t, return_map(state.f, phi, eta_0, dt, t.p_tr, t.tau_tr), dt, phi, eta_0, out);
  return out;
}

#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline bool GranularLaw::begin(const GranularState& state, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W,
                               double dt, double phi, double eta_0, Trial& t, GranularUpdate& out) const {
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

template <bool kDiagnostics>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void GranularLaw::finish(GranularState& state, const Trial& t, ReturnMap r, double dt, double phi,
                                double eta_0, GranularUpdate& out) const {
  out.f_old = state.f;
  const double fn = state.f;
  out.jammed = phi >= phi_j_;
  const double p_tr = t.p_tr, tau_tr = t.tau_tr, fm = t.fm, inv_eta_B = t.inv_eta_B;
  const Eigen::Matrix3d& s_tr = t.s;
  out.tau_trial = tau_tr;
  out.p_trial = p_tr;
  // Linearly implicit E24 step with end-of-step tau_bar, gamma_dot^p: f = (f_n + dt H' f_m)/(1 + dt (H' + S')),
  // H' = K_0 gamma_dot^p (tau_bar/tau*)^{3/2}, S' = K_0 (gamma_dot^p + tau_bar/eta_B + xi_dot_eps); `stiff` = dt (H' + S').
  auto f_next = [&](const ReturnMap& rr, double& stiff) {
    return structure_step(K_0_, tau_star_, xi_dot_eps_, dt, fn, fm, inv_eta_B, rr.tau, rr.g, stiff);
  };

  // ---- the return map r with f_n (given), then the structure update ----
  double stiff = 0.0;
  double f_used = fn;
  double f_new = f_next(r, stiff);
  const bool forced = out.jammed && options_.jammed_structure == JammedStructure::kForceOne;
  if (forced) {
    f_new = 1.0;
  } else if (options_.structure_update == StructureUpdate::kImplicit ||
             (options_.structure_update == StructureUpdate::kAuto && stiff > options_.stiff_structure)) {
    // Monolithic backward Euler in f: find f with f = f_next(return_map(f)), i.e. phi_m, a of the return
    // map and the E24 rates all at the end of the step. Z(f) = f - f_next(return_map(f)) has Z(0) <= 0 and
    // Z(max(f_n, f_m)) >= 0 (f_next <= max(f_n, f_m)); the bracket starts at [f_n, staggered f] so that
    // the root nearest the staggered prediction is found; Illinois iteration.
    ReturnMap rz;
    double dummy = 0.0;
    int structure_iterations = 0;  // a local, not out: out must not escape into the (out-of-line) lambda
    auto Z = [&](double ff, ReturnMap& rr, double& fnext) {
      rr = return_map(ff, phi, eta_0, dt, p_tr, tau_tr);
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
      for (int k = 0; k < options_.max_iter; ++k) {
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
    out.structure_iterations = structure_iterations;
    r.converged = r.converged && ok;
    if (!ok) out.message = "implicit structure update did not converge within the iteration cap";
  }
  const double phi_m = phi_j_ + (phi_c_ - phi_j_) * f_used;  // E1 as used by the return map
  const double a = a_0_ + (a_inf_ - a_0_) * f_used;          // E2
  out.phi_m = phi_m;
  const double tau = r.tau, p = r.p, g = r.g;
  const GranularRegime regime = r.regime;

  // ---- diagnostics E18–E20 at the end state ----
  out.regime = regime;
  out.gamma_dot_p = g;
  out.xi_dot_1 = r.xi1;
  out.xi_dot_2 = r.xi2;
  if constexpr (!kDiagnostics) {
    (void)a;
  } else if (p > 0.0 && g > 0.0) {
    out.I_v = eta_0 * g / p;                      // E19
    out.I = g * granular_.d * std::sqrt(granular_.rho_s / p);
    out.I_m = std::sqrt(out.I * out.I + 2.0 * out.I_v);
    out.phi_eq = phi_m / (1.0 + a * out.I_m);     // E18
    out.beta = K_3_ * (phi - out.phi_eq);
    out.mu_p = mu_q(out.I_m) + 2.5 * phi * out.I_v / (a * out.I_m);  // E20
  } else if (p > 0.0 || regime == GranularRegime::kElastic) {
    out.phi_eq = phi_m;
    out.beta = K_3_ * (phi - phi_m);
    out.mu_p = mu_q(0.0);
  } else {  // p = 0: I_m -> infinity while flowing (reported as 0), phi_eq -> 0
    out.phi_eq = g > 0.0 ? 0.0 : phi_m;
    out.beta = g > 0.0 ? K_3_ * phi : K_3_ * (phi - phi_m);
    out.mu_p = mu_q(0.0);
  }
  out.tau_bar = tau;
  out.p = p;
  out.iterations = r.iterations;
  out.residual = r.residual;
  out.converged = r.converged;

  // ---- final stress: radial return in deviatoric space ----
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

namespace {

/// Runs `jobs` iterative solves in N lanes: load(l, j) puts job j into lane l, step() advances every
/// lane by one iteration (vectorised; idle lanes compute on their last values, which are finite),
/// settle(l, j) books lane l's iteration and returns true when its job j is done; the lane then
/// takes the next job.
template <int N, class Load, class Step, class Settle>
void run_lanes(int jobs, Load&& load, Step&& step, Settle&& settle) {
  int lane_job[N];
  int next = 0, active = 0;
  for (int l = 0; l < N; ++l) {
    lane_job[l] = next < jobs ? next++ : -1;
    if (lane_job[l] >= 0) {
      load(l, lane_job[l]);
      ++active;
    }
  }
  while (active > 0) {
    step();
    for (int l = 0; l < N; ++l) {
      if (lane_job[l] < 0 || !settle(l, lane_job[l])) continue;
      lane_job[l] = next < jobs ? next++ : -1;
      if (lane_job[l] >= 0) load(l, lane_job[l]);
      else --active;
    }
  }
}

}  // namespace

namespace {

// The branch of return_map a point takes, as a double (one element width in the lane loops).
constexpr double kElasticTrial = 0.0, kClosedForm = 1.0, kF1Solve = 2.0, kSeparatedForm = 3.0, kTensionSolve = 4.0;

/// What the lane loops of advance_batch need of the law and the step.
struct BatchConsts {
  F1Consts c;
  double dt, G, K, eta_0, phi_j, phi_c, a_0, a_inf, mu0;
  double K_0, tau_star, xi_dot_eps;
  double stiff_max;      ///< finish() takes the implicit structure update above this dt (H' + S') (kAuto)
  double phi_forced;     ///< finish() forces f = 1 from this phi on (kForceOne), else infinity
  bool implicit_always;  ///< kImplicit: every point goes through finish()
  bool step_ok;          ///< step_inputs_valid(dt, eta_0)
  const rheology::SteadyParams* steady;
};

/// One block of points in component-major arrays (a lane per point).
struct BatchBlock {
  static constexpr int kSize = 128;
  double bS[9][kSize], bL[9][kSize], t_s[9][kSize];  // sigma_n, L, deviator of the E16 trial
  double s_f[kSize], s_phi[kSize], s_p_tr[kSize], s_tau_tr[kSize], t_fm[kSize], t_inv_eta_B[kSize], ok[kSize];
  // return_map's branch (kind), the f_1 + f_3 closed form, the solves' constants and starts
  double kind[kSize], c_g[kSize], c_p[kSize], c_tau[kSize], c_xi2[kSize];
  double phi_m[kSize], a[kSize], visc[kSize], lo[kSize], x[kSize], hi[kSize], g_max[kSize], tu[kSize], xi1[kSize];
  double f1_trial[kSize], dil_p[kSize], e_lo[6][kSize];  // what decides the branch; e_lo: F1Value at u_eq
  // the return maps' results, and the ends of the updates
  double r_tau[kSize], r_p[kSize], r_g[kSize], r_ok[kSize], e_f[kSize], e_fast[kSize], e_sig[9][kSize];
  // the rest of a point's ReturnMap (regime as a double, iterations of a scalar return_map)
  double r_xi1[kSize], r_xi2[kSize], r_res[kSize], r_reg[kSize], r_it[kSize];
};

// The lane loops below are functions of their own: inside the (large) advance_batch, GCC 12 left
// some of them scalar once the function had grown past a size.

/// The 9 entries of m matrices, point-major, into component-major rows out[q][i] (a transpose;
/// values unchanged). With SSE2, two points at a time: 2 x 2 transposes of entry pairs, half the
/// stores of the scalar loop (this gather was a third of the trials' time).
inline void gather_components(const Eigen::Matrix3d* mats, int m, double (*out)[BatchBlock::kSize]) {
  int i = 0;
#if defined(__SSE2__)
  for (; i + 1 < m; i += 2) {
    const double* a = mats[i].data();
    const double* c = mats[i + 1].data();
    for (int q = 0; q < 8; q += 2) {
      const __m128d A = _mm_loadu_pd(a + q), C = _mm_loadu_pd(c + q);
      _mm_storeu_pd(&out[q][i], _mm_unpacklo_pd(A, C));
      _mm_storeu_pd(&out[q + 1][i], _mm_unpackhi_pd(A, C));
    }
    _mm_storeu_pd(&out[8][i], _mm_set_pd(c[8], a[8]));
  }
#endif
  for (; i < m; ++i)
    for (int q = 0; q < 9; ++q) out[q][i] = mats[i].data()[q];
}

/// The entries xx, yx, xy, yy, zz (T9 indices 0, 1, 3, 4, 8) of m matrices into rows out[q][i] of
/// those indices (the others are not written), as gather_components.
inline void gather_plane_components(const Eigen::Matrix3d* mats, int m, double (*out)[BatchBlock::kSize]) {
  int i = 0;
#if defined(__SSE2__)
  for (; i + 1 < m; i += 2) {
    const double* a = mats[i].data();
    const double* c = mats[i + 1].data();
    const __m128d A0 = _mm_loadu_pd(a), C0 = _mm_loadu_pd(c), A3 = _mm_loadu_pd(a + 3), C3 = _mm_loadu_pd(c + 3);
    _mm_storeu_pd(&out[0][i], _mm_unpacklo_pd(A0, C0));
    _mm_storeu_pd(&out[1][i], _mm_unpackhi_pd(A0, C0));
    _mm_storeu_pd(&out[3][i], _mm_unpacklo_pd(A3, C3));
    _mm_storeu_pd(&out[4][i], _mm_unpackhi_pd(A3, C3));
    _mm_storeu_pd(&out[8][i], _mm_set_pd(c[8], a[8]));
  }
#endif
  for (; i < m; ++i) {
    const double* a = mats[i].data();
    out[0][i] = a[0], out[1][i] = a[1], out[3][i] = a[3], out[4][i] = a[4], out[8][i] = a[8];
  }
}

/// Whether the m matrices sigma and L all have zero xz, yz, zx, zy entries (an axisymmetric flow
/// without swirl, plane strain): stops at the first one that does not.
inline bool block_in_plane(const Eigen::Matrix3d* sigma, const Eigen::Matrix3d* L, int m) {
  for (int i = 0; i < m; ++i) {
    const double* s = sigma[i].data();
    const double* l = L[i].data();
    const bool zero = (s[2] == 0.0) & (s[5] == 0.0) & (s[6] == 0.0) & (s[7] == 0.0) & (l[2] == 0.0) &
                      (l[5] == 0.0) & (l[6] == 0.0) & (l[7] == 0.0);
    if (!zero) return false;
  }
  return true;
}

/// (1) The E16 trials (begin(): checks, trial, f_m) of the block's points. `Plane`: sigma and L
/// have zero xz, yz, zx, zy entries (advance_batch's `in_plane`), and the trials read and form
/// only the other five (elastic_trial_plane; the same values).
template <bool Plane>
[[gnu::noinline]] void batch_trials(const BatchConsts& k, BatchBlock& b, int m, const Eigen::Matrix3d* sigma,
                                    const Eigen::Matrix3d* L, const double* f, const double* phi) {
  if constexpr (Plane) {
    gather_plane_components(sigma, m, b.bS);
    gather_plane_components(L, m, b.bL);
  } else {
    gather_components(sigma, m, b.bS);
    gather_components(L, m, b.bL);
  }
  const double dt = k.dt, G = k.G, K = k.K;
  const bool step_ok = k.step_ok;
#pragma omp simd
  for (int i = 0; i < m; ++i) {
    T9 Sx, Dx, Wx, sx;
    double pt, tt;
    if constexpr (Plane) {
      Sx.v[0] = b.bS[0][i], Sx.v[1] = b.bS[1][i], Sx.v[2] = 0.0, Sx.v[3] = b.bS[3][i], Sx.v[4] = b.bS[4][i];
      Sx.v[5] = 0.0, Sx.v[6] = 0.0, Sx.v[7] = 0.0, Sx.v[8] = b.bS[8][i];
      const double l0 = b.bL[0][i], l1 = b.bL[1][i], l3 = b.bL[3][i], l4 = b.bL[4][i], l8 = b.bL[8][i];
      Dx.v[0] = 0.5 * (l0 + l0), Dx.v[1] = 0.5 * (l1 + l3), Dx.v[2] = 0.0, Dx.v[3] = 0.5 * (l3 + l1);
      Dx.v[4] = 0.5 * (l4 + l4), Dx.v[5] = 0.0, Dx.v[6] = 0.0, Dx.v[7] = 0.0, Dx.v[8] = 0.5 * (l8 + l8);
      Wx.v[0] = 0.0, Wx.v[1] = 0.5 * (l1 - l3), Wx.v[2] = 0.0, Wx.v[3] = 0.5 * (l3 - l1), Wx.v[4] = 0.0;
      Wx.v[5] = 0.0, Wx.v[6] = 0.0, Wx.v[7] = 0.0, Wx.v[8] = 0.0;
      elastic_trial_plane(Sx, Dx, Wx, dt, G, K, sx, pt, tt);
    } else {
      for (int q = 0; q < 9; ++q) Sx.v[q] = b.bS[q][i];
      for (int jj = 0; jj < 3; ++jj) {
        for (int ii = 0; ii < 3; ++ii) {
          Dx.v[ii + 3 * jj] = 0.5 * (b.bL[ii + 3 * jj][i] + b.bL[jj + 3 * ii][i]);
          Wx.v[ii + 3 * jj] = 0.5 * (b.bL[ii + 3 * jj][i] - b.bL[jj + 3 * ii][i]);
        }
      }
      elastic_trial(Sx, Dx, Wx, dt, G, K, sx, pt, tt);
    }
    const double ff = f[i], ph = phi[i];
    const bool ok = step_ok & point_inputs_valid(ph, ff, Sx, Dx, Wx);  // as begin()
    for (int q = 0; q < 9; ++q) b.t_s[q][i] = sx.v[q];
    b.ok[i] = ok ? 1.0 : 0.0;  // (a bool store here stops the SSE2 vectorisation)
    b.s_f[i] = ff;
    b.s_phi[i] = ph;
    b.s_p_tr[i] = ok ? pt : 1.0;
    b.s_tau_tr[i] = ok ? tt : 1.0;
    b.t_fm[i] = rheology::f_m(*k.steady, ph);
  }
}

/// (2) return_map up to its Newton solves: the branch each point takes, the closed forms and the
/// solves' starts, every candidate computed in every lane with the inline functions and
/// expressions of return_map (so the same values, bit for bit).
[[gnu::noinline]] void batch_classify(const BatchConsts& k, BatchBlock& b, int m) {
  const F1Consts c = k.c;
  const double phi_j = k.phi_j, phi_c = k.phi_c, a_0 = k.a_0, a_inf = k.a_inf, eta_0 = k.eta_0, mu0 = k.mu0;
#pragma omp simd
  for (int i = 0; i < m; ++i) {
    const double ph = b.s_phi[i], p_tr = b.s_p_tr[i], tau_tr = b.s_tau_tr[i];
    const double phi_m = phi_j + (phi_c - phi_j) * b.s_f[i];  // E1
    const double a = a_0 + (a_inf - a_0) * b.s_f[i];          // E2
    const double visc = 2.5 * ph / a * eta_0;
    const double u_eq_below = (phi_m - ph) / (a * ph);
    const double u_eq = ph < phi_m ? u_eq_below : 0.0;
    const double g_max = tau_tr / c.Gdt;
    const double dil = c.Kdt * c.K_3 * ph;
    F1Value e;
    compressive(c, ph, phi_m, a, visc, p_tr, tau_tr, u_eq, e, b.c_g[i], b.c_p[i], b.c_tau[i], b.c_xi2[i]);
    // return_map's beta_of(0) = K_3 (phi - phi_m/(1 + a 0)): phi_m/1 = phi_m exactly (a is finite
    // for valid f), so no division here
    const double fr0 = (mu0 + c.K_3 * (ph - phi_m)) * p_tr;
    b.f1_trial[i] = tau_tr - (fr0 < 0.0 ? 0.0 : fr0);  // E21 at gamma_dot = 0 (std::max(fr0, 0))
    b.dil_p[i] = p_tr + dil * g_max;
    b.e_lo[0][i] = e.g, b.e_lo[1][i] = e.p, b.e_lo[2][i] = e.R, b.e_lo[3][i] = e.be, b.e_lo[4][i] = e.mq;
    b.e_lo[5][i] = e.disc;
    const double g_sep = tau_tr > 0.0 ? g_max : 0.0;
    b.xi1[i] = separated_xi1(c, ph, p_tr, g_sep);  // E22
    b.phi_m[i] = phi_m, b.a[i] = a, b.visc[i] = visc, b.lo[i] = u_eq;
    b.g_max[i] = g_max;
  }
  // The branch (a loop of its own: in the loop above, GCC 12 finds no vector type once these
  // selects are in it)
  int f1_solves = 0, tension_solves = 0;
  for (int i = 0; i < m; ++i) {
    const double ph = b.s_phi[i], p_tr = b.s_p_tr[i], tau_tr = b.s_tau_tr[i];
    // p_tr > 0: elastic (f_1 and f_3 inactive at the trial), the f_1 + f_3 closed form, or the f_1 solve
    const double closed_or_f1 = b.e_lo[2][i] <= 0.0 && b.lo[i] > 0.0 ? kClosedForm : kF1Solve;
    const double kind_c = !(ph < b.phi_m[i]) && b.f1_trial[i] <= 0.0 ? kElasticTrial : closed_or_f1;
    // p_tr <= 0: separated (f_2 active) unless shear dilatancy builds pressure, else the fast path
    const double kind_t = tau_tr > 0.0 && b.dil_p[i] > 0.0 ? kTensionSolve : kSeparatedForm;
    b.kind[i] = p_tr > 0.0 ? kind_c : kind_t;
    f1_solves += b.kind[i] == kF1Solve ? 1 : 0;
    tension_solves += b.kind[i] == kTensionSolve ? 1 : 0;
  }
  // The p_tr <= 0 fast path's starts (a square root and two divisions per lane), only in blocks
  // that have such a solve
  if (tension_solves > 0) {
#pragma omp simd
    for (int i = 0; i < m; ++i) {
      const double dil = c.Kdt * c.K_3 * b.s_phi[i];
      b.tu[i] = tension_start(c, b.phi_m[i], b.a[i], b.s_p_tr[i], dil, b.g_max[i]);
    }
  }
  // The f_1 solves' starts (a quarter of the loop above), only in blocks that have such a solve
  if (f1_solves == 0) return;
#pragma omp simd
  for (int i = 0; i < m; ++i) {
    const F1Value e{b.e_lo[0][i], b.e_lo[1][i], b.e_lo[2][i], b.e_lo[3][i], b.e_lo[4][i], b.e_lo[5][i]};
    f1_start(c, mu0, b.s_phi[i], b.phi_m[i], b.a[i], b.visc[i], b.s_p_tr[i], b.s_tau_tr[i], b.lo[i], b.g_max[i], e,
             b.x[i], b.hi[i]);
  }
}

/// (2b) The results of return_map's closed-form branches (elastic trial, f_1 + f_3, separated) in
/// every lane, as return_map writes them (the lanes of the Newton solves are overwritten after
/// their solves; r_ok: the point's inputs are valid, and a closed form has converged).
[[gnu::noinline]] void batch_closed(BatchBlock& b, int m) {
  constexpr double kEl = static_cast<double>(GranularRegime::kElastic);
  constexpr double kSep = static_cast<double>(GranularRegime::kSeparated);
  constexpr double kSC = static_cast<double>(GranularRegime::kShearCompaction);
  constexpr double kC = static_cast<double>(GranularRegime::kCompaction);
  // (GCC 12 leaves this loop scalar, "control flow in loop", with or without omp simd, like the
  // branch decision in batch_classify; the inputs are loaded unconditionally all the same)
  for (int i = 0; i < m; ++i) {
    const double k = b.kind[i], p_tr = b.s_p_tr[i], tau_tr = b.s_tau_tr[i];
    const double c_tau = b.c_tau[i], c_p = b.c_p[i], c_g = b.c_g[i], c_xi2 = b.c_xi2[i];
    const double g_max = b.g_max[i], xi1 = b.xi1[i];
    const bool el = k == kElasticTrial, cf = k == kClosedForm, sep = k == kSeparatedForm;
    b.r_tau[i] = el ? tau_tr : (cf ? c_tau : 0.0);
    b.r_p[i] = el ? p_tr : (cf ? c_p : 0.0);
    const double g_sep = tau_tr > 0.0 ? g_max : 0.0;
    b.r_g[i] = cf ? c_g : (sep ? g_sep : 0.0);
    b.r_xi1[i] = sep ? xi1 : 0.0;
    b.r_xi2[i] = cf ? c_xi2 : 0.0;
    const double reg_cf = c_g > 0.0 ? kSC : kC;
    const double reg_sep = ((tau_tr > 0.0) | (p_tr < 0.0)) ? kSep : kEl;
    b.r_reg[i] = cf ? reg_cf : (sep ? reg_sep : kEl);
    b.r_res[i] = 0.0;
    b.r_it[i] = 0.0;
    b.r_ok[i] = b.ok[i];
  }
}

/// (4) The ends of the updates (finish()) in lanes: the staggered E24 step and the radial return.
/// e_fast = 0 where finish() itself must run: the return map failed, a result is not finite (or
/// their sum overflows), or the point needs the implicit structure update or the forced f = 1.
[[gnu::noinline]] void batch_finish(const BatchConsts& k, BatchBlock& b, int m) {
  const double K_0 = k.K_0, tau_star = k.tau_star, xi_dot_eps = k.xi_dot_eps, dt = k.dt;
  const double stiff_max = k.stiff_max, phi_forced = k.phi_forced, lanes_ok = k.implicit_always ? 0.0 : 1.0;
#pragma omp simd
  for (int i = 0; i < m; ++i) {
    const double tau = b.r_tau[i], pp = b.r_p[i], gg = b.r_g[i], tau_tr = b.s_tau_tr[i];
    double stiff;
    const double f_new = structure_step(K_0, tau_star, xi_dot_eps, dt, b.s_f[i], b.t_fm[i], b.t_inv_eta_B[i], tau, gg,
                                        stiff);
    const double scale_pos = tau / tau_tr;
    const double scale = tau_tr > 0.0 ? scale_pos : 0.0;
    double sum = f_new + gg + pp;
    for (int q = 0; q < 9; ++q) {
      const double v = scale * b.t_s[q][i] - ((q % 4 == 0) ? pp : 0.0);
      b.e_sig[q][i] = v;
      sum += v;
    }
    b.e_f[i] = f_new;
    const bool fast = (b.r_ok[i] * lanes_ok != 0.0) & !(stiff > stiff_max) & !(b.s_phi[i] >= phi_forced) &
                      (sum - sum == 0.0);
    b.e_fast[i] = fast ? 1.0 : 0.0;
  }
}

/// The Newton solves' lanes (kLanes wide) in SoA.
template <int N>
struct SolveLanes {
  double x[N], lo[N], hi[N], phi[N], phi_m[N], a[N], visc[N], p_tr[N], tau_tr[N], g_max[N];
  double g[N], p[N], R[N], dR[N], status[N];
  int it[N];
  bool final_eval[N];
  SolveLanes() {
    for (int l = 0; l < N; ++l) {  // finite values for lanes that never get a job
      x[l] = lo[l] = hi[l] = g_max[l] = g[l] = 1.0;
      phi[l] = 0.5, phi_m[l] = 0.6, a[l] = 1.0, visc[l] = 1.0, p_tr[l] = 1.0, tau_tr[l] = 1.0;
      p[l] = R[l] = dR[l] = status[l] = 0.0;
      it[l] = 0;
      final_eval[l] = false;
    }
  }
  void load(int l, double ph, double ph_m, double aa, double vi, double pt, double tt) {
    phi[l] = ph, phi_m[l] = ph_m, a[l] = aa, visc[l] = vi, p_tr[l] = pt, tau_tr[l] = tt;
    it[l] = 0;
    final_eval[l] = false;
  }
};

/// One iteration of every lane of the f_1-only solves: R(u) and dR/du at x (return_map's loop).
template <int N>
[[gnu::noinline]] void f1_lanes_value(const F1Consts& c, SolveLanes<N>& s) {
#pragma omp simd
  for (int l = 0; l < N; ++l) {
    F1Value e;
    f1_value(c, s.phi[l], s.phi_m[l], s.a[l], s.visc[l], s.p_tr[l], s.tau_tr[l], s.x[l], e);
    s.g[l] = e.g;
    s.p[l] = e.p;
    s.R[l] = e.R;
    s.dR[l] = f1_slope(c, s.phi_m[l], s.a[l], s.visc[l], s.p_tr[l], s.x[l], e);
  }
}

/// One Newton step of every lane of the p_tr <= 0 fast path (tension_step).
template <int N>
[[gnu::noinline]] void tension_lanes_step(const F1Consts& c, double tol, SolveLanes<N>& s) {
#pragma omp simd
  for (int l = 0; l < N; ++l)
    s.status[l] = tension_step(c, s.phi[l], s.phi_m[l], s.a[l], s.visc[l], s.p_tr[l], s.tau_tr[l], s.g_max[l], tol,
                               s.g[l], s.x[l], s.p[l], s.R[l]);
}

}  // namespace

void GranularLaw::advance_batch(std::int64_t n, Eigen::Matrix3d* sigma, double* f, const Eigen::Matrix3d* L,
                                const double* phi, double dt, GranularStep* step, bool in_plane) const {
  // Blocks of points: (1) the trials in lanes; (2) return_map up to its Newton solves in lanes:
  // the branches, the closed forms' results (elastic, f_1 + f_3, separated) in the block's r_*
  // arrays, and the solves as lists of points (the f_1-only branch; the p_tr <= 0 fast path);
  // (3) their Newton iterations in kLanes lanes, a lane taking the next point when its own is
  // done, the results into r_*; (4) the ends of the updates in lanes.
  // Every point does the arithmetic of advance() in the same order (the same inline functions), so
  // the results are those of advance(), bit for bit; a point whose solve fails in lanes, or that
  // needs the implicit structure update, goes through return_map()/finish() themselves.
  constexpr int kBlock = BatchBlock::kSize;
  constexpr int N = kLanes;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const F1Consts c{K_ * dt, G_ * dt, 2.0 * eta_0_, d2_rho_s_, K_3_, mu_1_, mu_2_, b_};
  BatchConsts kc{};
  kc.c = c;
  kc.dt = dt, kc.G = G_, kc.K = K_, kc.eta_0 = eta_0_;
  kc.phi_j = phi_j_, kc.phi_c = phi_c_, kc.a_0 = a_0_, kc.a_inf = a_inf_, kc.mu0 = mu_q(0.0);
  kc.K_0 = K_0_, kc.tau_star = tau_star_, kc.xi_dot_eps = xi_dot_eps_;
  kc.stiff_max = options_.structure_update == StructureUpdate::kAuto ? options_.stiff_structure : kInf;
  kc.implicit_always = options_.structure_update == StructureUpdate::kImplicit;
  kc.phi_forced = options_.jammed_structure == JammedStructure::kForceOne ? phi_j_ : kInf;
  kc.step_ok = step_inputs_valid(dt, eta_0_);
  kc.steady = &steady_;
  const double tol = options_.rel_tol;
  const int cap = options_.max_iter;
  BatchBlock b;
  for (std::int64_t b0 = 0; b0 < n; b0 += kBlock) {
    const int m = static_cast<int>(std::min<std::int64_t>(kBlock, n - b0));
    int f1_point[kBlock], tj_point[kBlock];
    // ---- (1) trials ----
    // (the in-plane trials also for blocks whose points all happen to be in plane motion)
    if (in_plane || block_in_plane(sigma + b0, L + b0, m)) batch_trials<true>(kc, b, m, sigma + b0, L + b0, f + b0, phi + b0);
    else batch_trials<false>(kc, b, m, sigma + b0, L + b0, f + b0, phi + b0);
    // E8 on its own, in blocks with the powers in vector lanes (inside begin() they serialised
    // with the trial); lanes of invalid points (and past m) get a stand-in phi and then 0
    static_assert(kBlock % numerics::kMathBlock == 0);
    for (int i0 = 0; i0 < m; i0 += numerics::kMathBlock) {
      double x[numerics::kMathBlock], r[numerics::kMathBlock];
      for (int j = 0; j < numerics::kMathBlock; ++j) x[j] = i0 + j < m && b.ok[i0 + j] != 0.0 ? phi[b0 + i0 + j] : 0.5;
      inv_eta_B_block(x, r);
      for (int j = 0; j < numerics::kMathBlock && i0 + j < m; ++j) b.t_inv_eta_B[i0 + j] = b.ok[i0 + j] != 0.0 ? r[j] : 0.0;
    }
    // ---- (2) return_map up to its Newton solves: the branches, the closed forms' results, the
    // solves as lists of points ----
    batch_classify(kc, b, m);
    batch_closed(b, m);
    int n_f1 = 0, n_tj = 0;
    for (int i = 0; i < m; ++i) {  // (branch-free compaction)
      const bool v = b.ok[i] != 0.0;
      f1_point[n_f1] = i;
      n_f1 += v && b.kind[i] == kF1Solve ? 1 : 0;
      tj_point[n_tj] = i;
      n_tj += v && b.kind[i] == kTensionSolve ? 1 : 0;
    }
    // A point's return map from return_map() itself (a failed lane solve), into the block's arrays
    auto store_scalar = [&](int i, const ReturnMap& r) {
      b.r_tau[i] = r.tau, b.r_p[i] = r.p, b.r_g[i] = r.g, b.r_xi1[i] = r.xi1, b.r_xi2[i] = r.xi2;
      b.r_res[i] = r.residual, b.r_reg[i] = static_cast<double>(r.regime), b.r_it[i] = r.iterations;
      b.r_ok[i] = r.converged ? 1.0 : 0.0;
    };
    // ---- (3) the Newton solves in lanes; a result per listed point (res[k] for point list[k]) ----
    struct Result {
      double g, p, u, R;
      int status;  // 1 converged, 2 failed, 3 (tension) step converged: check below
    };
    Result res[kBlock];
    SolveLanes<N> s;
    // (3a) f_1-only branch: Newton in u with bracket [lo, hi] (return_map's scalar loop, same steps)
    run_lanes<N>(
        n_f1,
        [&](int l, int j) {
          const int i = f1_point[j];
          s.load(l, b.s_phi[i], b.phi_m[i], b.a[i], b.visc[i], b.s_p_tr[i], b.s_tau_tr[i]);
          s.x[l] = b.x[i], s.lo[l] = b.lo[i], s.hi[l] = b.hi[i];
        },
        [&] { f1_lanes_value<N>(c, s); },
        [&](int l, int j) {
          if (!s.final_eval[l]) {  // (st == 1: converged at the evaluated x, which f1_step leaves as it was)
            const int st = f1_step(s.R[l], s.dR[l], s.tau_tr[l], tol, s.x[l], s.lo[l], s.hi[l]);
            ++s.it[l];
            if (st == 2) {
              s.final_eval[l] = true;  // evaluate at the new x, then stop
              return false;
            }
            if (st == 0 && s.it[l] < cap) return false;
            if (st == 0) {  // iteration cap
              res[j] = Result{0.0, 0.0, 0.0, 0.0, 2};
              return true;
            }
          }
          res[j] = Result{s.g[l], s.p[l], s.x[l], s.R[l], 1};
          return true;
        });
    for (int k = 0; k < n_f1; ++k) {  // the solved return maps' ends (the scalar path for a failed job)
      const int i = f1_point[k];
      const std::int64_t q = b0 + i;
      const Result& r = res[k];
      const double tau_tr = b.s_tau_tr[i];
      const double residual = std::fabs(r.R) / tau_tr;
      if (r.status == 1 && residual <= 1e-10) {
        b.r_g[i] = r.g;
        b.r_p[i] = r.p;
        b.r_res[i] = residual;
        b.r_reg[i] = static_cast<double>(GranularRegime::kShear);
        // tau_bar from the friction side of E21: accurate even when G dt g >> tau_bar
        b.r_tau[i] = std::min(friction_of(c, b.s_phi[i], b.phi_m[i], b.a[i], b.visc[i], r.g, r.p, r.u), tau_tr);
      } else {
        store_scalar(i, return_map(f[q], phi[q], eta_0_, dt, b.s_p_tr[i], tau_tr));  // the scalar path and its fallback
      }
    }
    // (3b) p_tr <= 0 fast path: Newton on (gamma_dot, u), at most kTensionIterations steps
    run_lanes<N>(
        n_tj,
        [&](int l, int j) {
          const int i = tj_point[j];
          s.load(l, b.s_phi[i], b.phi_m[i], b.a[i], b.visc[i], b.s_p_tr[i], b.s_tau_tr[i]);
          s.g_max[l] = b.g_max[i], s.g[l] = b.g_max[i], s.x[l] = b.tu[i];
        },
        [&] { tension_lanes_step<N>(c, tol, s); },
        [&](int l, int j) {
          ++s.it[l];
          const int st = static_cast<int>(s.status[l]);
          if (st == 0 && s.it[l] < kTensionIterations) return false;
          res[j] = Result{s.g[l], s.p[l], s.x[l], s.R[l], st == 0 ? 2 : st};
          return true;
        });
    for (int k = 0; k < n_tj; ++k) {
      const int i = tj_point[k];
      const std::int64_t q = b0 + i;
      const Result& r = res[k];
      const double ph = b.s_phi[i], phi_m = b.phi_m[i], a = b.a[i], visc = b.visc[i];
      const double p_tr = b.s_p_tr[i], tau_tr = b.s_tau_tr[i];
      bool fast = r.status == 1;
      double gg = r.g, uu = r.u, pp = r.p, residual = std::fabs(r.R) / tau_tr;
      if (r.status == 3)  // return_map's check after a converged step
        fast = tension_accept(c, ph, phi_m, a, visc, p_tr, tau_tr, gg, uu, pp, residual);
      if (!fast) {
        store_scalar(i, return_map(f[q], phi[q], eta_0_, dt, p_tr, tau_tr));  // the nested solve
        continue;
      }
      b.r_g[i] = gg;
      b.r_p[i] = pp;
      b.r_res[i] = residual;
      b.r_tau[i] = std::min(friction_of(c, ph, phi_m, a, visc, gg, pp, uu), tau_tr);
      b.r_reg[i] = static_cast<double>(pp > 0.0 ? GranularRegime::kShear : GranularRegime::kSeparated);
      b.r_xi1[i] = pp <= 0.0 ? separated_xi1(c, ph, p_tr, gg) : 0.0;
    }
    // ---- (4) the ends of the updates in lanes; finish() itself where they cannot be ----
    batch_finish(kc, b, m);
    for (int i = 0; i < m; ++i) {
      const std::int64_t q = b0 + i;
      if (b.ok[i] == 0.0) {
        step[q] = GranularStep{GranularRegime::kElastic, false, 0.0};
        continue;
      }
      const auto regime = static_cast<GranularRegime>(static_cast<int>(b.r_reg[i]));
      if (b.e_fast[i] != 0.0) {
        step[q] = GranularStep{regime, true, b.r_g[i]};
        for (int k = 0; k < 9; ++k) sigma[q].data()[k] = b.e_sig[k][i];
        f[q] = b.e_f[i];
        continue;
      }
      ReturnMap rr;
      rr.tau = b.r_tau[i], rr.p = b.r_p[i], rr.g = b.r_g[i], rr.xi1 = b.r_xi1[i], rr.xi2 = b.r_xi2[i];
      rr.residual = b.r_res[i], rr.regime = regime, rr.converged = b.r_ok[i] != 0.0;
      rr.iterations = static_cast<int>(b.r_it[i]);
      GranularState st;
      for (int k = 0; k < 9; ++k) st.sigma.data()[k] = sigma[q].data()[k];
      st.f = f[q];
      Trial t;
      for (int k = 0; k < 9; ++k) t.s.data()[k] = b.t_s[k][i];
      t.p_tr = b.s_p_tr[i];
      t.tau_tr = b.s_tau_tr[i];
      t.fm = b.t_fm[i];
      t.inv_eta_B = b.t_inv_eta_B[i];
      GranularUpdate out;
      finish<false>(st, t, rr, dt, phi[q], eta_0_, out);
      step[q] = GranularStep{out.regime, out.ok(), out.gamma_dot_p};
      if (!out.ok()) continue;
      for (int k = 0; k < 9; ++k) sigma[q].data()[k] = st.sigma.data()[k];
      f[q] = st.f;
    }
  }
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
      G_, K_, K_0_, granular_.d, granular_.rho_s, u.message ? u.message : "ok", regime_name(u.regime),
      u.iterations, u.residual, before.f, mat(before.sigma), phi, dt, mat(D), mat(W), u.tau_trial, u.p_trial,
      u.tau_bar, u.p, u.gamma_dot_p);
}

void GranularLaw::require_ok(const GranularUpdate& u, const GranularState& before, const Eigen::Matrix3d& D,
                             const Eigen::Matrix3d& W, double dt, double phi) const {
  if (!u.ok()) throw NumericalError(describe(u, before, D, W, dt, phi));
}

}  // namespace oobleck::material
