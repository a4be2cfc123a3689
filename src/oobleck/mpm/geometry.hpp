#pragma once
// Geometry policies and small fixed-size types of the MPM solver (model.md §7).
//
// A geometry policy says how many spatial dimensions the grid has (`dim`) and how many velocity
// components a point carries (`ncomp`), and supplies the geometry-specific pieces of the step:
// the 3×3 velocity gradient built from the nodal velocity gradient, and the point measure.
// Plane strain (dim = ncomp = 2) and 3D (dim = ncomp = 3) are implemented; axisymmetric with swirl
// is dim = 2, ncomp = 3 ((r, z, θ) ordering) and adds hoop terms in `velocity_gradient` and a hoop
// force hook (see docs/mpm.md) — the transfers are written for ncomp ≠ dim already.
#include <Eigen/Core>

namespace oobleck::mpm {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;
using Mat3 = Eigen::Matrix3d;

/// Plane strain: (x, y) grid, velocity (v_x, v_y); the out-of-plane strain rate is zero, so the
/// 3×3 velocity gradient has a zero third row and column (σ_zz still evolves in the laws).
struct PlaneStrain {
  static constexpr int dim = 2;
  static constexpr int ncomp = 2;
  static constexpr const char* name = "plane_strain";
  /// 3×3 velocity gradient L [1/s] from Σ_i v_i ∇N_ipᵀ (ncomp × dim).
  static Mat3 velocity_gradient(const Mat<ncomp, dim>& grad_v, const Vec<dim>& /*x*/,
                                const Vec<ncomp>& /*v*/) {
    Mat3 L = Mat3::Zero();
    L.topLeftCorner<2, 2>() = grad_v;
    return L;
  }
};

/// Full 3D: (x, y, z) grid and velocity.
struct ThreeD {
  static constexpr int dim = 3;
  static constexpr int ncomp = 3;
  static constexpr const char* name = "3d";
  static Mat3 velocity_gradient(const Mat<ncomp, dim>& grad_v, const Vec<dim>& /*x*/,
                                const Vec<ncomp>& /*v*/) {
    return grad_v;
  }
};

}  // namespace oobleck::mpm
