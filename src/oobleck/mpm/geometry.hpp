#pragma once
// Geometry policies and small fixed-size types of the MPM solver (docs/mpm.md, "Geometry modes").
//
// A geometry policy says how many spatial dimensions the grid has (`dim`) and how many velocity
// components a point carries (`ncomp`), and supplies the geometry-specific pieces of the step:
//   velocity_gradient(∑ v_i ∇N_ipᵀ, x_p, v_p)  the 3×3 L the laws integrate (axisymmetric: relative
//                                             to the turning local basis, see Axisymmetric),
//   measure(x, area)                          point volume from its cross-section (per radian: A r),
//   and, when has_hoop_terms, the per-point nodal force terms scaled by N_ip:
//   hoop_force(σ, x, V) and inertial_acceleration(x, v) (centrifugal / Coriolis), and the extra
//   divergence term div_extra(q, x) = q_r/r.
// Plane strain (dim = ncomp = 2), 3D (dim = ncomp = 3) and axisymmetric with swirl (dim = 2,
// ncomp = 3, components (r, z, θ)) are implemented.
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
  static constexpr bool has_hoop_terms = false;
  static double measure(const Vec<dim>& /*x*/, double area) { return area; }
  /// 3×3 velocity gradient L [1/s] from Σ_i v_i ∇N_ipᵀ (ncomp × dim).
  static Mat3 velocity_gradient(const Mat<ncomp, dim>& grad_v, const Vec<dim>& /*x*/, const Vec<ncomp>& /*v*/) {
    Mat3 L = Mat3::Zero();
    L.topLeftCorner<2, 2>() = grad_v;
    return L;
  }
  /// velocity_gradient written entry by entry into L (column-major 3×3) from its columns
  /// g_a = ∑ v_i ∂_a N_ip (G2P's hot path: no temporary matrix); returns tr L.
  static double write_velocity_gradient(double* L, const double* g0, const double* g1, const Vec<dim>& /*x*/,
                                        const double* /*v*/) {
    L[0] = g0[0], L[1] = g0[1], L[2] = 0.0;
    L[3] = g1[0], L[4] = g1[1], L[5] = 0.0;
    L[6] = 0.0, L[7] = 0.0, L[8] = 0.0;
    return (L[0] + L[4]) + L[8];  // the order of Mat3::trace()
  }
};

/// Full 3D: (x, y, z) grid and velocity.
struct ThreeD {
  static constexpr int dim = 3;
  static constexpr int ncomp = 3;
  static constexpr const char* name = "3d";
  static constexpr bool has_hoop_terms = false;
  static double measure(const Vec<dim>& /*x*/, double volume) { return volume; }
  static Mat3 velocity_gradient(const Mat<ncomp, dim>& grad_v, const Vec<dim>& /*x*/, const Vec<ncomp>& /*v*/) {
    return grad_v;
  }
};

/// Axisymmetric with swirl (docs/mpm.md, "Geometry modes"): grid (r, z), velocity and 3×3 tensors in (r, z, θ)
/// order. Masses and volumes are per radian (m = ρ A r, V = A r). The weak form per radian gives,
/// per point and scaled by N_ip (dV = r dr dz):
///   f_r −= σ_θθ V/r,  f_θ += σ_rθ V/r                         (hoop terms)
///   f_r += m v_θ²/r,  f_θ −= m v_r v_θ/r                       (centrifugal, Coriolis: the physical
///                                                                components' inertial terms)
/// and div q = ∂q_r/∂r + ∂q_z/∂z + q_r/r.
///
/// The velocity gradient in the physical (r, z, θ) components has the geometry entries
/// (∇v)_θθ = v_r/r and (∇v)_rθ = −v_θ/r. The laws integrate their stresses as components in this
/// local basis, and the basis turns with the point as it moves in θ: at the spin Ω_b with
/// (Ω_b)_θr = v_θ/r = −(Ω_b)_rθ. The rate of the components is the objective (Jaumann) rate with
/// the spin W − Ω_b, so L here is the gradient relative to the turning basis, L = ∇v − Ω_b
/// (docs/equations.md, E16): the same D = sym L, the spin W = skew L − Ω_b, and
///   L_θθ = v_r/r,  L_rθ = 0,  L_θr = ∂v_θ/∂r − v_θ/r.
/// A rigid rotation v_θ = ω r has L = 0 and keeps every stress component; without Ω_b it would
/// turn the stress at the rate ω against its own basis.
struct Axisymmetric {
  static constexpr int dim = 2;
  static constexpr int ncomp = 3;
  static constexpr const char* name = "axisymmetric";
  static constexpr bool has_hoop_terms = true;
  static double measure(const Vec<dim>& x, double area) { return area * x[0]; }
  static Mat3 velocity_gradient(const Mat<ncomp, dim>& grad_v, const Vec<dim>& x, const Vec<ncomp>& v) {
    Mat3 L = Mat3::Zero();
    L.leftCols<2>() = grad_v;
    const double ir = 1.0 / x[0];
    L(2, 0) -= v[2] * ir;  // − (Ω_b)_θr
    L(2, 2) = v[0] * ir;
    return L;
  }
  /// velocity_gradient written entry by entry (see PlaneStrain); returns tr L.
  static double write_velocity_gradient(double* L, const double* g0, const double* g1, const Vec<dim>& x,
                                        const double* v) {
    const double ir = 1.0 / x[0];
    L[0] = g0[0], L[1] = g0[1], L[2] = g0[2] - v[2] * ir;
    L[3] = g1[0], L[4] = g1[1], L[5] = g1[2];
    L[6] = 0.0, L[7] = 0.0, L[8] = v[0] * ir;
    return (L[0] + L[4]) + L[8];
  }
  static Vec<ncomp> hoop_force(const Mat3& sigma, const Vec<dim>& x, double V) {
    const double Vr = V / x[0];  // (one division: P2G calls these per point)
    return Vec<ncomp>(-sigma(2, 2) * Vr, 0.0, sigma(0, 2) * Vr);
  }
  static Vec<ncomp> inertial_acceleration(const Vec<dim>& x, const Vec<ncomp>& v) {
    const double ir = 1.0 / x[0];
    return Vec<ncomp>(v[2] * v[2] * ir, 0.0, -v[0] * v[2] * ir);
  }
  static double div_extra(const Vec<ncomp>& q, const Vec<dim>& x) { return q[0] / x[0]; }
};

}  // namespace oobleck::mpm
