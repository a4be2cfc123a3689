#pragma once
// Phase 3, the grid pass (docs/mpm.md, "The step"): the grid update of every body, with the
// phase coupling for the mixture (E28–E29 of docs/equations.md). Its parts are node-local, so they
// run in one pass over the nodes (couple_nodes); step.hpp holds its region.
//
// Before the pass over the nodes, body by body (each touches only its own field, so the bodies
// run in parallel): the walls' ghost contributions folded onto their mirrors (fold_wall_images)
// and a rigid body's nodal velocities (predict_rigid, which reads the folded masses).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "oobleck/core/comm.hpp"
#include "oobleck/material/drag.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/parallel.hpp"
#include "oobleck/mpm/solver_state.hpp"
#include "oobleck/numerics/vector_math.hpp"

namespace oobleck::mpm::phases {

/// The linear kernels' mass floor (SolverOptions::linear_mass_floor): per body floor · Σ m_p / Σ V0_p
/// (over every rank), per node the measure V_i; once, at the first step (or when bodies change).
template <class G>
inline void prepare_mass_floor(SolverState<G>& s) {
  if (s.mass_floor_density.size() == s.bodies.size()) return;
  std::vector<double> sums(2 * s.bodies.size(), 0.0);
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    for (std::int64_t p = 0; p < s.bodies[b]->size(); ++p) {
      sums[2 * b] += s.bodies[b]->mass_kg[p];
      sums[2 * b + 1] += s.bodies[b]->volume0_m3[p];
    }
  if (s.dec) comm::sum_ordered(sums);
  s.mass_floor_density.assign(s.bodies.size(), 0.0);
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    if (!s.rigid[b].rigid() && sums[2 * b + 1] > 0.0)
      s.mass_floor_density[b] = s.opt.linear_mass_floor * sums[2 * b] / sums[2 * b + 1];
  const int nn = s.grid.node_count();
  s.mass_floor_measure.resize(static_cast<std::size_t>(nn));
  const double h = s.grid.h_m, cell = s.grid.cell_volume();
  for (int i = 0; i < nn; ++i) {
    Vec<G::dim> x = s.grid.node_position(i);
    if constexpr (G::has_hoop_terms) x[0] = std::fabs(x[0]);
    s.mass_floor_measure[i] = G::has_hoop_terms ? std::max(G::measure(x, cell), 0.125 * cell * h) : cell;
  }
}

/// Before the region: the deformable solids whose predictions the pass over the nodes makes (the
/// wheel; without a fluid body, the grains too), and the nodal porosity's size (mixture).
template <class G>
inline void prepare_grid_pass(SolverState<G>& s) {
  s.solids.clear();
  for (int b = 0; b < s.body_count(); ++b)
    if (!s.rigid[b].rigid() && b != s.grains && b != s.fluid) s.solids.push_back(&s.fields[b]);
  if (s.fluid < 0) {
    if (s.grains >= 0) s.solids.push_back(&s.fields[s.grains]);
  } else {
    s.porosity.resize(static_cast<std::size_t>(s.grid.node_count()));
  }
}

/// Body b: the walls' ghost contributions folded onto their mirrors, and a rigid body's nodal
/// velocities predicted from the folded masses.
template <class G>
inline void fold_and_predict(SolverState<G>& s, int b) {
  fold_wall_images<G>(s.grid, s.bc, s.fields[b]);
  if (s.rigid[b].rigid()) predict_rigid(s.rigid[b], s.fields[b], s.opt.gravity_m_s2, s.opt.dt_s);
}

/// Step 3(b) at node i: v_old = mv/m, v = (mv + Δt f)/m; with the linear kernels' mass floor
/// (SolverOptions::linear_mass_floor) v = mv/m + Δt f/max(m, floor).
template <class G>
inline void predict_node(const SolverState<G>& s, GridField<G>& field, int i, double dt) {
  const double m = field.mass_kg[i];
  if (m > 0.0) {
    field.velocity_old[i] = field.momentum[i] / m;
    const double floor_density = s.mass_floor_density.empty() ? 0.0 : s.mass_floor_density[&field - s.fields.data()];
    const double m_floor = floor_density * (floor_density > 0.0 ? s.mass_floor_measure[i] : 0.0);
    if (m < m_floor)
      field.velocity[i] = field.velocity_old[i] + (dt / m_floor) * field.force_N[i];
    else
      field.velocity[i] = (field.momentum[i] + dt * field.force_N[i]) / m;
  } else {
    field.velocity_old[i].setZero();
    field.velocity[i].setZero();
  }
}

/// Without a fluid body, every thread: the predictions of the solids (prepare_grid_pass) over its
/// share of the nodes.
template <class G>
inline void predict_solids(const parallel::Team& team, SolverState<G>& s) {
  const double dt = s.opt.dt_s;
  const parallel::Range r = team.share(s.grid.node_count());
  for (GridField<G>* sf : s.solids)
    for (auto i = static_cast<int>(r.begin); i < static_cast<int>(r.end); ++i) predict_node(s, *sf, i, dt);
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
template <class G>
inline void couple_nodes(SolverState<G>& st, int i0, int count) {
  constexpr int NC = G::ncomp;
  constexpr int kBlock = numerics::kMathBlock;
  const double dt = st.opt.dt_s;
  GridField<G>& s = st.fields[st.grains >= 0 ? st.grains : st.fluid];
  GridField<G>& f = st.fields[st.fluid];
  const bool grains = st.grains >= 0;
  const auto& mx = st.opt.mixture;
  double phi_b[kBlock], Re_b[kBlock], C_V[kBlock];
  bool drag[kBlock];
  for (int j = 0; j < kBlock; ++j) {
    phi_b[j] = 0.5;  // (a harmless stand-in for nodes without drag)
    Re_b[j] = 0.0;
    drag[j] = false;
  }
  for (GridField<G>* sf : st.solids)
    for (int j = 0; j < count; ++j) predict_node(st, *sf, i0 + j, dt);
  for (int j = 0; j < count; ++j) {
    const int i = i0 + j;
    const double V = f.volume_m3[i], ms = grains ? s.mass_kg[i] : 0.0, mf = f.mass_kg[i];
    double n = 1.0;
    if (V > 0.0 && ms > 0.0) n = std::clamp(1.0 - ms / (mx.rho_s_kg_m3 * V), mx.min_porosity, 1.0);
    st.porosity[i] = n;
    const Vec<NC> Fp = f.pressure_force_N[i] - V * mx.background_pressure_gradient_Pa_m;
    f.force_N[i] += n * Fp;
    predict_node(st, f, i, dt);
    if (!grains) continue;
    s.force_N[i] += (1.0 - n) * Fp;
    predict_node(st, s, i, dt);
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

/// With a fluid body, every thread: blocks of numerics::kMathBlock nodes of couple_nodes, handed
/// out dynamically (each node is independent: the same values whichever thread computes it; a
/// thread that ran a side task joins when it is done).
template <class G>
inline void couple_node_blocks(const parallel::Team& team, SolverState<G>& s) {
  constexpr int kBlock = numerics::kMathBlock;
  const int nn = s.grid.node_count();
  const int blocks = (nn + kBlock - 1) / kBlock;
  team.dynamic(blocks, 4, [&](std::int64_t blk) {
    const int i0 = static_cast<int>(blk) * kBlock;
    couple_nodes(s, i0, std::min(kBlock, nn - i0));
  });
}

}  // namespace oobleck::mpm::phases
