#pragma once
// The solver's state (docs/mpm.md, "The step"): the options, the grid, the bodies and their nodal
// fields, the third bodies and contact pairs, the decomposition, and the scratch of the phases.
// Solver<G> (solver.hpp) owns one SolverState and is its public interface; the phases
// (mpm/phases/*.hpp) are functions of (team, state) and the step (step.hpp) calls them in order.
// The phases are declared inline: GCC's inliner gives inline functions its larger limits (the
// node kernels, e.g. predict_node, stay inlined into the grid pass).
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "oobleck/material/drag.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/contact.hpp"
#include "oobleck/mpm/decomposition.hpp"
#include "oobleck/mpm/fields.hpp"
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

/// A box around every contact solid's points (over every rank), grown by two kernel widths:
/// the mixture's points that reach the nodes where a solid has mass lie inside.
template <int D>
struct ContactBox {
  bool any = false;
  Vec<D> centre = Vec<D>::Zero(), half = Vec<D>::Zero();
};

template <class G>
struct SolverState {
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;

  SolverState(const Grid<D>& g, const SolverOptions<G>& o) : grid(g), opt(o) {}

  Grid<D> grid;  ///< the grid this rank solves on (its block's local grid when decomposed)
  SolverOptions<G> opt;
  std::unique_ptr<Decomposition<D>> dec;  ///< decomposed runs only
  std::unique_ptr<Halo<D>> halo;
  std::int64_t points_migrated = 0;
  BoundaryConditions<D> bc{};
  std::vector<std::unique_ptr<Body<G>>> bodies;
  std::vector<RigidMotion<G>> rigid;      ///< per body: deformable, prescribed or free rigid
  std::vector<ContactPair<G>> contacts;   ///< solid–mixture contact pairs (docs/contact.md)
  std::vector<Motor<G>> motors;           ///< angular-velocity motors (docs/contact.md, wheel)
  std::vector<double> contact_weight;     ///< per node: weight in the body impulse sums
  std::vector<double> node_measure;       ///< per node: h^D (per radian h² r) for the overlap test
  std::vector<double> mixture_volume;     ///< nodal grains volume when there is no fluid body
  std::vector<Vec<D>> mixture_gradient;   ///< nodal mixture mass gradient (combined normals)
  bool mixture_volume_scattered = false;  ///< mixture_volume holds this step's grains volume
  ContactBox<D> solids_box;               ///< the mixture's points near the contact solids (this step)
  std::vector<double> pair_sums;          ///< every pair's PairSums share, pair after pair (this step)
  std::vector<ShapeCache<D>> caches;
  std::vector<std::int64_t> non_finite_kinematics;  ///< per body, from the last G2P
  std::vector<GridField<G>> fields;
  int threads = 1;
  int grains = -1, fluid = -1;
  StepTimings timings;
  /// Scratch of the grid pass (refilled per step): the deformable solids' fields.
  std::vector<GridField<G>*> solids;
  std::vector<double> porosity;  ///< nodal porosity n_i of the mixture
  std::vector<Vec<NC>> flux;     ///< nodal mixture volume flux q_i
  // Scratch of the points' phases (refilled per step): the G2P tasks of the deformable bodies and
  // their body indices; bodies with a law, costliest first; per body the lowest index of a
  // non-finite law result; the counters of the threads' shares.
  std::vector<G2PTask<G>> g2p_tasks;
  std::vector<int> g2p_bodies;
  std::vector<std::int64_t> p2g_outside;  ///< per body: points whose support left the grid (P2G)
  std::vector<int> law_bodies;
  std::vector<std::int64_t> law_first_bad;
  parallel::StealingShares shares;         ///< the G2P tasks' and the law bodies' shares
  std::uint64_t swirl = 0;                 ///< bit k: G2P body k has θ velocity (axisymmetric, phase 5)
  std::vector<double> mass_floor_density;  ///< per body: linear_mass_floor · ρ̄_b (linear kernels; empty: off)
  std::vector<double> mass_floor_measure;  ///< per node: V_i of the mass floor
  double time_s = 0.0;
  std::int64_t steps = 0;

  int body_count() const { return static_cast<int>(bodies.size()); }
  /// The whole domain's grid: `grid` on one rank, the decomposition's global grid otherwise.
  const Grid<D>& global_grid() const { return dec ? dec->global() : grid; }
  /// Nodes of this rank's grid.
  int node_count() const { return grid.node_count(); }

  /// f() timed as the step's communication (a decomposed run's exchanges).
  template <class F>
  void timed_exchange(F&& f) {
    const double t0 = parallel::wall_time();
    f();
    timings.communication += parallel::wall_time() - t0;
  }

  /// Every nodal array the step keeps, with how a decomposed run's halo treats it (fields.hpp
  /// HaloRule; the exchanges' lists are taken from here, in this order): each body's field, each
  /// contact pair's sums, then the mixture's arrays.
  NodalFieldList nodal_fields() {
    NodalFieldList list;
    for (int b = 0; b < body_count(); ++b) fields[b].declare_nodal_fields(list, b == fluid);
    for (auto& c : contacts) c.declare_nodal_fields(list);
    list.add("mixture_gradient", mixture_gradient, HaloRule::sum_before_contact);
    list.add("mixture_volume", mixture_volume,
             mixture_volume_scattered ? HaloRule::sum_before_contact : HaloRule::none);
    if (fluid >= 0) list.add("porosity", porosity, HaloRule::copy_before_flux);
    list.add("flux", flux, HaloRule::none);
    return list;
  }
};

}  // namespace oobleck::mpm
