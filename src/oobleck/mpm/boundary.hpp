#pragma once
// Walls as mirror planes (docs/mpm.md, "The step" phases 3 and 5; "Grid, shape functions and boundary conventions").
//
// Convention (docs/mpm.md): a wall lies on the face node plane of a non-periodic axis (logical
// index 0 or cells). The shape functions are not modified near it; instead the two ghost layers
// beyond it are *images* of the interior nodes, as if the material were reflected across the
// wall (image-particle method):
//   slip (frictionless):  normal component odd, tangential components even;
//   no-slip:              all components odd (v_image = −v);
//   prescribed velocity U: all components odd about U (v_image = 2U − v);
//   axis (r = 0, axisymmetric): v_r and v_θ odd, v_z even (masses per radian ∝ |r| mirror evenly).
// Two calls implement it:
//   fold_wall_images()            after P2G + loads: what the real points scattered to a ghost node
//                                 is added, reflected, to its interior mirror node (the wall node
//                                 receives its own reflection), so interior nodes carry mass,
//                                 momentum, force (and the fluid's pressure force and mixture
//                                 volume) of points *and* their images;
//   apply_boundary_conditions()   after the grid update: the wall node's constrained components
//                                 are set exactly, and every ghost node's velocity (and FLIP's
//                                 v_old) is set to the reflection of its mirror.
// With B-splines this keeps the interior's second-order accuracy up to the wall (a one-sided
// "ghost nodes = 0" treatment would add pinned mass and drop to low order). With linear weights it
// reduces to the usual nodal condition. Faces are processed axis by axis, so corners get the
// composition of the two reflections. An `Open` face imposes nothing (ghost nodes are plain nodes;
// points may move at most one cell outside the domain).
#include <algorithm>
#include <array>

#include "oobleck/mpm/geometry.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

enum class WallType {
  Open,        ///< nothing imposed
  NoSlip,      ///< v = 0
  Slip,        ///< frictionless, bilateral: normal component v_n = U_n (tangential free)
  Prescribed,  ///< every component v = U (moving wall, driven bob, …)
  Axis,        ///< symmetry axis r = 0 (axisymmetric): v_r = v_θ = 0, v_z free
  Friction,    ///< bilateral normal as Slip, Coulomb friction |Δv_t| ≤ μ Δv_n on the tangential
               ///< velocity relative to the wall (velocity_m_s), from the wall's normal impulse
};

struct FaceCondition {
  WallType type = WallType::Open;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();  ///< wall velocity U (components ≥ ncomp ignored)
  double friction_coefficient = 0.0;                       ///< μ of a Friction wall [-]
};

/// Face index: 2a for the lower face of axis a, 2a + 1 for the upper face.
template <int D>
using BoundaryConditions = std::array<FaceCondition, 2 * D>;

namespace detail {
/// Reflection signs s_c (+1 even, −1 odd) of a face on axis a and the wall velocity U.
template <int NC, int D>
void reflection(const FaceCondition& c, int a, Vec<NC>& s, Vec<NC>& U) {
  s.setConstant(-1.0);
  U.setZero();
  if (c.type == WallType::Axis) {  // mirror through the axis: v_r and v_θ odd, v_z even
    s.setConstant(1.0);
    s[a] = -1.0;
    if constexpr (NC > D) s[NC - 1] = -1.0;
  } else if (c.type == WallType::Slip || c.type == WallType::Friction) {
    s.setConstant(1.0);
    s[a] = -1.0;
    U[a] = c.velocity_m_s[a];
  } else if (c.type == WallType::Prescribed) {
    for (int k = 0; k < NC; ++k) U[k] = c.velocity_m_s[k];
  }
}

/// Calls f(node, mirror_node, depth) for every node of a face's layers: depth 0 is the wall node
/// (mirror = itself), depth j ≥ 1 the ghost node j layers outside (mirror = j layers inside).
template <int D, class F>
void for_face_layers(const Grid<D>& grid, int a, bool upper, F&& f) {
  // Visit only the slab of the face: depth 0 … kGhost along axis a, every node of the other axes.
  const int N = grid.cells[a], st = grid.stride(a);
  const int layers = Grid<D>::kGhost + 1;
  const int outer = grid.node_count() / (grid.nodes(a) * st);  // product of the slower axes
  for (int o = 0; o < outer; ++o) {
    for (int depth = 0; depth < layers; ++depth) {
      const int i = upper ? N + depth : -depth;  // logical index of the layer
      const int mirror_i = upper ? N - depth : depth;
      const int s_i = grid.storage_index(a, i), s_m = grid.storage_index(a, mirror_i);
      const int base = o * grid.nodes(a) * st;
      for (int r = 0; r < st; ++r) f(base + s_i * st + r, base + s_m * st + r, depth);
    }
  }
}
}  // namespace detail

/// The same folding for a nodal gradient of a scalar that walls mirror evenly (contact's mass
/// gradients): the image's gradient has its component normal to the wall reversed, so the wall
/// node keeps its tangential part (doubled, as its mass) and loses its normal one; ghost j's image
/// is added to mirror j. Open faces and periodic axes are left alone.
template <int D>
void fold_wall_gradient(const Grid<D>& grid, const BoundaryConditions<D>& bc, std::vector<Vec<D>>& grad) {
  for (int a = 0; a < D; ++a) {
    if (grid.periodic[a]) continue;
    for (int side = 0; side < 2; ++side) {
      if (bc[2 * a + side].type == WallType::Open) continue;
      detail::for_face_layers(grid, a, side == 1, [&](int ghost, int mirror, int depth) {
        Vec<D> img = grad[ghost];
        img[a] = -img[a];
        if (depth == 0)
          grad[ghost] += img;
        else
          grad[mirror] += img;
      });
    }
  }
}

/// Add the reflected ghost-node contributions onto their interior mirrors (see header).
template <class G>
void fold_wall_images(const Grid<G::dim>& grid, const BoundaryConditions<G::dim>& bc, GridField<G>& field) {
  constexpr int D = G::dim, NC = G::ncomp;
  for (int a = 0; a < D; ++a) {
    if (grid.periodic[a]) continue;
    for (int side = 0; side < 2; ++side) {
      const FaceCondition& c = bc[2 * a + side];
      if (c.type == WallType::Open) continue;
      Vec<NC> s, U;
      detail::reflection<NC, D>(c, a, s, U);
      const Vec<NC> one_minus_s = Vec<NC>::Ones() - s;
      // Targets (depth 0 … ghost) and sources (ghost nodes and the wall node) are read before
      // written: the wall node reads itself, mirror j ≥ 1 reads ghost j only.
      detail::for_face_layers(grid, a, side == 1, [&](int ghost, int mirror, int depth) {
        const double m = field.mass_kg[ghost];
        const Vec<NC> p = field.momentum[ghost], f = field.force_N[ghost];
        const Vec<NC> p_img = s.cwiseProduct(p) + m * one_minus_s.cwiseProduct(U);
        const Vec<NC> f_img = s.cwiseProduct(f);
        const Vec<NC> fp_img = s.cwiseProduct(field.pressure_force_N[ghost]);
        const double V = field.volume_m3[ghost];
        if (c.type == WallType::Friction) {
          // Record the *real* (unfolded) normal momentum, force and mass of the node pair
          // (mirror + its ghost; the wall node alone) along the inward normal; the wall's normal
          // impulse follows after the grid update (apply_boundary_conditions).
          const double n_in = side == 0 ? 1.0 : -1.0;
          if (depth == 0) {
            field.wall_normal_momentum[ghost] = n_in * p[a];
            field.wall_normal_force[ghost] = n_in * f[a];
            field.wall_mass_difference[ghost] = m;
          } else {
            field.wall_normal_momentum[mirror] = n_in * (field.momentum[mirror][a] + p[a]);
            field.wall_normal_force[mirror] = n_in * (field.force_N[mirror][a] + f[a]);
            field.wall_mass_difference[mirror] = field.mass_kg[mirror] - m;
          }
        }
        if (depth == 0) {
          field.mass_kg[ghost] = 2.0 * m;
          field.momentum[ghost] = p + p_img;
          field.force_N[ghost] = f + f_img;
          field.pressure_force_N[ghost] += fp_img;
          field.volume_m3[ghost] = 2.0 * V;
        } else {
          field.mass_kg[mirror] += m;
          field.momentum[mirror] += p_img;
          field.force_N[mirror] += f_img;
          field.pressure_force_N[mirror] += fp_img;
          field.volume_m3[mirror] += V;
        }
      });
    }
  }
}

/// Impose the wall conditions on the updated nodal velocities and set the ghost nodes' velocities
/// to the reflections of their mirrors (see header). Friction walls: at every node of the face
/// layers, the normal impulse the wall gave the real mass of the node (and of its ghost, which
/// moves with it), J_n = (m_node − m_ghost) v_n − (P_n + Δt F_n) from the unfolded real normal
/// momentum P_n and force F_n recorded by fold_wall_images (effective stress and gravity; the
/// pore-pressure split is not included, so friction follows the effective normal stress), limits
/// the tangential slip: |v_t − U_t| ← max(0, |v_t − U_t| − μ J_n/m_real) when J_n > 0.
template <class G>
void apply_boundary_conditions(const Grid<G::dim>& grid, const BoundaryConditions<G::dim>& bc, GridField<G>& field,
                               double dt_s = 0.0) {
  constexpr int D = G::dim, NC = G::ncomp;
  for (int a = 0; a < D; ++a) {
    if (grid.periodic[a]) continue;
    for (int side = 0; side < 2; ++side) {
      const FaceCondition& c = bc[2 * a + side];
      if (c.type == WallType::Open) continue;
      Vec<NC> s, U;
      detail::reflection<NC, D>(c, a, s, U);
      const Vec<NC> one_minus_s = Vec<NC>::Ones() - s;
      // Wall node first (its odd components are fixed to U), then the ghosts from their mirrors.
      detail::for_face_layers(grid, a, side == 1, [&](int node, int, int depth) {
        if (depth != 0) return;
        for (int k = 0; k < NC; ++k) {
          if (s[k] < 0.0) {
            field.velocity[node][k] = U[k];
            field.velocity_old[node][k] = U[k];
          }
        }
      });
      if (c.type == WallType::Friction) {
        const double mu = c.friction_coefficient;
        detail::for_face_layers(grid, a, side == 1, [&](int node, int mirror, int depth) {
          const int t = depth == 0 ? node : mirror;
          const double n_in = side == 0 ? 1.0 : -1.0;
          const double Jn = field.wall_mass_difference[t] * n_in * field.velocity[t][a] -
                            (field.wall_normal_momentum[t] + dt_s * field.wall_normal_force[t]);
          // Real mass that feels this node's tangential change: the wall node carries its own
          // image (half of its folded mass); a mirror node's velocity is also its ghost's, so its
          // whole folded mass is real.
          const double m = depth == 0 ? 0.5 * field.mass_kg[t] : field.mass_kg[t];
          if (!(Jn > 0.0 && m > 0.0)) return;
          Vec<NC> vt = Vec<NC>::Zero();
          for (int k = 0; k < NC; ++k)
            if (k != a) vt[k] = field.velocity[t][k] - c.velocity_m_s[k];
          const double speed = vt.norm();
          if (speed <= 0.0) return;
          const double scale = std::max(0.0, 1.0 - mu * Jn / (m * speed));
          field.velocity[t] -= (1.0 - scale) * vt;
        });
      }
      detail::for_face_layers(grid, a, side == 1, [&](int ghost, int mirror, int depth) {
        if (depth == 0) return;
        field.velocity[ghost] = s.cwiseProduct(field.velocity[mirror]) + one_minus_s.cwiseProduct(U);
        field.velocity_old[ghost] = s.cwiseProduct(field.velocity_old[mirror]) + one_minus_s.cwiseProduct(U);
        field.mass_kg[ghost] = field.mass_kg[mirror];
      });
    }
  }
}

}  // namespace oobleck::mpm
