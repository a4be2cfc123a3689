#pragma once
// Scene [[body]] entries (scene/config.hpp BodyConfig) turned into solver bodies (docs/contact.md):
// point lattices for boxes, discs, spoked wheels and cylinders, the rigid/elastic motion, the contact pair
// and the motor (used by scene/build.cpp; prescribed_velocity also by the run loop's ramp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"
#include "oobleck/scene/config.hpp"

namespace oobleck::scene {

/// Whether x lies inside the body's shape (box, disc, hub + paddles of a spoked wheel, cylinder).
/// For periodic axes the caller passes x relative to the centre's image (minimum image).
template <int D>
bool inside_body(const scene::BodyConfig& b, const mpm::Vec<D>& x) {
  switch (b.shape) {
    case scene::BodyShape::Box:
      for (int a = 0; a < D; ++a)
        if (x[a] < b.min_m[a] || x[a] > b.max_m[a]) return false;
      return true;
    case scene::BodyShape::Disc:
    case scene::BodyShape::Wheel: {
      // In the plane of x and the last axis; 3D: `width` along y, the axle.
      if (D == 3 && std::fabs(x[1] - b.centre_m[1]) > 0.5 * b.width_m) return false;
      const double dx = x[0] - b.centre_m[0], dy = x[D - 1] - b.centre_m[D - 1];
      const double r2 = dx * dx + dy * dy;
      if (b.shape == scene::BodyShape::Disc) return r2 <= b.radius_m * b.radius_m;
      if (r2 <= b.hub_radius_m * b.hub_radius_m) return true;
      const double tip = b.hub_radius_m + b.paddle_length_m;
      for (int k = 0; k < b.paddles; ++k) {
        const double th = b.angle_deg * M_PI / 180.0 + 2.0 * M_PI * k / b.paddles;
        const double along = dx * std::cos(th) + dy * std::sin(th);
        const double across = -dx * std::sin(th) + dy * std::cos(th);
        if (along >= 0.0 && along <= tip && std::fabs(across) <= 0.5 * b.paddle_width_m) return true;
      }
      return false;
    }
    case scene::BodyShape::Cylinder: {
      if constexpr (D == 3) {
        const scene::CylinderFrame f = scene::cylinder_frame(b);
        double along = 0.0;
        for (int a = 0; a < 3; ++a) along += (x[a] - f.base_m[a]) * f.axis[a];
        if (along < 0.0 || along > b.length_m) return false;
        double off2 = 0.0;
        for (int a = 0; a < 3; ++a) {
          const double d = x[a] - f.base_m[a] - along * f.axis[a];
          off2 += d * d;
        }
        return off2 <= b.radius_m * b.radius_m;
      }
      return false;  // the configuration allows cylinders on 3D grids only
    }
  }
  return false;
}

/// Bounding box of a body's shape.
template <int D>
void body_bounds(const scene::BodyConfig& b, mpm::Vec<D>& lo, mpm::Vec<D>& hi) {
  if (b.shape == scene::BodyShape::Box) {
    for (int a = 0; a < D; ++a) {
      lo[a] = b.min_m[a];
      hi[a] = b.max_m[a];
    }
    return;
  }
  if (b.shape == scene::BodyShape::Cylinder) {
    const scene::CylinderFrame f = scene::cylinder_frame(b);
    for (int a = 0; a < D; ++a) {
      lo[a] = f.lo_m[a];
      hi[a] = f.hi_m[a];
    }
    return;
  }
  const double R = b.shape == scene::BodyShape::Disc ? b.radius_m : b.hub_radius_m + b.paddle_length_m;
  for (int a = 0; a < D; ++a) {
    const double half = D == 3 && a == 1 ? 0.5 * b.width_m : R;  // 3D: the width along the axle
    lo[a] = b.centre_m[a] - half;
    hi[a] = b.centre_m[a] + half;
  }
}

/// Velocity of body `bc` over the step [t, t + Δt]: its `velocity`, scaled for a prescribed body
/// with a `ramp_time` T by min(1, (t + Δt/2)/T) (the ramp at the step's midpoint, so the
/// displacement follows v_0 t²/(2T) exactly while it ramps up).
template <int NC>
mpm::Vec<NC> prescribed_velocity(const scene::BodyConfig& bc, double t_s, double dt_s) {
  mpm::Vec<NC> v;
  for (int c = 0; c < NC; ++c) v[c] = bc.velocity_m_s[c];
  if (bc.ramp_time_s > 0.0) v *= std::min(1.0, (t_s + 0.5 * dt_s) / bc.ramp_time_s);
  return v;
}

/// Add body `bc` to the solver: points on a lattice of points_per_cell per axis inside its
/// shape, its law (elastic) or rigid motion (prescribed, free), its contact pair with the
/// mixture and its motor. Returns {body index, contact pair index}.
template <class G>
std::pair<int, int> add_third_body(mpm::Solver<G>& solver, const scene::BodyConfig& bc, double h_m,
                                   const std::string& file) {
  constexpr int D = G::dim, NC = G::ncomp;
  mpm::Vec<D> lo, hi;
  body_bounds<D>(bc, lo, hi);
  const double dx = h_m / bc.points_per_cell;
  int n[D];
  std::int64_t total = 1;
  for (int a = 0; a < D; ++a) {
    n[a] = std::max(1, static_cast<int>(std::lround((hi[a] - lo[a]) / dx)));
    total *= n[a];
  }
  double cell = 1.0;
  for (int a = 0; a < D; ++a) cell *= dx;
  std::vector<mpm::Vec<D>> xs;
  std::vector<double> vols;
  double whole_volume = 0.0;
  for (std::int64_t q = 0; q < total; ++q) {
    std::int64_t rem = q;
    mpm::Vec<D> x;
    for (int a = D - 1; a >= 0; --a) {
      const auto i = rem % n[a];
      rem /= n[a];
      x[a] = lo[a] + (static_cast<double>(i) + 0.5) * dx;
    }
    if (!inside_body<D>(bc, x)) continue;
    const double v = G::measure(x, cell);
    whole_volume += std::is_same_v<G, mpm::Axisymmetric> ? 2.0 * M_PI * v : v;
    solver.grid().wrap(x);
    xs.push_back(x);
    vols.push_back(v);
  }
  if (xs.empty()) {
    throw InputError(
        fmt::format("{}: body '{}' got no material points: it must span at least one point spacing "
                    "(cell_size/points_per_cell = {} m)",
                    file, bc.name, dx));
  }
  const double density = bc.mass_kg ? *bc.mass_kg / whole_volume : bc.density_kg_m3;
  const mpm::Vec<NC> v0 = prescribed_velocity<NC>(bc, 0.0, 0.0);  // at rest when it ramps up
  const int index = solver.body_count();
  auto& body = solver.add_body(bc.name, mpm::Phase::Solid);
  if (bc.motion == scene::BodyMotionKind::Elastic) {
    material::LinearElasticParams ep;
    ep.youngs_modulus_Pa = bc.youngs_modulus_Pa;
    ep.poisson_ratio = bc.poisson_ratio;
    body.set_law(std::make_unique<mpm::LinearElasticLaw<G>>(ep));
  }
  for (std::size_t p = 0; p < xs.size(); ++p) body.add_point(xs[p], vols[p], density, v0);
  if (bc.motion == scene::BodyMotionKind::Prescribed) solver.set_prescribed_velocity(index, v0);
  if (bc.motion == scene::BodyMotionKind::Free) solver.set_free_rigid(index, v0);
  const int pair = solver.add_contact(index, bc.friction);
  if (bc.motor_omega_rad_s) solver.add_motor(index, *bc.motor_omega_rad_s, bc.motor_gain);
  return {index, pair};
}

}  // namespace oobleck::scene
