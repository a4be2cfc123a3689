// [analysis] kind = "couette" (docs/verification.md): a Newtonian fluid between a turning inner
// cylinder and a fixed outer one; the wall torques and the velocity profile against the closed
// form v_theta = A r + B/r.
#include <cmath>

#include "oobleck/core/comm.hpp"
#include "oobleck/run/analysis_kinds.hpp"

namespace oobleck::run {

namespace {

template <class G>
class CouetteAnalysis final : public SceneAnalysis<G> {
  using Base = SceneAnalysis<G>;
  using Base::cfg_;
  using Base::scene_;

 public:
  using Base::Base;

  nlohmann::json result() const override {
    nlohmann::json a = nlohmann::json::object();
    if (scene_.fluid < 0 || G::ncomp != 3) return a;
    // Torque on a coaxial cylinder of radius r: M(r) = 2 pi r^2 H tau_r_theta (whole cylinder).
    // At steady state r^2 tau_r_theta is uniform in the gap (torque balance); a least-squares line
    // of r^2 tau_r_theta against r over all fluid points, evaluated at each wall, gives the wall
    // torques (their difference measures the discretization error). Analytic: M = 4 pi eta B H.
    const auto& body = this->solver().body(scene_.fluid);
    const double ri = cfg_.grid.origin_m[0], ro = ri + cfg_.grid.size_m[0];
    const double H = cfg_.grid.size_m[1];
    const double eta = cfg_.fluid.eta_0_Pa_s;
    const double U = cfg_.boundary[0].velocity_m_s[2];
    const double B = U * ri * ro * ro / (ro * ro - ri * ri);
    const double A = -U * ri / (ro * ro - ri * ri);
    // Sums over the fluid's points (decomposed runs: over every rank): n, r, m, r², r m and the
    // squared velocity error against A r + B/r.
    double sums[6] = {static_cast<double>(body.size()), 0, 0, 0, 0, 0};
    for (std::int64_t p = 0; p < body.size(); ++p) {
      const double r = body.x_m[p][0];
      const double m = r * r * body.stress_Pa[p](0, 2);
      const double d = body.v_m_s[p][G::ncomp - 1] - (A * r + B / r);
      sums[1] += r;
      sums[2] += m;
      sums[3] += r * r;
      sums[4] += r * m;
      sums[5] += d * d;
    }
    if (this->solver().decomposition()) comm::sum(sums);
    const auto [np, sr, sm, srr, srm, e2] = sums;
    const double slope = (np * srm - sr * sm) / (np * srr - sr * sr);
    const double icpt = (sm - slope * sr) / np;
    a["torque_inner"] = std::fabs(2.0 * M_PI * H * (icpt + slope * ri));
    a["torque_outer"] = std::fabs(2.0 * M_PI * H * (icpt + slope * ro));
    a["torque_analytic"] = std::fabs(4.0 * M_PI * eta * B * H);
    // Velocity profile error against A r + B/r at the points (L2 relative to U).
    a["velocity_profile_rms_error"] = std::sqrt(e2 / np) / std::fabs(U);
    a["units"] = {{"torque_inner", "N m"},  // (the whole cylinder's)
                  {"torque_outer", "N m"},
                  {"torque_analytic", "N m"},
                  {"velocity_profile_rms_error", "1"}};
    return a;
  }
};

}  // namespace

template <class G>
std::unique_ptr<SceneAnalysis<G>> make_couette_analysis(const scene::SceneConfig& config,
                                                        const scene::BuiltScene<G>& scene) {
  return std::make_unique<CouetteAnalysis<G>>(config, scene);
}

OOBLECK_INSTANTIATE_ANALYSIS_MAKER(make_couette_analysis);

}  // namespace oobleck::run
