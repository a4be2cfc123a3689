// [analysis] kind = "settling" (docs/verification.md): the settling velocity of a uniform
// suspension, measured in the middle half of the column and averaged over the steps after
// analysis.average_from, against the drag-buoyancy balance.
#include <cmath>

#include "oobleck/core/comm.hpp"
#include "oobleck/material/drag.hpp"
#include "oobleck/run/analysis_kinds.hpp"

namespace oobleck::run {

namespace {

template <class G>
class SettlingAnalysis final : public SceneAnalysis<G> {
  static constexpr int D = G::dim;
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  using Base::Base;

  void after_step() override {
    if (scene_.grains < 0 || scene_.fluid < 0) return;
    if (this->solver().time_s() < cfg_.analysis.average_from_s) return;
    // Mean vertical velocities of both phases in the middle half of the column, the mixture volume
    // flux j = phi v_s + (1 - phi) v_f there, and the settling velocity -(v_s - j), positive down.
    const auto& reg = cfg_.regions.front();
    const double z0 = reg.min_m[D - 1], z1 = reg.max_m[D - 1];
    const double lo = z0 + 0.25 * (z1 - z0), hi = z1 - 0.25 * (z1 - z0);
    auto mean_v = [&](const mpm::Body<G>& body, double* sums) {
      double mv = 0.0, m = 0.0, volume = 0.0;
      for (std::int64_t p = 0; p < body.size(); ++p) {
        if (body.x_m[p][D - 1] < lo || body.x_m[p][D - 1] > hi) continue;
        mv += body.mass_kg[p] * body.v_m_s[p][D - 1];
        m += body.mass_kg[p];
        volume += body.volume_m3[p];
      }
      sums[0] = mv;
      sums[1] = m;
      sums[2] = volume;
    };
    double sums[6];  // grains' and fluid's Σ m v, Σ m, Σ V (decomposed runs: over every rank)
    mean_v(this->solver().body(scene_.grains), sums);
    mean_v(this->solver().body(scene_.fluid), sums + 3);
    if (this->solver().decomposition()) comm::sum(sums);
    const double vs = sums[1] > 0 ? sums[0] / sums[1] : 0.0;
    const double vf = sums[4] > 0 ? sums[3] / sums[4] : 0.0;
    const double phi = reg.phi;
    const double j = phi * vs + (1.0 - phi) * vf;
    this->settling_.sum += -(vs - j);
    ++this->settling_.samples;
  }

  nlohmann::json result() const override {
    // Drag-buoyancy balance (derivation in docs/verification.md): with zero mixture volume flux
    // the fluid pressure gradient carries the mixture weight, so per mixture volume the drag
    // balances phi (1 - phi)(rho_s - rho_f) g: 18 phi (1-phi) eta_0/d^2 F(phi, Re) w = phi (1-phi) drho g,
    // w = v_s - v_f the slip velocity; the grain velocity in the zero-flux frame is (1 - phi) w.
    const double phi = cfg_.regions.front().phi;
    const double g = std::fabs(cfg_.gravity_m_s2[D - 1]);
    const double drho = cfg_.material.granular.rho_s - cfg_.fluid.rho_f0_kg_m3;
    const material::DragParams dp = this->solver().options().mixture.drag;
    double w = 0.0;
    for (int it = 0; it < 100; ++it) {
      const double Re = material::drag_reynolds(w, 1.0 - phi, cfg_.fluid.rho_f0_kg_m3, dp.d_m, dp.eta_0_Pa_s);
      const double w_new = drho * g * dp.d_m * dp.d_m / (18.0 * dp.eta_0_Pa_s * material::drag_F(dp, phi, Re));
      if (std::fabs(w_new - w) <= 1e-14 * std::fabs(w_new)) {
        w = w_new;
        break;
      }
      w = w_new;
    }
    nlohmann::json a = nlohmann::json::object();
    const auto [sum, samples] = this->settling_;  // (checkpointed by the base, run/analysis.hpp)
    a["settling_velocity"] = samples > 0 ? sum / static_cast<double>(samples) : NAN;
    a["settling_velocity_analytic"] = (1.0 - phi) * w;
    a["settling_samples"] = samples;
    a["units"] = {{"settling_velocity", "m/s"}, {"settling_velocity_analytic", "m/s"}, {"settling_samples", "1"}};
    return a;
  }
};

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_settling_analysis(const scene::SceneConfig& config,
                                                         const scene::BuiltScene<G>& scene) {
  return std::make_unique<SettlingAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_settling_analysis);

}  // namespace oobleck::run
