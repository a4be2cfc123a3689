#pragma once
// Adapter that plugs the granular law (material/granular.hpp, E16–E24) into a grain body.
// State per point: the structure f; the stress lives in the body. phi_p = m_p/(rho_s V_p) (granular
// mass conservation) is clamped into (0, 1) before the call. A point whose update
// fails (non-convergence, non-finite input) stops the run with a diagnosis naming the point, the
// law, its state and inputs (NumericalError), never a silent NaN.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/mpm/body.hpp"

namespace oobleck::mpm {

template <class G>
class GranularBodyLaw final : public StressLaw<G> {
 public:
  GranularBodyLaw(const rheology::Preset& preset, material::GranularOptions options = {})
      : law_(preset, options), rho_s_(preset.granular.rho_s), G_(preset.granular.G), K_(preset.granular.K) {}

  void resize(std::int64_t n) override {
    const auto s = static_cast<std::size_t>(n);
    f.resize(s, 0.0);
    regime.resize(s, 0);
    gamma_dot_p.resize(s, 0.0);
  }

  /// Volume fraction of point q from its mass and current (mixture) volume.
  double phi_of(const Body<G>& body, std::int64_t q) const {
    return std::clamp(body.mass_kg[q] / (rho_s_ * body.volume_m3[q]), 1e-9, 1.0 - 1e-9);
  }

  /// Plane strain: L has no out-of-plane shear (PlaneStrain::write_velocity_gradient), and the law
  /// never creates xz, yz stresses from zero ones, so the law's in-plane trials apply
  /// (advance_batch's in_plane: the same results, 9% less time for the law on the wheel's bed).
  static constexpr bool kInPlane = std::is_same_v<G, PlaneStrain>;

  // Chunks of kChunk points: the cost per point ranges from a closed form to tens of Newton steps
  // and an implicit structure solve, and it is clustered in space (points are stored by region),
  // so the threads steal each other's remaining chunks (ScheduleHint::uneven_chunks; a
  // plain static split left one thread waiting: rod impact, 1.3x faster stress pass on 2 threads
  // with a dynamic schedule, which stealing keeps while a point stays with its thread). Each point is
  // independent: the results do not depend on the schedule. Within a chunk the law runs its
  // Newton iterations in lanes across points (GranularLaw::advance_batch).
  std::int64_t chunk_count(const Body<G>& body) const override { return (body.size() + kChunk - 1) / kChunk; }
  std::int64_t update_chunk(Body<G>& body, double dt_s, std::int64_t c) override {
    const std::int64_t q0 = c * kChunk, m = std::min(kChunk, body.size() - q0);
    if (m <= 0) return kAllFinite;
    double phi[kChunk];
    material::GranularStep step[kChunk];
    for (std::int64_t i = 0; i < m; ++i) phi[i] = phi_of(body, q0 + i);
#ifndef NDEBUG
    if constexpr (kInPlane)
      for (std::int64_t i = 0; i < m; ++i)
        for (int e : {2, 5, 6, 7})
          assert(body.stress_Pa[q0 + i].data()[e] == 0.0 && body.L_1_s[q0 + i].data()[e] == 0.0);
#endif
    law_.advance_batch(m, body.stress_Pa.data() + q0, f.data() + q0, body.L_1_s.data() + q0, phi, dt_s, step, kInPlane);
    std::int64_t first_bad = kAllFinite;
    for (std::int64_t i = 0; i < m; ++i) {
      if (!step[i].ok) {
        first_bad = std::min(first_bad, q0 + i);
        continue;
      }
      regime[q0 + i] = static_cast<std::uint8_t>(step[i].regime);
      gamma_dot_p[q0 + i] = step[i].gamma_dot_p;
    }
    return first_bad;
  }
  /// A point whose update failed stops the run with the diagnosis (its state was left as it was).
  void end_update(Body<G>& body, double dt_s, std::int64_t first_bad) override {
    if (first_bad == kAllFinite) return;
    const std::int64_t q = first_bad;
    const Mat3& L = body.L_1_s[q];
    const Mat3 D = 0.5 * (L + L.transpose());
    const Mat3 W = 0.5 * (L - L.transpose());
    const material::GranularState before{body.stress_Pa[q], f[q]};
    material::GranularState after = before;
    const auto u = law_.update(after, D, W, dt_s, phi_of(body, q));
    throw NumericalError(fmt::format("body '{}', point {} at x = ({}): {}", body.name, q,
                                     fmt::join(body.x_m[q].data(), body.x_m[q].data() + G::dim, ", "),
                                     law_.describe(u, before, D, W, dt_s, phi_of(body, q))));
  }
  /// A point takes ≈ 10× the fluid's update (the trial, the branch, Newton lanes), and the chunks'
  /// costs vary (see kChunk).
  ScheduleHint schedule_hint() const override { return {.relative_cost_per_point = 10.0, .uneven_chunks = true}; }

  /// Fastest granular wave: sqrt((K + 4G/3)/(phi rho_s)) at the loosest point (phi >= 0.05 so
  /// isolated surface points do not stall the run; they carry no stress when separated).
  double max_wave_speed(const Body<G>& body) const override {
    double phi_min = 1.0;
    for (std::int64_t q = 0; q < body.size(); ++q) phi_min = std::min(phi_min, phi_of(body, q));
    phi_min = std::max(phi_min, 0.05);
    return body.size() > 0 ? std::sqrt((K_ + 4.0 * G_ / 3.0) / (phi_min * rho_s_)) : 0.0;
  }
  const char* name() const override { return "granular (E16-E24)"; }
  /// A non-finite result never reaches the stresses: end_update throws with the diagnosis.
  std::int64_t first_non_finite_stress() const override { return kAllFinite; }
  const material::GranularLaw& law() const { return law_; }
  void declare_fields(Body<G>& body, FieldList& list) override {
    list.group("granular");
    list.add("f", f, "1", FrameForm::scalar);
    list.derived("phi", "1", [this, &body](std::span<double> out) {
      for (std::size_t p = 0; p < out.size(); ++p) out[p] = phi_of(body, static_cast<std::int64_t>(p));
    });
    list.derived("tau_bar", "Pa", [&body](std::span<double> out) {
      for (std::size_t p = 0; p < out.size(); ++p) out[p] = material::tau_bar(body.stress_Pa[p]);
    });
    list.add("regime", regime, "1", FrameForm::scalar);
    list.add("gamma_dot_p", gamma_dot_p, "1/s", FrameForm::scalar);
  }

  std::vector<double> f;             ///< micro-structure per point
  std::vector<std::uint8_t> regime;  ///< material::GranularRegime of the last step
  std::vector<double> gamma_dot_p;   ///< plastic shear rate of the last step [1/s]

 private:
  static constexpr std::int64_t kChunk = 256;  ///< points per chunk
  material::GranularLaw law_;
  double rho_s_, G_, K_;
};

}  // namespace oobleck::mpm
