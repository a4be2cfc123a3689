#pragma once
// One explicit step (docs/mpm.md, "The step": update-stress-last), written out: the phases of
// mpm/phases/*.hpp in order, numbered as docs/mpm.md numbers them, with every parallel region,
// barrier and halo exchange of a decomposed run (docs/mpi.md; the arrays of each exchange are the
// registry's, SolverState::nodal_fields and fields.hpp HaloRule) on its own line.
#include <cstdint>

#include "oobleck/mpm/halo.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/phases/contact.hpp"
#include "oobleck/mpm/phases/grid.hpp"
#include "oobleck/mpm/phases/p2g.hpp"
#include "oobleck/mpm/phases/points.hpp"
#include "oobleck/mpm/solver_state.hpp"

namespace oobleck::mpm {

/// A decomposed run's nodal exchange `rule`: the registry's arrays of that rule (Halo::apply).
template <class G>
inline void halo_exchange(SolverState<G>& s, HaloRule rule) {
  s.timed_exchange([&] { s.halo->apply(rule, s.nodal_fields().exchanged(rule)); });
}

/// The step with kernels of S nodes per axis (K = S^D in all).
template <class G, int S>
inline void step_kernel(SolverState<G>& s) {
  constexpr int K = S * S * (G::dim == 3 ? S : 1);
  double t_lap = parallel::wall_time();  // the timings' laps (StepTimings)
  auto lap = [&](double& acc) {
    const double t = parallel::wall_time();
    acc += t - t_lap;
    t_lap = t;
  };
  const int nn = s.grid.node_count();
  // 1. Motors: velocity drive of driven bodies (contact.hpp).
  phases::apply_motors(s);
  // 2. P2G: shape functions, mass, momentum, forces, gravity; decomposed: the sums to the owners.
  phases::p2g_prepare<G, K>(s);
  parallel::region([&](const parallel::Team& team) {
    phases::p2g_scatter<G, K>(team, s);
    team.barrier();
    phases::p2g_sum(team, s);
  });
  phases::p2g_check(s);
  if (s.halo) halo_exchange(s, HaloRule::sum_after_p2g);
  lap(s.timings.p2g);
  // 3. Grid: walls fold ghosts, rigid predictions; porosity, buoyancy (E28), v = (mv + Δt f)/m,
  //    drag (E29); beside it (one thread), contact's mass gradients (contact, parts 1 and 2).
  if (s.opt.shape == ShapeKind::Linear && s.opt.linear_mass_floor > 0.0) phases::prepare_mass_floor(s);
  phases::prepare_rigid_and_contact(s);
  phases::prepare_grid_pass(s);
  if (s.fluid < 0) {
    for (int b = 0; b < s.body_count(); ++b) phases::fold_and_predict(s, b);
    phases::scatter_contact_gradients<G, K>(s);
    parallel::region([&](const parallel::Team& team) { phases::predict_solids(team, s); }, nn >= kParallelMinNodes);
  } else {
    parallel::region(
        [&](const parallel::Team& team) {
          team.dynamic(s.body_count(), 1, [&](std::int64_t b) { phases::fold_and_predict(s, static_cast<int>(b)); });
          team.barrier();
          team.single_nowait([&] { phases::scatter_contact_gradients<G, K>(s); });
          phases::couple_node_blocks(team, s);
        },
        nn >= kParallelMinNodes / 32);  // ~20 ns per node (drag)
  }
  // 4. Contact impulses (contact.hpp), rigid bodies' velocities; decomposed: contact's sums first.
  if (s.halo && !s.contacts.empty()) halo_exchange(s, HaloRule::sum_before_contact);
  phases::resolve_contacts(s);
  lap(s.timings.grid);
  // 5.–7. (rigid bodies' points move with their body before the region)
  phases::prepare_points(s);
  parallel::region([&](const parallel::Team& team) {
    // 5. Walls on nodal velocities; decomposed: the owners' velocities (and porosity) out to the
    //    neighbours' copies (on the first thread); mixture flux q (E27) and the swirl test.
    phases::apply_walls(team, s);
    team.barrier();
    if (s.halo) {
      if (team.rank() == 0) halo_exchange(s, HaloRule::copy_before_flux);
      team.barrier();
    }
    phases::flux_and_swirl(team, s);
    team.barrier();
    team.single([&] { phases::prepare_point_tasks<G, K>(s, team.size()); });
    // 6. G2P: x, v (APIC or FLIP/PIC), C, L, V ← V exp(Δt tr L).
    phases::g2p(team, s);
    team.barrier();
    if (team.rank() == 0) lap(s.timings.g2p);
    // 7. Laws: stresses (and their state) from L, costliest bodies first; end_update after.
    phases::laws(team, s);
  });
  phases::end_laws(s);
  lap(s.timings.stress);
  // 8. Mixture points back out of free rigid bodies (contact.hpp); decomposed: points to their
  //    new blocks.
  phases::keep_mixture_out_of_free_rigid_bodies(s);
  if (s.dec) {
    s.timed_exchange([&] {
      for (auto& b : s.bodies) s.points_migrated += migrate_points(*b, *s.dec);
    });
    lap(s.timings.stress);
  }
}

/// One step of length opt.dt_s: step_kernel for the shape functions' support, then the clock.
template <class G>
inline void step(SolverState<G>& s) {
  static_assert(G::dim == 2 || G::dim == 3);
  switch (kernel_support(s.opt.shape)) {
    case 2: step_kernel<G, 2>(s); break;
    case 4: step_kernel<G, 4>(s); break;
    default: step_kernel<G, 3>(s); break;
  }
  s.time_s += s.opt.dt_s;
  ++s.steps;
}

}  // namespace oobleck::mpm
