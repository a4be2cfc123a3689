#pragma once
// Phase 2, P2G (docs/mpm.md, "The step"), of every body in one region (step.hpp): each point's
// shape functions (into its body's cache) and its scatter, then the nodal sums and gravity. Every
// thread scatters its static share of each body's points into its copy of that body's nodal
// arrays, with no barrier between the bodies; after one barrier, each thread sums the copies over
// its share of the nodes, body after body.
#include <cstdint>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/solver_state.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm::phases {

/// f(kernel) with the kernel object of the step's shape functions (support K nodes in all).
template <class G, int K, class F>
inline void with_step_kernel(const SolverState<G>& s, F&& f) {
  with_kernel(s.opt.shape, s.opt.gimp_half_width_cells, [&](auto kernel) {
    if constexpr (decltype(kernel)::support == support_of<G::dim>(K)) f(kernel);
    // (other supports not reached: the step's dispatch and with_kernel read the same option)
  });
}

/// Before the region: the threads of the step's regions, and each body's shape cache made ready
/// for the scatter (detail::p2g_prepare).
template <class G, int K>
inline void p2g_prepare(SolverState<G>& s) {
  parallel::set_threads(s.threads);
  for (int b = 0; b < s.body_count(); ++b)
    with_step_kernel<G, K>(
        s, [&](auto kernel) { detail::p2g_prepare<G, K, decltype(kernel)>(*s.bodies[b], s.caches[b]); });
  s.p2g_outside.assign(s.bodies.size(), 0);
}

/// Every thread: its static share of every body's points scattered into its copy of the body's
/// nodal sums (shape functions, mass, momentum, forces; detail::p2g_scatter_range).
template <class G, int K>
inline void p2g_scatter(const parallel::Team& team, SolverState<G>& s) {
  const bool apic = s.opt.transfer == Transfer::Apic;
  for (int b = 0; b < s.body_count(); ++b)
    with_step_kernel<G, K>(s, [&](auto kernel) {
      const std::int64_t out = detail::p2g_scatter_share<G, K>(team, *s.bodies[b], s.grid, kernel, s.caches[b],
                                                               s.fields[b], apic, b == s.fluid);
      if (out > 0) parallel::atomic_add(s.p2g_outside[b], out);
    });
}

/// Every thread, after the scatter's barrier: the threads' copies summed over its share of the
/// nodes, body after body, and gravity f_i += m_i g (detail::p2g_sum_nodes).
template <class G>
inline void p2g_sum(const parallel::Team& team, SolverState<G>& s) {
  for (int b = 0; b < s.body_count(); ++b) detail::p2g_sum_share(team, s.fields[b], b == s.fluid, &s.opt.gravity_m_s2);
}

/// After the region: a point whose support left the grid stops the run, naming its body.
template <class G>
inline void p2g_check(const SolverState<G>& s) {
  for (int b = 0; b < s.body_count(); ++b)
    if (s.p2g_outside[b] > 0)
      throw NumericalError(
          fmt::format("mpm: {} point(s) of body '{}' left the grid (more than one cell outside the domain) at "
                      "step {}, t = {} s",
                      s.p2g_outside[b], s.bodies[b]->name, s.steps, s.time_s));
}

}  // namespace oobleck::mpm::phases
