#pragma once
// The explicit MPM step (docs/mpm.md, "The step": update-stress-last) for any number of bodies on one grid.
//
//   Solver<PlaneStrain> s(grid, options);
//   auto& b = s.add_body("bar");  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(p));
//   fill_box(b, lo, hi, h, ppc, rho, v0);  s.boundaries()[0] = {WallType::Slip};
//   while (s.time_s() < T) s.step();
//
// Solver<G> is the public interface: it builds the scene (bodies, third bodies, contact pairs,
// motors, boundaries, the decomposition) into its SolverState (solver_state.hpp) and answers what
// the runs read back. The step is written out in step.hpp, its phases in mpm/phases/*.hpp: P2G
// (p2g.hpp); the grid pass with the phase coupling (porosity, buoyancy split, semi-implicit drag,
// E28–E29 of docs/equations.md; grid.hpp); contact with third bodies (docs/contact.md;
// phases/contact.hpp), its mass gradients scattered beside the grid pass and its impulses after
// it; the walls, the mixture flux, G2P and the laws (points.hpp).
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

#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/decomposition.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/halo.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/shape.hpp"
#include "oobleck/mpm/solver_state.hpp"
#include "oobleck/mpm/step.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

template <class G>
class Solver {
 public:
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;

  Solver(const Grid<D>& grid, const SolverOptions<G>& options) : s_(grid, options) {
    if (!(s_.opt.dt_s > 0.0)) throw InputError(fmt::format("mpm: dt must be > 0 s, got {}", s_.opt.dt_s));
    if (!(s_.opt.flip_fraction >= 0.0 && s_.opt.flip_fraction <= 1.0))
      throw InputError(fmt::format("mpm: flip_fraction must be in [0, 1], got {}", s_.opt.flip_fraction));
    if (s_.opt.shape == ShapeKind::UGimp &&
        !(s_.opt.gimp_half_width_cells > 0.0 && s_.opt.gimp_half_width_cells <= 0.5))
      throw InputError(
          fmt::format("mpm: uGIMP half width must be in (0, 0.5] cells, got {}", s_.opt.gimp_half_width_cells));
    s_.threads = s_.opt.threads > 0 ? s_.opt.threads : parallel::max_threads();
  }

  /// Add a body. At most one Grains and one Fluid body (they are coupled at the nodes).
  Body<G>& add_body(const std::string& name, Phase phase = Phase::Solid) {
    const int index = static_cast<int>(s_.bodies.size());
    if (phase == Phase::Grains) {
      if (s_.grains >= 0) throw InputError("mpm: only one granular body per solver");
      s_.grains = index;
    }
    if (phase == Phase::Fluid) {
      if (s_.fluid >= 0) throw InputError("mpm: only one fluid body per solver");
      s_.fluid = index;
    }
    s_.bodies.push_back(std::make_unique<Body<G>>());
    s_.bodies.back()->name = name;
    s_.rigid.emplace_back();
    if constexpr (std::is_same_v<G, Axisymmetric>) s_.rigid.back().free_mask = Vec<NC>(0.0, 1.0, 0.0);
    s_.caches.emplace_back();
    s_.fields.emplace_back();
    s_.fields.back().resize(s_.grid.node_count(), s_.threads);
    return *s_.bodies.back();
  }

  // ---- Third bodies and contact (docs/contact.md, contact.hpp) ----------------------------------

  /// Make body b rigid, every point moving at v until the next call (intruder; called before
  /// each step to ramp it up); the contact force on it is the reaction the drive must supply.
  void set_prescribed_velocity(int b, const Vec<NC>& v) {
    check_solid(b, "prescribed velocity");
    s_.rigid[b].kind = BodyMotion::Prescribed;
    s_.rigid[b].velocity_m_s = v;
    for (auto& vp : s_.bodies[b]->v_m_s) vp = v;
  }
  /// Make body b a free rigid body that only translates (launched rod), starting at velocity v;
  /// driven by gravity and its contact impulses. Components with free_mask 0 are held at v
  /// (default: all free; axisymmetric: only v_z).
  void set_free_rigid(int b, const Vec<NC>& v) {
    check_solid(b, "free rigid");
    s_.rigid[b].kind = BodyMotion::FreeRigid;
    s_.rigid[b].velocity_m_s = v;
    for (auto& vp : s_.bodies[b]->v_m_s) vp = v;
  }
  RigidMotion<G>& rigid_motion(int b) { return s_.rigid[b]; }
  /// Contact between solid body b and the mixture (its grains and/or fluid body), Coulomb
  /// coefficient μ between solid and grains (docs/contact.md). Returns the pair index. One pair
  /// per solid (the step completes every pair's sums after the last pair, then moves the bodies).
  int add_contact(int b, double friction_coefficient) {
    check_solid(b, "contact");
    for (const auto& c : s_.contacts)
      if (c.solid == b)
        throw InputError(fmt::format("mpm: contact: body '{}' has a contact pair already", s_.bodies[b]->name));
    if (!(friction_coefficient >= 0.0))
      throw InputError(fmt::format("mpm: friction coefficient must be >= 0, got {}", friction_coefficient));
    s_.contacts.emplace_back();
    s_.contacts.back().solid = b;
    s_.contacts.back().friction_coefficient = friction_coefficient;
    s_.contacts.back().mass_gradient.assign(static_cast<std::size_t>(s_.grid.node_count()), Vec<D>::Zero());
    s_.contacts.back().volume_m3.assign(static_cast<std::size_t>(s_.grid.node_count()), 0.0);
    return static_cast<int>(s_.contacts.size()) - 1;
  }
  const ContactPair<G>& contact(int pair) const { return s_.contacts[pair]; }
  /// The unit normal contact used at node i for the pair in the last step (contact.hpp
  /// contact_normal); zero where it had none.
  Vec<NC> contact_normal_at(int pair, int i) const {
    const ContactPair<G>& c = s_.contacts[pair];
    Vec<NC> n = Vec<NC>::Zero();  // (left so where there is no normal)
    contact_normal(c, c.combined_normal ? s_.mixture_gradient.data() : nullptr, i, n);
    return n;
  }
  /// Declare pair `pair`'s persistent fields (mpm/fields.hpp; restored in place).
  void declare_contact_fields(int pair, FieldList& list) { s_.contacts[pair].declare_fields(list); }
  int contact_count() const { return static_cast<int>(s_.contacts.size()); }
  /// Contact force on body b from the mixture over the last step [N] (sum over its pairs; per
  /// radian in axisymmetric mode, per unit depth in plane strain).
  Vec<NC> contact_force(int b) const {
    Vec<NC> F = Vec<NC>::Zero();
    for (const auto& c : s_.contacts)
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
      if (s_.rigid[b].rigid()) throw InputError("mpm: a motor drives a deformable body");
      if (!(gain > 0.0 && gain <= 1.0))
        throw InputError(fmt::format("mpm: motor gain must be in (0, 1], got {}", gain));
      s_.motors.push_back({});
      s_.motors.back().body = b;
      s_.motors.back().omega_rad_s = omega_rad_s;
      s_.motors.back().gain = gain;
      return static_cast<int>(s_.motors.size()) - 1;
    }
  }
  Motor<G>& motor(int m) { return s_.motors[m]; }

  BoundaryConditions<D>& boundaries() { return s_.bc; }
  const Grid<D>& grid() const { return s_.grid; }
  SolverOptions<G>& options() { return s_.opt; }
  int body_count() const { return static_cast<int>(s_.bodies.size()); }
  Body<G>& body(int b) { return *s_.bodies[b]; }
  const GridField<G>& field(int b) const { return s_.fields[b]; }
  const ShapeCache<D>& shape_cache(int b) const { return s_.caches[b]; }
  double time_s() const { return s_.time_s; }
  /// Nodal porosity of the last step (mixture only; empty otherwise).
  const std::vector<double>& nodal_porosity() const { return s_.porosity; }
  /// Declare the nodal arrays the frames show on the grid (mpm/fields.hpp): the nodal porosity
  /// n of the last step (E28), when there is a mixture.
  void declare_grid_fields(FieldList& list) {
    if (!s_.porosity.empty()) list.add_nodal("porosity", s_.porosity, "1");
  }
  std::int64_t steps() const { return s_.steps; }
  /// Restore the clock from a checkpoint (restart).
  void set_clock(double time_s, std::int64_t steps) {
    s_.time_s = time_s;
    s_.steps = steps;
  }
  int threads() const { return s_.threads; }

  /// Domain decomposition (decomposition.hpp, docs/mpi.md): from here on this rank solves on its
  /// block's local grid and keeps only the points inside its block; the step exchanges the
  /// nodal sums and values with the neighbours and moves points that cross a block face. Call
  /// once, after the bodies are filled and the boundaries set, before the first step, on every
  /// rank with the whole scene. Third bodies: every rank holds each rigid body's motion, each
  /// contact pair's sums and each motor, completed over the ranks (contact.hpp); a free rigid
  /// body's shape is built here, from all its points.
  void decompose(const Decomposition<D>& dec) {
    if (s_.dec) throw InputError("mpm: the solver is already decomposed");
    for (auto& c : s_.contacts)
      if (s_.rigid[c.solid].kind == BodyMotion::FreeRigid && !c.shape.built)
        build_rigid_shape(c.shape, *s_.bodies[c.solid], s_.grid);
    s_.contact_weight.clear();      // (recomputed on the local grid, owned nodes only)
    s_.mass_floor_density.clear();  // (linear kernels: recomputed over every rank's points)
    s_.dec = std::make_unique<Decomposition<D>>(dec);
    s_.grid = s_.dec->local_grid();
    for (int a = 0; a < D; ++a) {  // faces inside the domain (or across a split periodic axis) are open
      if (!s_.dec->split(a)) continue;
      if (s_.dec->coords()[a] > 0 || s_.dec->global().periodic[a]) s_.bc[2 * a] = FaceCondition{};
      if (s_.dec->coords()[a] < s_.dec->dims()[a] - 1 || s_.dec->global().periodic[a])
        s_.bc[2 * a + 1] = FaceCondition{};
    }
    for (auto& f : s_.fields) f.resize(s_.grid.node_count(), s_.threads);
    for (auto& c : s_.contacts) {
      c.mass_gradient.assign(static_cast<std::size_t>(s_.grid.node_count()), Vec<D>::Zero());
      c.volume_m3.assign(static_cast<std::size_t>(s_.grid.node_count()), 0.0);
    }
    for (auto& b : s_.bodies) keep_owned_points(*b, *s_.dec);
    s_.halo = std::make_unique<Halo<D>>(*s_.dec, s_.grid);
  }
  /// The decomposition, or nullptr (one rank).
  const Decomposition<D>* decomposition() const { return s_.dec.get(); }
  /// The whole domain's grid: grid() on one rank, the decomposition's global grid otherwise (for
  /// positions: periodic images, the domain's bounds).
  const Grid<D>& global_grid() const { return s_.dec ? s_.dec->global() : s_.grid; }
  /// Bytes this rank sent in the nodal exchanges so far (0 on one rank).
  std::int64_t halo_bytes_sent() const { return s_.halo ? s_.halo->bytes_sent() : 0; }
  /// Points that left this rank for another so far (0 on one rank).
  std::int64_t points_migrated() const { return s_.points_migrated; }

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
    for (const auto& b : s_.bodies) {
      double c = b->law ? b->law->max_wave_speed(*b) : 0.0;
      double vmax = 0.0;
      for (const auto& v : b->v_m_s) vmax = std::max(vmax, v.norm());
      c_max = std::max(c_max, c + vmax);
      if (b->law) dt_visc = std::min(dt_visc, b->law->viscous_dt_limit(*b, s_.grid.h_m));
    }
    if (s_.dec) {  // every rank's points
      c_max = comm::max(c_max);
      dt_visc = comm::min(dt_visc);
    }
    return {c_max > 0.0 ? cfl * s_.grid.h_m / c_max : INFINITY, dt_visc};
  }

  /// Refuse a time step above the stable one (docs/mpm.md, "The step"): throws InputError with the numbers.
  void check_time_step(double cfl = 0.5) const {
    const double dt_max = stable_dt(cfl);
    if (s_.opt.dt_s > dt_max)
      throw InputError(
          fmt::format("mpm: time step dt = {:.4g} s is above the stable limit {:.4g} s (CFL {} on the fastest "
                      "wave, viscous limit rho h^2/(2 eta), h = {:.4g} m)",
                      s_.opt.dt_s, dt_max, cfl, s_.grid.h_m));
  }

  /// One explicit step of length options().dt_s, in the phases of docs/mpm.md ("The step"),
  /// written out in step.hpp.
  void step() { mpm::step(s_); }

  /// The NaN guard fused into the last step's G2P for body b: the lowest index of a point whose
  /// new position, velocity or volume is not finite, kAllFinite, or kNotChecked (rigid bodies, or
  /// before the first step).
  std::int64_t first_non_finite_kinematics(int b) const {
    return static_cast<std::size_t>(b) < s_.non_finite_kinematics.size() ? s_.non_finite_kinematics[b] : kNotChecked;
  }

  /// Wall time per part of the step, accumulated since construction or reset_timings().
  const StepTimings& timings() const { return s_.timings; }
  void reset_timings() { s_.timings = {}; }

 private:
  void check_solid(int b, const char* what) const {
    if (b < 0 || b >= body_count()) throw InputError(fmt::format("mpm: {}: no body with index {}", what, b));
    if (b == s_.grains || b == s_.fluid)
      throw InputError(fmt::format("mpm: {}: body '{}' is a mixture phase, not a solid", what, s_.bodies[b]->name));
  }

  SolverState<G> s_;
};

}  // namespace oobleck::mpm
