#pragma once
// Phases 5–7 (docs/mpm.md, "The step"), every body in one region (step.hpp): the walls'
// conditions on the nodal velocities and the mixture flux (5), G2P (6) and the laws (7).
//
// G2P (6): the deformable bodies one after the other with no barrier between them, each thread
// first its static share of the body's blocks — the split of P2G's scatter, the points whose data
// are in its core's caches — then what is left of the other threads' shares (stealing: a slower
// core's points move to the other only at the end of its share). Rigid bodies' points move with
// their body, before the region.
//
// The laws (7): the bodies with costly, uneven chunks first (ScheduleHint; the granular law) in
// static shares with stealing, then the others (the fluid's, an elastic body's) in static shares:
// the points each thread maps in G2P and scatters in P2G. No barrier between the bodies; then each
// law's end_update, in body order, after the region.
//
// Every point's update is independent of the others: the results do not depend on the schedule
// (bit for bit the same on any number of threads as a serial run of the same code).
#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/solver_state.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

/// Phase 6 for one body, by the calling thread of a region: G2P's blocks of `task` in static
/// shares with stealing (set `set` of `shares`, started with task.blocks). Returns the lowest
/// index of a non-finite point among the blocks this thread ran, or kAllFinite.
template <class G>
std::int64_t run_g2p_share(const parallel::Team& team, parallel::StealingShares& shares, int set,
                           const G2PTask<G>& task) {
  constexpr std::int64_t kBlocksAtATime = 4;  // (4 × 32 points taken from a share at a time)
  std::int64_t bad = kAllFinite;
  shares.run(team, set, task.blocks, kBlocksAtATime,
             [&](std::int64_t b0, std::int64_t b1) { bad = std::min(bad, task.run(b0, b1)); });
  return bad;
}

/// Phase 7 for one body, by the calling thread of a region: the law's chunks as its ScheduleHint
/// says (uneven: static shares with stealing, set `set` of `shares`, started with the chunk count;
/// otherwise the thread's static share). Returns the lowest index of a non-finite point among the
/// chunks this thread ran, or kAllFinite. end_update follows after the region.
template <class G>
std::int64_t run_law_share(const parallel::Team& team, parallel::StealingShares& shares, int set, StressLaw<G>& law,
                           Body<G>& body, double dt_s) {
  const std::int64_t chunks = law.chunk_count(body);
  std::int64_t bad = kAllFinite;
  auto run = [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c) bad = std::min(bad, law.update_chunk(body, dt_s, c));
  };
  if (law.schedule_hint().uneven_chunks) {
    shares.run(team, set, chunks, 1, run);
  } else {
    const parallel::Range r = team.share(chunks);
    run(r.begin, r.end);
  }
  return bad;
}

namespace phases {

/// Before the region: rigid bodies' points moved with their body; the G2P bodies (the deformable
/// ones) and the law bodies (costliest first) listed; the per-body results reset; the flux sized.
template <class G>
inline void prepare_points(SolverState<G>& s) {
  const int nb = s.body_count();
  s.non_finite_kinematics.assign(s.bodies.size(), kAllFinite);
  s.g2p_bodies.clear();
  for (int b = 0; b < nb; ++b) {
    if (s.rigid[b].rigid()) {
      move_rigid_points(*s.bodies[b], s.rigid[b], s.grid, s.opt.dt_s);
      s.non_finite_kinematics[b] = kNotChecked;
    } else {
      s.g2p_bodies.push_back(b);
    }
  }
  s.law_bodies.clear();
  for (int b = 0; b < nb; ++b)
    if (s.bodies[b]->law) s.law_bodies.push_back(b);
  std::stable_sort(s.law_bodies.begin(), s.law_bodies.end(), [&](int a, int b) {
    return s.bodies[a]->law->schedule_hint().relative_cost_per_point >
           s.bodies[b]->law->schedule_hint().relative_cost_per_point;
  });
  s.law_first_bad.assign(s.bodies.size(), kAllFinite);
  if (s.fluid >= 0) s.flux.resize(static_cast<std::size_t>(s.grid.node_count()));
  s.swirl = 0;
}

/// Phase 5a, every thread: the walls' conditions on every body's nodal velocities (each body its
/// own field: the bodies handed out dynamically; a barrier follows: the flux reads the
/// constrained velocities).
template <class G>
inline void apply_walls(const parallel::Team& team, SolverState<G>& s) {
  team.dynamic(s.body_count(), 1,
               [&](std::int64_t b) { apply_boundary_conditions<G>(s.grid, s.bc, s.fields[b], s.opt.dt_s); });
}

/// The mixture's nodal volume flux q_i = (1 − n_i) v^s_i + n_i v^f_i (E27) over the nodes
/// [i0, i1), and (axisymmetric) which of the G2P bodies have θ velocity (or, the fluid, θ flux)
/// on these nodes: bit k of the result for g2p_bodies[k] (g2p_without_swirl, node by node).
template <class G>
inline std::uint64_t mixture_flux_and_swirl(SolverState<G>& s, int i0, int i1) {
  std::uint64_t swirl = 0;
  if (s.fluid >= 0) {
    const GridField<G>& sf = s.fields[s.grains >= 0 ? s.grains : s.fluid];  // n = 1 without grains
    const GridField<G>& f = s.fields[s.fluid];
    for (int i = i0; i < i1; ++i) {
      const double n = s.porosity[i];
      s.flux[i] = (1.0 - n) * sf.velocity[i] + n * f.velocity[i];
    }
  }
  if constexpr (G::has_hoop_terms) {
    const int nk = std::min<int>(64, static_cast<int>(s.g2p_bodies.size()));
    for (int k = 0; k < nk; ++k) {
      const int b = s.g2p_bodies[k];
      const GridField<G>& field = s.fields[b];
      bool none = true;
      for (int i = i0; i < i1; ++i)
        none &=
            (field.velocity[i][2] == 0.0) & (field.velocity_old[i][2] == 0.0) & (b != s.fluid || s.flux[i][2] == 0.0);
      if (!none) swirl |= std::uint64_t{1} << k;
    }
    // (bodies past the 64th keep the general kernels: the same values)
    for (int k = nk; k < static_cast<int>(s.g2p_bodies.size()); ++k) swirl |= std::uint64_t{1} << 63;
  }
  return swirl;
}

/// Phase 5b, every thread: the mixture flux and the swirl test over its share of the nodes on
/// grids of 512 nodes and more (the intruder's 2200: 0.7% of the samples on the master when
/// serial); smaller ones on the first thread, the others going on to the barrier that follows.
template <class G>
inline void flux_and_swirl(const parallel::Team& team, SolverState<G>& s) {
  const int nn = s.grid.node_count();
  std::uint64_t mine = 0;
  if (nn >= kParallelMinNodes / 64) {
    const parallel::Range r = team.share(nn);
    mine = mixture_flux_and_swirl(s, static_cast<int>(r.begin), static_cast<int>(r.end));
  } else if (team.rank() == 0) {
    mine = mixture_flux_and_swirl(s, 0, nn);
  }
  if (mine != 0) parallel::atomic_or(s.swirl, mine);
}

/// On one thread, after the swirl test: the G2P tasks of the deformable bodies (their kernels
/// chosen by the test) and the stealing shares of the G2P tasks and of the law bodies.
template <class G, int K>
inline void prepare_point_tasks(SolverState<G>& s, int team) {
  static_assert(!std::is_same_v<G, Axisymmetric> || K == 4 || K == 9 || K == 16,
                "a new kernel support: add its axisymmetric G2P to transfer_axisymmetric.cpp");
  const int ntasks = static_cast<int>(s.g2p_bodies.size());
  s.g2p_tasks.clear();
  for (int k = 0; k < ntasks; ++k) {
    const int b = s.g2p_bodies[k];
    s.g2p_tasks.push_back(make_g2p_task<G, K>(
        *s.bodies[b], s.caches[b], s.fields[b], s.grid, s.opt.transfer, s.opt.flip_fraction, s.opt.dt_s,
        b == s.fluid ? s.porosity.data() : nullptr, b == s.fluid ? s.flux.data() : nullptr,
        G::has_hoop_terms && (s.swirl >> std::min(k, 63) & 1u) == 0));
  }
  s.shares.resize(ntasks + static_cast<int>(s.law_bodies.size()), team);
  for (int k = 0; k < ntasks; ++k) s.shares.start(k, s.g2p_tasks[k].blocks);
  for (std::size_t k = 0; k < s.law_bodies.size(); ++k) {
    Body<G>& body = *s.bodies[s.law_bodies[k]];
    s.shares.start(ntasks + static_cast<int>(k), body.law->chunk_count(body));
  }
}

/// Phase 6, every thread: each G2P body's blocks in static shares with stealing, no barrier
/// between the bodies.
template <class G>
inline void g2p(const parallel::Team& team, SolverState<G>& s) {
  for (int k = 0; k < static_cast<int>(s.g2p_tasks.size()); ++k) {
    const std::int64_t bad = run_g2p_share(team, s.shares, k, s.g2p_tasks[k]);
    if (bad != kAllFinite) parallel::atomic_min(s.non_finite_kinematics[s.g2p_bodies[k]], bad);
  }
}

/// Phase 7, every thread: the laws' chunks, the costliest bodies first, no barrier between them.
template <class G>
inline void laws(const parallel::Team& team, SolverState<G>& s) {
  const int ntasks = static_cast<int>(s.g2p_tasks.size());
  for (std::size_t k = 0; k < s.law_bodies.size(); ++k) {
    const int b = s.law_bodies[k];
    const std::int64_t bad =
        run_law_share(team, s.shares, ntasks + static_cast<int>(k), *s.bodies[b]->law, *s.bodies[b], s.opt.dt_s);
    if (bad != kAllFinite) parallel::atomic_min(s.law_first_bad[b], bad);
  }
}

/// After the region: each law's end_update, in body order.
template <class G>
inline void end_laws(SolverState<G>& s) {
  for (int b = 0; b < s.body_count(); ++b)
    if (s.bodies[b]->law) s.bodies[b]->law->end_update(*s.bodies[b], s.opt.dt_s, s.law_first_bad[b]);
}

}  // namespace phases
}  // namespace oobleck::mpm
