#include "oobleck/scene/build.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/drag.hpp"
#include "oobleck/mpm/initial_state.hpp"
#include "oobleck/scene/third_bodies.hpp"

namespace oobleck::scene {

namespace {

/// The grid and the solver's options (shape function, transfer, gravity, mixture coupling).
template <class G>
std::unique_ptr<mpm::Solver<G>> make_solver(const SceneConfig& cfg, int threads) {
  constexpr int D = G::dim;
  const auto& gc = cfg.grid;
  mpm::Vec<D> origin;
  std::array<int, D> cells{};
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) {
    origin[a] = gc.origin_m[a];
    cells[a] = gc.cells[a];
    periodic[a] = cfg.boundary[2 * a].type == BoundaryType::Periodic;
  }
  mpm::Grid<D> grid(origin, gc.cell_size_m, cells, periodic);

  mpm::SolverOptions<G> so;
  so.dt_s = 1.0;  // set by set_time_step, once the bodies exist
  switch (gc.shape) {
    case ShapeKind::Linear: so.shape = mpm::ShapeKind::Linear; break;
    case ShapeKind::Quadratic: so.shape = mpm::ShapeKind::QuadraticBSpline; break;
    case ShapeKind::Cubic: so.shape = mpm::ShapeKind::CubicBSpline; break;
    case ShapeKind::UGimp: so.shape = mpm::ShapeKind::UGimp; break;
  }
  so.gimp_half_width_cells = 0.5 / cfg.regions.front().points_per_cell;
  so.transfer = cfg.transfer.scheme == TransferScheme::Apic ? mpm::Transfer::Apic : mpm::Transfer::FlipPicBlend;
  so.flip_fraction = cfg.transfer.flip_fraction;
  so.gravity_m_s2 = mpm::Vec<G::ncomp>::Zero();
  for (int a = 0; a < D; ++a) so.gravity_m_s2[a] = cfg.gravity_m_s2[a];
  so.threads = threads;
  so.mixture.rho_s_kg_m3 = cfg.material.granular.rho_s;
  so.mixture.rho_f0_kg_m3 = cfg.fluid.rho_f0_kg_m3;
  so.mixture.min_porosity = cfg.coupling.porosity_min;
  so.mixture.drag.law =
      cfg.coupling.drag == DragLaw::Beetstra ? material::DragLaw::Beetstra : material::DragLaw::CarmanKozeny;
  so.mixture.drag.d_m = cfg.material.granular.d;
  so.mixture.drag.eta_0_Pa_s = cfg.fluid.eta_0_Pa_s;
  return std::make_unique<mpm::Solver<G>>(grid, so);
}

/// The six faces' wall conditions (step 4b of the solver).
template <class G>
void set_walls(const SceneConfig& cfg, mpm::Solver<G>& solver) {
  for (int face = 0; face < 2 * G::dim; ++face) {
    const BoundaryConfig& b = cfg.boundary[face];
    mpm::FaceCondition& fc = solver.boundaries()[face];
    switch (b.type) {
      case BoundaryType::NoSlip: fc.type = mpm::WallType::NoSlip; break;
      case BoundaryType::Slip: fc.type = mpm::WallType::Slip; break;
      case BoundaryType::Friction:
        fc.type = mpm::WallType::Friction;
        fc.friction_coefficient = b.friction;
        break;
      case BoundaryType::Velocity:
        fc.type = mpm::WallType::Prescribed;
        fc.velocity_m_s = Eigen::Vector3d(b.velocity_m_s[0], b.velocity_m_s[1], b.velocity_m_s[2]);
        break;
      case BoundaryType::Axis: fc.type = mpm::WallType::Axis; break;
      case BoundaryType::Open:
      case BoundaryType::Periodic: fc.type = mpm::WallType::Open; break;
    }
  }
}

/// The grains' and the fluid's bodies, created with their laws on first use (one body per phase
/// whatever the number of regions that fill it).
template <class G>
struct MixtureBodies {
  const SceneConfig& cfg;
  BuiltScene<G>& s;

  mpm::Body<G>& grains() {
    if (s.grains < 0) {
      s.grains = s.solver->body_count();
      auto& b = s.solver->add_body("grains", mpm::Phase::Grains);
      auto law = std::make_unique<mpm::GranularBodyLaw<G>>(cfg.material);
      s.granular_law = law.get();
      b.set_law(std::move(law));
    }
    return s.solver->body(s.grains);
  }
  mpm::Body<G>& fluid() {
    if (s.fluid < 0) {
      s.fluid = s.solver->body_count();
      auto& b = s.solver->add_body("fluid", mpm::Phase::Fluid);
      material::FluidParams fp;
      fp.eta_0_Pa_s = cfg.fluid.eta_0_Pa_s;
      fp.kappa_Pa = cfg.fluid.kappa_Pa;
      fp.rho_f0_kg_m3 = cfg.fluid.rho_f0_kg_m3;
      auto law = std::make_unique<mpm::FluidLaw<G>>(fp, cfg.coupling.porosity_min);
      s.fluid_law = law.get();
      b.set_law(std::move(law));
    }
    return s.solver->body(s.fluid);
  }
};

/// The bed's top, its volume fraction and whether its grains start out of contact, from the
/// regions with an initial state (the last such region's phi and state).
struct Bed {
  double surface = -std::numeric_limits<double>::infinity();
  double phi = 0.0;
  bool suspended = false;
};

/// Points on a lattice in every region's box: the mixture's phases or an elastic solid.
template <class G>
Bed fill_regions(const SceneConfig& cfg, BuiltScene<G>& s) {
  constexpr int D = G::dim, NC = G::ncomp;
  const double h = cfg.grid.cell_size_m;
  const double rho_s = cfg.material.granular.rho_s;
  const double rho_f = cfg.fluid.rho_f0_kg_m3;
  MixtureBodies<G> mix{cfg, s};
  Bed bed;
  for (const auto& r : cfg.regions) {
    mpm::Vec<D> lo, hi;
    for (int a = 0; a < D; ++a) {
      lo[a] = r.min_m[a];
      hi[a] = r.max_m[a];
    }
    mpm::Vec<NC> v0;
    for (int c = 0; c < NC; ++c) v0[c] = r.velocity_m_s[c];
    auto velocity = [v0](const mpm::Vec<D>&) { return v0; };
    switch (r.phase) {
      case Phase::Mixture:
        mpm::fill_box(mix.grains(), lo, hi, h, r.points_per_cell, r.phi * rho_s, velocity);
        mpm::fill_box(mix.fluid(), lo, hi, h, r.points_per_cell, (1.0 - r.phi) * rho_f, velocity);
        break;
      case Phase::Grains: mpm::fill_box(mix.grains(), lo, hi, h, r.points_per_cell, r.phi * rho_s, velocity); break;
      case Phase::Fluid: mpm::fill_box(mix.fluid(), lo, hi, h, r.points_per_cell, rho_f, velocity); break;
      case Phase::Elastic: {
        auto& b = s.solver->add_body(r.name, mpm::Phase::Solid);
        material::LinearElasticParams ep;
        ep.youngs_modulus_Pa = r.elastic.youngs_modulus_Pa;
        ep.poisson_ratio = r.elastic.poisson_ratio;
        b.set_law(std::make_unique<mpm::LinearElasticLaw<G>>(ep));
        mpm::fill_box(b, lo, hi, h, r.points_per_cell, r.elastic.density_kg_m3, velocity);
        break;
      }
    }
    if (r.initial_state != InitialState::AtRest) {
      bed.surface = std::max(bed.surface, r.max_m[D - 1]);
      bed.phi = r.phi;
      bed.suspended = r.initial_state == InitialState::Suspended;
    }
  }
  for (int b = 0; b < s.solver->body_count(); ++b) {
    if (s.solver->body(b).size() == 0) {
      throw InputError(
          fmt::format("{}: body '{}' got no material points: regions must span at least one "
                      "point spacing (cell_size/points_per_cell)",
                      cfg.file, s.solver->body(b).name));
    }
  }
  return bed;
}

/// The bed's initial stresses: a suspension carried by its fluid, or a hydrostatic bed.
template <class G>
void set_initial_state(const SceneConfig& cfg, const Bed& bed, BuiltScene<G>& s) {
  constexpr int D = G::dim;
  if (!std::isfinite(bed.surface)) return;
  const double rho_s = cfg.material.granular.rho_s;
  const double rho_f = cfg.fluid.rho_f0_kg_m3;
  if (bed.suspended) {
    // Grains out of contact: the fluid pressure carries the whole mixture weight,
    // p_f = rho_mix g depth with rho_mix = phi rho_s + (1 - phi) rho_f (E26: ln J = -p_f/kappa),
    // and the granular stress is zero.
    const double g = -cfg.gravity_m_s2[D - 1];
    const double rho_mix = bed.phi * rho_s + (1.0 - bed.phi) * rho_f;
    if (s.fluid >= 0) {
      auto& fl = s.solver->body(s.fluid);
      for (std::int64_t p = 0; p < fl.size(); ++p) {
        const double pf = rho_mix * g * std::max(bed.surface - fl.x_m[p][D - 1], 0.0);
        const double ln_J = -pf / cfg.fluid.kappa_Pa;
        s.fluid_law->ln_J[p] = ln_J;
        fl.mass_kg[p] /= std::exp(ln_J);
        fl.stress_Pa[p] = -pf * mpm::Mat3::Identity();
        fl.phi[p] = bed.phi;
      }
    }
    return;
  }
  mpm::HydrostaticBed hb;
  hb.surface_m = bed.surface;
  hb.g_m_s2 = -cfg.gravity_m_s2[D - 1];
  hb.rho_s_kg_m3 = rho_s;
  hb.rho_f0_kg_m3 = rho_f;
  const double K = cfg.material.granular.K, Gm = cfg.material.granular.G;
  const double nu = (3 * K - 2 * Gm) / (2 * (3 * K + Gm));
  hb.K0 = nu / (1 - nu);  // uniaxial-strain elastic skeleton
  hb.phi_bed = bed.phi;
  mpm::set_hydrostatic_bed<G>(hb, s.grains >= 0 ? &s.solver->body(s.grains) : nullptr,
                              s.fluid >= 0 ? &s.solver->body(s.fluid) : nullptr);
}

/// The [[body]] entries (third_bodies.hpp), their motors numbered in file order.
template <class G>
void add_bodies(const SceneConfig& cfg, BuiltScene<G>& s) {
  for (const auto& bc : cfg.bodies) {
    ThirdBody tb;
    tb.cfg = &bc;
    std::tie(tb.body, tb.pair) = add_third_body<G>(*s.solver, bc, cfg.grid.cell_size_m, cfg.file);
    if (bc.motor_omega_rad_s) {
      int m = 0;
      for (const auto& other : s.third) m += other.motor >= 0 ? 1 : 0;
      tb.motor = m;
    }
    if (bc.name == cfg.analysis.body) s.analysed = static_cast<int>(s.third.size());
    s.third.push_back(tb);
  }
}

/// time.dt (checked against the stable step) or the CFL-stable step of the built bodies.
template <class G>
void set_time_step(const SceneConfig& cfg, BuiltScene<G>& s) {
  if (cfg.time.dt_s) {
    s.dt_s = *cfg.time.dt_s;
    s.solver->options().dt_s = s.dt_s;
    try {
      s.solver->check_time_step(1.0);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: key 'time.dt' = {}: {}", cfg.file, s.dt_s, e.what()));
    }
  } else {
    s.dt_s = s.solver->stable_dt(cfg.time.cfl);
    if (!std::isfinite(s.dt_s)) {
      throw InputError(
          fmt::format("{}: no stable time step could be derived (no material with a wave speed); "
                      "set time.dt",
                      cfg.file));
    }
    s.solver->options().dt_s = s.dt_s;
  }
  // Linear kernels: the nodal mass floor (SolverOptions::linear_mass_floor) (Δt/Δt_crit)², Δt_crit
  // the wave's stable step on a full node (CFL 1): cfl² for a step from time.cfl (a viscous limit
  // below the wave's does not enter: it is not what a small mass shortens).
  if (s.solver->options().shape == mpm::ShapeKind::Linear) {
    const double ratio = s.dt_s / s.solver->time_step_limits(1.0).first;
    s.solver->options().linear_mass_floor = cfg.grid.linear_mass_floor.value_or(std::min(1.0, ratio * ratio));
  }
  s.total_steps = std::max(1L, static_cast<long>(std::llround(cfg.time.duration_s / s.dt_s)));
}

}  // namespace

template <class G>
BuiltScene<G> build_scene(const SceneConfig& config, int threads) {
  BuiltScene<G> s;
  s.solver = make_solver<G>(config, threads);
  set_walls(config, *s.solver);
  const Bed bed = fill_regions(config, s);
  set_initial_state(config, bed, s);
  add_bodies(config, s);
  set_time_step(config, s);
  return s;
}

double bed_surface(const SceneConfig& config) {
  double top = -INFINITY;
  for (const auto& r : config.regions)
    if (r.phase != Phase::Elastic) top = std::max(top, r.max_m[config.grid.dim - 1]);
  return top;
}

template BuiltScene<mpm::PlaneStrain> build_scene(const SceneConfig&, int);
template BuiltScene<mpm::Axisymmetric> build_scene(const SceneConfig&, int);
template BuiltScene<mpm::ThreeD> build_scene(const SceneConfig&, int);

}  // namespace oobleck::scene
