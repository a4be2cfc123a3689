#pragma once
// Uniform Cartesian background grid (docs/mpm.md, "Grid, shape functions and boundary conventions").
//
// Conventions (docs/mpm.md):
// * The physical domain of axis a is [origin_a, origin_a + cells_a h]; its nodes have *logical*
//   indices i = 0 … cells_a, node i at origin_a + i h.
// * Non-periodic axes are extended by `kGhost` = 2 layers of ghost nodes on each side (logical
//   indices −2, −1 and cells+1, cells+2). Shape functions are never truncated or modified near
//   a wall: points near the edge simply reach ghost nodes, so partition of unity, ∑∇N = 0 and
//   linear reproduction hold everywhere. Boundary conditions of a face act on the face node layer
//   and all ghost layers beyond it. Points may move at most one cell outside the domain (cubic
//   B-splines) before the solver stops with an error.
// * Periodic axes have cells_a unique nodes; logical index i maps to i mod cells_a and positions
//   wrap into [origin_a, origin_a + cells_a h).
// * Storage is row-major: the last axis is contiguous.
#include <array>
#include <cmath>
#include <cstdint>

#include "oobleck/mpm/geometry.hpp"

namespace oobleck::mpm {

/// The solver's node passes that have a region of their own (the velocity update of beds without
/// fluid; the grid pass and the mixture flux at fractions of it, Solver) run on several threads
/// only above this many nodes: below it the fork/join (a futex wake-up per region with
/// OMP_WAIT_POLICY=PASSIVE) costs more than the few ns of work per node. Each node is independent
/// in these passes, so the results do not depend on the choice.
inline constexpr int kParallelMinNodes = 1 << 15;

template <int D>
struct Grid {
  static constexpr int kGhost = 2;

  Vec<D> origin_m = Vec<D>::Zero();  ///< [m] lower corner of the physical domain
  double h_m = 1.0;                  ///< [m] cell size (same on every axis)
  std::array<int, D> cells{};        ///< cells per axis
  std::array<bool, D> periodic{};    ///< periodic axes

  Grid() = default;
  Grid(const Vec<D>& origin, double h, const std::array<int, D>& n_cells, const std::array<bool, D>& periodic_axes = {})
      : origin_m(origin), h_m(h), cells(n_cells), periodic(periodic_axes) {}

  /// Stored nodes along axis a.
  int nodes(int a) const { return periodic[a] ? cells[a] : cells[a] + 1 + 2 * kGhost; }
  /// Total number of stored nodes.
  int node_count() const {
    int n = 1;
    for (int a = 0; a < D; ++a) n *= nodes(a);
    return n;
  }
  /// Flat-index stride of axis a (row-major).
  int stride(int a) const {
    int s = 1;
    for (int b = a + 1; b < D; ++b) s *= nodes(b);
    return s;
  }
  /// Storage index along axis a of logical index i; −1 if outside the stored nodes.
  int storage_index(int a, int i) const {
    if (periodic[a]) {
      const int n = cells[a];
      return ((i % n) + n) % n;
    }
    const int s = i + kGhost;
    return (s >= 0 && s < nodes(a)) ? s : -1;
  }
  /// Logical index along axis a of a storage index.
  int logical_index(int a, int s) const { return periodic[a] ? s : s - kGhost; }
  /// Storage multi-index of a flat node index.
  std::array<int, D> unflatten(int flat) const {
    std::array<int, D> s{};
    for (int a = D - 1; a >= 0; --a) {
      s[a] = flat % nodes(a);
      flat /= nodes(a);
    }
    return s;
  }
  /// Position [m] of a stored node.
  Vec<D> node_position(int flat) const {
    const auto s = unflatten(flat);
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = origin_m[a] + logical_index(a, s[a]) * h_m;
    return x;
  }
  /// Domain length [m] along axis a.
  double length(int a) const { return cells[a] * h_m; }
  /// Nodal volume h^D [m^D] (the measure of one node's control volume inside the domain).
  double cell_volume() const { return std::pow(h_m, D); }
  /// Wrap a position into the periodic range on periodic axes.
  void wrap(Vec<D>& x) const {
    for (int a = 0; a < D; ++a) x[a] = wrapped(a, x[a]);
  }
  /// Coordinate x_a wrapped into the periodic range (unchanged on a non-periodic axis).
  double wrapped(int a, double xa) const {
    if (!periodic[a]) return xa;
    const double L = length(a);
    double r = xa - origin_m[a];
    // Inside the range (away from its end by more than round-off) floor(r/L) = 0: the same
    // result without the division.
    if (r >= 0.0 && r <= L * (1.0 - 1e-10)) return origin_m[a] + r;
    r -= L * std::floor(r / L);
    if (r >= L) r -= L;  // guards r == L after round-off
    return origin_m[a] + r;
  }
};

}  // namespace oobleck::mpm
