#pragma once
// Domain decomposition (docs/mpi.md): the background grid's cells split into blocks over a
// Cartesian grid of ranks; each rank owns the points inside its block and solves on a local grid
// that is its block with the grid's two ghost layers on every side (grid.hpp).
//
// Ownership of nodes along a split axis a, with the rank's block [c0, c1) of the global cells and
// n = c1 − c0 local cells (local logical index l = global index − c0):
//   l in [0, n)         owned (a rank at the upper end of a non-periodic axis also owns l = n
//                       and the ghost layers beyond the domain; one at the lower end those below);
//   l in [−2, 0)        the lower neighbour's, l in [n, n + 3) the upper neighbour's.
// After P2G the partial sums on a neighbour's nodes are sent to it and added (Halo::sum); after
// the grid update the owners' values are copied back out (Halo::copy). Axis by axis, each slab
// spanning the other axes' ghost layers too, so that corner nodes reach their owner in two (three)
// hops. A block needs at least kMinBlockCells cells along a split axis.
//
// An axis that is not split (one rank along it) keeps its periodicity in the local grid; a split
// periodic axis is non-periodic locally (its wrap is the neighbour relation of the end ranks).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/mpm/grid.hpp"

namespace oobleck::mpm {

/// Fewest cells of a block along a split axis: the upper neighbour's ghost layers l = n … n + 2
/// land on owned nodes 0 … 2 of the block above.
inline constexpr int kMinBlockCells = Grid<2>::kGhost + 1;

/// Parse "2x1" / "2x1x1" (one factor per axis); InputError naming `what` otherwise.
template <int D>
std::array<int, D> parse_ranks_grid(const std::string& text, const std::string& what) {
  std::array<int, D> dims{};
  std::size_t pos = 0;
  for (int a = 0; a < D; ++a) {
    const std::size_t end = text.find('x', pos);
    const std::string part = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    int v = 0;
    try {
      std::size_t used = 0;
      v = std::stoi(part, &used);
      if (used != part.size()) v = 0;
    } catch (const std::exception&) {
      v = 0;
    }
    if (v < 1 || (a < D - 1 && end == std::string::npos) || (a == D - 1 && end != std::string::npos))
      throw InputError(fmt::format("{} '{}': expected {} positive factors joined by 'x' (one per grid axis, e.g. {})",
                                   what, text, D, D == 2 ? "2x1" : "2x1x1"));
    dims[a] = v;
    pos = end + 1;
  }
  return dims;
}

template <int D>
class Decomposition {
 public:
  /// Points per cell layer along each axis (load[a][c]: the points whose cell index along axis a
  /// is c), for cuts that balance the points; empty: cuts that balance the cells.
  using Load = std::array<std::vector<double>, D>;

  /// The layout of `ranks` ranks over `global`: `dims` given (all > 0, product = ranks) or chosen
  /// (dims all 0: the split with the least block surface, i.e. the fewest ghost nodes). Along each
  /// split axis the cuts give every block about the same share of `load` (of the cells without
  /// it), at least kMinBlockCells cells each. InputError when the product differs from the rank
  /// count or a block would be thinner than kMinBlockCells.
  Decomposition(const Grid<D>& global, int ranks, int rank, std::array<int, D> dims = {}, const Load& load = {})
      : global_(global), rank_(rank) {
    bool given = true;
    for (int a = 0; a < D; ++a) given = given && dims[a] > 0;
    if (given) {
      dims_ = dims;
    } else if (const auto chosen = choose_dims(global, ranks)) {
      dims_ = *chosen;
    } else {
      throw InputError(fmt::format(
          "domain decomposition over {} ranks: the grid ({} cells) is too small; every split leaves a block "
          "thinner than {} cells along a split axis (the ghost layers of the shape functions). Use fewer ranks or "
          "a finer grid",
          ranks, fmt::join(global.cells, "x"), kMinBlockCells));
    }
    int product = 1;
    for (int a = 0; a < D; ++a) product *= dims_[a];
    if (product != ranks)
      throw InputError(fmt::format("--ranks-grid {}: {} ranks in the grid, but the run has {} (mpirun -np {})",
                                   dims_string(), product, ranks, ranks));
    for (int a = 0; a < D; ++a) {
      if (dims_[a] > 1 && global.cells[a] / dims_[a] < kMinBlockCells)
        throw InputError(fmt::format(
            "domain decomposition {} over {} ranks: axis {} has {} cells, {} per rank; a block needs at least {} "
            "cells along a split axis (the ghost layers of the shape functions). Use fewer ranks along that axis "
            "(--ranks-grid) or a finer grid",
            dims_string(), ranks, a, global.cells[a], global.cells[a] / dims_[a], kMinBlockCells));
    }
    const auto c = comm::cart_coords(dims_, rank_);
    for (int a = 0; a < D; ++a) {
      coords_[a] = c[a];
      starts_[a] = cuts(global.cells[a], dims_[a], load[a]);
    }
  }

  const std::array<int, D>& dims() const { return dims_; }
  const std::array<int, D>& coords() const { return coords_; }
  int rank() const { return rank_; }
  int ranks() const {
    int n = 1;
    for (int a = 0; a < D; ++a) n *= dims_[a];
    return n;
  }
  bool split(int a) const { return dims_[a] > 1; }
  const Grid<D>& global() const { return global_; }
  /// First global cell of the block with coordinate k along axis a (k = dims: the end).
  int start(int a, int k) const { return starts_[a][k]; }
  int block_begin(int a) const { return starts_[a][coords_[a]]; }
  int block_cells(int a) const { return starts_[a][coords_[a] + 1] - starts_[a][coords_[a]]; }

  /// The rank's local grid: its block, periodic only on unsplit periodic axes.
  Grid<D> local_grid() const {
    Vec<D> origin = global_.origin_m;
    std::array<int, D> cells{};
    std::array<bool, D> periodic{};
    for (int a = 0; a < D; ++a) {
      origin[a] += block_begin(a) * global_.h_m;
      cells[a] = block_cells(a);
      periodic[a] = global_.periodic[a] && !split(a);
    }
    return Grid<D>(origin, global_.h_m, cells, periodic);
  }

  /// Whether this rank owns the local grid's nodes with logical index l along axis a (see the
  /// header: [0, n) of a split axis, and the ghost layers beyond a non-periodic domain's end; every
  /// node along an axis that is not split).
  bool owns(int a, int l) const {
    if (!split(a)) return true;
    const bool first = coords_[a] == 0, last = coords_[a] == dims_[a] - 1, periodic = global_.periodic[a];
    if (l < 0) return first && !periodic;
    if (l >= block_cells(a)) return last && !periodic;
    return true;
  }

  /// The neighbour along axis a on side `upper` (wrapping on periodic axes), or −1.
  int neighbour(int a, bool upper) const {
    if (!split(a)) return -1;
    auto c = coords_;
    c[a] += upper ? 1 : -1;
    if (c[a] < 0 || c[a] >= dims_[a]) {
      if (!global_.periodic[a]) return -1;
      c[a] = (c[a] + dims_[a]) % dims_[a];
    }
    return cart(c);
  }

  /// The rank that owns a position (wrapped on periodic axes; positions outside the domain go to
  /// the end blocks).
  int owner(const Vec<D>& x_m) const {
    std::array<int, D> c{};
    for (int a = 0; a < D; ++a) {
      if (!split(a)) continue;
      const double xa = global_.wrapped(a, x_m[a]);
      const int cell = static_cast<int>(std::floor((xa - global_.origin_m[a]) / global_.h_m));
      // the block whose [start, end) holds the cell (clamped to the end blocks)
      const auto& s = starts_[a];
      const auto it = std::upper_bound(s.begin() + 1, s.end() - 1, cell);
      c[a] = static_cast<int>(it - (s.begin() + 1));
    }
    return cart(c);
  }

  /// "2x1x1".
  std::string dims_string() const { return fmt::format("{}", fmt::join(dims_, "x")); }

 private:
  int cart(const std::array<int, D>& c) const { return comm::cart_rank(dims_, c); }

  /// Block starts along one axis of `cells` cells in `parts` blocks (parts + 1 values, 0 … cells):
  /// block k starts at the first cell where the cumulative load reaches k/parts of the total,
  /// kept kMinBlockCells apart; equal shares of the cells without a load.
  static std::vector<int> cuts(int cells, int parts, const std::vector<double>& load) {
    std::vector<int> s(static_cast<std::size_t>(parts) + 1);
    for (int k = 0; k <= parts; ++k) s[k] = static_cast<int>(static_cast<long>(cells) * k / parts);
    double total = 0.0;
    for (double w : load) total += w;
    if (parts == 1 || static_cast<int>(load.size()) != cells || !(total > 0.0)) return s;
    double cum = 0.0;
    int c = 0;
    for (int k = 1; k < parts; ++k) {
      const double target = total * k / parts;
      while (c < cells && cum + load[c] <= target) cum += load[c++];
      // the nearer of the two cell faces around the target
      int cut = (c < cells && target - cum > cum + load[c] - target) ? c + 1 : c;
      cut = std::clamp(cut, s[k - 1] + kMinBlockCells, cells - (parts - k) * kMinBlockCells);
      s[k] = cut;
    }
    return s;
  }

  /// The split of `ranks` with the fewest ghost nodes (the least block surface), among those whose
  /// blocks are at least kMinBlockCells thick along split axes; of equal ones, the one that splits
  /// the later axes more.
  static std::optional<std::array<int, D>> choose_dims(const Grid<D>& g, int ranks) {
    std::optional<std::array<int, D>> best;
    double best_surface = std::numeric_limits<double>::infinity();
    std::array<int, D> d{};
    auto visit = [&](auto&& self, int a, int left) -> void {
      if (a == D - 1) {
        d[a] = left;
        double surface = 0.0;
        for (int b = 0; b < D; ++b) {
          if (d[b] > 1 && g.cells[b] / d[b] < kMinBlockCells) return;
          double face = 1.0;
          for (int e = 0; e < D; ++e)
            if (e != b) face *= static_cast<double>(g.cells[e]) / d[e];
          if (d[b] > 1) surface += face;
        }
        if (surface < best_surface) {
          best_surface = surface;
          best = d;
        }
        return;
      }
      for (int f = 1; f <= left; ++f)
        if (left % f == 0) {
          d[a] = f;
          self(self, a + 1, left / f);
        }
    };
    visit(visit, 0, ranks);
    return best;
  }

  Grid<D> global_;
  int rank_ = 0;
  std::array<int, D> dims_{}, coords_{};
  std::array<std::vector<int>, D> starts_;
};

}  // namespace oobleck::mpm
