#include "oobleck/material/granular.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
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

/// x^alpha for alpha >= 0, with small integer exponents by multiplication (E8 is evaluated per call);
/// int_alpha: alpha as an int when it is a whole number <= 8, else INT_MIN (GranularLaw::kNonInteger).
inline double pow_term(double x, double alpha, int int_alpha, double& log_x, bool& have_log) {
  if (int_alpha != std::numeric_limits<int>::min()) {
    double y = 1.0;
    for (int k = 0; k < int_alpha; ++k) y *= x;
    return y;
  }
  if (!have_log) {
    log_x = std::log(x);
    have_log = true;
  }
  return std::exp(alpha * log_x);
}

/// m.allFinite() without branches: x * 0 is NaN exactly when x is infinite or NaN.
inline bool finite3(const Eigen::Matrix3d& m) {
  const double* x = m.data();
  double z = 0.0;
  for (int i = 0; i < 9; ++i) z += x[i] * 0.0;
  return z == 0.0;
}

/// E16 trial sig + dt (2 G D + W sig - sig W) + dt (K - 2G/3) tr(D) 1, written out so that it inlines.
/// Every sum is formed in the order of the Eigen 3.4 expression it replaces (the SSE2 lazy product
/// sums rows 0-1 as (k0 + k1) + k2 and row 2 as k0 + (k1 + k2); the trace is d00 + (d11 + d22)), so
/// the result is the same bit for bit. (For W = skew(L), with its zero diagonal, the order is moot.)
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void jaumann_trial(const Eigen::Matrix3d& S, const Eigen::Matrix3d& D, const Eigen::Matrix3d& W, double dt,
                          double G, double K, Eigen::Matrix3d& r) {
  const double two_G = 2.0 * G;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      double ws, sw;
      if (i < 2) {
        ws = (W(i, 0) * S(0, j) + W(i, 1) * S(1, j)) + W(i, 2) * S(2, j);
        sw = (S(i, 0) * W(0, j) + S(i, 1) * W(1, j)) + S(i, 2) * W(2, j);
      } else {
        ws = W(i, 0) * S(0, j) + (W(i, 1) * S(1, j) + W(i, 2) * S(2, j));
        sw = S(i, 0) * W(0, j) + (S(i, 1) * W(1, j) + S(i, 2) * W(2, j));
      }
      r(i, j) = S(i, j) + dt * ((two_G * D(i, j) + ws) - sw);
    }
  }
  const double trD = D(0, 0) + (D(1, 1) + D(2, 2));
  const double vol = dt * (K - two_G / 3.0) * trD;
  for (int i = 0; i < 3; ++i) r(i, i) += vol;
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
  auto friction = [&](double gg, double pp, double uu) {
    if (!(pp > 0.0)) return 0.0;
    if (!(uu > 0.0)) return std::max((mu_q(0.0) + beta_of(0.0)) * pp, 0.0);
    return std::max((mu_q(uu) + beta_of(uu)) * pp + visc * gg / uu, 0.0);
  };

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
      // Fast path, parametrised by u = I_m >= u_eq (beta >= 0, xi_dot_2 = 0): for given u the
      // pressure balance p = p_tr + K dt beta(u) gamma_dot with p = Q(gamma_dot)/u^2 is a quadratic
      // in gamma_dot with one positive root; R(u) = tau_tr - G dt gamma_dot - (mu_p + beta) p is the
      // E21 residual (decreasing in u, see docs/granular.md).
      // The value (g, p, R) and the derivatives (dg, dp, dR) are separate steps: the f_1 + f_3
      // branch below needs only the value at u_eq.
      struct Eval {
        double g, dg, p, dp, R, dR;
        double u, be, mq, disc, gv;  // intermediates of the value reused by the derivatives
      };
      auto eval_value = [&](double uu) {
        Eval e{};
        e.u = uu;
        e.be = beta_of(uu);
        const double A2 = d2_rho_s_;
        const double B2 = two_eta - Kdt * e.be * uu * uu;
        const double C2 = p_tr * uu * uu;
        e.disc = std::sqrt(B2 * B2 + 4.0 * A2 * C2);
        e.g = B2 >= 0.0 ? 2.0 * C2 / (B2 + e.disc) : (e.disc - B2) / (2.0 * A2);
        e.p = p_tr + Kdt * e.be * e.g;
        e.mq = mu_q(uu);
        // viscous friction term of E20 times p: (5/2) phi/a * I_v/I_m * p = visc * g/u
        e.gv = uu > 0.0 ? e.g / uu : 0.0;
        e.R = tau_tr - Gdt * e.g - (e.mq + e.be) * e.p - visc * e.gv;
        return e;
      };
      auto eval_derivatives = [&](Eval& e) {
        const double uu = e.u, be = e.be, dbe = dbeta_of(uu);
        const double dB2 = -Kdt * (dbe * uu * uu + 2.0 * be * uu);
        const double dC2 = 2.0 * p_tr * uu;
        e.dg = e.disc > 0.0 ? (dC2 - dB2 * e.g) / e.disc : 0.0;
        e.dp = Kdt * (dbe * e.g + be * e.dg);
        const double dmq = b_ == 0.0 ? 0.0 : (mu_2_ - mu_1_) * b_ / ((uu + b_) * (uu + b_));
        const double dgv = uu > 0.0 ? e.dg / uu - e.g / (uu * uu)
                                    : p_tr / two_eta;  // g ~ p_tr u^2/(2 eta_0) as u -> 0
        e.dR = -Gdt * e.dg - (dmq + dbe) * e.p - (e.mq + be) * e.dp - visc * dgv;
      };
      auto eval = [&](double uu) {
        Eval e = eval_value(uu);
        eval_derivatives(e);
        return e;
      };
      Eval e_lo = eval_value(u_eq);
      if (e_lo.R <= 0.0 && u_eq > 0.0) {
        // -------- f_1 + f_3 (E21, E23 with K_4 = 0): beta = 0, I_m = u_eq; closed form ----------
        // tau_tr - G dt g = mu_q p + visc g/u_eq with p = Q(g)/u_eq^2: quadratic A g^2 + B g - C = 0.
        const double mq = mu_q(u_eq);
        const double u2 = u_eq * u_eq;
        const double A = mq * d2_rho_s_;
        const double B = Gdt * u2 + mq * two_eta + visc * u_eq;
        const double C = tau_tr * u2;
        g = 2.0 * C / (B + std::sqrt(B * B + 4.0 * A * C));
        p = std::min(Q_of(g) / u2, p_tr);  // <= p_tr by construction; min guards round-off
        // tau_bar from the friction side of E21 (tau_tr - G dt g cancels when G dt g >> tau_bar)
        tau = std::min(mq * p + visc * g / u_eq, tau_tr);
        u = u_eq;
        xi2 = std::min((p - p_tr) / Kdt, 0.0);  // E23: xi_dot_2 <= 0
        regime = g > 0.0 ? GranularRegime::kShearCompaction : GranularRegime::kCompaction;
      } else {
        // -------- f_1 only: root of R(u) on [u_lo, u_hi] --------
        eval_derivatives(e_lo);
        double lo = u_eq, hi;
        // Upper bracket: with beta >= 0, gamma_dot(u) >= the beta = 0 root, so gamma_dot(u_hi) >= gamma_max
        // when Q(gamma_max)/u_hi^2 <= p_tr; there R <= -(mu_p + beta) p < 0.
        hi = std::max(u_eq, std::sqrt(Q_of(g_max) / p_tr)) * (1.0 + 1e-12) + 1e-300;
        // Initial guess: rigid-plastic, viscous balance tau_tr/p_tr = mu_q + beta(u) + (5/4)(phi/a) u
        // (drop G dt, K dt): c1 a u^2 + (c1 - r a) u - (r + K_3 phi_m) = 0.
        double x;
        {
          const double c1 = 1.25 * phi / a;
          const double r = tau_tr / p_tr - mu0 - K_3_ * phi;
          const double qa = c1 * a, qb = c1 - r * a, qc = -(r + K_3_ * phi_m);
          const double disc = qb * qb - 4.0 * qa * qc;
          x = (qc < 0.0 && disc >= 0.0) ? (qb <= 0.0 ? (-qb + std::sqrt(disc)) / (2.0 * qa)
                                                      : -2.0 * qc / (qb + std::sqrt(disc)))
                                        : 0.5 * (lo + hi);
          if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
          // Near a steady state the root sits just above u_eq: a Newton step from the lower end is better.
          if (e_lo.dR < 0.0) {
            const double xn = lo - e_lo.R / e_lo.dR;
            if (xn > lo && xn < x) x = xn;
          }
        }
        Eval e{};
        converged = false;
        for (iterations = 1; iterations <= cap; ++iterations) {
          e = eval(x);
          if (std::fabs(e.R) <= 1e-14 * tau_tr) {
            converged = true;
            break;
          }
          if (e.R > 0.0) lo = x; else hi = x;
          double next = (e.dR < 0.0) ? x - e.R / e.dR : -1.0;
          const bool newton = next > lo && next < hi;
          if (!newton) next = (lo > 0.0 && hi > 4.0 * lo) ? std::sqrt(lo * hi) : 0.5 * (lo + hi);
          if ((newton && std::fabs(next - x) <= tol * x) || (hi - lo) <= tol * hi) {
            x = next;
            e = eval(x);
            converged = true;
            break;
          }
          x = next;
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
      xi1 = std::max(-p_tr / Kdt - K_3_ * phi * g, 0.0);  // E22: p = p_tr + K dt (beta g + xi_1) = 0
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
        double gg = g_max;
        double uu = 0.0;
        {
          const double S = p_tr + dil * gg, ck = Kdt * gg;
          uu = std::sqrt(Q_of(gg) / S);
          if (p_tr < 0.0) uu = std::max(uu, (phi_m * ck * K_3_ / S - 1.0) / a);
        }
        bool step_ok = false;
        for (int k = 1; k <= 8; ++k) {
          ++iterations;
          const double iu = 1.0 / uu;
          const double Qp = 2.0 * gg * d2_rho_s_ + two_eta;
          const double pp = Q_of(gg) * iu * iu;
          const double iq = 1.0 / (1.0 + a * uu);
          const double be = K_3_ * (phi - phi_m * iq), dbe = K_3_ * phi_m * a * iq * iq;
          const double mq = mu_q(uu);
          const double dmq = b_ == 0.0 ? 0.0 : (mu_2_ - mu_1_) * b_ / ((uu + b_) * (uu + b_));
          const double h = pp - p_tr - Kdt * gg * be;
          const double Rr = tau_tr - Gdt * gg - (mq + be) * pp - visc * gg * iu;
          // residual exit with the tolerances of the nested solve (|R| <= 1e-14 tau_tr, pressure
          // balance to 1e-15 of its terms)
          if (std::fabs(Rr) <= 1e-14 * tau_tr && std::fabs(h) <= 1e-15 * (std::fabs(p_tr) + pp) && be >= 0.0) {
            fast = true;
            g = gg;
            u = uu;
            p = pp;
            residual = std::fabs(Rr) / tau_tr;
            break;
          }
          const double hg = Qp * iu * iu - Kdt * be, hu = -2.0 * pp * iu - Kdt * gg * dbe;
          const double Rg = -Gdt - (mq + be) * Qp * iu * iu - visc * iu;
          const double Ru = -(dmq + dbe) * pp + 2.0 * (mq + be) * pp * iu + visc * gg * iu * iu;
          const double det = hg * Ru - hu * Rg;
          if (!(std::fabs(det) > 0.0)) break;
          const double dg = (hu * Rr - h * Ru) / det;
          const double du = (h * Rg - hg * Rr) / det;
          gg += dg;
          uu += du;
          if (!(gg > 0.0 && gg <= g_max && uu > 0.0 && std::isfinite(uu))) break;
          if (std::fabs(dg) <= tol * gg && std::fabs(du) <= tol * uu) {
            step_ok = true;
            break;
          }
        }
        if (step_ok && !fast) {
          const double pp = Q_of(gg) / (uu * uu);
          const double be = beta_of(uu);
          const double h = pp - p_tr - Kdt * gg * be;
          const double Rr = tau_tr - Gdt * gg - (mu_q(uu) + be) * pp - visc * gg / uu;
          const double res = std::fabs(Rr) / tau_tr;
          if (pp > 0.0 && be >= 0.0 && res <= 1e-10 && std::fabs(h) <= 1e-12 * (std::fabs(p_tr) + pp + Kdt * gg * be)) {
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
      if (p <= 0.0) xi1 = std::max(-p_tr / Kdt - K_3_ * phi * g, 0.0);
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
  out.f_old = state.f;
  // ---- input checks (never throw in the hot loop; report instead) ----
  if (!(dt > 0.0 && std::isfinite(dt)) || !(phi > 0.0 && phi < 1.0) || !(eta_0 > 0.0 && std::isfinite(eta_0)) ||
      !(state.f >= 0.0 && state.f <= 1.0) || !finite3(state.sigma) || !finite3(D) || !finite3(W)) {
    out.finite = false;
    out.converged = false;
    out.message = "invalid input: need dt > 0, 0 < phi < 1, eta_0 > 0, f in [0, 1] and finite sigma, D, W";
    return out;
  }
  const double fn = state.f;
  out.jammed = phi >= phi_j_;

  // ---- E16: elastic trial (D^p = 0), explicit Jaumann rotation with sigma_n ----
  Eigen::Matrix3d s_tr;  // the trial stress, then its deviator
  jaumann_trial(state.sigma, D, W, dt, G_, K_, s_tr);
  const double p_tr = -s_tr.trace() / 3.0;
  s_tr.diagonal().array() += p_tr;  // dev sigma_tr
  const double tau_tr = std::sqrt(0.5 * s_tr.squaredNorm());
  out.tau_trial = tau_tr;
  out.p_trial = p_tr;

  // ---- E24 ingredients that depend on phi only: f_m (E9), 1/eta_B (E8) ----
  const double fm = rheology::f_m(steady_, phi);
  double inv_eta_B = 0.0;
  if (const double gap = phi_j_ - phi; gap > 0.0) {
    double lg = 0.0;
    bool have = false;
    for (std::size_t i = 0; i < steady_.eta_B_terms.size(); ++i) {
      const rheology::EtaBTerm& t = steady_.eta_B_terms[i];
      inv_eta_B += t.phi_i * pow_term(gap, t.alpha, eta_B_int_alpha_[i], lg, have);
    }
  }
  // Linearly implicit E24 step with end-of-step tau_bar, gamma_dot^p: f = (f_n + dt H' f_m)/(1 + dt (H' + S')),
  // H' = K_0 gamma_dot^p (tau_bar/tau*)^{3/2}, S' = K_0 (gamma_dot^p + tau_bar/eta_B + xi_dot_eps); `stiff` = dt (H' + S').
  auto f_next = [&](const ReturnMap& r, double& stiff) {
    const double x = r.tau / tau_star_;
    const double Hp = K_0_ * r.g * x * std::sqrt(x);
    const double Sp = K_0_ * (r.g + r.tau * inv_eta_B + xi_dot_eps_);
    stiff = dt * (Hp + Sp);
    return std::clamp((fn + dt * Hp * fm) / (1.0 + stiff), 0.0, 1.0);
  };

  // ---- return map with f_n, then the structure update ----
  ReturnMap r = return_map(fn, phi, eta_0, dt, p_tr, tau_tr);
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
    return out;
  }
  if (!out.converged && out.message == nullptr) out.message = "return map did not converge within the iteration cap";
  for (int i = 0; i < 9; ++i) state.sigma.data()[i] = sig.data()[i];
  state.f = f_new;
  return out;
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
