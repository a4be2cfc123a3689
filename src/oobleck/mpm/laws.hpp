#pragma once
// Adapters that plug the pure per-point laws of material/ into a body (StressLaw).
#include <algorithm>
#include <cmath>

#include "oobleck/material/elastic.hpp"
#include "oobleck/material/fluid.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/numerics/vector_math.hpp"

namespace oobleck::mpm {

/// Linear hypo-elastic solid (material/elastic.hpp); no per-point state besides the stress.
template <class G>
class LinearElasticLaw final : public StressLaw<G> {
 public:
  explicit LinearElasticLaw(const material::LinearElasticParams& p) : p_(p) {}
  void resize(std::int64_t) override {}
  void update_stress(Body<G>& body, double dt_s) override {
    const std::int64_t np = body.size();
    std::int64_t bad = kAllFinite;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (std::int64_t q = 0; q < np; ++q) {
      body.stress_Pa[q] = material::linear_elastic_update(body.stress_Pa[q], body.L_1_s[q], dt_s, p_);
      if (!std::isfinite(body.stress_Pa[q].sum())) bad = std::min(bad, q);
    }
    first_bad_ = bad;
  }
  std::int64_t first_non_finite_stress() const override { return first_bad_; }
  double max_wave_speed(const Body<G>& body) const override {
    // c = √(M/ρ) at the lightest point (current density m/V), the fastest wave.
    double rho_min = INFINITY;
    for (std::int64_t q = 0; q < body.size(); ++q)
      rho_min = std::min(rho_min, body.mass_kg[q] / body.volume_m3[q]);
    return body.size() > 0 ? std::sqrt(p_.p_wave_modulus_Pa() / rho_min) : 0.0;
  }
  const char* name() const override { return "linear_elastic"; }
  const material::LinearElasticParams& params() const { return p_; }

 private:
  material::LinearElasticParams p_;
  std::int64_t first_bad_ = kNotChecked;
};

/// Fluid phase of a mixture (E25–E27). State: J = ρ_f0/ρ_f per point. Needs body.phi and
/// body.div_q_1_s, which the solver's G2P fills for the fluid body from the nodal porosity and
/// mixture flux. `min_porosity` bounds n in the J update (model.md §5).
template <class G>
class FluidLaw final : public StressLaw<G> {
 public:
  FluidLaw(const material::FluidParams& p, double min_porosity) : p_(p), n_min_(min_porosity) {}
  void resize(std::int64_t n) override { J.resize(static_cast<std::size_t>(n), 1.0); }
  /// E27 J ← J exp(Δt div q / n) (material::update_fluid_volume_ratio), E26 p_f = −κ ln J
  /// (material::fluid_pressure) and E25, for blocks of points with the exp and log in vector lanes
  /// (numerics/vector_math.hpp).
  void update_stress(Body<G>& body, double dt_s) override {
    const std::int64_t np = body.size();
    constexpr int kBlock = numerics::kMathBlock;
    const std::int64_t blocks = (np + kBlock - 1) / kBlock;
    std::int64_t bad = kAllFinite;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (std::int64_t blk = 0; blk < blocks; ++blk) {
      const std::int64_t q0 = blk * kBlock;
      const int nb = static_cast<int>(std::min<std::int64_t>(kBlock, np - q0));
      double arg[kBlock], factor[kBlock], Jn[kBlock], lnJ[kBlock];
      for (int j = 0; j < kBlock; ++j) {
        const std::int64_t q = q0 + std::min(j, nb - 1);  // (lanes past the end repeat the last point)
        const double n = std::max(1.0 - body.phi[q], n_min_);
        arg[j] = dt_s * body.div_q_1_s[q] / n;
      }
      numerics::exp_block(arg, factor);
      for (int j = 0; j < kBlock; ++j) Jn[j] = J[q0 + std::min(j, nb - 1)] * factor[j];  // E27
      numerics::log_block(Jn, lnJ);
      for (int j = 0; j < nb; ++j) {
        const std::int64_t q = q0 + j;
        J[q] = Jn[j];
        const double p_f = -p_.kappa_Pa * lnJ[j];  // E26
        body.stress_Pa[q] = material::fluid_cauchy_stress_at_pressure(body.L_1_s[q], body.phi[q], p_f, p_.eta_0_Pa_s);
        if (!std::isfinite(body.stress_Pa[q].sum())) bad = std::min(bad, q);
      }
    }
    first_bad_ = bad;
  }
  std::int64_t first_non_finite_stress() const override { return first_bad_; }
  double max_wave_speed(const Body<G>&) const override {
    double J_max = 1.0;
    for (double j : J) J_max = std::max(J_max, j);
    return material::fluid_wave_speed(p_.kappa_Pa, p_.rho_f0_kg_m3 / J_max);
  }
  double viscous_dt_limit(const Body<G>& body, double h_m) const override {
    double phi_max = 0.0;
    for (double f : body.phi) phi_max = std::max(phi_max, f);
    return p_.rho_f0_kg_m3 * h_m * h_m / (2.0 * material::fluid_effective_viscosity(p_.eta_0_Pa_s, phi_max));
  }
  const char* name() const override { return "fluid"; }
  const material::FluidParams& params() const { return p_; }
  std::vector<double> J;  ///< ρ_f0/ρ_f per point

 private:
  material::FluidParams p_;
  double n_min_;
  std::int64_t first_bad_ = kNotChecked;
};

}  // namespace oobleck::mpm
