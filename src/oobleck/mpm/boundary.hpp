#pragma once
// Boundary conditions on nodal velocities (model.md §6 step 4, §7 walls).
//
// Each non-periodic face carries one condition. It acts on every node of the face layer and of
// the ghost layers beyond it (logical index ≤ 0 on a lower face, ≥ cells on an upper face), after
// the grid update, so the FLIP increment and the APIC/PIC velocity both see it. Faces are applied
// in order (axis 0 lower, axis 0 upper, axis 1 lower, …): at edges and corners the later face wins
// for the components it sets.
#include <array>

#include "oobleck/mpm/geometry.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

enum class WallType {
  Open,        ///< nothing imposed (points must stay within one cell of the domain)
  NoSlip,      ///< v = 0
  Slip,        ///< frictionless, bilateral: normal component v_n = wall normal velocity (0)
  Prescribed,  ///< every component v = velocity_m_s (moving wall, driven bob, …)
};

struct FaceCondition {
  WallType type = WallType::Open;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();  ///< wall velocity (components ≥ ncomp ignored)
};

/// Face index: 2a for the lower face of axis a, 2a + 1 for the upper face.
template <int D>
using BoundaryConditions = std::array<FaceCondition, 2 * D>;

template <class G>
void apply_boundary_conditions(const Grid<G::dim>& grid, const BoundaryConditions<G::dim>& bc,
                               GridField<G>& field) {
  constexpr int D = G::dim, NC = G::ncomp;
  const int nn = field.nodes();
#pragma omp parallel for schedule(static)
  for (int n = 0; n < nn; ++n) {
    const auto s = grid.unflatten(n);
    for (int a = 0; a < D; ++a) {
      if (grid.periodic[a]) continue;
      const int i = grid.logical_index(a, s[a]);
      int face = -1;
      if (i <= 0) face = 2 * a;
      if (i >= grid.cells[a]) face = 2 * a + 1;
      if (face < 0) continue;
      const FaceCondition& c = bc[face];
      Vec<NC>& v = field.velocity[n];
      switch (c.type) {
        case WallType::Open: break;
        case WallType::NoSlip: v.setZero(); break;
        case WallType::Slip: v[a] = c.velocity_m_s[a]; break;
        case WallType::Prescribed:
          for (int k = 0; k < NC; ++k) v[k] = c.velocity_m_s[k];
          break;
      }
    }
  }
}

}  // namespace oobleck::mpm
