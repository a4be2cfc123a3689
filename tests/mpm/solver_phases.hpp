#pragma once
// The solver's phases for one body, driven as Solver::step drives them (the same functions and
// the same scheduling of parallel.hpp), for tests that check one transfer or one law at a time.
#include <cstdint>

#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/solver.hpp"

namespace oobleck::mpm::phases {

/// Phase 2 (P2G) of one body on field.max_threads() threads: the shape cache, the scatter into
/// the threads' copies, a barrier, the sums (and gravity when given). Returns the number of points
/// whose support left the grid.
template <class G, int K, class Kernel>
std::int64_t particles_to_grid(const Body<G>& body, const Grid<G::dim>& grid, const Kernel& kernel,
                               ShapeCache<G::dim>& cache, GridField<G>& field, bool apic, bool split_pressure = false,
                               const Vec<G::ncomp>* gravity_m_s2 = nullptr) {
  detail::p2g_prepare<G, K, Kernel>(body, cache);
  const int saved = parallel::max_threads();
  parallel::set_threads(field.max_threads());
  std::int64_t outside = 0;
  parallel::region([&](const parallel::Team& team) {
    parallel::atomic_add(outside,
                         detail::p2g_scatter_share<G, K>(team, body, grid, kernel, cache, field, apic, split_pressure));
    team.barrier();
    detail::p2g_sum_share(team, field, split_pressure, gravity_m_s2);
  });
  parallel::set_threads(saved);
  return outside;
}

/// Phase 6 (G2P) of one body: its task's blocks in static shares with stealing. Returns the
/// lowest index of a point whose new x, v or V is not finite, or kAllFinite.
template <class G, int K>
std::int64_t grid_to_particles(Body<G>& body, const ShapeCache<G::dim>& cache, const GridField<G>& field,
                               const Grid<G::dim>& grid, Transfer transfer, double flip_fraction, double dt_s,
                               const double* porosity = nullptr, const Vec<G::ncomp>* mixture_flux = nullptr) {
  const G2PTask<G> task =
      make_g2p_task<G, K>(body, cache, field, grid, transfer, flip_fraction, dt_s, porosity, mixture_flux);
  parallel::StealingShares shares;
  std::int64_t bad = kAllFinite;
  parallel::region([&](const parallel::Team& team) {
    team.single([&] {
      shares.resize(1, team.size());
      shares.start(0, task.blocks);
    });
    parallel::atomic_min(bad, run_g2p_share(team, shares, 0, task));
  });
  return bad;
}

/// Phase 7 (the law) of one body: its chunks as its ScheduleHint says, then end_update.
template <class G>
void update_stress(StressLaw<G>& law, Body<G>& body, double dt_s) {
  parallel::StealingShares shares;
  std::int64_t bad = kAllFinite;
  parallel::region([&](const parallel::Team& team) {
    team.single([&] {
      shares.resize(1, team.size());
      shares.start(0, law.chunk_count(body));
    });
    parallel::atomic_min(bad, run_law_share(team, shares, 0, law, body, dt_s));
  });
  law.end_update(body, dt_s, bad);
}

}  // namespace oobleck::mpm::phases
