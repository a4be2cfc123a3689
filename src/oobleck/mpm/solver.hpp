#pragma once
// The explicit MPM step (docs/mpm.md, "The step": update-stress-last) for any number of bodies on one grid.
//
//   Solver<PlaneStrain> s(grid, options);
//   auto& b = s.add_body("bar");  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(p));
//   fill_box(b, lo, hi, h, ppc, rho, v0);  s.boundaries()[0] = {WallType::Slip};
//   while (s.time_s() < T) s.step();
//
// Each body has its own grid field. The phase coupling (porosity, buoyancy split, semi-implicit
// drag, E28–E29 of docs/equations.md) runs in `update_grid_and_couple()` between the wall folding and the boundary
// conditions; contact with third bodies (docs/contact.md, contact.hpp) scatters its mass gradients beside it
// (`scatter_contact_gradients()`, on one thread of that pass) and follows it in
// `resolve_contacts()`.
// Rigid bodies (prescribed or free translation) and motors: see contact.hpp and docs/contact.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/drag.hpp"
#include "oobleck/numerics/vector_math.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/decomposition.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/halo.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/shape.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

/// Role of a body: a single-phase solid, or the granular or fluid phase of the mixture.
enum class Phase { Solid, Grains, Fluid };

/// Mixture parameters (docs/equations.md, E28–E29), used when a Fluid body exists (the drag and porosity only
/// with a Grains body as well).
template <class G>
struct MixtureOptions {
  double rho_s_kg_m3 = 1620.0;   ///< grain true density ρ_s
  double rho_f0_kg_m3 = 1000.0;  ///< fluid rest density ρ_f0 (Re uses the nodal ρ_f)
  double min_porosity = 0.01;    ///< lower clamp of the nodal porosity n_i [base]
  material::DragParams drag;     ///< E29 (d, η_0, law)
  /// Imposed uniform background pressure gradient ∇p_0 [Pa/m], split like the fluid pressure
  /// (grains (1−n), fluid n). Periodic boxes use ∇p_0 = ρ_mix g to carry the mixture's weight.
  Vec<G::ncomp> background_pressure_gradient_Pa_m = Vec<G::ncomp>::Zero();
};

template <class G>
struct SolverOptions {
  double dt_s = 1e-5;                                  ///< time step [s]
  ShapeKind shape = ShapeKind::QuadraticBSpline;       ///< shape functions
  double gimp_half_width_cells = 0.25;                 ///< uGIMP ℓ in cells (= 1/(2 ppc))
  Transfer transfer = Transfer::Apic;                  ///< velocity transfer
  double flip_fraction = 0.99;                         ///< α of the FLIP/PIC blend
  Vec<G::ncomp> gravity_m_s2 = Vec<G::ncomp>::Zero();  ///< gravitational acceleration
  int threads = 0;                                     ///< OpenMP threads (0: omp default)
  MixtureOptions<G> mixture;                           ///< used when a Fluid body exists
  /// Linear kernels only (0: off): selective nodal mass scaling of the force update,
  /// v_i = mv_i/m_i + Δt f_i/m'_i with m'_i = max(m_i, linear_mass_floor · ρ̄_b V_i) (ρ̄_b = Σ m_p / Σ V0_p
  /// of the body, V_i = h^D, per radian max(h² |r_i|, h³/8)). A node that a body covers only at
  /// the edge of its points' supports has a mass fraction ε of a full node while ∇N of linear
  /// weights does not vanish there: its stable step is √ε of a full node's, and the paper's
  /// scenes blew up on such nodes (points crossing a grid line next to the intruder's face, a
  /// wheel whose points lie on grid lines). A floor of (Δt/Δt_crit)² (the scene builder sets
  /// cfl², docs/mpm.md) gives every node at least a full node's stable step. B-splines do not
  /// need it (∇N vanishes with N).
  double linear_mass_floor = 0.0;
};

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

/// Number of nodes per axis in the support of a kernel.
inline int kernel_support(ShapeKind k) {
  switch (k) {
    case ShapeKind::Linear: return 2;
    case ShapeKind::CubicBSpline: return 4;
    default: return 3;
  }
}

/// Accumulated wall time [s] per part of the step (where the time goes).
struct StepTimings {
  /// p2g includes the shape functions (fused); grid the walls' folding, the grid update, drag and
  /// contact; g2p the walls' conditions on the velocities, the mixture flux and G2P; stress the laws.
  double p2g = 0, grid = 0, g2p = 0, stress = 0;
  /// Decomposed runs: the exchanges with the other ranks (nodal sums and values, points), part of
  /// the four above (p2g holds the sums, g2p the values, stress the points' migration).
  double communication = 0;
  double total() const { return p2g + grid + g2p + stress; }
};

template <class G>
class Solver {
 public:
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;

  Solver(const Grid<D>& grid, const SolverOptions<G>& options) : grid_(grid), opt_(options) {
    if (!(opt_.dt_s > 0.0)) throw InputError(fmt::format("mpm: dt must be > 0 s, got {}", opt_.dt_s));
    if (!(opt_.flip_fraction >= 0.0 && opt_.flip_fraction <= 1.0))
      throw InputError(fmt::format("mpm: flip_fraction must be in [0, 1], got {}", opt_.flip_fraction));
    if (opt_.shape == ShapeKind::UGimp && !(opt_.gimp_half_width_cells > 0.0 && opt_.gimp_half_width_cells <= 0.5))
      throw InputError(
          fmt::format("mpm: uGIMP half width must be in (0, 0.5] cells, got {}", opt_.gimp_half_width_cells));
    threads_ = opt_.threads > 0 ? opt_.threads : parallel::max_threads();
  }

  /// Add a body. At most one Grains and one Fluid body (they are coupled at the nodes).
  Body<G>& add_body(const std::string& name, Phase phase = Phase::Solid) {
    const int index = static_cast<int>(bodies_.size());
    if (phase == Phase::Grains) {
      if (grains_ >= 0) throw InputError("mpm: only one granular body per solver");
      grains_ = index;
    }
    if (phase == Phase::Fluid) {
      if (fluid_ >= 0) throw InputError("mpm: only one fluid body per solver");
      fluid_ = index;
    }
    bodies_.push_back(std::make_unique<Body<G>>());
    bodies_.back()->name = name;
    rigid_.emplace_back();
    if constexpr (std::is_same_v<G, Axisymmetric>) rigid_.back().free_mask = Vec<NC>(0.0, 1.0, 0.0);
    caches_.emplace_back();
    fields_.emplace_back();
    fields_.back().resize(grid_.node_count(), threads_);
    return *bodies_.back();
  }

  // ---- Third bodies and contact (docs/contact.md, contact.hpp) ----------------------------------

  /// Make body b rigid, every point moving at v until the next call (intruder; called before
  /// each step to ramp it up); the contact force on it is the reaction the drive must supply.
  void set_prescribed_velocity(int b, const Vec<NC>& v) {
    check_solid(b, "prescribed velocity");
    rigid_[b].kind = BodyMotion::Prescribed;
    rigid_[b].velocity_m_s = v;
    for (auto& vp : bodies_[b]->v_m_s) vp = v;
  }
  /// Make body b a free rigid body that only translates (launched rod), starting at velocity v;
  /// driven by gravity and its contact impulses. Components with free_mask 0 are held at v
  /// (default: all free; axisymmetric: only v_z).
  void set_free_rigid(int b, const Vec<NC>& v) {
    check_solid(b, "free rigid");
    rigid_[b].kind = BodyMotion::FreeRigid;
    rigid_[b].velocity_m_s = v;
    for (auto& vp : bodies_[b]->v_m_s) vp = v;
  }
  RigidMotion<G>& rigid_motion(int b) { return rigid_[b]; }
  /// Contact between solid body b and the mixture (its grains and/or fluid body), Coulomb
  /// coefficient μ between solid and grains (docs/contact.md). Returns the pair index.
  int add_contact(int b, double friction_coefficient) {
    check_solid(b, "contact");
    if (!(friction_coefficient >= 0.0))
      throw InputError(fmt::format("mpm: friction coefficient must be >= 0, got {}", friction_coefficient));
    contacts_.emplace_back();
    contacts_.back().solid = b;
    contacts_.back().friction_coefficient = friction_coefficient;
    contacts_.back().mass_gradient.assign(static_cast<std::size_t>(grid_.node_count()), Vec<D>::Zero());
    contacts_.back().volume_m3.assign(static_cast<std::size_t>(grid_.node_count()), 0.0);
    return static_cast<int>(contacts_.size()) - 1;
  }
  const ContactPair<G>& contact(int pair) const { return contacts_[pair]; }
  /// The unit normal contact used at node i for the pair in the last step (contact.hpp
  /// contact_normal); zero where it had none.
  Vec<NC> contact_normal_at(int pair, int i) const {
    const ContactPair<G>& c = contacts_[pair];
    Vec<NC> n = Vec<NC>::Zero();  // (left so where there is no normal)
    contact_normal(c, c.combined_normal ? mixture_gradient_.data() : nullptr, i, n);
    return n;
  }
  /// Declare pair `pair`'s persistent fields (mpm/fields.hpp; restored in place).
  void declare_contact_fields(int pair, FieldList& list) { contacts_[pair].declare_fields(list); }
  int contact_count() const { return static_cast<int>(contacts_.size()); }
  /// Contact force on body b from the mixture over the last step [N] (sum over its pairs; per
  /// radian in axisymmetric mode, per unit depth in plane strain).
  Vec<NC> contact_force(int b) const {
    Vec<NC> F = Vec<NC>::Zero();
    for (const auto& c : contacts_)
      if (c.solid == b) F += c.force_N;
    return F;
  }
  /// Velocity-level motor holding the mean angular velocity ω of body b (plane strain and 3D; see
  /// contact.hpp). Returns the motor index.
  int add_motor(int b, double omega_rad_s, double gain = 1.0) {
    if constexpr (std::is_same_v<G, Axisymmetric>) {
      throw InputError("mpm: motors are implemented in plane strain and 3D only");
    } else {
      check_solid(b, "motor");
      if (rigid_[b].rigid()) throw InputError("mpm: a motor drives a deformable body");
      if (!(gain > 0.0 && gain <= 1.0))
        throw InputError(fmt::format("mpm: motor gain must be in (0, 1], got {}", gain));
      motors_.push_back({});
      motors_.back().body = b;
      motors_.back().omega_rad_s = omega_rad_s;
      motors_.back().gain = gain;
      return static_cast<int>(motors_.size()) - 1;
    }
  }
  Motor<G>& motor(int m) { return motors_[m]; }

  BoundaryConditions<D>& boundaries() { return bc_; }
  const Grid<D>& grid() const { return grid_; }
  SolverOptions<G>& options() { return opt_; }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  Body<G>& body(int b) { return *bodies_[b]; }
  const GridField<G>& field(int b) const { return fields_[b]; }
  const ShapeCache<D>& shape_cache(int b) const { return caches_[b]; }
  double time_s() const { return time_s_; }
  /// Nodal porosity of the last step (mixture only; empty otherwise).
  const std::vector<double>& nodal_porosity() const { return porosity_; }
  /// Declare the nodal arrays the frames show on the grid (mpm/fields.hpp): the nodal porosity
  /// n of the last step (E28), when there is a mixture.
  void declare_grid_fields(FieldList& list) {
    if (!porosity_.empty()) list.add_nodal("porosity", porosity_, "1");
  }
  std::int64_t steps() const { return steps_; }
  /// Restore the clock from a checkpoint (restart).
  void set_clock(double time_s, std::int64_t steps) {
    time_s_ = time_s;
    steps_ = steps;
  }
  int threads() const { return threads_; }

  /// Domain decomposition (decomposition.hpp, docs/mpi.md): from here on this rank solves on its
  /// block's local grid and keeps only the points inside its block; the step exchanges the
  /// nodal sums and values with the neighbours and moves points that cross a block face. Call
  /// once, after the bodies are filled and the boundaries set, before the first step, on every
  /// rank with the whole scene. Third bodies: every rank holds each rigid body's motion, each
  /// contact pair's sums and each motor, completed over the ranks (contact.hpp); a free rigid
  /// body's shape is built here, from all its points.
  void decompose(const Decomposition<D>& dec) {
    if (dec_) throw InputError("mpm: the solver is already decomposed");
    for (auto& c : contacts_)
      if (rigid_[c.solid].kind == BodyMotion::FreeRigid && !c.shape.built)
        build_rigid_shape(c.shape, *bodies_[c.solid], grid_);
    contact_weight_.clear();      // (recomputed on the local grid, owned nodes only)
    mass_floor_density_.clear();  // (linear kernels: recomputed over every rank's points)
    dec_ = std::make_unique<Decomposition<D>>(dec);
    grid_ = dec_->local_grid();
    for (int a = 0; a < D; ++a) {  // faces inside the domain (or across a split periodic axis) are open
      if (!dec_->split(a)) continue;
      if (dec_->coords()[a] > 0 || dec_->global().periodic[a]) bc_[2 * a] = FaceCondition{};
      if (dec_->coords()[a] < dec_->dims()[a] - 1 || dec_->global().periodic[a]) bc_[2 * a + 1] = FaceCondition{};
    }
    for (auto& f : fields_) f.resize(grid_.node_count(), threads_);
    for (auto& c : contacts_) {
      c.mass_gradient.assign(static_cast<std::size_t>(grid_.node_count()), Vec<D>::Zero());
      c.volume_m3.assign(static_cast<std::size_t>(grid_.node_count()), 0.0);
    }
    for (auto& b : bodies_) keep_owned_points(*b, *dec_);
    halo_ = std::make_unique<Halo<D>>(*dec_, grid_);
  }
  /// The decomposition, or nullptr (one rank).
  const Decomposition<D>* decomposition() const { return dec_.get(); }
  /// The whole domain's grid: grid() on one rank, the decomposition's global grid otherwise (for
  /// positions: periodic images, the domain's bounds).
  const Grid<D>& global_grid() const { return dec_ ? dec_->global() : grid_; }
  /// Bytes this rank sent in the nodal exchanges so far (0 on one rank).
  std::int64_t halo_bytes_sent() const { return halo_ ? halo_->bytes_sent() : 0; }
  /// Points that left this rank for another so far (0 on one rank).
  std::int64_t points_migrated() const { return points_migrated_; }

  /// Largest stable Δt [s]: the CFL condition on the fastest wave of every body
  /// (Δt ≤ cfl h / (c + |v|_max)) and the laws' viscous limits ρ h²/(2η) (docs/mpm.md, "The step"). The
  /// drag is semi-implicit and never limits Δt.
  double stable_dt(double cfl = 0.5) const {
    const auto [dt_wave, dt_visc] = time_step_limits(cfl);
    return std::min(dt_wave, dt_visc);
  }

  /// stable_dt's two limits: {cfl h/(c + |v|)_max (+∞ without waves), min ρ h²/(2η) (+∞ without)}.
  std::pair<double, double> time_step_limits(double cfl) const {
    double c_max = 0.0, dt_visc = INFINITY;
    for (const auto& b : bodies_) {
      double c = b->law ? b->law->max_wave_speed(*b) : 0.0;
      double vmax = 0.0;
      for (const auto& v : b->v_m_s) vmax = std::max(vmax, v.norm());
      c_max = std::max(c_max, c + vmax);
      if (b->law) dt_visc = std::min(dt_visc, b->law->viscous_dt_limit(*b, grid_.h_m));
    }
    if (dec_) {  // every rank's points
      c_max = comm::max(c_max);
      dt_visc = comm::min(dt_visc);
    }
    return {c_max > 0.0 ? cfl * grid_.h_m / c_max : INFINITY, dt_visc};
  }

  /// Refuse a time step above the stable one (docs/mpm.md, "The step"): throws InputError with the numbers.
  void check_time_step(double cfl = 0.5) const {
    const double dt_max = stable_dt(cfl);
    if (opt_.dt_s > dt_max)
      throw InputError(
          fmt::format("mpm: time step dt = {:.4g} s is above the stable limit {:.4g} s (CFL {} on the fastest "
                      "wave, viscous limit rho h^2/(2 eta), h = {:.4g} m)",
                      opt_.dt_s, dt_max, cfl, grid_.h_m));
  }

  /// One explicit step of length options().dt_s, in the phases of docs/mpm.md ("The step").
  void step() {
    with_support([&](auto S) {
      constexpr int K = ipow(decltype(S)::value, D);
      StepClock clock(timings_);
      apply_motors();                                       // 1. motors: velocity drive of driven bodies (contact.hpp)
      particles_to_grid_all<K>();                           // 2. P2G: shape functions, mass, momentum, forces, gravity
      if (halo_) timed_exchange([&] { sum_to_owners(); });  // (decomposed: partial sums to the owners)
      clock.lap(timings_.p2g);
      if (opt_.shape == ShapeKind::Linear && opt_.linear_mass_floor > 0.0) prepare_mass_floor();
      prepare_rigid_and_contact();
      update_grid_and_couple(                           // 3. grid: walls fold ghosts, rigid predictions; porosity,
          [this] { scatter_contact_gradients<K>(); });  // buoyancy (E28), v = (mv + Δt f)/m,
                                                        //    drag (E29); beside it, contact's mass gradients
      resolve_contacts();                               // 4. contact impulses (contact.hpp), rigid bodies' velocities
      clock.lap(timings_.grid);
      update_points<K>(clock);                  // 5. walls on nodal velocities, mixture flux q (E27);
                                                // 6. G2P: x, v (APIC or FLIP/PIC), C, L, V ← V exp(Δt tr L);
                                                // 7. laws: stresses (and their state) from L
      keep_mixture_out_of_free_rigid_bodies();  // 8. mixture points back out of free rigid bodies (contact.hpp)
      if (dec_) {                               // (decomposed: points to their new blocks)
        timed_exchange([&] {
          for (auto& b : bodies_) points_migrated_ += migrate_points(*b, *dec_);
        });
        clock.lap(timings_.stress);
      }
    });
    time_s_ += opt_.dt_s;
    ++steps_;
  }

  /// The NaN guard fused into the last step's G2P for body b: the lowest index of a point whose
  /// new position, velocity or volume is not finite, kAllFinite, or kNotChecked (rigid bodies, or
  /// before the first step).
  std::int64_t first_non_finite_kinematics(int b) const {
    return static_cast<std::size_t>(b) < non_finite_kinematics_.size() ? non_finite_kinematics_[b] : kNotChecked;
  }

  /// Wall time per part of the step, accumulated since construction or reset_timings().
  const StepTimings& timings() const { return timings_; }
  void reset_timings() { timings_ = {}; }

 private:
  static constexpr int ipow(int b, int e) { return e == 0 ? 1 : b * ipow(b, e - 1); }

  struct StepClock {
    explicit StepClock(StepTimings&) : t0(parallel::wall_time()) {}
    void lap(double& acc) {
      const double t = parallel::wall_time();
      acc += t - t0;
      t0 = t;
    }
    double t0;
  };

  template <class F>
  void with_support(F&& f) {
    switch (kernel_support(opt_.shape)) {
      case 2: f(std::integral_constant<int, 2>{}); break;
      case 4: f(std::integral_constant<int, 4>{}); break;
      default: f(std::integral_constant<int, 3>{}); break;
    }
  }

  /// Phase 2, P2G (docs/mpm.md, "The step") of every body in one region: each point's shape
  /// functions (into its body's cache) and its scatter, then the nodal sums and gravity. Every
  /// thread scatters its static share of each body's points into its copy of that body's nodal
  /// arrays, with no barrier between the bodies; after one barrier, each thread sums the copies
  /// over its share of the nodes, body after body.
  template <int K>
  void particles_to_grid_all() {
    parallel::set_threads(threads_);
    const bool apic = opt_.transfer == Transfer::Apic;
    const int nb = body_count();
    auto for_kernel = [&](auto&& f) {
      with_kernel(opt_.shape, opt_.gimp_half_width_cells, [&](auto kernel) {
        if constexpr (decltype(kernel)::support == support_of<D>(K)) f(kernel);
        // (other supports not reached: with_support and with_kernel read the same option)
      });
    };
    for (int b = 0; b < nb; ++b)
      for_kernel([&](auto kernel) { detail::p2g_prepare<G, K, decltype(kernel)>(*bodies_[b], caches_[b]); });
    p2g_outside_.assign(bodies_.size(), 0);
    parallel::region([&](const parallel::Team& team) {
      for (int b = 0; b < nb; ++b)
        for_kernel([&](auto kernel) {
          const std::int64_t out = detail::p2g_scatter_share<G, K>(team, *bodies_[b], grid_, kernel, caches_[b],
                                                                   fields_[b], apic, b == fluid_);
          if (out > 0) parallel::atomic_add(p2g_outside_[b], out);
        });
      team.barrier();
      for (int b = 0; b < nb; ++b) detail::p2g_sum_share(team, fields_[b], b == fluid_, &opt_.gravity_m_s2);
    });
    for (int b = 0; b < nb; ++b)
      if (p2g_outside_[b] > 0)
        throw NumericalError(
            fmt::format("mpm: {} point(s) of body '{}' left the grid (more than one cell outside the domain) at "
                        "step {}, t = {} s",
                        p2g_outside_[b], bodies_[b]->name, steps_, time_s_));
  }

  bool mixture() const { return grains_ >= 0 && fluid_ >= 0; }

  template <class F>
  void timed_exchange(F&& f) {
    const double t0 = parallel::wall_time();
    f();
    timings_.communication += parallel::wall_time() - t0;
  }

  /// Decomposed runs, after P2G: every body's nodal sums (mass, momentum, force; the fluid's
  /// pressure force and mixture volume) completed on their owners (halo.hpp).
  void sum_to_owners() {
    std::vector<NodalArray> arrays;
    for (int b = 0; b < body_count(); ++b) {
      GridField<G>& f = fields_[b];
      arrays.insert(arrays.end(), {nodal(f.mass_kg), nodal(f.momentum), nodal(f.force_N)});
      if (b == fluid_) arrays.insert(arrays.end(), {nodal(f.pressure_force_N), nodal(f.volume_m3)});
    }
    halo_->sum(arrays);
  }

  /// Decomposed runs, after the walls' conditions: the owners' nodal velocities (and the nodal
  /// porosity) copied out to the neighbours, for the flux and G2P (halo.hpp).
  void copy_from_owners() {
    std::vector<NodalArray> arrays;
    for (auto& f : fields_) arrays.insert(arrays.end(), {nodal(f.velocity), nodal(f.velocity_old)});
    if (fluid_ >= 0) arrays.push_back(nodal(porosity_));
    halo_->copy(arrays);
  }

  /// Phase 3, the grid pass: the grid update of every body, with the phase coupling for the
  /// mixture. Its parts are node-local, so they run in one pass over the nodes (couple_nodes).
  ///
  /// Before the pass over the nodes, body by body (each touches only its own field, so the
  /// bodies run in parallel): the walls' ghost contributions folded onto their mirrors
  /// (fold_wall_images, step 4a) and a rigid body's nodal velocities (predict_rigid, which reads
  /// the folded masses).
  ///
  /// `side` (contact's scatters) runs on one thread of the pass while the others start on the
  /// nodes; the node blocks are handed out dynamically so that thread joins them when it is done
  /// (each node is independent: the same values whichever thread computes it).
  template <class Side>
  void update_grid_and_couple(Side&& side) {
    const double dt = opt_.dt_s;
    const int nbodies = body_count();
    auto fold_and_predict = [&](int b) {
      fold_wall_images<G>(grid_, bc_, fields_[b]);
      if (rigid_[b].rigid()) predict_rigid(rigid_[b], fields_[b], opt_.gravity_m_s2, dt);
    };
    // Deformable solids (the wheel): their predictions join the mixture's pass over the nodes
    // below when there is a fluid; otherwise they get their own pass.
    solids_.clear();
    for (int b = 0; b < nbodies; ++b)
      if (!rigid_[b].rigid() && b != grains_ && b != fluid_) solids_.push_back(&fields_[b]);
    const int nn = grid_.node_count();
    if (fluid_ < 0) {
      for (int b = 0; b < nbodies; ++b) fold_and_predict(b);
      side();
      if (grains_ >= 0) solids_.push_back(&fields_[grains_]);
      parallel::region(
          [&](const parallel::Team& team) {
            const parallel::Range r = team.share(nn);
            for (GridField<G>* sf : solids_)
              for (auto i = static_cast<int>(r.begin); i < static_cast<int>(r.end); ++i) predict_node(*sf, i, dt);
          },
          nn >= kParallelMinNodes);
      return;
    }
    porosity_.resize(static_cast<std::size_t>(nn));
    constexpr int kBlock = numerics::kMathBlock;
    const int blocks = (nn + kBlock - 1) / kBlock;
    parallel::region(
        [&](const parallel::Team& team) {
          team.dynamic(nbodies, 1, [&](std::int64_t b) { fold_and_predict(static_cast<int>(b)); });
          team.barrier();
          team.single_nowait(side);
          team.dynamic(blocks, 4, [&](std::int64_t blk) {
            const int i0 = static_cast<int>(blk) * kBlock;
            couple_nodes(i0, std::min(kBlock, nn - i0));
          });
        },
        nn >= kParallelMinNodes / 32);  // ~20 ns per node (drag)
  }

  /// The grid pass over the nodes [i0, i0 + count), count <= numerics::kMathBlock (a fluid body
  /// exists):
  ///  * nodal porosity n_i = 1 − m^s_i/(ρ_s V_i) (clamped to [n_min, 1]; 1 where there are no
  ///    grains or no granular body), the pressure force ∑ V p ∇N split grains (1 − n_i), fluid n_i
  ///    (E28), and the same split of a background gradient −V_i ∇p_0 (the viscous τ_f already acts
  ///    on the fluid alone);
  ///  * predicted velocities v = (mv + Δt f)/m (step 5), also of the deformable solids;
  ///  * semi-implicit drag (E29, docs/equations.md): C_i = V_i C_V(φ_i, Re_i) with the predicted
  ///    velocities, F_d = C_i/(1 + Δt C_i (1/m_s + 1/m_f)) Δv; grains −F_d, fluid +F_d. The drag
  ///    coefficients of the block's mixture nodes are computed at once (their powers in vector
  ///    lanes).
  void couple_nodes(int i0, int count) {
    constexpr int kBlock = numerics::kMathBlock;
    const double dt = opt_.dt_s;
    GridField<G>& s = fields_[grains_ >= 0 ? grains_ : fluid_];
    GridField<G>& f = fields_[fluid_];
    const bool grains = grains_ >= 0;
    const auto& mx = opt_.mixture;
    double phi_b[kBlock], Re_b[kBlock], C_V[kBlock];
    bool drag[kBlock];
    for (int j = 0; j < kBlock; ++j) {
      phi_b[j] = 0.5;  // (a harmless stand-in for nodes without drag)
      Re_b[j] = 0.0;
      drag[j] = false;
    }
    for (GridField<G>* sf : solids_)
      for (int j = 0; j < count; ++j) predict_node(*sf, i0 + j, dt);
    for (int j = 0; j < count; ++j) {
      const int i = i0 + j;
      const double V = f.volume_m3[i], ms = grains ? s.mass_kg[i] : 0.0, mf = f.mass_kg[i];
      double n = 1.0;
      if (V > 0.0 && ms > 0.0) n = std::clamp(1.0 - ms / (mx.rho_s_kg_m3 * V), mx.min_porosity, 1.0);
      porosity_[i] = n;
      const Vec<NC> Fp = f.pressure_force_N[i] - V * mx.background_pressure_gradient_Pa_m;
      f.force_N[i] += n * Fp;
      predict_node(f, i, dt);
      if (!grains) continue;
      s.force_N[i] += (1.0 - n) * Fp;
      predict_node(s, i, dt);
      if (!(ms > 0.0 && mf > 0.0 && V > 0.0)) continue;
      const Vec<NC> dv = s.velocity[i] - f.velocity[i];
      const double rho_f = mf / (n * V);
      drag[j] = true;
      phi_b[j] = 1.0 - n;
      Re_b[j] = material::drag_reynolds(dv.norm(), n, rho_f, mx.drag.d_m, mx.drag.eta_0_Pa_s);
    }
    bool any_drag = false;
    for (int j = 0; j < count; ++j) any_drag = any_drag || drag[j];
    if (!any_drag) return;
    material::drag_coefficient_per_volume_block(mx.drag, phi_b, Re_b, C_V);
    for (int j = 0; j < count; ++j) {
      if (!drag[j]) continue;
      const int i = i0 + j;
      const double ms = s.mass_kg[i], mf = f.mass_kg[i];
      const double C = f.volume_m3[i] * C_V[j];
      const Vec<NC> Fd = material::semi_implicit_drag_force(ms, mf, s.velocity[i], f.velocity[i], C, dt);
      s.velocity[i] -= (dt / ms) * Fd;
      f.velocity[i] += (dt / mf) * Fd;
      s.force_N[i] -= Fd;  // kept for output/diagnostics
      f.force_N[i] += Fd;
    }
  }

  /// Before the grid pass (on the main thread: it may talk to the other ranks): the rigid bodies'
  /// masses (over every rank); contact (docs/contact.md), part 1: the node weights and measures (once;
  /// decomposed: 0 on the nodes another rank owns), the arrays part 2 fills, and the box of the
  /// mixture's points near the solids (part 2's scatter_mass_gradient_near).
  void prepare_rigid_and_contact() {
    for (int b = 0; b < body_count(); ++b) {
      if (!rigid_[b].rigid()) continue;
      double M = 0.0;
      for (double m : bodies_[b]->mass_kg) M += m;
      if (dec_) comm::sum_ordered({&M, 1});
      rigid_[b].mass_kg = M;
    }
    if (contacts_.empty()) return;
    if (contact_weight_.empty()) {  // once: node weights and measures (boundaries are set by now)
      contact_weight_ = detail::contact_node_weights<D>(grid_, bc_);
      if (dec_)
        for (int i = 0; i < grid_.node_count(); ++i) {
          const auto s = grid_.unflatten(i);
          for (int a = 0; a < D; ++a)
            if (!dec_->owns(a, grid_.logical_index(a, s[a]))) contact_weight_[i] = 0.0;
        }
      node_measure_.resize(contact_weight_.size());
      for (int i = 0; i < grid_.node_count(); ++i) node_measure_[i] = node_measure<G>(grid_, i);
    }
    mixture_gradient_.resize(contact_weight_.size());
    mixture_volume_.resize(contact_weight_.size());  // (each pair's arrays are sized with it)
    // (the box is used where the fluid gives the mixture's volume and a pair has the combined normal)
    const bool near = fluid_ >= 0 && std::any_of(contacts_.begin(), contacts_.end(),
                                                 [](const ContactPair<G>& c) { return c.combined_normal; });
    solids_box_ = near ? box_around_contact_solids() : Box{};
  }

  /// A box around every contact solid's points (over every rank), grown by two kernel widths:
  /// the mixture's points that reach the nodes where a solid has mass lie inside.
  struct Box {
    bool any = false;
    Vec<D> centre = Vec<D>::Zero(), half = Vec<D>::Zero();
  };
  Box box_around_contact_solids() const {
    const Grid<D>& grid = global_grid();
    Vec<D> ref = Vec<D>::Constant(INFINITY);  // the first solid's reference point (every rank's)
    for (const auto& c : contacts_) {
      ref = body_reference(*bodies_[c.solid], dec_ != nullptr);
      if (std::isfinite(ref[0])) break;
    }
    Box box;
    if (!std::isfinite(ref[0])) return box;  // no solid has points
    double lo_hi[2 * D];                     // lo, −hi (one minimum over the ranks)
    std::fill(lo_hi, lo_hi + 2 * D, INFINITY);
    for (const auto& c : contacts_) {
      const auto& sb = *bodies_[c.solid];
      for (std::int64_t p = 0; p < sb.size(); ++p) {
        const Vec<D> d = periodic_difference<D>(grid, sb.x_m[p], ref);
        for (int a = 0; a < D; ++a) {
          lo_hi[a] = std::min(lo_hi[a], d[a]);
          lo_hi[D + a] = std::min(lo_hi[D + a], -d[a]);
        }
      }
    }
    if (dec_) comm::min(lo_hi);
    const Vec<D> lo = Eigen::Map<const Vec<D>>(lo_hi), hi = -Eigen::Map<const Vec<D>>(lo_hi + D);
    const double margin = 2.0 * kernel_support(opt_.shape) * grid_.h_m;
    box.any = true;
    box.centre = ref + 0.5 * (lo + hi);
    box.half = 0.5 * (hi - lo) + Vec<D>::Constant(margin);
    return box;
  }

  /// Contact, part 2: the nodal mass gradients (and volumes) of the mixture near the solids and of
  /// each solid, from the step's shape functions. It reads only the points and their stencils of
  /// P2G and writes only contact arrays, so it runs on one thread while the others start the grid
  /// pass (update_grid_and_couple's side task).
  template <int K>
  void scatter_contact_gradients() {
    if (contacts_.empty()) return;
    GridField<G>* fluid = fluid_ >= 0 ? &fields_[fluid_] : nullptr;
    bool combined = false;  // (the mixture's gradient is shared by the pairs)
    for (const auto& c : contacts_) combined = combined || c.combined_normal;
    const int mix = grains_ >= 0 ? grains_ : fluid_;
    mixture_volume_scattered_ = false;
    if (mix >= 0 && fluid && combined) {
      // Mixture mass gradient only (the fluid gives the volume), from the mixture points near
      // the solids (solids_box_, part 1).
      if (solids_box_.any) {
        scatter_mass_gradient_near<G, K>(*bodies_[mix], caches_[mix], global_grid(), solids_box_.centre,
                                         solids_box_.half, mixture_gradient_);
      } else {
        for (auto& g : mixture_gradient_) g.setZero();
      }
    } else if (mix >= 0 && (combined || !fluid)) {  // mixture mass gradient and/or volume
      scatter_mass_gradient_and_volume<G, K>(*bodies_[mix], caches_[mix], combined ? &mixture_gradient_ : nullptr,
                                             mixture_volume_);
      mixture_volume_scattered_ = true;
    }
    for (auto& c : contacts_)
      scatter_mass_gradient_and_volume<G, K>(*bodies_[c.solid], caches_[c.solid], &c.mass_gradient, c.volume_m3);
  }

  /// Contact, part 3 (after the grid pass): every pair's impulses (docs/contact.md, contact.hpp),
  /// then the free rigid bodies' new velocity V = V + Δt g + (Σ impulses)/M on their free
  /// components.
  void resolve_contacts() {
    if (contacts_.empty()) {
      for (auto& rm : rigid_) rm.velocity_m_s = rm.predicted_m_s;
      return;
    }
    GridField<G>* grains = grains_ >= 0 ? &fields_[grains_] : nullptr;
    GridField<G>* fluid = fluid_ >= 0 ? &fields_[fluid_] : nullptr;
    // Nodal mixture volume Σ N V_p: the fluid's (its points carry the mixture volume, folded at
    // walls), else the grains' (scattered in part 2; fluid-free beds).
    const double* mixture_volume = mixture_volume_scattered_ ? mixture_volume_.data() : nullptr;
    if (fluid) mixture_volume = fluid->volume_m3.data();
    if (halo_) timed_exchange([&] { sum_contact_arrays_to_owners(); });
    // The gradients' images at walls and the axis (mirror planes, as the masses in phase 3).
    bool combined = false;
    for (auto& c : contacts_) {
      fold_wall_gradient<D>(grid_, bc_, c.mass_gradient);
      combined = combined || c.combined_normal;
    }
    if (combined) fold_wall_gradient<D>(grid_, bc_, mixture_gradient_);
    for (auto& rm : rigid_) rm.velocity_m_s = rm.predicted_m_s;
    const bool across_ranks = dec_ != nullptr;
    for (auto& c : contacts_) {
      RigidMotion<G>& rm = rigid_[c.solid];
      const Vec<D>* mix_grad = c.combined_normal ? mixture_gradient_.data() : nullptr;
      if (rm.kind == BodyMotion::FreeRigid && rm.mass_kg > 0.0) {  // whole-body solve
        const Vec<NC> J = resolve_rigid_contact(c, rm, fields_[c.solid], grains, fluid, contact_weight_, mixture_volume,
                                                node_measure_, mix_grad, across_ranks, opt_.dt_s);
        rm.velocity_m_s += J.cwiseProduct(rm.free_mask) / rm.mass_kg;
      } else {  // deformable or prescribed: node by node
        resolve_contact(c, rm, fields_[c.solid], grains, fluid, contact_weight_, mixture_volume, node_measure_,
                        mix_grad, across_ranks, opt_.dt_s);
      }
    }
  }

  /// Decomposed runs, before the contacts: contact's nodal sums of part 2 (each pair's mass
  /// gradient and volume, the mixture's gradient and scattered volume) completed on their owners.
  void sum_contact_arrays_to_owners() {
    std::vector<NodalArray> arrays;
    for (auto& c : contacts_) arrays.insert(arrays.end(), {nodal(c.mass_gradient), nodal(c.volume_m3)});
    arrays.push_back(nodal(mixture_gradient_));
    if (mixture_volume_scattered_) arrays.push_back(nodal(mixture_volume_));
    halo_->sum(arrays);
  }

  /// Contact, part 4 (after the points moved): mixture points inside a free rigid body put back
  /// outside it (contact.hpp, keep_points_out; serial, a test per mixture point).
  /// (The shape's anchor moves with the body, as its points did in update_points; a shape is
  /// built at its first use, from the moved points.)
  void keep_mixture_out_of_free_rigid_bodies() {
    for (auto& c : contacts_) {
      if (rigid_[c.solid].kind != BodyMotion::FreeRigid) continue;
      if (c.shape.built)
        move_anchor(c.shape, rigid_[c.solid], global_grid(), opt_.dt_s);
      else
        build_rigid_shape(c.shape, *bodies_[c.solid], grid_);
      c.points_kept_out = 0;
      for (int b : {grains_, fluid_})
        if (b >= 0) c.points_kept_out += keep_points_out(c.shape, *bodies_[b], global_grid());
    }
  }

  /// The linear kernels' mass floor (SolverOptions::linear_mass_floor): per body floor · Σ m_p / Σ V0_p
  /// (over every rank), per node the measure V_i; once, at the first step (or when bodies change).
  void prepare_mass_floor() {
    if (mass_floor_density_.size() == bodies_.size()) return;
    std::vector<double> sums(2 * bodies_.size(), 0.0);
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      for (std::int64_t p = 0; p < bodies_[b]->size(); ++p) {
        sums[2 * b] += bodies_[b]->mass_kg[p];
        sums[2 * b + 1] += bodies_[b]->volume0_m3[p];
      }
    if (dec_) comm::sum_ordered(sums);
    mass_floor_density_.assign(bodies_.size(), 0.0);
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      if (!rigid_[b].rigid() && sums[2 * b + 1] > 0.0)
        mass_floor_density_[b] = opt_.linear_mass_floor * sums[2 * b] / sums[2 * b + 1];
    const int nn = grid_.node_count();
    mass_floor_measure_.resize(static_cast<std::size_t>(nn));
    const double h = grid_.h_m, cell = grid_.cell_volume();
    for (int i = 0; i < nn; ++i) {
      Vec<D> x = grid_.node_position(i);
      if constexpr (G::has_hoop_terms) x[0] = std::fabs(x[0]);
      mass_floor_measure_[i] = G::has_hoop_terms ? std::max(G::measure(x, cell), 0.125 * cell * h) : cell;
    }
  }

  void apply_motors() {
    if constexpr (!std::is_same_v<G, Axisymmetric>)
      for (auto& m : motors_) apply_motor(m, *bodies_[m.body], global_grid(), dec_ != nullptr, opt_.dt_s);
  }

  void check_solid(int b, const char* what) const {
    if (b < 0 || b >= body_count()) throw InputError(fmt::format("mpm: {}: no body with index {}", what, b));
    if (b == grains_ || b == fluid_)
      throw InputError(fmt::format("mpm: {}: body '{}' is a mixture phase, not a solid", what, bodies_[b]->name));
  }

  /// Step 3(b) at node i: v_old = mv/m, v = (mv + Δt f)/m; with the linear kernels' mass floor
  /// (SolverOptions::linear_mass_floor) v = mv/m + Δt f/max(m, floor).
  void predict_node(GridField<G>& field, int i, double dt) const {
    const double m = field.mass_kg[i];
    if (m > 0.0) {
      field.velocity_old[i] = field.momentum[i] / m;
      const double floor_density = mass_floor_density_.empty() ? 0.0 : mass_floor_density_[&field - fields_.data()];
      const double m_floor = floor_density * (floor_density > 0.0 ? mass_floor_measure_[i] : 0.0);
      if (m < m_floor)
        field.velocity[i] = field.velocity_old[i] + (dt / m_floor) * field.force_N[i];
      else
        field.velocity[i] = (field.momentum[i] + dt * field.force_N[i]) / m;
    } else {
      field.velocity_old[i].setZero();
      field.velocity[i].setZero();
    }
  }

  /// The mixture's nodal volume flux q_i = (1 − n_i) v^s_i + n_i v^f_i (E27) over the nodes
  /// [i0, i1), and (axisymmetric) which of the G2P bodies have θ velocity (or, the fluid, θ flux)
  /// on these nodes: bit k of the result for g2p_bodies_[k] (g2p_without_swirl, node by node).
  std::uint64_t mixture_flux_and_swirl(int i0, int i1) {
    std::uint64_t swirl = 0;
    if (fluid_ >= 0) {
      const GridField<G>& s = fields_[grains_ >= 0 ? grains_ : fluid_];  // n = 1 without grains
      const GridField<G>& f = fields_[fluid_];
      for (int i = i0; i < i1; ++i) {
        const double n = porosity_[i];
        flux_[i] = (1.0 - n) * s.velocity[i] + n * f.velocity[i];
      }
    }
    if constexpr (G::has_hoop_terms) {
      const int nk = std::min<int>(64, static_cast<int>(g2p_bodies_.size()));
      for (int k = 0; k < nk; ++k) {
        const int b = g2p_bodies_[k];
        const GridField<G>& field = fields_[b];
        bool none = true;
        for (int i = i0; i < i1; ++i)
          none &=
              (field.velocity[i][2] == 0.0) & (field.velocity_old[i][2] == 0.0) & (b != fluid_ || flux_[i][2] == 0.0);
        if (!none) swirl |= std::uint64_t{1} << k;
      }
      // (bodies past the 64th keep the general kernels: the same values)
      for (int k = nk; k < static_cast<int>(g2p_bodies_.size()); ++k) swirl |= std::uint64_t{1} << 63;
    }
    return swirl;
  }

  /// On one thread of update_points' region, after the swirl test: the G2P tasks of the deformable
  /// bodies (their kernels chosen by the test) and the stealing shares of the G2P tasks and of the
  /// law bodies.
  template <int K>
  void prepare_point_tasks(std::uint64_t swirl, int team) {
    const int ntasks = static_cast<int>(g2p_bodies_.size());
    g2p_tasks_.clear();
    for (int k = 0; k < ntasks; ++k) {
      const int b = g2p_bodies_[k];
      g2p_tasks_.push_back(make_g2p_task<G, K>(*bodies_[b], caches_[b], fields_[b], grid_, opt_.transfer,
                                               opt_.flip_fraction, opt_.dt_s, b == fluid_ ? porosity_.data() : nullptr,
                                               b == fluid_ ? flux_.data() : nullptr,
                                               G::has_hoop_terms && (swirl >> std::min(k, 63) & 1u) == 0));
    }
    shares_.resize(ntasks + static_cast<int>(law_bodies_.size()), team);
    for (int k = 0; k < ntasks; ++k) shares_.start(k, g2p_tasks_[k].blocks);
    for (std::size_t k = 0; k < law_bodies_.size(); ++k) {
      Body<G>& body = *bodies_[law_bodies_[k]];
      shares_.start(ntasks + static_cast<int>(k), body.law->chunk_count(body));
    }
  }

  /// Phases 5–7 for every body in one parallel region (one fork per step; barriers after the
  /// walls, after the flux pass, and between G2P and the laws).
  ///
  /// G2P (6): the deformable bodies one after the other with no barrier between them, each
  /// thread first its static share of the body's blocks — the split of P2G's scatter, the points
  /// whose data are in its core's caches — then what is left of the other threads' shares
  /// (stealing: a slower core's points move to the other only at the end of its share).
  /// Rigid bodies' points move with their body, before the region.
  ///
  /// The laws (7): the bodies with costly, uneven chunks first (ScheduleHint; the granular law)
  /// in static shares with stealing, then the others (the fluid's, an elastic body's) in static
  /// shares: the points each thread maps in G2P and scatters in P2G. No barrier between the
  /// bodies; then each law's end_update, in body order.
  ///
  /// Every point's update is independent of the others: the results do not depend on the
  /// schedule (bit for bit the same on any number of threads as a serial run of the same code).
  template <int K>
  void update_points(StepClock& clock) {
    static_assert(!std::is_same_v<G, Axisymmetric> || K == 4 || K == 9 || K == 16,
                  "a new kernel support: add its axisymmetric G2P to transfer_axisymmetric.cpp");
    const int nb = static_cast<int>(bodies_.size());
    non_finite_kinematics_.assign(bodies_.size(), kAllFinite);
    g2p_bodies_.clear();
    for (int b = 0; b < nb; ++b) {
      if (rigid_[b].rigid()) {
        move_rigid_points(*bodies_[b], rigid_[b], grid_, opt_.dt_s);
        non_finite_kinematics_[b] = kNotChecked;
      } else {
        g2p_bodies_.push_back(b);
      }
    }
    law_bodies_.clear();
    for (int b = 0; b < nb; ++b)
      if (bodies_[b]->law) law_bodies_.push_back(b);
    std::stable_sort(law_bodies_.begin(), law_bodies_.end(), [&](int a, int b) {
      return bodies_[a]->law->schedule_hint().relative_cost_per_point >
             bodies_[b]->law->schedule_hint().relative_cost_per_point;
    });
    law_first_bad_.assign(bodies_.size(), kAllFinite);
    const double dt = opt_.dt_s;
    const int ntasks = static_cast<int>(g2p_bodies_.size());
    const int nn = grid_.node_count();
    if (fluid_ >= 0) flux_.resize(static_cast<std::size_t>(nn));
    // The pass over the nodes (the flux, the swirl test) runs in parallel on grids of 512 nodes
    // and more (the intruder's 2200: 0.7% of the samples on the master when serial); smaller
    // ones on the first thread, the others waiting.
    const bool node_pass_parallel = nn >= kParallelMinNodes / 64;
    std::uint64_t swirl = 0;
    parallel::region([&](const parallel::Team& team) {
      // Phase 5a: the walls' conditions on every body's nodal velocities (each body its own
      // field: the bodies in parallel; the barrier: the flux reads the constrained velocities).
      team.dynamic(nb, 1, [&](std::int64_t b) { apply_boundary_conditions<G>(grid_, bc_, fields_[b], opt_.dt_s); });
      team.barrier();
      if (halo_) {  // decomposed: the owners' velocities (and porosity) out to the neighbours' copies
        if (team.rank() == 0) timed_exchange([&] { copy_from_owners(); });
        team.barrier();
      }
      // Phase 5b: the mixture flux and the swirl test, node by node.
      std::uint64_t mine = 0;
      if (node_pass_parallel) {
        const parallel::Range r = team.share(nn);
        mine = mixture_flux_and_swirl(static_cast<int>(r.begin), static_cast<int>(r.end));
      } else if (team.rank() == 0) {
        mine = mixture_flux_and_swirl(0, nn);
      }
      if (mine != 0) parallel::atomic_or(swirl, mine);
      team.barrier();
      team.single([&] { prepare_point_tasks<K>(swirl, team.size()); });
      // Phase 6, G2P: each body's blocks in static shares with stealing.
      for (int k = 0; k < ntasks; ++k) {
        const std::int64_t bad = run_g2p_share(team, shares_, k, g2p_tasks_[k]);
        if (bad != kAllFinite) parallel::atomic_min(non_finite_kinematics_[g2p_bodies_[k]], bad);
      }
      team.barrier();
      if (team.rank() == 0) clock.lap(timings_.g2p);
      // Phase 7, the laws, costliest bodies first.
      for (std::size_t k = 0; k < law_bodies_.size(); ++k) {
        const int b = law_bodies_[k];
        const std::int64_t bad =
            run_law_share(team, shares_, ntasks + static_cast<int>(k), *bodies_[b]->law, *bodies_[b], dt);
        if (bad != kAllFinite) parallel::atomic_min(law_first_bad_[b], bad);
      }
    });
    for (int b = 0; b < nb; ++b)  // (in body order, as the laws were run before)
      if (bodies_[b]->law) bodies_[b]->law->end_update(*bodies_[b], dt, law_first_bad_[b]);
    clock.lap(timings_.stress);
  }

  Grid<D> grid_;  ///< the grid this rank solves on (its block's local grid when decomposed)
  SolverOptions<G> opt_;
  std::unique_ptr<Decomposition<D>> dec_;  ///< decomposed runs only
  std::unique_ptr<Halo<D>> halo_;
  std::int64_t points_migrated_ = 0;
  BoundaryConditions<D> bc_{};
  std::vector<std::unique_ptr<Body<G>>> bodies_;
  std::vector<RigidMotion<G>> rigid_;      ///< per body: deformable, prescribed or free rigid
  std::vector<ContactPair<G>> contacts_;   ///< solid–mixture contact pairs (docs/contact.md)
  std::vector<Motor<G>> motors_;           ///< angular-velocity motors (docs/contact.md, wheel)
  std::vector<double> contact_weight_;     ///< per node: weight in the body impulse sums
  std::vector<double> node_measure_;       ///< per node: h^D (per radian h² r) for the overlap test
  std::vector<double> mixture_volume_;     ///< nodal grains volume when there is no fluid body
  std::vector<Vec<D>> mixture_gradient_;   ///< nodal mixture mass gradient (combined normals)
  bool mixture_volume_scattered_ = false;  ///< mixture_volume_ holds this step's grains volume
  Box solids_box_;                         ///< the mixture's points near the contact solids (this step)
  std::vector<ShapeCache<D>> caches_;
  std::vector<std::int64_t> non_finite_kinematics_;  ///< per body, from the last G2P
  std::vector<GridField<G>> fields_;
  int threads_ = 1;
  int grains_ = -1, fluid_ = -1;
  StepTimings timings_;
  std::vector<GridField<G>*>
      solids_;                    ///< scratch of update_grid_and_couple (refilled per call): deformable solids' fields
  std::vector<double> porosity_;  ///< nodal porosity n_i of the mixture
  std::vector<Vec<NC>> flux_;     ///< nodal mixture volume flux q_i
  // scratch of update_points (refilled per call): the G2P tasks of the deformable bodies and
  // their body indices; bodies with a law, costliest first; per body the lowest index of a
  // non-finite law result; the counters of the threads' shares
  std::vector<G2PTask<G>> g2p_tasks_;
  std::vector<int> g2p_bodies_;
  std::vector<std::int64_t> p2g_outside_;  ///< per body: points whose support left the grid (P2G)
  std::vector<int> law_bodies_;
  std::vector<std::int64_t> law_first_bad_;
  parallel::StealingShares shares_;         ///< the G2P tasks' and the law bodies' shares
  std::vector<double> mass_floor_density_;  ///< per body: linear_mass_floor · ρ̄_b (linear kernels; empty: off)
  std::vector<double> mass_floor_measure_;  ///< per node: V_i of the mass floor
  double time_s_ = 0.0;
  std::int64_t steps_ = 0;
};

}  // namespace oobleck::mpm
