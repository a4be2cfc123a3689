#pragma once
// Adapters that plug the pure per-point laws of material/ into a body (StressLaw).
#include <algorithm>
#include <cmath>

#include "oobleck/material/elastic.hpp"
#include "oobleck/material/fluid.hpp"
#include "oobleck/mpm/body.hpp"

namespace oobleck::mpm {

/// Linear hypo-elastic solid (material/elastic.hpp); no per-point state besides the stress.
template <class G>
class LinearElasticLaw final : public StressLaw<G> {
 public:
  explicit LinearElasticLaw(const material::LinearElasticParams& p) : p_(p) {}
  void resize(std::int64_t) override {}
  std::int64_t chunk_count(const Body<G>& body) const override { return (body.size() + kChunk - 1) / kChunk; }
  std::int64_t update_chunk(Body<G>& body, double dt_s, std::int64_t c) override {
    const std::int64_t q1 = std::min(body.size(), (c + 1) * kChunk);
    std::int64_t bad = kAllFinite;
    for (std::int64_t q = c * kChunk; q < q1; ++q) {
      body.stress_Pa[q] = material::linear_elastic_update(body.stress_Pa[q], body.L_1_s[q], dt_s, p_);
      if (!std::isfinite(body.stress_Pa[q].sum())) bad = std::min(bad, q);
    }
    return bad;
  }
  void end_update(Body<G>&, double, std::int64_t first_bad) override { first_bad_ = first_bad; }
  std::int64_t first_non_finite_stress() const override { return first_bad_; }
  double max_wave_speed(const Body<G>& body) const override {
    // c = √(M/ρ) at the lightest point (current density m/V), the fastest wave.
    double rho_min = INFINITY;
    for (std::int64_t q = 0; q < body.size(); ++q) rho_min = std::min(rho_min, body.mass_kg[q] / body.volume_m3[q]);
    return body.size() > 0 ? std::sqrt(p_.p_wave_modulus_Pa() / rho_min) : 0.0;
  }
  const char* name() const override { return "linear_elastic"; }
  const material::LinearElasticParams& params() const { return p_; }

 private:
  static constexpr std::int64_t kChunk = 1024;  ///< points per chunk (≈ 10 µs of work)
  material::LinearElasticParams p_;
  std::int64_t first_bad_ = kNotChecked;
};

/// Fluid phase of a mixture (E25–E27). State: ln J, J = ρ_f0/ρ_f, per point. Needs body.phi and
/// body.div_q_1_s, which the solver's G2P fills for the fluid body from the nodal porosity and
/// mixture flux. `min_porosity` bounds n in the J update (E27, docs/equations.md).
template <class G>
class FluidLaw final : public StressLaw<G> {
 public:
  FluidLaw(const material::FluidParams& p, double min_porosity) : p_(p), n_min_(min_porosity) {}
  void resize(std::int64_t n) override { ln_J.resize(static_cast<std::size_t>(n), 0.0); }
  /// E27 in logarithms, ln J ← ln J + Δt div q / n (material::update_fluid_log_volume_ratio), E26
  /// p_f = −κ ln J (material::fluid_pressure_from_log_volume_ratio) and E25. (The state is ln J,
  /// not J: the exponential update of E27 and the logarithm of E26 cancel, and ln J ≈ −p_f/κ keeps
  /// its relative precision where J is within 1e-3 of 1.)
  std::int64_t chunk_count(const Body<G>& body) const override { return (body.size() + kChunk - 1) / kChunk; }
  std::int64_t update_chunk(Body<G>& body, double dt_s, std::int64_t c) override {
    const std::int64_t q1 = std::min(body.size(), (c + 1) * kChunk);
    std::int64_t bad = kAllFinite;
    for (std::int64_t q = c * kChunk; q < q1; ++q) {
      const double n = std::max(1.0 - body.phi[q], n_min_);
      const double lj = material::update_fluid_log_volume_ratio(ln_J[q], body.div_q_1_s[q], n, dt_s);  // E27
      ln_J[q] = lj;
      const double p_f = material::fluid_pressure_from_log_volume_ratio(lj, p_.kappa_Pa);  // E26
      body.stress_Pa[q] = material::fluid_cauchy_stress_at_pressure(body.L_1_s[q], body.phi[q], p_f, p_.eta_0_Pa_s);
      if (!std::isfinite(body.stress_Pa[q].sum())) bad = std::min(bad, q);
    }
    return bad;
  }
  void end_update(Body<G>&, double, std::int64_t first_bad) override { first_bad_ = first_bad; }
  std::int64_t first_non_finite_stress() const override { return first_bad_; }
  double max_wave_speed(const Body<G>&) const override {
    double ln_J_max = 0.0;  // (J ≥ 1: the density at rest or below)
    for (double lj : ln_J) ln_J_max = std::max(ln_J_max, lj);
    return material::fluid_wave_speed(p_.kappa_Pa, p_.rho_f0_kg_m3 / std::exp(ln_J_max));
  }
  double viscous_dt_limit(const Body<G>& body, double h_m) const override {
    double phi_max = 0.0;
    for (double f : body.phi) phi_max = std::max(phi_max, f);
    return p_.rho_f0_kg_m3 * h_m * h_m / (2.0 * material::fluid_effective_viscosity(p_.eta_0_Pa_s, phi_max));
  }
  const char* name() const override { return "fluid"; }
  const material::FluidParams& params() const { return p_; }
  /// ln J (checkpoints before ln J stored J: read as its logarithm, which differs from an
  /// uninterrupted run by that logarithm's round-off); the frames show the body's phi, its
  /// pressure as fluid_pressure, and J = ρ_f0/ρ_f.
  void declare_fields(Body<G>& /*body*/, FieldList& list) override {
    list.show("pressure", FrameForm::scalar, "fluid_pressure");
    list.show("phi", FrameForm::scalar);
    list.group("fluid");
    list.add("ln_J", ln_J, "1", FrameForm::none, {}, "J", [](double J) { return std::log(J); });
    list.derived("J", "1", [this](std::span<double> out) {
      for (std::size_t p = 0; p < out.size(); ++p) out[p] = std::exp(ln_J[p]);
    });
  }
  std::vector<double> ln_J;  ///< ln(ρ_f0/ρ_f) per point (E26: p_f = −κ ln J)

 private:
  static constexpr std::int64_t kChunk = 1024;  ///< points per chunk (≈ 10 µs of work)
  material::FluidParams p_;
  double n_min_;
  std::int64_t first_bad_ = kNotChecked;
};

}  // namespace oobleck::mpm
