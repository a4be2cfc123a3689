#pragma once
// Point-field measures that the scene analyses and snapshots read (run/analysis_*.cpp,
// run/snapshots.cpp): a body's centre of mass on a periodic grid and its totals (over every rank
// in decomposed runs), and the mass-weighted nodal average of a point quantity (a post-processing
// interpolation, independent of the solver's kernel).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "oobleck/analysis/data.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/halo.hpp"
#include "oobleck/mpm/solver.hpp"

namespace oobleck::run {

/// Centre of mass of body b, periodic axes unwrapped about its first point (then wrapped);
/// decomposed runs: over every rank's points, about a reference every rank shares (the least of
/// the ranks' mpm::body_reference along each axis). Zero for a body without points.
template <class G>
mpm::Vec<G::dim> centre_of_mass(mpm::Solver<G>& solver, int b) {
  constexpr int D = G::dim;
  const mpm::Body<G>& body = solver.body(b);
  const bool across = solver.decomposition() != nullptr;
  const mpm::Grid<D>& grid = solver.global_grid();
  mpm::Vec<D> x0 = mpm::body_reference(body);
  if (across) comm::min({x0.data(), static_cast<std::size_t>(D)});
  if (!std::isfinite(x0[0])) return mpm::Vec<D>::Zero();
  mpm::Vec<D> s = mpm::Vec<D>::Zero();
  double M = 0.0;
  for (std::int64_t p = 0; p < body.size(); ++p) {
    s += body.mass_kg[p] * mpm::periodic_difference<D>(grid, body.x_m[p], x0);
    M += body.mass_kg[p];
  }
  if (across) {
    double sums[D + 1];
    std::copy_n(s.data(), D, sums);
    sums[D] = M;
    comm::sum(sums);
    s = Eigen::Map<const mpm::Vec<D>>(sums);
    M = sums[D];
  }
  mpm::Vec<D> c = x0 + s / M;
  grid.wrap(c);
  return c;
}

/// Whole-body totals of body b (decomposed runs: over every rank's points): points, mass,
/// momentum, and the lowest coordinate along the last axis (+inf without points).
template <class G>
struct BodyTotals {
  std::int64_t points = 0;
  double mass_kg = 0.0, lowest_m = INFINITY;
  mpm::Vec<G::ncomp> momentum = mpm::Vec<G::ncomp>::Zero();
  mpm::Vec<G::ncomp> mean_velocity() const { return momentum / mass_kg; }
};
template <class G>
BodyTotals<G> body_totals(mpm::Solver<G>& solver, int b) {
  constexpr int NC = G::ncomp;
  const mpm::Body<G>& body = solver.body(b);
  BodyTotals<G> t;
  t.points = body.size();
  t.mass_kg = body.total_mass();
  t.momentum = body.total_momentum();
  for (const auto& x : body.x_m) t.lowest_m = std::min(t.lowest_m, x[G::dim - 1]);
  if (solver.decomposition()) {
    double sums[NC + 1];
    std::copy_n(t.momentum.data(), NC, sums);
    sums[NC] = t.mass_kg;
    comm::sum(sums);
    t.momentum = Eigen::Map<const mpm::Vec<NC>>(sums);
    t.mass_kg = sums[NC];
    t.points = comm::sum(t.points);
    t.lowest_m = comm::min(t.lowest_m);
  }
  return t;
}

/// Mass-weighted nodal average of a point quantity over one or more bodies on the physical
/// nodes of a 2D grid, with bilinear (tent) weights: value_i = Σ w_ip m_p q_p / Σ w_ip m_p
/// (0 where no point contributes). Independent of the solver's kernel: a plain post-processing
/// interpolation. `value(b, p)` gives q of point p of body b. Decomposed runs: `grid` is the
/// global grid and `across_ranks` sums both sums over the ranks first (every rank gets the field).
template <class G, class F>
analysis::GridField2D nodal_average(const mpm::Grid<2>& grid, const std::vector<const mpm::Body<G>*>& bodies, F&& value,
                                    bool across_ranks = false) {
  analysis::GridField2D out;
  out.origin_x = grid.origin_m[0];
  out.origin_y = grid.origin_m[1];
  out.h = grid.h_m;
  out.nx = static_cast<std::size_t>(grid.periodic[0] ? grid.cells[0] : grid.cells[0] + 1);
  out.ny = static_cast<std::size_t>(grid.periodic[1] ? grid.cells[1] : grid.cells[1] + 1);
  out.values.assign(out.nx * out.ny, 0.0);
  std::vector<double> mass(out.values.size(), 0.0);
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const auto& body = *bodies[b];
    for (std::int64_t p = 0; p < body.size(); ++p) {
      const double q = value(b, p), m = body.mass_kg[p];
      const double fx = (body.x_m[p][0] - out.origin_x) / out.h, fy = (body.x_m[p][1] - out.origin_y) / out.h;
      const auto i0 = static_cast<long>(std::floor(fx)), j0 = static_cast<long>(std::floor(fy));
      const double tx = fx - static_cast<double>(i0), ty = fy - static_cast<double>(j0);
      for (int dj = 0; dj < 2; ++dj) {
        for (int di = 0; di < 2; ++di) {
          long i = i0 + di, j = j0 + dj;
          if (grid.periodic[0])
            i = ((i % static_cast<long>(out.nx)) + static_cast<long>(out.nx)) % static_cast<long>(out.nx);
          if (grid.periodic[1])
            j = ((j % static_cast<long>(out.ny)) + static_cast<long>(out.ny)) % static_cast<long>(out.ny);
          if (i < 0 || j < 0 || i >= static_cast<long>(out.nx) || j >= static_cast<long>(out.ny)) continue;
          const double w = (di ? tx : 1.0 - tx) * (dj ? ty : 1.0 - ty) * m;
          const auto k = static_cast<std::size_t>(j) * out.nx + static_cast<std::size_t>(i);
          out.values[k] += w * q;
          mass[k] += w;
        }
      }
    }
  }
  if (across_ranks) {
    std::vector<double> sums = out.values;
    sums.insert(sums.end(), mass.begin(), mass.end());
    comm::sum(sums);
    std::copy_n(sums.begin(), out.values.size(), out.values.begin());
    std::copy(sums.begin() + static_cast<long>(out.values.size()), sums.end(), mass.begin());
  }
  for (std::size_t k = 0; k < mass.size(); ++k) out.values[k] = mass[k] > 0.0 ? out.values[k] / mass[k] : 0.0;
  return out;
}

/// A nodal array of the solver's grid (its storage, e.g. the nodal porosity) on the global grid's
/// physical nodes, x fastest, on every rank (decomposed runs: each node from its owner).
template <class G>
std::vector<double> physical_nodes_on_every_rank(const mpm::Solver<G>& solver, std::span<const double> stored) {
  constexpr int D = G::dim;
  const mpm::Grid<D>& grid = solver.global_grid();
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) n *= static_cast<std::size_t>(grid.periodic[a] ? grid.cells[a] : grid.cells[a] + 1);
  std::vector<double> out;
  if (const auto* dec = solver.decomposition()) {
    out = mpm::gather_physical_nodes<D>(*dec, solver.grid(), stored);
    out.resize(n, 0.0);
    comm::sum(out);  // (rank 0's values plus the others' zeros: exact)
    return out;
  }
  out.resize(n);
  std::size_t k = 0;
  std::array<int, 3> nodes{1, 1, 1};
  for (int a = 0; a < D; ++a) nodes[a] = grid.periodic[a] ? grid.cells[a] : grid.cells[a] + 1;
  for (int kk = 0; kk < nodes[2]; ++kk)
    for (int j = 0; j < nodes[1]; ++j)
      for (int i = 0; i < nodes[0]; ++i) {
        const int l[3] = {i, j, kk};
        int flat = 0;
        for (int a = 0; a < D; ++a) flat += grid.storage_index(a, l[a]) * grid.stride(a);
        out[k++] = stored[static_cast<std::size_t>(flat)];
      }
  return out;
}

}  // namespace oobleck::run
