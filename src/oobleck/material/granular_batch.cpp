// GranularLaw::advance_batch: the law for blocks of points, phase by phase in vector lanes, with the
// point kernels of granular_kernels.hpp that the scalar reference (granular.cpp) uses too, so
// that every point gets the results of advance() bit for bit (the contract: the test
// GranularBatchContract). Performance-sensitive: the lane loops rely on GCC 12 vectorising them
// (`omp simd`, lane functions kept out of line, SSE2 gathers) and on this file's flags in
// CMakeLists.txt (those of granular.cpp). How and why: docs/granular.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "oobleck/material/granular.hpp"
#include "oobleck/material/granular_kernels.hpp"
#include "oobleck/numerics/vector_math.hpp"
#include "oobleck/rheology/f_max.hpp"

namespace oobleck::material {

using namespace granular_kernels;

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
      if (lane_job[l] >= 0)
        load(l, lane_job[l]);
      else
        --active;
    }
  }
}

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
    const bool zero = (s[2] == 0.0) & (s[5] == 0.0) & (s[6] == 0.0) & (s[7] == 0.0) & (l[2] == 0.0) & (l[5] == 0.0) &
                      (l[6] == 0.0) & (l[7] == 0.0);
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
    const double f_new =
        structure_step(K_0, tau_star, xi_dot_eps, dt, b.s_f[i], b.t_fm[i], b.t_inv_eta_B[i], tau, gg, stiff);
    const double scale_pos = tau / tau_tr;
    const double scale = tau_tr > 0.0 ? scale_pos : 0.0;
    double sum = f_new + gg + pp;
    for (int q = 0; q < 9; ++q) {
      const double v = scale * b.t_s[q][i] - ((q % 4 == 0) ? pp : 0.0);
      b.e_sig[q][i] = v;
      sum += v;
    }
    b.e_f[i] = f_new;
    const bool fast =
        (b.r_ok[i] * lanes_ok != 0.0) & !(stiff > stiff_max) & !(b.s_phi[i] >= phi_forced) & (sum - sum == 0.0);
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
    if (in_plane || block_in_plane(sigma + b0, L + b0, m))
      batch_trials<true>(kc, b, m, sigma + b0, L + b0, f + b0, phi + b0);
    else
      batch_trials<false>(kc, b, m, sigma + b0, L + b0, f + b0, phi + b0);
    // E8 on its own, in blocks with the powers in vector lanes (inside begin() they serialised
    // with the trial); lanes of invalid points (and past m) get a stand-in phi and then 0
    static_assert(kBlock % numerics::kMathBlock == 0);
    for (int i0 = 0; i0 < m; i0 += numerics::kMathBlock) {
      double x[numerics::kMathBlock], r[numerics::kMathBlock];
      for (int j = 0; j < numerics::kMathBlock; ++j) x[j] = i0 + j < m && b.ok[i0 + j] != 0.0 ? phi[b0 + i0 + j] : 0.5;
      inv_eta_B_block(x, r);
      for (int j = 0; j < numerics::kMathBlock && i0 + j < m; ++j)
        b.t_inv_eta_B[i0 + j] = b.ok[i0 + j] != 0.0 ? r[j] : 0.0;
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

}  // namespace oobleck::material
