// The objective stress rate in axisymmetric mode with swirl (E16, geometry.hpp): the laws integrate
// stress components in the local (r, z, θ) basis, which turns with a point moving in θ at the spin
// v_θ/r. Axisymmetric::velocity_gradient gives the gradient relative to that basis, so that
//   - a pre-stressed material in rigid rotation keeps every stress component (the components in the
//     co-rotating basis of a rigidly rotating body are constant: exact kinematics), and
//   - shear between rotating cylinders is, at the point, plane simple shear at the local rate
//     γ̇ = ∂v_θ/∂r − v_θ/r whatever the cylinders' common rotation: the stress history equals the
//     plane-strain one with (r, θ) ↔ (y, x), for the elastic and the granular law (elastic loading,
//     then plastic flow and the structure f).
// Both checks would fail with the physical-component spin skew(∇v) (asserted below as well, so the
// tests can tell the two apart).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "oobleck/mpm/granular_body_law.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/rheology/params.hpp"
#include "solver_phases.hpp"

using namespace oobleck;
using namespace oobleck::mpm;

namespace {

/// Σ v_i ∇N_ipᵀ of the swirl field v_θ(r) at radius r: columns ∂/∂r, ∂/∂z of (v_r, v_z, v_θ).
Mat<3, 2> swirl_gradient(double dvtheta_dr) {
  Mat<3, 2> g = Mat<3, 2>::Zero();
  g(2, 0) = dvtheta_dr;
  return g;
}

/// The 3×3 gradient an axisymmetric point at radius r with swirl v_θ(r) hands to its law, through
/// both of the geometry's forms (the general one and G2P's entry-by-entry one; they must agree).
Mat3 axisymmetric_L(double r, double v_theta, double dvtheta_dr) {
  const Vec<2> x(r, 0.0);
  const Vec<3> v(0.0, 0.0, v_theta);
  Mat3 L = Axisymmetric::velocity_gradient(swirl_gradient(dvtheta_dr), x, v);
  Mat3 Lw;
  const double g0[3] = {0.0, 0.0, dvtheta_dr}, g1[3] = {0.0, 0.0, 0.0};
  const double vv[3] = {0.0, 0.0, v_theta};
  Axisymmetric::write_velocity_gradient(Lw.data(), g0, g1, x, vv);
  EXPECT_EQ(L, Lw);
  return L;
}

/// The physical components' gradient ∇v (L_rθ = −v_θ/r): what the laws were given before the
/// basis' spin was taken out. Used only to show the checks below can fail.
Mat3 physical_gradient(double r, double v_theta, double dvtheta_dr) {
  Mat3 L = Mat3::Zero();
  L(2, 0) = dvtheta_dr;
  L(0, 2) = -v_theta / r;
  return L;
}

/// A one-point body at radius r with stress s and volume fraction phi (m = φ ρ_s V).
template <class G>
Body<G> one_point(double r, const Mat3& s, double rho_s, double phi) {
  Body<G> b;
  b.name = "point";
  const double V = 1e-6;
  b.add_point(Vec<2>(r, 0.0), V, phi * rho_s);
  b.stress_Pa[0] = s;
  return b;
}

double max_abs_difference(const Mat3& a, const Mat3& b) { return (a - b).cwiseAbs().maxCoeff(); }

}  // namespace

TEST(ObjectiveRate, RigidRotationGivesAZeroGradientInTheTurningBasis) {
  for (double r : {1e-3, 0.05, 2.0})
    for (double omega : {-30.0, 0.7, 100.0}) {
      const Mat3 L = axisymmetric_L(r, omega * r, omega);
      EXPECT_LE(L.cwiseAbs().maxCoeff(), 4e-16 * std::abs(omega)) << "r = " << r << ", omega = " << omega;
    }
}

TEST(ObjectiveRate, PreStressedAnnulusInRigidRotationKeepsItsStressComponents) {
  // σ with every (r, z, θ) component nonzero, compressive, inside the granular yield surface.
  Mat3 s0;
  s0 << -300.0, 20.0, 40.0,  //
      20.0, -250.0, -15.0,   //
      40.0, -15.0, -280.0;
  const double omega = 40.0, dt = 1e-4;
  const int steps = 1500;  // 6 rad
  const rheology::Preset preset = rheology::load_preset("hermes2016");
  material::LinearElasticParams ep;
  ep.youngs_modulus_Pa = 1e6;
  for (double r : {0.01, 0.06}) {
    const Mat3 L = axisymmetric_L(r, omega * r, omega);
    Body<Axisymmetric> elastic = one_point<Axisymmetric>(r, s0, 1000.0, 0.5);
    LinearElasticLaw<Axisymmetric> elastic_law(ep);
    elastic_law.resize(1);
    Body<Axisymmetric> grains = one_point<Axisymmetric>(r, s0, preset.granular.rho_s, 0.56);
    GranularBodyLaw<Axisymmetric> granular_law(preset);
    granular_law.resize(1);
    granular_law.f[0] = 0.3;
    for (int n = 0; n < steps; ++n) {
      elastic.L_1_s[0] = L;
      grains.L_1_s[0] = L;
      phases::update_stress(elastic_law, elastic, dt);
      phases::update_stress(granular_law, grains, dt);
    }
    const double scale = s0.cwiseAbs().maxCoeff();
    EXPECT_LE(max_abs_difference(elastic.stress_Pa[0], s0), 1e-10 * scale) << "elastic, r = " << r;
    EXPECT_LE(max_abs_difference(grains.stress_Pa[0], s0), 1e-10 * scale) << "granular, r = " << r;
  }
  // The physical components' spin turns the same stress visibly within 0.5 rad (the error this
  // geometry removes): σ_rθ moves by a sizeable part of |σ|.
  {
    const double r = 0.05;
    Body<Axisymmetric> b = one_point<Axisymmetric>(r, s0, 1000.0, 0.5);
    LinearElasticLaw<Axisymmetric> law(ep);
    law.resize(1);
    for (int n = 0; n < 125; ++n) {  // 0.5 rad
      b.L_1_s[0] = physical_gradient(r, omega * r, omega);
      phases::update_stress(law, b, dt);
    }
    EXPECT_GT(max_abs_difference(b.stress_Pa[0], s0), 0.05 * s0.cwiseAbs().maxCoeff());
  }
}

TEST(ObjectiveRate, ShearBetweenRotatingCylindersIsPlaneSimpleShear) {
  // Taylor-Couette v_θ = A r + B/r with both cylinders turning (A: the common rotation). At a point
  // at radius R the motion is simple shear at γ̇ = ∂v_θ/∂r − v_θ/r = −2B/R² in the turning basis,
  // plus the rigid rotation: the stress must follow plane simple shear v_x = γ̇ y, with
  // θ ↔ x (flow) and r ↔ y (gradient), through elastic loading, yield and steady flow.
  const rheology::Preset preset = rheology::load_preset("hermes2016");
  const double gamma_dot = 5.0, A = 25.0, dt = 2e-5, phi = 0.56;
  const int steps = 20000;  // γ = 2: past yield into steady flow
  Mat3 s0 = Mat3::Zero();
  s0.diagonal().setConstant(-200.0);
  // (axisymmetric index) → (plane-strain index): r → y, z → z, θ → x
  const int to_plane[3] = {1, 2, 0};
  Mat3 Lp = Mat3::Zero();
  Lp(0, 1) = gamma_dot;  // ∂v_x/∂y
  for (double R : {0.02, 0.5}) {
    const double B = -0.5 * gamma_dot * R * R;
    const double v_theta = A * R + B / R, dv_dr = A - B / (R * R);
    const Mat3 L = axisymmetric_L(R, v_theta, dv_dr);
    Body<Axisymmetric> axi = one_point<Axisymmetric>(R, s0, preset.granular.rho_s, phi);
    GranularBodyLaw<Axisymmetric> axi_law(preset);
    axi_law.resize(1);
    axi_law.f[0] = 0.2;
    Body<Axisymmetric> old_axi = one_point<Axisymmetric>(R, s0, preset.granular.rho_s, phi);
    GranularBodyLaw<Axisymmetric> old_law(preset);
    old_law.resize(1);
    old_law.f[0] = 0.2;
    Body<PlaneStrain> ref = one_point<PlaneStrain>(1.0, s0, preset.granular.rho_s, phi);
    GranularBodyLaw<PlaneStrain> ref_law(preset);
    ref_law.resize(1);
    ref_law.f[0] = 0.2;
    double worst = 0.0, old_worst = 0.0, max_shear = 0.0;
    for (int n = 0; n < steps; ++n) {
      axi.L_1_s[0] = L;
      old_axi.L_1_s[0] = physical_gradient(R, v_theta, dv_dr);
      ref.L_1_s[0] = Lp;
      phases::update_stress(axi_law, axi, dt);
      phases::update_stress(old_law, old_axi, dt);
      phases::update_stress(ref_law, ref, dt);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double want = ref.stress_Pa[0](to_plane[i], to_plane[j]);
          worst = std::max(worst, std::abs(axi.stress_Pa[0](i, j) - want));
          old_worst = std::max(old_worst, std::abs(old_axi.stress_Pa[0](i, j) - want));
        }
      max_shear = std::max(max_shear, std::abs(ref.stress_Pa[0](0, 1)));
    }
    const double scale = ref.stress_Pa[0].cwiseAbs().maxCoeff();
    EXPECT_GT(ref_law.gamma_dot_p[0], 0.5 * gamma_dot) << "the reference must reach plastic flow";
    EXPECT_GT(max_shear, 10.0);
    EXPECT_LE(worst, 1e-9 * scale) << "R = " << R;
    EXPECT_NEAR(axi_law.f[0], ref_law.f[0], 1e-12) << "R = " << R;
    EXPECT_GT(old_worst, 0.05 * scale) << "R = " << R << ": the physical spin must differ here";
  }
}
