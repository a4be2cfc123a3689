#pragma once
// Linear (hypo-)elastic test solid: σ̇ = λ tr(D) 1 + 2μ D + W σ − σ W (Jaumann rate, objective
// for large rotations). Used to verify the MPM solver (V2 waves, conservation) and as the
// elastic-solid law of third bodies. Pure per-point function.
#include <Eigen/Core>
#include <cmath>

namespace oobleck::material {

struct LinearElasticParams {
  double youngs_modulus_Pa = 1e6;  ///< [Pa] E
  double poisson_ratio = 0.3;      ///< [-] ν
  double lame_lambda_Pa() const {
    return youngs_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
  double shear_modulus_Pa() const { return youngs_modulus_Pa / (2.0 * (1.0 + poisson_ratio)); }
  /// P-wave (constrained) modulus λ + 2μ [Pa].
  double p_wave_modulus_Pa() const { return lame_lambda_Pa() + 2.0 * shear_modulus_Pa(); }
};

/// One explicit step of the hypo-elastic law from the velocity gradient L [1/s] over dt [s].
inline Eigen::Matrix3d linear_elastic_update(const Eigen::Matrix3d& sigma, const Eigen::Matrix3d& L, double dt_s,
                                             const LinearElasticParams& p) {
  const Eigen::Matrix3d Dm = 0.5 * (L + L.transpose());
  const Eigen::Matrix3d W = 0.5 * (L - L.transpose());
  Eigen::Matrix3d rate = 2.0 * p.shear_modulus_Pa() * Dm + W * sigma - sigma * W;
  rate.diagonal().array() += p.lame_lambda_Pa() * Dm.trace();
  return sigma + dt_s * rate;
}

}  // namespace oobleck::material
