#pragma once
// Grid fields and the particle↔grid kernels of one body (docs/mpm.md, "The step": P2G, grid, G2P).
// Free functions over the body's arrays, the shape cache and the body's grid field, each over a
// range of points or nodes; which thread runs which range is decided in parallel.hpp.
//
// Race-free, deterministic scatter: each thread accumulates P2G into its own copy of the nodal
// arrays (thread 0 into the field itself) over its static share of the points; the copies are
// then summed node by node in thread order. For a fixed thread count the result is bitwise
// reproducible.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/shape.hpp"
#include "oobleck/numerics/vector_math.hpp"

namespace oobleck::mpm {

// Full unrolling of the S-node loops of the factorised transfers (S ≤ 4).
#if defined(__GNUC__) && !defined(__clang__)
#define OOBLECK_UNROLL _Pragma("GCC unroll 4")
#else
#define OOBLECK_UNROLL
#endif

/// Velocity transfer of G2P: FLIP/PIC blend (α = flip_fraction; 1 = pure FLIP, 0 = PIC) or APIC.
enum class Transfer { FlipPicBlend, Apic };

/// Nodal fields of one body on the grid.
template <class G>
struct GridField {
  static constexpr int NC = G::ncomp;
  std::vector<double> mass_kg;
  std::vector<Vec<NC>> momentum;      ///< [kg m/s] after P2G
  std::vector<Vec<NC>> force_N;       ///< internal + body forces (+ coupling) [N]
  std::vector<Vec<NC>> velocity_old;  ///< momentum/mass before the force update [m/s]
  std::vector<Vec<NC>> velocity;      ///< updated velocity after boundary conditions [m/s]
  // Fluid phase only (P2G with `split_pressure`): ∑_p V_p p_p ∇N_ip [N] (split by porosity, E28)
  // and the nodal mixture volume ∑_p N_ip V_p [m^D].
  std::vector<Vec<NC>> pressure_force_N;
  std::vector<double> volume_m3;
  // Friction walls: real normal momentum [kg m/s], force [N] and mass difference [kg] of the
  // wall-layer node pairs, recorded when folding (boundary.hpp).
  std::vector<double> wall_normal_momentum, wall_normal_force, wall_mass_difference;
  // Per-thread scatter copies for threads 1 … T−1 (thread 0 writes into the arrays above).
  std::vector<std::vector<double>> t_mass, t_volume;
  std::vector<std::vector<Vec<NC>>> t_momentum, t_force, t_pressure;

  void resize(int nodes, int threads) {
    const auto n = static_cast<std::size_t>(nodes);
    mass_kg.assign(n, 0.0);
    momentum.assign(n, Vec<NC>::Zero());
    force_N.assign(n, Vec<NC>::Zero());
    velocity_old.assign(n, Vec<NC>::Zero());
    velocity.assign(n, Vec<NC>::Zero());
    pressure_force_N.assign(n, Vec<NC>::Zero());
    volume_m3.assign(n, 0.0);
    wall_normal_momentum.assign(n, 0.0);
    wall_normal_force.assign(n, 0.0);
    wall_mass_difference.assign(n, 0.0);
    const auto extra = static_cast<std::size_t>(threads > 1 ? threads - 1 : 0);
    t_mass.assign(extra, std::vector<double>(n, 0.0));
    t_momentum.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_force.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_pressure.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_volume.assign(extra, std::vector<double>(n, 0.0));
  }
  int nodes() const { return static_cast<int>(mass_kg.size()); }
  int max_threads() const { return static_cast<int>(t_mass.size()) + 1; }
  /// The nodal arrays and their halo rules (fields.hpp; docs/mpi.md): P2G's sums (with
  /// `split_pressure`, the fluid's, also its pressure force and mixture volume) are completed on
  /// their owners, the velocities copied out from them; the friction walls' records stay local.
  void declare_nodal_fields(NodalFieldList& list, bool split_pressure) {
    const HaloRule fluid_sums = split_pressure ? HaloRule::sum_after_p2g : HaloRule::none;
    list.add("mass", mass_kg, HaloRule::sum_after_p2g);
    list.add("momentum", momentum, HaloRule::sum_after_p2g);
    list.add("force", force_N, HaloRule::sum_after_p2g);
    list.add("pressure_force", pressure_force_N, fluid_sums);
    list.add("volume", volume_m3, fluid_sums);
    list.add("velocity", velocity, HaloRule::copy_before_flux);
    list.add("velocity_old", velocity_old, HaloRule::copy_before_flux);
    list.add("wall_normal_momentum", wall_normal_momentum, HaloRule::none);
    list.add("wall_normal_force", wall_normal_force, HaloRule::none);
    list.add("wall_mass_difference", wall_mass_difference, HaloRule::none);
  }
};

namespace detail {
using V2 = Eigen::Matrix<double, 2, 1>;

/// The second axis' factors of a 2D stencil for the factorised transfers, each in both SIMD
/// lanes: per support node j1, N_1, N'_1 and N_1 o_1, and (N_1, N'_1) side by side.
template <int S>
struct SecondAxisFactors {
  V2 w[S], dw[S], wo[S], w_dw[S];
  // (always inlined: P2G and G2P per point, their factors in registers)
#if defined(__GNUC__)
  [[gnu::always_inline]]
#endif
  explicit SecondAxisFactors(const Stencil<2, S>& st) {
    for (int j1 = 0; j1 < S; ++j1) {
      w_dw[j1] = V2(st.w[j1][1], st.dw[j1][1]);
      w[j1] = V2::Constant(st.w[j1][1]);
      dw[j1] = V2::Constant(st.dw[j1][1]);
      wo[j1] = V2::Constant(st.w[j1][1] * st.off[j1][1]);
    }
  }
};

/// A point's terms of P2G (particles_to_grid_point_inlined): m_p, V_p, V_p p (the fluid's pressure
/// split), V_p σ (or V_p τ) and C by columns, v, the point force f_pt (external load, and the
/// axisymmetric hoop and inertial terms) and the pressure's hoop term. Components 0–1 as one
/// 2-vector (one SIMD register), component 2 (if any) as a scalar.
template <int D>
struct P2GPointTerms {
  double mp = 0.0, Vp = 0.0, Vpres = 0.0;
  V2 Vsig2[D], Cp2[D], v2, fpt2;
  double Vsig3[D], Cp3[D], v3 = 0.0, fpt3 = 0.0, fppt[3] = {0.0, 0.0, 0.0};
};

template <class G, bool Split>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline P2GPointTerms<G::dim>
p2g_point_terms(const Body<G>& body, std::int64_t p) {
  constexpr int D = G::dim, NC = G::ncomp;
  P2GPointTerms<D> t;
  const double mp = body.mass_kg[p], Vp = body.volume_m3[p];
  const Vec<NC> vp = body.v_m_s[p];
  Mat3 sig = body.stress_Pa[p];
  double Vpres = 0.0;
  if constexpr (Split) {
    const double pres = -sig.trace() * (1.0 / 3.0);  // × 1/3, not ÷ 3: no division latency per point
    sig.diagonal().array() += pres;                  // τ = σ + p 1
    Vpres = Vp * pres;
  }
  double Vsig[D][NC], Cp[D][NC], v[NC], fpt[NC], fppt[NC];
  for (int a = 0; a < D; ++a)
    for (int c = 0; c < NC; ++c) {
      Vsig[a][c] = Vp * sig(c, a);
      Cp[a][c] = body.C_1_s[p](c, a);
    }
  // Axisymmetric: hoop and inertial terms, applied with weight N_ip (zero-cost otherwise).
  Vec<NC> f_point = body.f_ext_N[p];  // external point load
  if constexpr (G::has_hoop_terms) {
    const Vec<D>& xp = body.x_m[p];
    f_point += G::hoop_force(sig, xp, Vp) + mp * G::inertial_acceleration(xp, vp);
    if constexpr (Split) {
      const Vec<NC> h = G::hoop_force(-(Vpres / Vp) * Mat3::Identity(), xp, Vp);
      for (int c = 0; c < NC; ++c) fppt[c] = h[c];
    }
  }
  for (int c = 0; c < NC; ++c) {
    v[c] = vp[c];
    fpt[c] = f_point[c];
  }
  // Components 0–1 as one 2-vector (one SIMD register), component 2 (if any) as a scalar.
  V2 Vsig2[D], Cp2[D];
  double Vsig3[D], Cp3[D];
  for (int a = 0; a < D; ++a) {
    Vsig2[a] = V2(Vsig[a][0], Vsig[a][1]);
    Cp2[a] = V2(Cp[a][0], Cp[a][1]);
    Vsig3[a] = NC == 3 ? Vsig[a][NC - 1] : 0.0;
    Cp3[a] = NC == 3 ? Cp[a][NC - 1] : 0.0;
  }
  const V2 v2(v[0], v[1]), fpt2(fpt[0], fpt[1]);
  const double v3 = v[NC - 1], fpt3 = fpt[NC - 1];
  t.mp = mp, t.Vp = Vp, t.Vpres = Vpres;
  for (int a = 0; a < D; ++a) {
    t.Vsig2[a] = Vsig2[a], t.Cp2[a] = Cp2[a];
    t.Vsig3[a] = Vsig3[a], t.Cp3[a] = Cp3[a];
  }
  t.v2 = v2, t.fpt2 = fpt2, t.v3 = v3, t.fpt3 = fpt3;
  if constexpr (G::has_hoop_terms && Split)
    for (int c = 0; c < NC; ++c) t.fppt[c] = fppt[c];
  return t;
}

/// P2G's scatter of point p on a 2D grid, the tensor product factorised (docs/mpm.md, "Data
/// layout"): with N = N_0 N_1, ∇N = (N'_0 N_1, N_0 N'_1) and x_i − x_p = (o_0, o_1), every nodal
/// term is N_1 (a per-row value) + N'_1 or N_1 o_1 (another per-row value); the per-row values are
/// formed once for each of the S rows j0, so a node costs a few multiply-adds.
template <class G, int K, bool Apic, bool Split, bool NoSwirl>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
p2g_scatter_point_2d(const P2GPointTerms<G::dim>& t, const ShapeCache<G::dim>& cache, std::int64_t p, double* m,
                     double* mv, double* f, double* fp, double* vol) {
  constexpr int D = G::dim, NC = G::ncomp, S = support_of<D>(K);
  constexpr bool kTheta = NC == 3 && !NoSwirl;  // the third component's nodal terms
  const double mp = t.mp, Vp = t.Vp, Vpres = t.Vpres;
  const V2 *Vsig2 = t.Vsig2, *Cp2 = t.Cp2;
  const double *Vsig3 = t.Vsig3, *Cp3 = t.Cp3, *fppt = t.fppt;
  const V2 v2 = t.v2, fpt2 = t.fpt2;
  const double v3 = t.v3, fpt3 = t.fpt3;
  (void)Vp, (void)Vpres, (void)Cp2, (void)Cp3, (void)fppt, (void)v3, (void)fpt3;
  const Stencil<D, S>& st = cache.template stencil<S>(p);
  const SecondAxisFactors<S> a1(st);
  OOBLECK_UNROLL
  for (int j0 = 0; j0 < S; ++j0) {
    const double w0 = st.w[j0][0], dw0 = st.dw[j0][0], o0 = st.off[j0][0];
    const double P = mp * w0;  // m_p N_0
    // momentum: N m_p (v + C (x_i − x_p)) = N_1 P (v + C_0 o_0) + N_1 o_1 P C_1
    V2 U2 = P * v2, Vc2 = V2::Zero();
    double U3 = P * v3, Vc3 = 0.0;
    if constexpr (Apic) {
      U2 = P * (v2 + Cp2[0] * o0);
      Vc2 = P * Cp2[1];
      U3 = P * (v3 + Cp3[0] * o0);
      Vc3 = P * Cp3[1];
    }
    // force: −V σ ∇N + N f_pt = N_1 (N_0 f_pt − N'_0 V σ_0) − N'_1 N_0 V σ_1
    const V2 E2 = w0 * fpt2 - dw0 * Vsig2[0], nB2 = -w0 * Vsig2[1];
    const double E3 = w0 * fpt3 - dw0 * Vsig3[0], nB3 = -w0 * Vsig3[1];
    const V2 PV2(Vpres * dw0, Vpres * w0);
    const int row = st.index[j0][0];
    OOBLECK_UNROLL
    for (int j1 = 0; j1 < S; ++j1) {
      const int i = row + st.index[j1][1];
      const double w1 = st.w[j1][1], dw1 = st.dw[j1][1];
      double* mvi = mv + static_cast<std::int64_t>(i) * NC;
      double* fi = f + static_cast<std::int64_t>(i) * NC;
      m[i] += P * w1;
      Eigen::Map<V2> mvi2(mvi), fi2(fi);
      if constexpr (Apic)
        mvi2 += a1.w[j1].cwiseProduct(U2) + a1.wo[j1].cwiseProduct(Vc2);
      else
        mvi2 += a1.w[j1].cwiseProduct(U2);
      fi2 += a1.w[j1].cwiseProduct(E2) + a1.dw[j1].cwiseProduct(nB2);
      if constexpr (kTheta) {
        if constexpr (Apic)
          mvi[2] += w1 * U3 + (w1 * st.off[j1][1]) * Vc3;
        else
          mvi[2] += w1 * U3;
        fi[2] += w1 * E3 + dw1 * nB3;
      }
      if constexpr (Split) {
        double* fpi = fp + static_cast<std::int64_t>(i) * NC;
        Eigen::Map<V2>(fpi) += PV2.cwiseProduct(a1.w_dw[j1]);            // V_p p (N'_0 N_1, N_0 N'_1)
        if constexpr (G::has_hoop_terms) fpi[0] += w1 * (w0 * fppt[0]);  // (its z and θ entries are zeros: left out)
        vol[i] += (w0 * Vp) * w1;
      }
    }
  }
}

/// P2G's scatter of point p node by node (3D).
template <class G, int K, bool Apic, bool Split, bool NoSwirl>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
p2g_scatter_point_general(const P2GPointTerms<G::dim>& t, const ShapeCache<G::dim>& cache, std::int64_t p, double* m,
                          double* mv, double* f, double* fp, double* vol) {
  constexpr int D = G::dim, NC = G::ncomp, S = support_of<D>(K);
  const double mp = t.mp, Vp = t.Vp, Vpres = t.Vpres;
  const V2 *Vsig2 = t.Vsig2, *Cp2 = t.Cp2;
  const double *Vsig3 = t.Vsig3, *Cp3 = t.Cp3, *fppt = t.fppt;
  const V2 v2 = t.v2, fpt2 = t.fpt2;
  const double v3 = t.v3, fpt3 = t.fpt3;
  (void)Vp, (void)Vpres, (void)Cp2, (void)Cp3, (void)fppt, (void)v3, (void)fpt3;
  for_each_node<D, S>(cache.template stencil<S>(p), [&](int i, double w, const double* g, const double* off) {
    const double wm = w * mp;
    double* mvi = mv + static_cast<std::int64_t>(i) * NC;
    double* fi = f + static_cast<std::int64_t>(i) * NC;
    m[i] += wm;
    Eigen::Map<V2> mvi2(mvi), fi2(fi);
    if constexpr (Apic) {
      V2 cx = Cp2[0] * off[0];
      for (int a = 1; a < D; ++a) cx += Cp2[a] * off[a];
      mvi2 += wm * (v2 + cx);
      if constexpr (NC == 3) {
        double cx3 = Cp3[0] * off[0];
        for (int a = 1; a < D; ++a) cx3 += Cp3[a] * off[a];
        mvi[2] += wm * (v3 + cx3);
      }
    } else {
      (void)off;
      mvi2 += wm * v2;
      if constexpr (NC == 3) mvi[2] += wm * v3;
    }
    {
      V2 s2 = Vsig2[0] * g[0];
      for (int a = 1; a < D; ++a) s2 += Vsig2[a] * g[a];
      fi2 -= s2;
      fi2 += w * fpt2;
      if constexpr (NC == 3) {
        double s3 = Vsig3[0] * g[0];
        for (int a = 1; a < D; ++a) s3 += Vsig3[a] * g[a];
        fi[2] -= s3;
        fi[2] += w * fpt3;
      }
    }
    if constexpr (Split) {
      double* fpi = fp + static_cast<std::int64_t>(i) * NC;
      for (int a = 0; a < D; ++a) fpi[a] += Vpres * g[a];
      if constexpr (G::has_hoop_terms)
        for (int c = 0; c < NC; ++c) fpi[c] += w * fppt[c];
      vol[i] += w * Vp;
    }
  });
}

/// Scatter of point p (P2G, see p2g_scatter_range), with the APIC and
/// split-pressure branches resolved at compile time and scalar per-point temporaries (no
/// stack round trips of Eigen 3-vectors in the node loop). Arithmetic order per component is that
/// of the Eigen expressions it replaces.
///
/// NoSwirl (axisymmetric only, see point_without_swirl): the point's θ entries of v, C, σ and f_ext
/// are zero, so all its θ terms on the nodes are zeros (of either sign) and adding them to the
/// nodal sums (which start at +0) changes no bit: they are left out.
///
/// Always inlined: p2g_scatter_range calls it through particles_to_grid_point (axisymmetric) or
/// inlines it into its loop over the points (plane strain, 3D; callgrind, wheel set-up: 1.4% fewer
/// instructions per step; for the axisymmetric kernels GCC's own choice, a call, is the shorter).
template <class G, int K, bool Apic, bool Split, bool NoSwirl = false>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
particles_to_grid_point_inlined(const Body<G>& body, const ShapeCache<G::dim>& cache, std::int64_t p, double* m,
                                double* mv, double* f, double* fp, double* vol) {
  static_assert(!NoSwirl || G::has_hoop_terms);
  const P2GPointTerms<G::dim> t = p2g_point_terms<G, Split>(body, p);
  if constexpr (G::dim == 2)
    p2g_scatter_point_2d<G, K, Apic, Split, NoSwirl>(t, cache, p, m, mv, f, fp, vol);
  else
    p2g_scatter_point_general<G, K, Apic, Split, NoSwirl>(t, cache, p, m, mv, f, fp, vol);
}

/// particles_to_grid_point_inlined behind a call that GCC may or may not inline (the
/// axisymmetric kernels' P2G; the tests' reference).
template <class G, int K, bool Apic, bool Split, bool NoSwirl = false>
inline void particles_to_grid_point(const Body<G>& body, const ShapeCache<G::dim>& cache, std::int64_t p, double* m,
                                    double* mv, double* f, double* fp, double* vol) {
  particles_to_grid_point_inlined<G, K, Apic, Split, NoSwirl>(body, cache, p, m, mv, f, fp, vol);
}

/// Axisymmetric: whether point p has no swirl, i.e. zero θ entries of v, of C's θ row, of σ's
/// (θ,r), (θ,z), (r,θ) and of f_ext. Then its hoop θ force and Coriolis term are zeros as well, and
/// P2G may leave out all its θ terms (particles_to_grid_point's NoSwirl).
template <class G>
inline bool point_without_swirl(const Body<G>& body, std::int64_t p) {
  // (the bits of the seven values but their signs: zero only if each is ±0; a NaN is not zero)
  const Mat3& s = body.stress_Pa[p];
  const auto& C = body.C_1_s[p];
  auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  const std::uint64_t any = bits(body.v_m_s[p][2]) | bits(C(2, 0)) | bits(C(2, 1)) | bits(s(2, 0)) | bits(s(2, 1)) |
                            bits(s(0, 2)) | bits(body.f_ext_N[p][2]);
  return (any << 1) == 0;
}

}  // namespace detail

namespace detail {

/// P2G, before its parallel region: the shape cache sized for the body's points.
template <class G, int K, class Kernel>
void p2g_prepare(const Body<G>& body, ShapeCache<G::dim>& cache) {
  constexpr int S = support_of<G::dim>(K);
  static_assert(Kernel::support == S);
  cache.reserve(body.size(), S);
  cache.apic_by_gradient = Kernel::apic_by_gradient;
}

/// The calling thread's copy of a field's nodal sums (thread 0: the field's own arrays).
template <class G>
struct ScatterArrays {
  double *m, *mv, *f, *fp, *vol;  ///< mass, momentum, force, pressure force (NC per node), volume

  ScatterArrays(GridField<G>& field, int t)
      : m(t == 0 ? field.mass_kg.data() : field.t_mass[t - 1].data()),
        mv((t == 0 ? field.momentum.data() : field.t_momentum[t - 1].data())->data()),
        f((t == 0 ? field.force_N.data() : field.t_force[t - 1].data())->data()),
        fp((t == 0 ? field.pressure_force_N.data() : field.t_pressure[t - 1].data())->data()),
        vol(t == 0 ? field.volume_m3.data() : field.t_volume[t - 1].data()) {}
  /// Zero the sums of nn nodes (the pressure force and volume only when the scatter splits them).
  void zero(int nn, bool split_pressure) const {
    constexpr int NC = G::ncomp;
    std::fill(m, m + nn, 0.0);
    std::fill(mv, mv + static_cast<std::int64_t>(nn) * NC, 0.0);
    std::fill(f, f + static_cast<std::int64_t>(nn) * NC, 0.0);
    if (split_pressure) {
      std::fill(fp, fp + static_cast<std::int64_t>(nn) * NC, 0.0);
      std::fill(vol, vol + nn, 0.0);
    }
  }
};

/// P2G's scatter (steps 1–2) of the points [p0, p1) into one copy of the nodal sums: each point's
/// shape functions (into `cache`, for the rest of the step) and its contributions. Returns the
/// number of these points whose support left the stored nodes.
template <class G, int K, class Kernel>
std::int64_t p2g_scatter_range(const Body<G>& body, const Grid<G::dim>& grid, const Kernel& kernel,
                               ShapeCache<G::dim>& cache, const ScatterArrays<G>& out, bool apic, bool split_pressure,
                               std::int64_t p0, std::int64_t p1) {
  constexpr int S = support_of<G::dim>(K);
  const StencilGrid<G::dim> sg(grid);
  std::int64_t bad = 0;
  auto scatter = [&]<bool A, bool Sp>() {
    for (std::int64_t p = p0; p < p1; ++p) {
      if (!make_stencil(grid, sg, kernel, body.x_m[p], cache.template stencil<S>(p), cache.inv_D[p])) ++bad;
      if constexpr (G::has_hoop_terms) {
        // Beds without swirl (the intruder, the rod) skip the θ terms: the same sums; points
        // with swirl take the general kernel.
        if (point_without_swirl(body, p))
          particles_to_grid_point<G, K, A, Sp, true>(body, cache, p, out.m, out.mv, out.f, out.fp, out.vol);
        else
          particles_to_grid_point<G, K, A, Sp>(body, cache, p, out.m, out.mv, out.f, out.fp, out.vol);
      } else {
        // (plane strain and 3D: inlined here)
        particles_to_grid_point_inlined<G, K, A, Sp>(body, cache, p, out.m, out.mv, out.f, out.fp, out.vol);
      }
    }
  };
  if (apic) {
    if (split_pressure)
      scatter.template operator()<true, true>();
    else
      scatter.template operator()<true, false>();
  } else {
    if (split_pressure)
      scatter.template operator()<false, true>();
    else
      scatter.template operator()<false, false>();
  }
  return bad;
}

/// P2G's first phase for the calling thread of a region: it zeroes its copy of the nodal sums and
/// scatters its static share of the points into it (no barrier). Returns the number of its points
/// whose support left the stored nodes.
template <class G, int K, class Kernel>
std::int64_t p2g_scatter_share(const parallel::Team& team, const Body<G>& body, const Grid<G::dim>& grid,
                               const Kernel& kernel, ShapeCache<G::dim>& cache, GridField<G>& field, bool apic,
                               bool split_pressure) {
  const ScatterArrays<G> out(field, team.rank());
  out.zero(field.nodes(), split_pressure);
  const parallel::Range r = team.share(body.size());
  return p2g_scatter_range<G, K>(body, grid, kernel, cache, out, apic, split_pressure, r.begin, r.end);
}

/// P2G's second phase (step 3's gravity with it) over the nodes [i0, i1): the threads' copies
/// summed into the field in thread order, then f_i += m_i g. Each node is summed by one thread, in
/// the same order whichever it is.
template <class G>
void p2g_sum_nodes(GridField<G>& field, int copies, bool split_pressure, const Vec<G::ncomp>* gravity_m_s2, int i0,
                   int i1) {
  constexpr int NC = G::ncomp;
  const bool gravity = gravity_m_s2 != nullptr && gravity_m_s2->squaredNorm() != 0.0;
  const Vec<NC> g = gravity ? *gravity_m_s2 : Vec<NC>::Zero();
  for (int i = i0; i < i1; ++i) {
    for (int u = 1; u < copies; ++u) {
      field.mass_kg[i] += field.t_mass[u - 1][i];
      field.momentum[i] += field.t_momentum[u - 1][i];
      field.force_N[i] += field.t_force[u - 1][i];
      if (split_pressure) {
        field.pressure_force_N[i] += field.t_pressure[u - 1][i];
        field.volume_m3[i] += field.t_volume[u - 1][i];
      }
    }
    if (gravity) field.force_N[i] += field.mass_kg[i] * g;
  }
}

/// P2G's second phase for the calling thread of a region, after a barrier that follows every
/// thread's p2g_scatter_share: the sums over its static share of the nodes (no barrier).
template <class G>
void p2g_sum_share(const parallel::Team& team, GridField<G>& field, bool split_pressure,
                   const Vec<G::ncomp>* gravity_m_s2) {
  const parallel::Range r = team.share(field.nodes());
  p2g_sum_nodes(field, team.size(), split_pressure, gravity_m_s2, static_cast<int>(r.begin), static_cast<int>(r.end));
}

}  // namespace detail

/// What G2P of one body reads and writes (see make_g2p_task).
template <class G>
struct G2PArgs {
  Body<G>* body = nullptr;
  const ShapeCache<G::dim>* cache = nullptr;
  const GridField<G>* field = nullptr;
  const Grid<G::dim>* grid = nullptr;
  double alpha = 1.0;  ///< FLIP fraction (FLIP/PIC blend only)
  double dt_s = 0.0;
  const double* porosity = nullptr;             ///< n_i (the mixture's fluid only)
  const Vec<G::ncomp>* mixture_flux = nullptr;  ///< q_i (the mixture's fluid only)
};

/// G2P of one body as independent blocks of numerics::kMathBlock points, its kernel chosen once
/// (make_g2p_task): a caller runs the blocks in any order and on any thread (each point's update
/// reads only the grid and the point itself), e.g. several bodies in one parallel region.
template <class G>
struct G2PTask {
  G2PArgs<G> args;
  std::int64_t (*kernel)(const G2PArgs<G>&, std::int64_t, std::int64_t) = nullptr;
  std::int64_t blocks = 0;  ///< ⌈points / kMathBlock⌉
  /// Blocks [b0, b1): the lowest index of a point whose new x, v or V is not finite, or kAllFinite.
  std::int64_t run(std::int64_t b0, std::int64_t b1) const { return kernel(args, b0, b1); }
};

namespace detail {

/// G2P's sums over the nodes of one point: ∑N v_i, ∑N (v_i − v_i^old) (FLIP), ∑ v_i ∇Nᵀ, the APIC
/// B = ∑N v_i (x_i − x_p)ᵀ, and for the mixture's fluid ∑N q_i, φ's ∑N n_i and div q = ∑ q_i·∇N.
/// Components 0–1 as one 2-vector (one SIMD register), component 2 (if any) as a scalar.
template <int D>
struct G2PSums {
  V2 vp2 = V2::Zero(), dv2 = V2::Zero(), q2 = V2::Zero(), gv2[D], B2[D];
  double vp3 = 0.0, dv3 = 0.0, q3 = 0.0, gv3[D], B3[D];
  double n_p = 0.0, div_q = 0.0;
  G2PSums() {
    for (int a = 0; a < D; ++a) {
      gv2[a].setZero();
      B2[a].setZero();
      gv3[a] = 0.0;
      B3[a] = 0.0;
    }
  }
};

/// accumulate_g2p on a 2D grid: the tensor product factorised (as in P2G): per row j0 the sums
/// over j1 of N_1 v_i, N'_1 v_i and N_1 o_1 v_i, then ∑N v = ∑ N_0 (∑N_1 v), ∇: (∑ N'_0 (∑N_1 v),
/// ∑ N_0 (∑N'_1 v)), B = ∑N v (x_i − x_p)ᵀ = (∑ N_0 o_0 (∑N_1 v), ∑ N_0 (∑N_1 o_1 v)).
template <class G, int K, bool Apic, bool ByGrad, bool Mixture, bool NoSwirl>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
accumulate_g2p_2d(const ShapeCache<G::dim>& cache, std::int64_t p, const double* vel, const double* vel_old,
                  const double* flux, const double* porosity, G2PSums<G::dim>& s) {
  constexpr int D = G::dim, NC = G::ncomp, S = support_of<D>(K);
  constexpr bool kTheta = NC == 3 && !NoSwirl;  // the third component's sums over the nodes
  (void)vel_old, (void)flux, (void)porosity;    // (read by the FLIP and mixture kernels only)
  const Stencil<D, S>& st = cache.template stencil<S>(p);
  const SecondAxisFactors<S> a1(st);
  OOBLECK_UNROLL
  for (int j0 = 0; j0 < S; ++j0) {
    const double w0 = st.w[j0][0], dw0 = st.dw[j0][0], o0 = st.off[j0][0];
    V2 t2 = V2::Zero(), tg2 = V2::Zero(), to2 = V2::Zero(), td2 = V2::Zero(), tq2 = V2::Zero();
    double t3 = 0.0, tg3 = 0.0, to3 = 0.0, td3 = 0.0, tq3 = 0.0, tn = 0.0, tqy = 0.0;
    const int row = st.index[j0][0];
    OOBLECK_UNROLL
    for (int j1 = 0; j1 < S; ++j1) {
      const int i = row + st.index[j1][1];
      const double w1 = st.w[j1][1], dw1 = st.dw[j1][1];
      const double* vi = vel + static_cast<std::int64_t>(i) * NC;
      const V2 vi2 = Eigen::Map<const V2>(vi);
      t2 += a1.w[j1].cwiseProduct(vi2);
      tg2 += a1.dw[j1].cwiseProduct(vi2);
      if constexpr (kTheta) {
        t3 += w1 * vi[2];
        tg3 += dw1 * vi[2];
      }
      if constexpr (Apic && !ByGrad) {
        to2 += a1.wo[j1].cwiseProduct(vi2);
        if constexpr (kTheta) to3 += (w1 * st.off[j1][1]) * vi[2];
      }
      if constexpr (!Apic) {
        const double* vo = vel_old + static_cast<std::int64_t>(i) * NC;
        td2 += a1.w[j1].cwiseProduct(vi2 - Eigen::Map<const V2>(vo));
        if constexpr (kTheta) td3 += w1 * (vi[2] - vo[2]);
      }
      if constexpr (Mixture) {
        const double* qi = flux + static_cast<std::int64_t>(i) * NC;
        tn += w1 * porosity[i];
        tq2 += a1.w[j1].cwiseProduct(Eigen::Map<const V2>(qi));
        tqy += dw1 * qi[1];
        if constexpr (kTheta) tq3 += w1 * qi[2];
      }
    }
    s.vp2 += w0 * t2;
    s.gv2[0] += dw0 * t2;
    s.gv2[1] += w0 * tg2;
    if constexpr (kTheta) {
      s.vp3 += w0 * t3;
      s.gv3[0] += dw0 * t3;
      s.gv3[1] += w0 * tg3;
    }
    if constexpr (Apic && !ByGrad) {
      s.B2[0] += (w0 * o0) * t2;
      s.B2[1] += w0 * to2;
      if constexpr (kTheta) {
        s.B3[0] += (w0 * o0) * t3;
        s.B3[1] += w0 * to3;
      }
    }
    if constexpr (!Apic) {
      s.dv2 += w0 * td2;
      if constexpr (kTheta) s.dv3 += w0 * td3;
    }
    if constexpr (Mixture) {
      s.n_p += w0 * tn;
      s.div_q += dw0 * tq2[0] + w0 * tqy;
      if constexpr (G::has_hoop_terms) {
        s.q2 += w0 * tq2;
        if constexpr (kTheta) s.q3 += w0 * tq3;
      }
    }
    (void)o0;
  }
}

/// accumulate_g2p on a 3D grid: node by node over the stencil.
template <class G, int K, bool Apic, bool ByGrad, bool Mixture, bool NoSwirl>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
accumulate_g2p_nodes(const ShapeCache<G::dim>& cache, std::int64_t p, const double* vel, const double* vel_old,
                     const double* flux, const double* porosity, G2PSums<G::dim>& s) {
  constexpr int D = G::dim, NC = G::ncomp, S = support_of<D>(K);
  (void)vel_old, (void)flux, (void)porosity;  // (read by the FLIP and mixture kernels only)
  for_each_node<D, S>(cache.template stencil<S>(p), [&](int i, double w, const double* g, const double* off) {
    const double* vi = vel + static_cast<std::int64_t>(i) * NC;
    const V2 vi2 = Eigen::Map<const V2>(vi);
    const double vi3 = NC == 3 ? vi[NC - 1] : 0.0;
    if constexpr (Mixture) {
      const double* qi = flux + static_cast<std::int64_t>(i) * NC;
      s.n_p += w * porosity[i];
      double d = qi[0] * g[0];
      for (int a = 1; a < D; ++a) d += qi[a] * g[a];
      s.div_q += d;
      if constexpr (G::has_hoop_terms) {
        s.q2 += w * Eigen::Map<const V2>(qi);
        s.q3 += w * qi[2];
      }
    }
    s.vp2 += w * vi2;
    if constexpr (NC == 3) s.vp3 += w * vi3;
    for (int a = 0; a < D; ++a) {
      s.gv2[a] += vi2 * g[a];
      if constexpr (NC == 3) s.gv3[a] += vi3 * g[a];
    }
    if constexpr (Apic) {
      if constexpr (!ByGrad) {
        const V2 wv2 = w * vi2;
        const double wv3 = w * vi3;
        for (int a = 0; a < D; ++a) {
          s.B2[a] += wv2 * off[a];
          if constexpr (NC == 3) s.B3[a] += wv3 * off[a];
        }
      }
    } else {
      const double* vo = vel_old + static_cast<std::int64_t>(i) * NC;
      s.dv2 += w * (vi2 - Eigen::Map<const V2>(vo));
      if constexpr (NC == 3) s.dv3 += w * (vi3 - vo[2]);
    }
    (void)off;
  });
}

/// G2P's first half for point p (grid_to_particles_kernel): the sums over its nodes (docs/mpm.md
/// phase 6) from the nodal velocities, old velocities (FLIP), flux and porosity (mixture).
template <class G, int K, bool Apic, bool ByGrad, bool Mixture, bool NoSwirl>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
accumulate_g2p(const ShapeCache<G::dim>& cache, std::int64_t p, const double* vel, const double* vel_old,
               const double* flux, const double* porosity, G2PSums<G::dim>& s) {
  if constexpr (G::dim == 2)
    accumulate_g2p_2d<G, K, Apic, ByGrad, Mixture, NoSwirl>(cache, p, vel, vel_old, flux, porosity, s);
  else
    accumulate_g2p_nodes<G, K, Apic, ByGrad, Mixture, NoSwirl>(cache, p, vel, vel_old, flux, porosity, s);
}

/// write_back_g2p for a 2D grid: the update written straight from the accumulators to the
/// point's arrays, component by component (a temporary vector or matrix filled by parts and read
/// whole stalls on store forwarding); the same values as write_back_g2p_general.
template <class G, bool Apic, bool ByGrad, bool Mixture>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
write_back_g2p_2d(const G2PArgs<G>& args, std::int64_t p, G2PSums<G::dim>& s, double& vol_arg, double& kin_sum) {
  constexpr int D = G::dim, NC = G::ncomp;
  Body<G>& body = *args.body;
  const Grid<G::dim>& grid = *args.grid;
  const double alpha = args.alpha, dt_s = args.dt_s;
  const double* const inv_D = args.cache->inv_D.data()->data();
  Vec<D>* const xs = body.x_m.data();
  Vec<NC>* const vs = body.v_m_s.data();
  Mat<NC, D>* const Cs = body.C_1_s.data();
  Mat3* const Ls = body.L_1_s.data();
  (void)alpha, (void)inv_D, (void)Cs;  // (FLIP reads alpha; APIC inv_D and C)
  // The point's update written straight from the accumulators to its arrays, component by
  // component (a temporary vector or matrix filled by parts and read whole stalls on store
  // forwarding); the same values as the general path below.
  double* const xp = xs[p].data();
  const double x_old0 = xp[0], x_old1 = xp[1];
  const double xn0 = grid.wrapped(0, x_old0 + dt_s * s.vp2[0]), xn1 = grid.wrapped(1, x_old1 + dt_s * s.vp2[1]);
  xp[0] = xn0;
  xp[1] = xn1;
  double* const vq = vs[p].data();
  double v_new[NC];
  if constexpr (Apic) {
    Eigen::Map<V2>{v_new} = s.vp2;
    if constexpr (NC == 3) v_new[2] = s.vp3;
  } else {
    const V2 vb = alpha * (Eigen::Map<const V2>(vq) + s.dv2) + (1.0 - alpha) * s.vp2;
    Eigen::Map<V2>{v_new} = vb;
    if constexpr (NC == 3) v_new[2] = alpha * (vq[2] + s.dv3) + (1.0 - alpha) * s.vp3;
  }
  double v_pic[NC];
  Eigen::Map<V2>{v_pic} = s.vp2;
  if constexpr (NC == 3) v_pic[2] = s.vp3;
  for (int c = 0; c < NC; ++c) vq[c] = v_new[c];
  double g[D][NC];
  for (int a = 0; a < D; ++a) {
    Eigen::Map<V2>{g[a]} = s.gv2[a];
    if constexpr (NC == 3) g[a][2] = s.gv3[a];
  }
  if constexpr (Apic) {
    double* const Cq = Cs[p].data();  // column-major NC × D
    for (int a = 0; a < D; ++a) {
      if constexpr (ByGrad) {
        for (int c = 0; c < NC; ++c) Cq[a * NC + c] = g[a][c];
      } else {
        const double sD = inv_D[p * D + a];
        Eigen::Map<V2>(Cq + a * NC) = s.B2[a] * sD;
        if constexpr (NC == 3) Cq[a * NC + 2] = s.B3[a] * sD;
      }
    }
  }
  const Vec<D> x_old(x_old0, x_old1);
  if constexpr (Mixture) {
    if constexpr (G::has_hoop_terms) {
      const Vec<NC> qp(s.q2[0], s.q2[1], s.q3);
      s.div_q += G::div_extra(qp, x_old);
    }
    body.phi[p] = 1.0 - s.n_p;
    body.div_q_1_s[p] = s.div_q;
  }
  // L at the start-of-step position from the grid velocity field (hoop entries use Σ N v_i).
  const double trL = G::write_velocity_gradient(Ls[p].data(), g[0], g[1], x_old, v_pic);
  vol_arg = dt_s * trL;
  double vsum = v_new[0];
  for (int c = 1; c < NC; ++c) vsum += v_new[c];
  kin_sum = (xn0 + xn1) + vsum;
}

/// write_back_g2p for any grid (3D).
template <class G, bool Apic, bool ByGrad, bool Mixture>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
write_back_g2p_general(const G2PArgs<G>& args, std::int64_t p, G2PSums<G::dim>& s, double& vol_arg, double& kin_sum) {
  constexpr int D = G::dim, NC = G::ncomp;
  Body<G>& body = *args.body;
  const Grid<G::dim>& grid = *args.grid;
  const double alpha = args.alpha, dt_s = args.dt_s;
  const double* const inv_D = args.cache->inv_D.data()->data();
  Vec<D>* const xs = body.x_m.data();
  Vec<NC>* const vs = body.v_m_s.data();
  Mat<NC, D>* const Cs = body.C_1_s.data();
  Mat3* const Ls = body.L_1_s.data();
  (void)alpha, (void)inv_D, (void)Cs;                          // (FLIP reads alpha; APIC inv_D and C)
  double v_pic[NC], dv[NC], q_p[NC], grad_v[D][NC], B[D][NC];  // column-major like Mat<NC, D>
  for (int c = 0; c < 2; ++c) {
    v_pic[c] = s.vp2[c];
    dv[c] = s.dv2[c];
    q_p[c] = s.q2[c];
    for (int a = 0; a < D; ++a) {
      grad_v[a][c] = s.gv2[a][c];
      B[a][c] = s.B2[a][c];
    }
  }
  if constexpr (NC == 3) {
    v_pic[2] = s.vp3;
    dv[2] = s.dv3;
    q_p[2] = s.q3;
    for (int a = 0; a < D; ++a) {
      grad_v[a][2] = s.gv3[a];
      B[a][2] = s.B3[a];
    }
  }
  const Vec<D> x_old = xs[p];
  Vec<D> x;
  for (int a = 0; a < D; ++a) x[a] = x_old[a] + dt_s * v_pic[a];
  grid.wrap(x);
  xs[p] = x;
  const Eigen::Map<const Vec<NC>> vpic(v_pic);
  const Eigen::Map<const Mat<NC, D>> gv(&grad_v[0][0]);
  if constexpr (Apic) {
    vs[p] = vpic;
    if constexpr (ByGrad) {
      Cs[p] = gv;
    } else {
      Mat<NC, D> C;
      for (int a = 0; a < D; ++a) {
        const double sD = inv_D[p * D + a];
        for (int c = 0; c < NC; ++c) C(c, a) = B[a][c] * sD;
      }
      Cs[p] = C;
    }
  } else {
    Vec<NC> v;
    for (int c = 0; c < NC; ++c) v[c] = alpha * (vs[p][c] + dv[c]) + (1.0 - alpha) * v_pic[c];
    vs[p] = v;
  }
  if constexpr (Mixture) {
    if constexpr (G::has_hoop_terms) s.div_q += G::div_extra(Eigen::Map<const Vec<NC>>(q_p), x_old);
    body.phi[p] = 1.0 - s.n_p;
    body.div_q_1_s[p] = s.div_q;
  }
  // L at the start-of-step position from the grid velocity field (hoop entries use Σ N v_i).
  const Mat3 L = G::velocity_gradient(gv, x_old, vpic);
  Ls[p] = L;
  vol_arg = dt_s * L.trace();
  kin_sum = x.sum() + vs[p].sum();
}

/// G2P's second half for point p: its new position (wrapped on periodic axes) and velocity (APIC
/// or the FLIP/PIC blend), C (APIC), the mixture's φ and div q, and the velocity gradient L at the
/// start-of-step position (hoop entries from ∑N v_i); returns Δt tr L (for V ← V exp(Δt tr L)) and
/// the sum of the new x and v (for the NaN guard).
template <class G, bool Apic, bool ByGrad, bool Mixture>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
write_back_g2p(const G2PArgs<G>& args, std::int64_t p, G2PSums<G::dim>& s, double& vol_arg, double& kin_sum) {
  if constexpr (G::dim == 2)
    write_back_g2p_2d<G, Apic, ByGrad, Mixture>(args, p, s, vol_arg, kin_sum);
  else
    write_back_g2p_general<G, Apic, ByGrad, Mixture>(args, p, s, vol_arg, kin_sum);
}

/// G2P for one body with the per-point branches resolved at compile time (APIC or FLIP/PIC,
/// APIC by gradient, mixture fields). Plain scalar accumulators: the Eigen fixed-size 3-vectors of
/// the axisymmetric mode went through the stack with partial stores and wide reloads (store
/// forwarding stalls); the arithmetic and its order per component are unchanged.
///
/// NoSwirl (axisymmetric only): the body's nodal θ velocities (new and old) and, for the mixture,
/// the θ flux are all zero, so every θ sum over the nodes is +0 (they start at +0): the sums are
/// left out and stay +0, the same values.
/// The blocks [block_begin, block_end) of numerics::kMathBlock points (called by G2PTask::run; not
/// parallel itself).
template <class G, int K, bool Apic, bool ByGrad, bool Mixture, bool NoSwirl = false>
std::int64_t grid_to_particles_kernel(const G2PArgs<G>& args, std::int64_t block_begin, std::int64_t block_end) {
  constexpr int D = G::dim;
  static_assert(!NoSwirl || G::has_hoop_terms);
  Body<G>& body = *args.body;
  const ShapeCache<G::dim>& cache = *args.cache;
  const GridField<G>& field = *args.field;
  const double* const porosity = args.porosity;
  const std::int64_t np = body.size();
  const double* const vel = field.velocity.data()->data();
  const double* const vel_old = field.velocity_old.data()->data();
  const double* const flux = Mixture ? args.mixture_flux->data() : nullptr;
  double* const Vs = body.volume_m3.data();
  std::int64_t bad = kAllFinite;
  // Points in blocks of numerics::kMathBlock: the per-point work, then the block's volume update
  // V ← V exp(Δt tr L) (step 7) with the exponentials in vector lanes (numerics/vector_math.hpp)
  // and the NaN guard.
  constexpr int kBlock = numerics::kMathBlock;
  for (std::int64_t blk = block_begin; blk < block_end; ++blk) {
    const std::int64_t p0 = blk * kBlock;
    const int nb = static_cast<int>(std::min<std::int64_t>(kBlock, np - p0));
    // per point: Δt tr L, the new x and v summed (for the guard), exp(Δt tr L)
    double vol_arg[kBlock], kin_sum[kBlock], vol_factor[kBlock];
    for (int j = nb; j < kBlock; ++j) vol_arg[j] = 0.0;
    for (int j = 0; j < nb; ++j) {
      const std::int64_t p = p0 + j;
      G2PSums<D> s;
      accumulate_g2p<G, K, Apic, ByGrad, Mixture, NoSwirl>(cache, p, vel, vel_old, flux, porosity, s);
      write_back_g2p<G, Apic, ByGrad, Mixture>(args, p, s, vol_arg[j], kin_sum[j]);
    }
    numerics::exp_block(vol_arg, vol_factor);
    for (int j = 0; j < nb; ++j) {
      const std::int64_t p = p0 + j;
      const double V = Vs[p] * vol_factor[j];  // step 7: V ← V exp(Δt tr L)
      Vs[p] = V;
      // NaN/Inf guard of the new x, v, V (a sum is finite only if every term is)
      if (!std::isfinite(kin_sum[j] + V)) bad = std::min(bad, p);
    }
  }
  return bad;
}

}  // namespace detail

/// G2P (docs/mpm.md, "The step" phase 6): positions x ← x + Δt ∑N v_i (wrapped on periodic axes), velocities by
/// the FLIP/PIC blend v ← α (v + ∑N (v_i − v_i^old)) + (1 − α) ∑N v_i or by APIC (v ← ∑N v_i,
/// C ← B D⁻¹, or ∑ v_i ∇Nᵀ for linear weights), and the velocity gradient L = ∑ v_i ∇Nᵀ (plus
/// geometry terms). Also the volume update V ← V exp(Δt tr L) (step 7), fused into the same loop.
///
/// For the fluid phase of a mixture, `porosity` (n_i) and `mixture_flux` (q_i = (1−n_i) v^s_i +
/// n_i v^f_i) are given; the point's φ = 1 − ∑N n_i and div q = ∑ q_i·∇N_ip are stored in
/// body.phi and body.div_q_1_s for the fluid law (E25, E27).
///
/// Returns the lowest index of a point whose new position, velocity or volume is not finite, or
/// kAllFinite (the run's NaN guard, fused into this pass).
/// Whether a body's G2P may take the NoSwirl kernels (axisymmetric only): no θ velocity on any
/// node, new or old, and for the mixture's fluid (`mixture_flux` given) no θ flux. Those kernels
/// give the same values as the general ones, only faster.
template <class G>
bool g2p_without_swirl(const GridField<G>& field, const Vec<G::ncomp>* mixture_flux) {
  if constexpr (!G::has_hoop_terms) {
    return false;
  } else {
    const int nn = field.nodes();
    bool no_swirl = true;
    for (int i = 0; i < nn; ++i)
      no_swirl &= (field.velocity[i][2] == 0.0) & (field.velocity_old[i][2] == 0.0) &
                  (mixture_flux == nullptr || mixture_flux[i][2] == 0.0);
    return no_swirl;
  }
}

/// G2P of one body as a task (see G2PTask). `no_swirl`: the answer of g2p_without_swirl when the
/// caller has it already (the solver finds it in its pass over the nodes); otherwise scanned here.
template <class G, int K>
G2PTask<G> make_g2p_task(Body<G>& body, const ShapeCache<G::dim>& cache, const GridField<G>& field,
                         const Grid<G::dim>& grid, Transfer transfer, double flip_fraction, double dt_s,
                         const double* porosity = nullptr, const Vec<G::ncomp>* mixture_flux = nullptr,
                         std::optional<bool> no_swirl_known = std::nullopt) {
  const bool mix = porosity != nullptr;
  const bool no_swirl = no_swirl_known ? *no_swirl_known : g2p_without_swirl(field, mix ? mixture_flux : nullptr);
  G2PTask<G> task;
  task.args = {
      &body, &cache, &field, &grid, flip_fraction, dt_s, mix ? porosity : nullptr, mix ? mixture_flux : nullptr};
  task.blocks = (body.size() + numerics::kMathBlock - 1) / numerics::kMathBlock;
  auto pick = [&]<bool A, bool BG>() {
    auto with = [&]<bool NS>() {
      task.kernel = mix ? &detail::grid_to_particles_kernel<G, K, A, BG, true, NS>
                        : &detail::grid_to_particles_kernel<G, K, A, BG, false, NS>;
    };
    if constexpr (G::has_hoop_terms)
      if (no_swirl) return with.template operator()<true>();
    with.template operator()<false>();
  };
  if (transfer != Transfer::Apic)
    pick.template operator()<false, false>();
  else if (cache.apic_by_gradient)
    pick.template operator()<true, true>();
  else
    pick.template operator()<true, false>();
  return task;
}

// The axisymmetric G2P is compiled in its own translation unit, transfer_axisymmetric.cpp, with
// 128-bit auto-vectorisation (see there and docs/mpm.md "Performance"); the other units use it.
#define OOBLECK_AXISYMMETRIC_G2P(KIND, K)                                                                          \
  KIND template G2PTask<Axisymmetric> make_g2p_task<Axisymmetric, K>(                                              \
      Body<Axisymmetric>&, const ShapeCache<2>&, const GridField<Axisymmetric>&, const Grid<2>&, Transfer, double, \
      double, const double*, const Vec<3>*, std::optional<bool>);
OOBLECK_AXISYMMETRIC_G2P(extern, 4)
OOBLECK_AXISYMMETRIC_G2P(extern, 9)
OOBLECK_AXISYMMETRIC_G2P(extern, 16)

}  // namespace oobleck::mpm
