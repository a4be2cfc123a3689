#pragma once
// Shape functions (one small struct per kind) and the per-point cache of node indices, weights,
// gradients and node offsets, computed once per step (model.md §6 step 1).
//
// Every kernel is a 1D function evaluated in cell units: given the point coordinate ξ = (x − x_0)/h
// it returns the logical index `base` of its first support node and, for the `support` nodes
// base … base + support − 1, the weights N(ξ − i) and the derivatives dN/dξ. The D-dimensional
// function is the tensor product. All kernels reproduce constants and linear fields exactly
// (∑N = 1, ∑∇N = 0, ∑N x_i = x_p), which the tests check near walls and periodic seams too.
#include <cmath>
#include <cstdint>
#include <vector>

#include "oobleck/mpm/grid.hpp"

namespace oobleck::mpm {

enum class ShapeKind { Linear, QuadraticBSpline, CubicBSpline, UGimp };

/// Multilinear hat functions (support 2 nodes per axis).
struct LinearKernel {
  static constexpr int support = 2;
  /// APIC with linear weights uses C_p = ∑ v_i ∇N_ipᵀ (Jiang et al. 2015); D_p is singular at nodes.
  static constexpr bool apic_by_gradient = true;
  void operator()(double xi, int& base, double* w, double* dw) const {
    base = static_cast<int>(std::floor(xi));
    const double f = xi - base;
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = -1.0;
    dw[1] = 1.0;
  }
};

/// Quadratic B-spline (support 3). C¹; APIC inertia D_p = h²/4.
struct QuadraticBSplineKernel {
  static constexpr int support = 3;
  static constexpr bool apic_by_gradient = false;
  void operator()(double xi, int& base, double* w, double* dw) const {
    base = static_cast<int>(std::floor(xi - 0.5));
    const double f = xi - base;  // in [0.5, 1.5)
    const double a = 1.5 - f, b = f - 1.0, c = f - 0.5;
    w[0] = 0.5 * a * a;
    w[1] = 0.75 - b * b;
    w[2] = 0.5 * c * c;
    dw[0] = -a;
    dw[1] = -2.0 * b;
    dw[2] = c;
  }
};

/// Cubic B-spline (support 4). C²; APIC inertia D_p = h²/3.
struct CubicBSplineKernel {
  static constexpr int support = 4;
  static constexpr bool apic_by_gradient = false;
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

/// Per-point cache of the tensor-product shape functions for one body: for point p and local node
/// k < K = support^D, entry p*K + k holds the flat node index, N_ip, ∇N_ip [1/m] and x_i − x_p [m].
/// `inv_D` is the diagonal of APIC's inverse inertia D_p⁻¹ [1/m²] (unused for linear weights).
/// Buffers grow only when the number of points or K grows (no allocation in a steady step).
template <int D>
struct ShapeCache {
  int K = 0;
  bool apic_by_gradient = false;
  std::int64_t points = 0;
  std::vector<int> node;
  std::vector<double> w;
  std::vector<Vec<D>> grad;
  std::vector<Vec<D>> offset;
  std::vector<Vec<D>> inv_D;

  void reserve(std::int64_t np, int k) {
    K = k;
    points = np;
    const auto n = static_cast<std::size_t>(np * k);
    if (node.size() < n) {
      node.resize(n);
      w.resize(n);
      grad.resize(n);
      offset.resize(n);
    }
    if (inv_D.size() < static_cast<std::size_t>(np)) inv_D.resize(static_cast<std::size_t>(np));
  }
};

/// Fill the cache for all points at positions x (OpenMP over points). Returns the number of
/// points whose support leaves the stored nodes (0 when all is well; the caller reports them).
template <int D, class Kernel>
std::int64_t compute_shape_cache(const Grid<D>& grid, const Kernel& kernel, const std::vector<Vec<D>>& x,
                                 ShapeCache<D>& cache) {
  constexpr int S = Kernel::support;
  int K = 1;
  for (int a = 0; a < D; ++a) K *= S;
  const auto np = static_cast<std::int64_t>(x.size());
  cache.reserve(np, K);
  cache.apic_by_gradient = Kernel::apic_by_gradient;
  const double h = grid.h_m, inv_h = 1.0 / h;
  int stride[D], nodes[D];
  bool periodic[D];
  for (int a = 0; a < D; ++a) {
    stride[a] = grid.stride(a);
    nodes[a] = grid.nodes(a);
    periodic[a] = grid.periodic[a];
  }
  std::int64_t bad = 0;
#pragma omp parallel for schedule(static) reduction(+ : bad)
  for (std::int64_t p = 0; p < np; ++p) {
    double w1[D][S], dw1[D][S], off1[D][S];
    int idx1[D][S];
    bool ok = true;
    for (int a = 0; a < D; ++a) {
      const double xi = (x[p][a] - grid.origin_m[a]) * inv_h;
      int base = 0;
      kernel(xi, base, w1[a], dw1[a]);
      double m2 = 0.0;
      for (int j = 0; j < S; ++j) {
        dw1[a][j] *= inv_h;
        off1[a][j] = (base + j - xi) * h;
        m2 += w1[a][j] * off1[a][j] * off1[a][j];
      }
      // Storage indices of base … base + S − 1 (= grid.storage_index, one modulo per axis).
      if (periodic[a]) {
        int st = grid.storage_index(a, base);
        for (int j = 0; j < S; ++j, ++st) {
          if (st >= nodes[a]) st -= nodes[a];
          idx1[a][j] = st * stride[a];
        }
      } else {
        for (int j = 0; j < S; ++j) {
          const int st = base + j + Grid<D>::kGhost;
          const bool in = st >= 0 && st < nodes[a];
          ok = ok && in;
          idx1[a][j] = in ? st * stride[a] : 0;
        }
      }
      cache.inv_D[p][a] = m2 > 0.0 ? 1.0 / m2 : 0.0;
    }
    if (!ok) ++bad;
    // Tensor product; local node k enumerates (j_0, …, j_{D−1}) with the last axis fastest.
    const std::int64_t o = p * K;
    if constexpr (D == 2) {
      int k = 0;
      for (int j0 = 0; j0 < S; ++j0) {
        for (int j1 = 0; j1 < S; ++j1, ++k) {
          cache.node[o + k] = idx1[0][j0] + idx1[1][j1];
          cache.w[o + k] = w1[0][j0] * w1[1][j1];
          cache.grad[o + k] = Vec<D>(dw1[0][j0] * w1[1][j1], w1[0][j0] * dw1[1][j1]);
          cache.offset[o + k] = Vec<D>(off1[0][j0], off1[1][j1]);
        }
      }
    } else {
      for (int k = 0; k < K; ++k) {
        int rem = k, flat = 0;
        double wk = 1.0;
        int j[D];
        for (int a = D - 1; a >= 0; --a) {
          j[a] = rem % S;
          rem /= S;
        }
        Vec<D> g, off;
        for (int a = 0; a < D; ++a) {
          flat += idx1[a][j[a]];
          wk *= w1[a][j[a]];
          off[a] = off1[a][j[a]];
        }
        for (int a = 0; a < D; ++a) {
          double ga = dw1[a][j[a]];
          for (int b = 0; b < D; ++b)
            if (b != a) ga *= w1[b][j[b]];
          g[a] = ga;
        }
        cache.node[o + k] = flat;
        cache.w[o + k] = wk;
        cache.grad[o + k] = g;
        cache.offset[o + k] = off;
      }
    }
  }
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
