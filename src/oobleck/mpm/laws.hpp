#pragma once
// Adapters that plug the pure per-point laws of material/ into a body (StressLaw).
#include <algorithm>
#include <cmath>

#include "oobleck/material/elastic.hpp"
#include "oobleck/mpm/body.hpp"

namespace oobleck::mpm {

/// Linear hypo-elastic solid (material/elastic.hpp); no per-point state besides the stress.
template <class G>
class LinearElasticLaw final : public StressLaw<G> {
 public:
  explicit LinearElasticLaw(const material::LinearElasticParams& p) : p_(p) {}
  void resize(std::int64_t) override {}
  void update_stress(Body<G>& body, double dt_s) override {
    const std::int64_t np = body.size();
#pragma omp parallel for schedule(static)
    for (std::int64_t q = 0; q < np; ++q)
      body.stress_Pa[q] = material::linear_elastic_update(body.stress_Pa[q], body.L_1_s[q], dt_s, p_);
  }
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
};

}  // namespace oobleck::mpm
