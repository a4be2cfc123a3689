#pragma once
// The step's contact phases (docs/contact.md; the kernels in mpm/contact.hpp): the motors
// (phase 1), contact part 1 before the grid pass (the rigid masses, node weights, the box near the
// solids), part 2 beside the grid pass (the mass gradients' scatter), part 3 after it (phase 4:
// the impulses and the rigid bodies' velocities) and part 4 after the points moved (phase 8: the
// mixture's points out of free rigid bodies). step.hpp calls them and completes contact's nodal
// sums on their owners (HaloRule::sum_before_contact) between parts 2 and 3. The kernels return
// this rank's share of each whole-body sum; these phases complete the shares over the ranks
// (`complete`, `shared_reference`), each where the step needs it.
#include <algorithm>
#include <cmath>
#include <span>
#include <cstddef>
#include <type_traits>

#include "oobleck/core/comm.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/solver_state.hpp"

namespace oobleck::mpm::phases {

/// Completes this rank's share of a sum over the ranks in place (decomposed runs; the same bits on
/// every rank: comm::sum_ordered); a run on one rank has the whole sum already.
template <class G>
inline void complete(const SolverState<G>& s, std::span<double> share) {
  if (s.dec) comm::sum_ordered(share);
}

/// Body b's reference point for minimum-image differences (contact.hpp body_reference), the same
/// on every rank: decomposed, the least over the ranks along each axis.
template <class G>
inline Vec<G::dim> shared_reference(const SolverState<G>& s, int b) {
  Vec<G::dim> x0 = body_reference(*s.bodies[b]);
  if (s.dec) comm::min({x0.data(), static_cast<std::size_t>(G::dim)});
  return x0;
}

/// Phase 1: the velocity-level motors of driven bodies (plane strain and 3D), each from its body's
/// angular state over every rank's points (the two stages of moments completed in turn).
template <class G>
inline void apply_motors(SolverState<G>& s) {
  if constexpr (!std::is_same_v<G, Axisymmetric>) {
    const Grid<G::dim>& grid = s.global_grid();
    for (auto& m : s.motors) {
      Body<G>& body = *s.bodies[m.body];
      BodyMoments<G> moments;
      moments.x0 = shared_reference(s, m.body);
      AngularState<G> state;
      if (std::isfinite(moments.x0[0])) {  // (else no rank has points of the body)
        add_first_moments(moments, body, grid);
        complete(s, moments.first);
        add_second_moments(moments, body, grid);
        complete(s, moments.second);
        state = angular_state(moments, grid);
      }
      apply_motor(m, body, grid, state, s.opt.dt_s);
    }
  }
}

/// The box around every contact solid's points (over every rank), grown by two kernel widths.
template <class G>
inline ContactBox<G::dim> box_around_contact_solids(const SolverState<G>& s) {
  constexpr int D = G::dim;
  const Grid<D>& grid = s.global_grid();
  Vec<D> ref = Vec<D>::Constant(INFINITY);  // the first solid's reference point (every rank's)
  for (const auto& c : s.contacts) {
    ref = shared_reference(s, c.solid);
    if (std::isfinite(ref[0])) break;
  }
  ContactBox<D> box;
  if (!std::isfinite(ref[0])) return box;  // no solid has points
  double lo_hi[2 * D];                     // lo, −hi (one minimum over the ranks)
  std::fill(lo_hi, lo_hi + 2 * D, INFINITY);
  for (const auto& c : s.contacts) {
    const auto& sb = *s.bodies[c.solid];
    for (std::int64_t p = 0; p < sb.size(); ++p) {
      const Vec<D> d = periodic_difference<D>(grid, sb.x_m[p], ref);
      for (int a = 0; a < D; ++a) {
        lo_hi[a] = std::min(lo_hi[a], d[a]);
        lo_hi[D + a] = std::min(lo_hi[D + a], -d[a]);
      }
    }
  }
  if (s.dec) comm::min(lo_hi);
  const Vec<D> lo = Eigen::Map<const Vec<D>>(lo_hi), hi = -Eigen::Map<const Vec<D>>(lo_hi + D);
  const double margin = 2.0 * kernel_support(s.opt.shape) * s.grid.h_m;
  box.any = true;
  box.centre = ref + 0.5 * (lo + hi);
  box.half = 0.5 * (hi - lo) + Vec<D>::Constant(margin);
  return box;
}

/// Before the grid pass (on the main thread: it may talk to the other ranks): the rigid bodies'
/// masses (over every rank); contact, part 1: the node weights and measures (once; decomposed: 0
/// on the nodes another rank owns), the arrays part 2 fills, and the box of the mixture's points
/// near the solids (part 2's scatter_mass_gradient_near).
template <class G>
inline void prepare_rigid_and_contact(SolverState<G>& s) {
  constexpr int D = G::dim;
  for (int b = 0; b < s.body_count(); ++b) {
    if (!s.rigid[b].rigid()) continue;
    double M = 0.0;
    for (double m : s.bodies[b]->mass_kg) M += m;
    complete(s, {&M, 1});
    s.rigid[b].mass_kg = M;
  }
  if (s.contacts.empty()) return;
  if (s.contact_weight.empty()) {  // once: node weights and measures (boundaries are set by now)
    s.contact_weight = detail::contact_node_weights<D>(s.grid, s.bc);
    if (s.dec)
      for (int i = 0; i < s.grid.node_count(); ++i) {
        const auto c = s.grid.unflatten(i);
        for (int a = 0; a < D; ++a)
          if (!s.dec->owns(a, s.grid.logical_index(a, c[a]))) s.contact_weight[i] = 0.0;
      }
    s.node_measure.resize(s.contact_weight.size());
    for (int i = 0; i < s.grid.node_count(); ++i) s.node_measure[i] = node_measure<G>(s.grid, i);
  }
  s.mixture_gradient.resize(s.contact_weight.size());
  s.mixture_volume.resize(s.contact_weight.size());  // (each pair's arrays are sized with it)
  // (the box is used where the fluid gives the mixture's volume and a pair has the combined normal)
  const bool near = s.fluid >= 0 && std::any_of(s.contacts.begin(), s.contacts.end(),
                                                [](const ContactPair<G>& c) { return c.combined_normal; });
  s.solids_box = near ? box_around_contact_solids(s) : ContactBox<D>{};
}

/// Contact, part 2: the nodal mass gradients (and volumes) of the mixture near the solids and of
/// each solid, from the step's shape functions. It reads only the points and their stencils of
/// P2G and writes only contact arrays, so it runs on one thread while the others start the grid
/// pass.
template <class G, int K>
inline void scatter_contact_gradients(SolverState<G>& s) {
  if (s.contacts.empty()) return;
  GridField<G>* fluid = s.fluid >= 0 ? &s.fields[s.fluid] : nullptr;
  bool combined = false;  // (the mixture's gradient is shared by the pairs)
  for (const auto& c : s.contacts) combined = combined || c.combined_normal;
  const int mix = s.grains >= 0 ? s.grains : s.fluid;
  s.mixture_volume_scattered = false;
  if (mix >= 0 && fluid && combined) {
    // Mixture mass gradient only (the fluid gives the volume), from the mixture points near
    // the solids (solids_box, part 1).
    if (s.solids_box.any) {
      scatter_mass_gradient_near<G, K>(*s.bodies[mix], s.caches[mix], s.global_grid(), s.solids_box.centre,
                                       s.solids_box.half, s.mixture_gradient);
    } else {
      for (auto& g : s.mixture_gradient) g.setZero();
    }
  } else if (mix >= 0 && (combined || !fluid)) {  // mixture mass gradient and/or volume
    scatter_mass_gradient_and_volume<G, K>(*s.bodies[mix], s.caches[mix], combined ? &s.mixture_gradient : nullptr,
                                           s.mixture_volume);
    s.mixture_volume_scattered = true;
  }
  for (auto& c : s.contacts)
    scatter_mass_gradient_and_volume<G, K>(*s.bodies[c.solid], s.caches[c.solid], &c.mass_gradient, c.volume_m3);
}

/// A free rigid body's velocity V from its contact (the model: contact.hpp, kRigidContactPasses):
/// the fixed-point iteration on the active set, each pass's normal system completed over the
/// ranks before it is solved (one rank: the body's terms first, then the nodes'; decomposed: the
/// nodes' terms over every rank, then the body's).
template <class G>
inline Vec<G::ncomp> rigid_contact_velocity(const SolverState<G>& s, const ContactNodes<G>& nodes,
                                            const RigidMotion<G>& rm) {
  constexpr int NC = G::ncomp;
  const double M = rm.mass_kg;
  const Vec<NC> Vstar = rm.velocity_m_s;  // V* = V + Δt g (resolve_contacts)
  Vec<NC> V = Vstar;
  for (int it = 0; it < kRigidContactPasses; ++it) {
    RigidSystem<G> sys = s.dec ? RigidSystem<G>{} : RigidSystem<G>::body_terms(M, Vstar);
    add_rigid_system(nodes, V, sys);
    if (s.dec) {
      complete(s, sys.share);
      sys.A() = M * Mat<NC, NC>::Identity() + sys.A();
      sys.b() = M * Vstar + sys.b();
    }
    const Vec<NC> V_new = solve_rigid_system(sys, rm, Vstar);
    const bool settled = (V_new - V).norm() <= 1e-14 * (1.0 + V_new.norm());
    V = V_new;
    if (settled && it > 0) break;
  }
  return V;
}

/// Phase 4, contact part 3 (after the grid pass; decomposed: with part 2's sums completed on
/// their owners): every pair's impulses (docs/contact.md, contact.hpp), then the free rigid
/// bodies' new velocity V = V + Δt g + (Σ impulses)/M on their free components.
template <class G>
inline void resolve_contacts(SolverState<G>& s) {
  constexpr int D = G::dim, NC = G::ncomp;
  if (s.contacts.empty()) {
    for (auto& rm : s.rigid) rm.velocity_m_s = rm.predicted_m_s;
    return;
  }
  GridField<G>* grains = s.grains >= 0 ? &s.fields[s.grains] : nullptr;
  GridField<G>* fluid = s.fluid >= 0 ? &s.fields[s.fluid] : nullptr;
  // Nodal mixture volume Σ N V_p: the fluid's (its points carry the mixture volume, folded at
  // walls), else the grains' (scattered in part 2; fluid-free beds).
  const double* mixture_volume = s.mixture_volume_scattered ? s.mixture_volume.data() : nullptr;
  if (fluid) mixture_volume = fluid->volume_m3.data();
  // The gradients' images at walls and the axis (mirror planes, as the masses in phase 3).
  bool combined = false;
  for (auto& c : s.contacts) {
    fold_wall_gradient<D>(s.grid, s.bc, c.mass_gradient);
    combined = combined || c.combined_normal;
  }
  if (combined) fold_wall_gradient<D>(s.grid, s.bc, s.mixture_gradient);
  for (auto& rm : s.rigid) rm.velocity_m_s = rm.predicted_m_s;
  constexpr std::size_t n = PairSums<G>::size;
  s.pair_sums.resize(s.contacts.size() * n);
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    ContactPair<G>& c = s.contacts[k];
    const RigidMotion<G>& rm = s.rigid[c.solid];
    const ContactNodes<G> nodes{c,
                                s.fields[c.solid],
                                grains,
                                fluid,
                                s.contact_weight,
                                mixture_volume,
                                s.node_measure,
                                c.combined_normal ? s.mixture_gradient.data() : nullptr};
    const PairSums<G> share = rm.kind == BodyMotion::FreeRigid && rm.mass_kg > 0.0
                                  ? apply_rigid_impulses(nodes, rigid_contact_velocity(s, nodes, rm))  // whole body
                                  : resolve_contact(nodes, rm);  // deformable or prescribed: node by node
    std::copy(share.share.begin(), share.share.end(), s.pair_sums.begin() + static_cast<std::ptrdiff_t>(k * n));
  }
  // Every pair's sums completed at once (one pair per solid: Solver::add_contact), then the free
  // rigid bodies' velocities V = V* + (Σ impulses)/M on their free components.
  complete(s, s.pair_sums);
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    ContactPair<G>& c = s.contacts[k];
    RigidMotion<G>& rm = s.rigid[c.solid];
    const Vec<NC> J = finish_pair(c, PairSums<G>(s.pair_sums.data() + k * n), s.opt.dt_s);
    if (rm.kind == BodyMotion::FreeRigid && rm.mass_kg > 0.0)
      rm.velocity_m_s += J.cwiseProduct(rm.free_mask) / rm.mass_kg;
  }
}

/// Phase 8, contact part 4 (after the points moved): mixture points inside a free rigid body put
/// back outside it (contact.hpp, keep_points_out; serial, a test per mixture point). (The shape's
/// anchor moves with the body, as its points did in phase 6; a shape is built at its first use,
/// from the moved points.)
template <class G>
inline void keep_mixture_out_of_free_rigid_bodies(SolverState<G>& s) {
  for (auto& c : s.contacts) {
    if (s.rigid[c.solid].kind != BodyMotion::FreeRigid) continue;
    if (c.shape.built)
      move_anchor(c.shape, s.rigid[c.solid], s.global_grid(), s.opt.dt_s);
    else
      build_rigid_shape(c.shape, *s.bodies[c.solid], s.grid);
    c.points_kept_out = 0;
    for (int b : {s.grains, s.fluid})
      if (b >= 0) c.points_kept_out += keep_points_out(c.shape, *s.bodies[b], s.global_grid());
  }
}

}  // namespace oobleck::mpm::phases
