#pragma once
// The explicit MPM step (model.md §6, update-stress-last) for any number of bodies on one grid.
//
//   Solver<PlaneStrain> s(grid, options);
//   auto& b = s.add_body("bar");  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(p));
//   fill_box(b, lo, hi, h, ppc, rho, v0);  s.boundaries()[0] = {WallType::Slip};
//   while (s.time_s() < T) s.step();
//
// Each body has its own grid field; the phase coupling (buoyancy split, semi-implicit drag,
// model.md §5) and contact (§8) plug into `couple_bodies()` between the predicted grid velocities
// and the boundary conditions.
#include <cmath>
#include <cstdint>
#include <memory>
#include <omp.h>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/shape.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

template <class G>
struct SolverOptions {
  double dt_s = 1e-5;                                   ///< time step [s]
  ShapeKind shape = ShapeKind::QuadraticBSpline;        ///< shape functions
  double gimp_half_width_cells = 0.25;                  ///< uGIMP ℓ in cells (= 1/(2 ppc))
  Transfer transfer = Transfer::Apic;                   ///< velocity transfer
  double flip_fraction = 0.99;                          ///< α of the FLIP/PIC blend
  Vec<G::ncomp> gravity_m_s2 = Vec<G::ncomp>::Zero();   ///< gravitational acceleration
  int threads = 0;                                      ///< OpenMP threads (0: omp default)
};

/// Number of nodes per axis in the support of a kernel.
inline int kernel_support(ShapeKind k) {
  switch (k) {
    case ShapeKind::Linear: return 2;
    case ShapeKind::CubicBSpline: return 4;
    default: return 3;
  }
}

template <class G>
class Solver {
 public:
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;

  Solver(const Grid<D>& grid, const SolverOptions<G>& options) : grid_(grid), opt_(options) {
    if (!(opt_.dt_s > 0.0)) throw InputError(fmt::format("mpm: dt must be > 0 s, got {}", opt_.dt_s));
    if (!(opt_.flip_fraction >= 0.0 && opt_.flip_fraction <= 1.0))
      throw InputError(fmt::format("mpm: flip_fraction must be in [0, 1], got {}", opt_.flip_fraction));
    if (opt_.shape == ShapeKind::UGimp &&
        !(opt_.gimp_half_width_cells > 0.0 && opt_.gimp_half_width_cells <= 0.5))
      throw InputError(fmt::format("mpm: uGIMP half width must be in (0, 0.5] cells, got {}",
                                   opt_.gimp_half_width_cells));
    threads_ = opt_.threads > 0 ? opt_.threads : omp_get_max_threads();
  }

  Body<G>& add_body(const std::string& name) {
    bodies_.push_back(std::make_unique<Body<G>>());
    bodies_.back()->name = name;
    caches_.emplace_back();
    fields_.emplace_back();
    fields_.back().resize(grid_.node_count(), threads_);
    return *bodies_.back();
  }

  BoundaryConditions<D>& boundaries() { return bc_; }
  const Grid<D>& grid() const { return grid_; }
  SolverOptions<G>& options() { return opt_; }
  int body_count() const { return static_cast<int>(bodies_.size()); }
  Body<G>& body(int b) { return *bodies_[b]; }
  const GridField<G>& field(int b) const { return fields_[b]; }
  const ShapeCache<D>& shape_cache(int b) const { return caches_[b]; }
  double time_s() const { return time_s_; }
  std::int64_t steps() const { return steps_; }
  int threads() const { return threads_; }

  /// Largest stable Δt [s] from the CFL condition on the fastest wave of every body
  /// (Δt ≤ cfl h / (c + |v|_max), model.md §6).
  double stable_dt(double cfl = 0.5) const {
    double c_max = 0.0;
    for (const auto& b : bodies_) {
      double c = b->law ? b->law->max_wave_speed(*b) : 0.0;
      double vmax = 0.0;
      for (const auto& v : b->v_m_s) vmax = std::max(vmax, v.norm());
      c_max = std::max(c_max, c + vmax);
    }
    return c_max > 0.0 ? cfl * grid_.h_m / c_max : INFINITY;
  }

  /// One explicit step of length options().dt_s.
  void step() {
    with_support([&](auto S) {
      constexpr int K = ipow(decltype(S)::value, D);
      compute_shape_functions();           // 1. N_ip, ∇N_ip cached per point
      particles_to_grid_all<K>();          // 2. mass, momentum, internal force
      apply_body_loads();                  // 3. gravity (motors later)
      fold_wall_images_all();              // 4a. walls: ghost contributions onto mirrors
      predict_grid_velocities();           // 5. v = (mv + Δt f)/m
      couple_bodies();                     // 3b. buoyancy, semi-implicit drag, contact (hook)
      apply_boundary_conditions_all();     // 4b. walls on nodal velocities, ghost images
      grid_to_particles_all<K>();          // 6–7. x, v (FLIP/PIC or APIC), L, V ← V exp(Δt tr L)
      update_stresses();                   // 8. laws
    });
    time_s_ += opt_.dt_s;
    ++steps_;
  }

 private:
  static constexpr int ipow(int b, int e) { return e == 0 ? 1 : b * ipow(b, e - 1); }

  template <class F>
  void with_support(F&& f) {
    switch (kernel_support(opt_.shape)) {
      case 2: f(std::integral_constant<int, 2>{}); break;
      case 4: f(std::integral_constant<int, 4>{}); break;
      default: f(std::integral_constant<int, 3>{}); break;
    }
  }

  void compute_shape_functions() {
    omp_set_num_threads(threads_);
    for (std::size_t b = 0; b < bodies_.size(); ++b) {
      const std::int64_t bad = with_kernel(opt_.shape, opt_.gimp_half_width_cells, [&](auto kernel) {
        return compute_shape_cache(grid_, kernel, bodies_[b]->x_m, caches_[b]);
      });
      if (bad > 0)
        throw NumericalError(fmt::format(
            "mpm: {} point(s) of body '{}' left the grid (more than one cell outside the domain) at "
            "step {}, t = {} s",
            bad, bodies_[b]->name, steps_, time_s_));
    }
  }

  template <int K>
  void particles_to_grid_all() {
    const bool apic = opt_.transfer == Transfer::Apic;
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      particles_to_grid<G, K>(*bodies_[b], caches_[b], fields_[b], apic);
  }

  void apply_body_loads() {
    if (opt_.gravity_m_s2.squaredNorm() == 0.0) return;
    for (auto& f : fields_) add_gravity(f, opt_.gravity_m_s2);
  }

  void fold_wall_images_all() {
    for (auto& f : fields_) fold_wall_images<G>(grid_, bc_, f);
  }

  void predict_grid_velocities() {
    for (auto& f : fields_) update_grid_velocity(f, opt_.dt_s);
  }

  void couple_bodies() {}  // single-phase bodies: nothing yet (model.md §5, §8 plug in here)

  void apply_boundary_conditions_all() {
    for (auto& f : fields_) apply_boundary_conditions<G>(grid_, bc_, f);
  }

  template <int K>
  void grid_to_particles_all() {
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      grid_to_particles<G, K>(*bodies_[b], caches_[b], fields_[b], grid_, opt_.transfer,
                              opt_.flip_fraction, opt_.dt_s);
  }

  void update_stresses() {
    for (auto& b : bodies_)
      if (b->law) b->law->update_stress(*b, opt_.dt_s);
  }

  Grid<D> grid_;
  SolverOptions<G> opt_;
  BoundaryConditions<D> bc_{};
  std::vector<std::unique_ptr<Body<G>>> bodies_;
  std::vector<ShapeCache<D>> caches_;
  std::vector<GridField<G>> fields_;
  int threads_ = 1;
  double time_s_ = 0.0;
  std::int64_t steps_ = 0;
};

}  // namespace oobleck::mpm
