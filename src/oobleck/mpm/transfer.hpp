#pragma once
// Grid fields and the particle↔grid kernels of one body (model.md §6 steps 2, 5, 6, 7).
// Free functions over the body's arrays, the shape cache and the body's grid field.
//
// Race-free, deterministic scatter: each OpenMP thread accumulates P2G into its own copy of the
// nodal arrays (thread 0 into the field itself) over a static partition of the points; the copies
// are then summed node by node in thread order. For a fixed thread count the result is bitwise
// reproducible.
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/shape.hpp"

namespace oobleck::mpm {

/// Velocity transfer of G2P: FLIP/PIC blend (α = flip_fraction; 1 = pure FLIP, 0 = PIC) or APIC.
enum class Transfer { FlipPicBlend, Apic };

/// Nodal fields of one body on the grid.
template <class G>
struct GridField {
  static constexpr int NC = G::ncomp;
  std::vector<double> mass_kg;
  std::vector<Vec<NC>> momentum;      ///< [kg m/s] after P2G
  std::vector<Vec<NC>> force_N;       ///< internal + body forces (+ coupling) [N]
  std::vector<Vec<NC>> velocity_old;  ///< momentum/mass before the force update [m/s]
  std::vector<Vec<NC>> velocity;      ///< updated velocity after boundary conditions [m/s]
  // Fluid phase only (P2G with `split_pressure`): ∑_p V_p p_p ∇N_ip [N] (split by porosity, E28)
  // and the nodal mixture volume ∑_p N_ip V_p [m^D].
  std::vector<Vec<NC>> pressure_force_N;
  std::vector<double> volume_m3;
  // Friction walls: real normal momentum [kg m/s], force [N] and mass difference [kg] of the
  // wall-layer node pairs, recorded when folding (boundary.hpp).
  std::vector<double> wall_normal_momentum, wall_normal_force, wall_mass_difference;
  // Per-thread scatter copies for threads 1 … T−1 (thread 0 writes into the arrays above).
  std::vector<std::vector<double>> t_mass, t_volume;
  std::vector<std::vector<Vec<NC>>> t_momentum, t_force, t_pressure;

  void resize(int nodes, int threads) {
    const auto n = static_cast<std::size_t>(nodes);
    mass_kg.assign(n, 0.0);
    momentum.assign(n, Vec<NC>::Zero());
    force_N.assign(n, Vec<NC>::Zero());
    velocity_old.assign(n, Vec<NC>::Zero());
    velocity.assign(n, Vec<NC>::Zero());
    pressure_force_N.assign(n, Vec<NC>::Zero());
    volume_m3.assign(n, 0.0);
    wall_normal_momentum.assign(n, 0.0);
    wall_normal_force.assign(n, 0.0);
    wall_mass_difference.assign(n, 0.0);
    const auto extra = static_cast<std::size_t>(threads > 1 ? threads - 1 : 0);
    t_mass.assign(extra, std::vector<double>(n, 0.0));
    t_momentum.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_force.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_pressure.assign(extra, std::vector<Vec<NC>>(n, Vec<NC>::Zero()));
    t_volume.assign(extra, std::vector<double>(n, 0.0));
  }
  int nodes() const { return static_cast<int>(mass_kg.size()); }
  int max_threads() const { return static_cast<int>(t_mass.size()) + 1; }
};

/// P2G (model.md §6 step 2): nodal mass, momentum (with the APIC affine term when `apic`),
/// internal force f_i = −∑_p V_p σ_p ∇N_ip, and external point loads ∑_p N_ip f_ext,p. K = local nodes per point (support^dim).
/// With `split_pressure` (the fluid phase) the stress is split as σ = τ − p 1 (p = −tr σ/3): the
/// internal force gets only τ, the pressure part ∑ V_p p_p ∇N_ip goes to `pressure_force_N` for the
/// buoyancy split (E28), and the nodal mixture volume ∑ N_ip V_p is accumulated.
template <class G, int K>
void particles_to_grid(const Body<G>& body, const ShapeCache<G::dim>& cache, GridField<G>& field, bool apic,
                       bool split_pressure = false) {
  constexpr int D = G::dim, NC = G::ncomp;
  const std::int64_t np = body.size();
  const int nn = field.nodes();
  int team = 1;
#pragma omp parallel num_threads(field.max_threads())
  {
    const int t = omp_get_thread_num();
#pragma omp single
    team = omp_get_num_threads();
    double* m = t == 0 ? field.mass_kg.data() : field.t_mass[t - 1].data();
    Vec<NC>* mv = t == 0 ? field.momentum.data() : field.t_momentum[t - 1].data();
    Vec<NC>* f = t == 0 ? field.force_N.data() : field.t_force[t - 1].data();
    Vec<NC>* fp = t == 0 ? field.pressure_force_N.data() : field.t_pressure[t - 1].data();
    double* vol = t == 0 ? field.volume_m3.data() : field.t_volume[t - 1].data();
    for (int i = 0; i < nn; ++i) {
      m[i] = 0.0;
      mv[i].setZero();
      f[i].setZero();
    }
    if (split_pressure) {
      for (int i = 0; i < nn; ++i) {
        fp[i].setZero();
        vol[i] = 0.0;
      }
    }
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < np; ++p) {
      const double mp = body.mass_kg[p], Vp = body.volume_m3[p];
      const Vec<NC> vp = body.v_m_s[p];
      const Mat<NC, D> Cp = body.C_1_s[p];
      Mat3 sig = body.stress_Pa[p];
      double Vpres = 0.0;
      if (split_pressure) {
        const double pres = -sig.trace() / 3.0;
        sig.diagonal().array() += pres;  // τ = σ + p 1
        Vpres = Vp * pres;
      }
      const Mat<NC, D> Vsig = Vp * sig.template topLeftCorner<NC, D>();
      // Axisymmetric: hoop and inertial terms, applied with weight N_ip (zero-cost otherwise).
      Vec<NC> f_point = body.f_ext_N[p], fp_point = Vec<NC>::Zero();  // external point load
      if constexpr (G::has_hoop_terms) {
        const Vec<D>& xp = body.x_m[p];
        f_point += G::hoop_force(sig, xp, Vp) + mp * G::inertial_acceleration(xp, vp);
        if (split_pressure) fp_point = G::hoop_force(-(Vpres / Vp) * Mat3::Identity(), xp, Vp);
      }
      const std::int64_t o = p * K;
      for (int k = 0; k < K; ++k) {
        const int i = cache.node[o + k];
        const double w = cache.w[o + k];
        m[i] += w * mp;
        if (apic) {
          mv[i] += (w * mp) * (vp + Cp * cache.offset[o + k]);
        } else {
          mv[i] += (w * mp) * vp;
        }
        f[i] -= Vsig * cache.grad[o + k];
        f[i] += w * f_point;
        if (split_pressure) {
          fp[i].template head<D>() += Vpres * cache.grad[o + k];
          if constexpr (G::has_hoop_terms) fp[i] += w * fp_point;
          vol[i] += w * Vp;
        }
      }
    }
  }
  if (team > 1) {
#pragma omp parallel for schedule(static) num_threads(team)
    for (int i = 0; i < nn; ++i) {
      for (int t = 1; t < team; ++t) {
        field.mass_kg[i] += field.t_mass[t - 1][i];
        field.momentum[i] += field.t_momentum[t - 1][i];
        field.force_N[i] += field.t_force[t - 1][i];
        if (split_pressure) {
          field.pressure_force_N[i] += field.t_pressure[t - 1][i];
          field.volume_m3[i] += field.t_volume[t - 1][i];
        }
      }
    }
  }
}

/// Body loads (model.md §6 step 3): gravity f_i += m_i g.
template <class G>
void add_gravity(GridField<G>& field, const Vec<G::ncomp>& g_m_s2) {
  const int nn = field.nodes();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nn; ++i) field.force_N[i] += field.mass_kg[i] * g_m_s2;
}

/// Grid update (model.md §6 step 5): v_old = mv/m, v = (mv + Δt f)/m on nodes with mass.
template <class G>
void update_grid_velocity(GridField<G>& field, double dt_s) {
  const int nn = field.nodes();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nn; ++i) {
    const double m = field.mass_kg[i];
    if (m > 0.0) {
      field.velocity_old[i] = field.momentum[i] / m;
      field.velocity[i] = (field.momentum[i] + dt_s * field.force_N[i]) / m;
    } else {
      field.velocity_old[i].setZero();
      field.velocity[i].setZero();
    }
  }
}

/// G2P (model.md §6 step 6): positions x ← x + Δt ∑N v_i (wrapped on periodic axes), velocities by
/// the FLIP/PIC blend v ← α (v + ∑N (v_i − v_i^old)) + (1 − α) ∑N v_i or by APIC (v ← ∑N v_i,
/// C ← B D⁻¹, or ∑ v_i ∇Nᵀ for linear weights), and the velocity gradient L = ∑ v_i ∇Nᵀ (plus
/// geometry terms). Also the volume update V ← V exp(Δt tr L) (step 7), fused into the same loop.
///
/// For the fluid phase of a mixture, `porosity` (n_i) and `mixture_flux` (q_i = (1−n_i) v^s_i +
/// n_i v^f_i) are given; the point's φ = 1 − ∑N n_i and div q = ∑ q_i·∇N_ip are stored in
/// body.phi and body.div_q_1_s for the fluid law (E25, E27).
template <class G, int K>
void grid_to_particles(Body<G>& body, const ShapeCache<G::dim>& cache, const GridField<G>& field,
                       const Grid<G::dim>& grid, Transfer transfer, double flip_fraction, double dt_s,
                       const double* porosity = nullptr, const Vec<G::ncomp>* mixture_flux = nullptr) {
  constexpr int D = G::dim, NC = G::ncomp;
  const std::int64_t np = body.size();
  const bool apic = transfer == Transfer::Apic;
  const bool by_grad = cache.apic_by_gradient;
  const double alpha = flip_fraction;
#pragma omp parallel for schedule(static)
  for (std::int64_t p = 0; p < np; ++p) {
    Vec<NC> v_pic = Vec<NC>::Zero(), dv = Vec<NC>::Zero();
    Mat<NC, D> grad_v = Mat<NC, D>::Zero(), B = Mat<NC, D>::Zero();
    double n_p = 0.0, div_q = 0.0;
    Vec<NC> q_p = Vec<NC>::Zero();
    const std::int64_t o = p * K;
    for (int k = 0; k < K; ++k) {
      const int i = cache.node[o + k];
      const double w = cache.w[o + k];
      const Vec<NC>& vi = field.velocity[i];
      if (porosity) {
        n_p += w * porosity[i];
        div_q += mixture_flux[i].template head<D>().dot(cache.grad[o + k]);
        if constexpr (G::has_hoop_terms) q_p += w * mixture_flux[i];
      }
      v_pic += w * vi;
      grad_v += vi * cache.grad[o + k].transpose();
      if (apic) {
        B += (w * vi) * cache.offset[o + k].transpose();
      } else {
        dv += w * (vi - field.velocity_old[i]);
      }
    }
    const Vec<D> x_old = body.x_m[p];
    Vec<D> x = x_old + dt_s * v_pic.template head<D>();
    grid.wrap(x);
    body.x_m[p] = x;
    if (apic) {
      body.v_m_s[p] = v_pic;
      body.C_1_s[p] = by_grad ? grad_v : Mat<NC, D>(B * cache.inv_D[p].asDiagonal());
    } else {
      body.v_m_s[p] = alpha * (body.v_m_s[p] + dv) + (1.0 - alpha) * v_pic;
    }
    if (porosity) {
      if constexpr (G::has_hoop_terms) div_q += G::div_extra(q_p, x_old);
      body.phi[p] = 1.0 - n_p;
      body.div_q_1_s[p] = div_q;
    }
    // L at the start-of-step position from the grid velocity field (hoop entries use Σ N v_i).
    const Mat3 L = G::velocity_gradient(grad_v, x_old, v_pic);
    body.L_1_s[p] = L;
    body.volume_m3[p] *= std::exp(dt_s * L.trace());  // step 7: V ← V exp(Δt tr L)
  }
}

}  // namespace oobleck::mpm
