#pragma once
// Shape functions (one small struct per kind) and the per-point cache of node indices, weights,
// gradients and node offsets, computed once per step (in P2G, docs/mpm.md "The step" phase 2).
//
// Every kernel is a 1D function evaluated in cell units: given the point coordinate ξ = (x − x_0)/h
// it returns the logical index `base` of its first support node and, for the `support` nodes
// base … base + support − 1, the weights N(ξ − i) and the derivatives dN/dξ. The D-dimensional
// function is the tensor product. All kernels reproduce constants and linear fields exactly
// (∑N = 1, ∑∇N = 0, ∑N x_i = x_p), which the tests check near walls and periodic seams too.
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/parallel.hpp"

namespace oobleck::mpm {

enum class ShapeKind { Linear, QuadraticBSpline, CubicBSpline, UGimp };

namespace kernel_detail {
inline double floor_of(double x) { return std::floor(x); }
template <class A>
auto floor_of(const A& x) {
  return x.floor().eval();
}
template <class T>
T constant(double v) {
  if constexpr (std::is_same_v<T, double>)
    return v;
  else
    return T::Constant(v);
}
}  // namespace kernel_detail

/// Multilinear hat functions (support 2 nodes per axis).
struct LinearKernel {
  static constexpr int support = 2;
  /// APIC with linear weights uses C_p = ∑ v_i ∇N_ipᵀ (Jiang et al. 2015); D_p is singular at nodes.
  static constexpr bool apic_by_gradient = true;
  /// T = double (one axis) or an Eigen array (all axes at once, the same operations per lane);
  /// base is the first support node as a floating-point integer.
  template <class T>
  void axes(const T& xi, T& base, T* w, T* dw) const {
    base = kernel_detail::floor_of(xi);
    const T f = xi - base;
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = kernel_detail::constant<T>(-1.0);
    dw[1] = kernel_detail::constant<T>(1.0);
  }
  void operator()(double xi, int& base, double* w, double* dw) const {
    double b = 0.0;
    axes(xi, b, w, dw);
    base = static_cast<int>(b);
  }
};

/// Quadratic B-spline (support 3). C¹; APIC inertia D_p = h²/4.
struct QuadraticBSplineKernel {
  static constexpr int support = 3;
  static constexpr bool apic_by_gradient = false;
  /// h²/D_p: the second moment of the weights is h²/4 wherever the point is (make_stencil).
  static constexpr double apic_inv_inertia_h2 = 4.0;
  /// As LinearKernel::axes.
  template <class T>
  void axes(const T& xi, T& base, T* w, T* dw) const {
    base = kernel_detail::floor_of(xi - 0.5);
    const T f = xi - base;  // in [0.5, 1.5)
    const T a = 1.5 - f, b = f - 1.0, c = f - 0.5;
    w[0] = 0.5 * a * a;
    w[1] = 0.75 - b * b;
    w[2] = 0.5 * c * c;
    dw[0] = -a;
    dw[1] = -2.0 * b;
    dw[2] = c;
  }
  void operator()(double xi, int& base, double* w, double* dw) const {
    double b = 0.0;
    axes(xi, b, w, dw);
    base = static_cast<int>(b);
  }
};

/// Cubic B-spline (support 4). C²; APIC inertia D_p = h²/3.
struct CubicBSplineKernel {
  static constexpr int support = 4;
  static constexpr bool apic_by_gradient = false;
  /// h²/D_p: the second moment of the weights is h²/3 wherever the point is (make_stencil).
  static constexpr double apic_inv_inertia_h2 = 3.0;
  void operator()(double xi, int& base, double* w, double* dw) const {
    base = static_cast<int>(std::floor(xi)) - 1;
    const double f = xi - base;  // in [1, 2); r_j = f − j is the signed distance to node j
    for (int j = 0; j < 4; ++j) {
      const double r = f - j, ar = std::fabs(r);
      if (ar < 1.0) {
        w[j] = 0.5 * ar * ar * ar - r * r + 2.0 / 3.0;
        dw[j] = 1.5 * r * ar - 2.0 * r;
      } else if (ar < 2.0) {
        const double t = 2.0 - ar;
        w[j] = t * t * t / 6.0;
        dw[j] = -0.5 * t * t * (r > 0.0 ? 1.0 : -1.0);
      } else {
        w[j] = 0.0;
        dw[j] = 0.0;
      }
    }
  }
};

/// Undeformed GIMP (uGIMP): the hat function convolved with the point's characteristic function of
/// fixed half-width ℓ = `half_width` (in cell units, 0 < ℓ ≤ 1/2; ℓ = 1/(2 × points per cell)).
/// Support 3 nodes (|r| < 1 + ℓ ≤ 3/2).
struct UGimpKernel {
  static constexpr int support = 3;
  static constexpr bool apic_by_gradient = false;
  double half_width = 0.25;  ///< ℓ [cells]
  void operator()(double xi, int& base, double* w, double* dw) const {
    const double l = half_width;
    base = static_cast<int>(std::floor(xi + 0.5)) - 1;
    for (int j = 0; j < 3; ++j) {
      const double r = xi - (base + j), ar = std::fabs(r), s = r > 0.0 ? 1.0 : -1.0;
      if (ar < l) {
        w[j] = 1.0 - (r * r + l * l) / (2.0 * l);
        dw[j] = -r / l;
      } else if (ar <= 1.0 - l) {
        w[j] = 1.0 - ar;
        dw[j] = -s;
      } else if (ar < 1.0 + l) {
        const double t = 1.0 + l - ar;
        w[j] = t * t / (4.0 * l);
        dw[j] = -s * t / (2.0 * l);
      } else {
        w[j] = 0.0;
        dw[j] = 0.0;
      }
    }
  }
};

/// Largest support (nodes per axis) of any kernel.
inline constexpr int kMaxSupport = 4;

/// The 1D factors of one point's shape functions: for support node j < S and axis a, the
/// storage index times the axis stride of node base + j (periodic seams wrapped), N, dN/dx [1/m]
/// and x_i − x_p [m]. The D-dimensional values are tensor products formed on the fly
/// (for_each_node): per point this stores 4 D S numbers instead of S^D nodes × (2 + 2D) numbers,
/// so the shape pass writes, and P2G/G2P read, a fraction of the bytes. The axis is the inner
/// index so that make_stencil computes and stores the D axes of one j together (one SIMD store).
template <int D, int S>
struct Stencil {
  int index[S][D];
  double w[S][D];
  double dw[S][D];
  double off[S][D];
};

/// Support per axis S of a kernel with K = S^D nodes per point.
template <int D>
constexpr int support_of(int K) {
  for (int s = 1; s <= kMaxSupport; ++s) {
    int k = 1;
    for (int a = 0; a < D; ++a) k *= s;
    if (k == K) return s;
  }
  return 0;
}

/// Visit the S^D support nodes of a stencil with f(i, N_ip, ∇N_ip, x_i − x_p): flat node index,
/// weight, gradient [1/m] (double[D]) and offset [m] (double[D]). Local node k enumerates
/// (j_0, …, j_{D−1}) with the last axis fastest (the scatter order, hence the round-off, is fixed).
/// Products are formed as ((N_0 N_1) N_2) and ∂_a N = (N'_a ∏_{b≠a} N_b in increasing b).
template <int D, int S, class F>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline void
for_each_node(const Stencil<D, S>& s, F&& f) {
  static_assert(D >= 1 && D <= 3 && S >= 1 && S <= kMaxSupport);
  if constexpr (D == 1) {
    for (int j0 = 0; j0 < S; ++j0) {
      const double g[1] = {s.dw[j0][0]}, o[1] = {s.off[j0][0]};
      f(s.index[j0][0], s.w[j0][0], g, o);
    }
  } else if constexpr (D == 2) {
    for (int j0 = 0; j0 < S; ++j0) {
      for (int j1 = 0; j1 < S; ++j1) {
        const double g[2] = {s.dw[j0][0] * s.w[j1][1], s.w[j0][0] * s.dw[j1][1]};
        const double o[2] = {s.off[j0][0], s.off[j1][1]};
        f(s.index[j0][0] + s.index[j1][1], s.w[j0][0] * s.w[j1][1], g, o);
      }
    }
  } else {
    for (int j0 = 0; j0 < S; ++j0) {
      for (int j1 = 0; j1 < S; ++j1) {
        const double w01 = s.w[j0][0] * s.w[j1][1];
        const double g0 = s.dw[j0][0] * s.w[j1][1], g1 = s.dw[j1][1] * s.w[j0][0];
        const int i01 = s.index[j0][0] + s.index[j1][1];
        for (int j2 = 0; j2 < S; ++j2) {
          const double g[3] = {g0 * s.w[j2][2], g1 * s.w[j2][2], (s.dw[j2][2] * s.w[j0][0]) * s.w[j1][1]};
          const double o[3] = {s.off[j0][0], s.off[j1][1], s.off[j2][2]};
          f(i01 + s.index[j2][2], w01 * s.w[j2][2], g, o);
        }
      }
    }
  }
}

/// Per-point cache of the shape functions of one body: one Stencil per point (computed once per
/// step, in P2G: docs/mpm.md "The step" phase 2), sized for the kernel's support S (one of the three arrays is used),
/// and `inv_D`, the diagonal of APIC's inverse inertia D_p⁻¹ [1/m²] (unused for linear weights).
/// K = S^D nodes per point. Buffers grow only when the number of points grows (no allocation in a
/// steady step). The per-node accessors are for tests and cold code; hot loops use
/// for_each_node(cache.stencil<S>(p), …).
template <int D>
struct ShapeCache {
  int S = 0;
  int K = 0;
  bool apic_by_gradient = false;
  std::int64_t points = 0;
  std::vector<Vec<D>> inv_D;

  void reserve(std::int64_t np, int support) {
    S = support;
    K = 1;
    for (int a = 0; a < D; ++a) K *= support;
    points = np;
    const auto n = static_cast<std::size_t>(np);
    if (inv_D.size() < n) inv_D.resize(n);
    with_support([&](auto& v) {
      if (v.size() < n) v.resize(n);
    });
  }
  template <int Sk>
  const Stencil<D, Sk>& stencil(std::int64_t p) const {
    return stencils<Sk>()[static_cast<std::size_t>(p)];
  }
  template <int Sk>
  Stencil<D, Sk>& stencil(std::int64_t p) {
    return const_cast<Stencil<D, Sk>&>(std::as_const(*this).template stencil<Sk>(p));
  }

  /// Flat node index, N_ip, ∇N_ip [1/m] and x_i − x_p [m] of local node k < K of point p.
  int node(std::int64_t p, int k) const {
    return visit(p, k, [](const auto& s, const int* j) {
      int i = 0;
      for (int a = 0; a < D; ++a) i += s.index[j[a]][a];
      return i;
    });
  }
  double weight(std::int64_t p, int k) const {
    return visit(p, k, [](const auto& s, const int* j) {
      double w = 1.0;
      for (int a = 0; a < D; ++a) w *= s.w[j[a]][a];
      return w;
    });
  }
  Vec<D> gradient(std::int64_t p, int k) const {
    return visit(p, k, [](const auto& s, const int* j) {
      Vec<D> g;
      for (int a = 0; a < D; ++a) {
        double ga = s.dw[j[a]][a];
        for (int b = 0; b < D; ++b)
          if (b != a) ga *= s.w[j[b]][b];
        g[a] = ga;
      }
      return g;
    });
  }
  Vec<D> offset(std::int64_t p, int k) const {
    return visit(p, k, [](const auto& s, const int* j) {
      Vec<D> o;
      for (int a = 0; a < D; ++a) o[a] = s.off[j[a]][a];
      return o;
    });
  }

 private:
  std::vector<Stencil<D, 2>> stencil2_;
  std::vector<Stencil<D, 3>> stencil3_;
  std::vector<Stencil<D, 4>> stencil4_;

  template <int Sk>
  const std::vector<Stencil<D, Sk>>& stencils() const {
    static_assert(Sk >= 2 && Sk <= kMaxSupport);
    if constexpr (Sk == 2)
      return stencil2_;
    else if constexpr (Sk == 3)
      return stencil3_;
    else
      return stencil4_;
  }
  template <class F>
  void with_support(F&& f) {
    if (S == 2)
      f(stencil2_);
    else if (S == 3)
      f(stencil3_);
    else
      f(stencil4_);
  }
  /// f(stencil of p, per-axis indices of local node k), the last axis fastest.
  template <class F>
  auto visit(std::int64_t p, int k, F&& f) const {
    int j[D];
    for (int a = D - 1; a >= 0; --a) {
      j[a] = k % S;
      k /= S;
    }
    if (S == 2) return f(stencil<2>(p), j);
    if (S == 3) return f(stencil<3>(p), j);
    return f(stencil<4>(p), j);
  }
};

/// What make_stencil needs of the grid, gathered once per pass.
template <int D>
struct StencilGrid {
  double origin[D], h, inv_h;
  int stride[D], nodes[D];
  bool periodic[D];
  explicit StencilGrid(const Grid<D>& grid) : h(grid.h_m), inv_h(1.0 / grid.h_m) {
    for (int a = 0; a < D; ++a) {
      origin[a] = grid.origin_m[a];
      stride[a] = grid.stride(a);
      nodes[a] = grid.nodes(a);
      periodic[a] = grid.periodic[a];
    }
  }
};

/// Whether a kernel evaluates all axes at once on Eigen arrays (`axes`); the others go axis by axis.
template <class Kernel, int D>
concept AxesKernel = requires(const Kernel& k, const Eigen::Array<double, D, 1>& xi, Eigen::Array<double, D, 1>& b,
                              Eigen::Array<double, D, 1>* w) {
  k.axes(xi, b, w, w);
};

/// The stencil of a point at x and the diagonal of APIC's D_p⁻¹ [1/m²]. Returns false when the
/// support leaves the stored nodes (non-periodic axes; those indices are set to 0).
///
/// The D axes are computed side by side in Eigen arrays (one SIMD lane per axis for D = 2) with
/// exactly the operations of the 1D kernel per lane, so the values equal the axis-by-axis ones; the
/// shape pass is bound by its stores, and those of one support node j go out together.
template <int D, class Kernel>
#if defined(__GNUC__)
[[gnu::always_inline]]
#endif
inline bool
make_stencil(const Grid<D>& grid, const StencilGrid<D>& sg, const Kernel& kernel, const Vec<D>& x,
             Stencil<D, Kernel::support>& s, Vec<D>& inv_D) {
  constexpr int S = Kernel::support;
  using A = Eigen::Array<double, D, 1>;
  A xi, basef, w[S], dw[S];
  for (int a = 0; a < D; ++a) xi[a] = (x[a] - sg.origin[a]) * sg.inv_h;
  if constexpr (AxesKernel<Kernel, D>) {
    kernel.axes(xi, basef, w, dw);
  } else {
    for (int a = 0; a < D; ++a) {
      int base = 0;
      double w1[S], dw1[S];
      kernel(xi[a], base, w1, dw1);
      basef[a] = base;
      for (int j = 0; j < S; ++j) {
        w[j][a] = w1[j];
        dw[j][a] = dw1[j];
      }
    }
  }
  // B-splines: APIC's D_p is the same at every point (h²/4 quadratic, h²/3 cubic; Jiang et al.
  // 2015), so no second moment and no division per point
  constexpr bool constant_inertia = requires { Kernel::apic_inv_inertia_h2; };
  A m2 = A::Zero();
  for (int j = 0; j < S; ++j) {
    const A off = ((basef + static_cast<double>(j)) - xi) * sg.h;
    if constexpr (!constant_inertia) m2 += w[j] * off * off;
    Eigen::Map<A>(s.w[j]) = w[j];
    Eigen::Map<A>(s.dw[j]) = dw[j] * sg.inv_h;
    Eigen::Map<A>(s.off[j]) = off;
  }
  if constexpr (constant_inertia) {
    inv_D.setConstant(Kernel::apic_inv_inertia_h2 * (sg.inv_h * sg.inv_h));
  } else {
    const A inv_m2 = 1.0 / m2;  // all lanes in one division (1/0 = inf is not selected)
    inv_D = (m2 > 0.0).select(inv_m2, 0.0).matrix();
  }
  // Storage indices of base … base + S − 1 (= grid.storage_index, one modulo per axis).
  bool ok = true;
  for (int a = 0; a < D; ++a) {
    const int base = static_cast<int>(basef[a]);
    if (sg.periodic[a]) {
      // base is within one cell of [0, cells) for a wrapped point: no integer division then.
      int st = base < 0 ? base + sg.nodes[a] : base;
      if (st < 0 || st >= sg.nodes[a]) st = grid.storage_index(a, base);
      for (int j = 0; j < S; ++j, ++st) {
        if (st >= sg.nodes[a]) st -= sg.nodes[a];
        s.index[j][a] = st * sg.stride[a];
      }
    } else {
      for (int j = 0; j < S; ++j) {
        const int st = base + j + Grid<D>::kGhost;
        const bool in = st >= 0 && st < sg.nodes[a];
        ok = ok && in;
        s.index[j][a] = in ? st * sg.stride[a] : 0;
      }
    }
  }
  return ok;
}

/// Fill the cache for all points at positions x (each thread of a region its static share of
/// the points, parallel.hpp). Returns the number of points whose support leaves the stored nodes
/// (0 when all is well; the caller reports them).
template <int D, class Kernel>
std::int64_t compute_shape_cache(const Grid<D>& grid, const Kernel& kernel, const std::vector<Vec<D>>& x,
                                 ShapeCache<D>& cache) {
  const auto np = static_cast<std::int64_t>(x.size());
  cache.reserve(np, Kernel::support);
  cache.apic_by_gradient = Kernel::apic_by_gradient;
  const StencilGrid<D> sg(grid);
  std::int64_t bad = 0;
  parallel::region([&](const parallel::Team& team) {
    const parallel::Range r = team.share(np);
    std::int64_t mine = 0;
    for (std::int64_t p = r.begin; p < r.end; ++p)
      if (!make_stencil(grid, sg, kernel, x[p], cache.template stencil<Kernel::support>(p), cache.inv_D[p])) ++mine;
    if (mine > 0) parallel::atomic_add(bad, mine);
  });
  return bad;
}

/// Call f(kernel) with the kernel object of the requested kind (one dispatch per step).
template <class F>
decltype(auto) with_kernel(ShapeKind kind, double gimp_half_width_cells, F&& f) {
  switch (kind) {
    case ShapeKind::Linear: return f(LinearKernel{});
    case ShapeKind::QuadraticBSpline: return f(QuadraticBSplineKernel{});
    case ShapeKind::CubicBSpline: return f(CubicBSplineKernel{});
    case ShapeKind::UGimp:
    default: return f(UGimpKernel{gimp_half_width_cells});
  }
}

}  // namespace oobleck::mpm
