#pragma once
// The track of the analysed [[body]] (intrusion, rod, wheel analyses): at every sample its
// centre of mass, mean velocity, mean contact force since the previous sample, extreme
// coordinate along the last axis and motor state; persistent as "analysis/track" (one row of
// 4 + D + 2 NC numbers per sample), "analysis/track_impulse" and the attribute "track_time".
#include <algorithm>
#include <cmath>
#include <vector>

#include "oobleck/mpm/fields.hpp"
#include "oobleck/run/nodal_fields.hpp"
#include "oobleck/scene/build.hpp"

namespace oobleck::run {

template <class G>
class BodyTrack {
 public:
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;
  using Vd = mpm::Vec<D>;
  using Vn = mpm::Vec<NC>;

  /// One sample: time, extreme coordinate along the last axis (bottom for rod and intruder),
  /// motor ω and torque, centre of mass, mean velocity, and mean contact force over the interval
  /// since the previous sample (impulse / time).
  struct Sample {
    double t = 0.0, bottom = 0.0, omega = 0.0, torque = 0.0;
    Vd centre = Vd::Zero();
    Vn velocity = Vn::Zero(), force = Vn::Zero();
  };

  explicit BodyTrack(const scene::BuiltScene<G>& scene) : scene_(scene) {}

  const std::vector<Sample>& samples() const { return track_; }

  void sample() {
    auto& solver = *scene_.solver;
    const scene::ThirdBody& tb = scene_.analysed_body();
    const BodyTotals<G> totals = body_totals(solver, tb.body);  // (decomposed: every rank's points)
    Sample s;
    s.t = solver.time_s();
    s.centre = centre_of_mass(solver, tb.body);
    s.velocity = totals.mean_velocity();
    s.bottom = totals.lowest_m;
    const Vn J = solver.contact(tb.pair).impulse_sum_N_s;
    s.force = s.t > time_ ? Vn((J - impulse_) / (s.t - time_)) : Vn(solver.contact(tb.pair).force_N);
    impulse_ = J;
    time_ = s.t;
    if (tb.motor >= 0) {
      s.omega = solver.motor(tb.motor).omega_measured_rad_s;
      s.torque = solver.motor(tb.motor).torque_N_m;
    }
    track_.push_back(s);
  }

  /// Persistent state (call with the list's group "analysis"): the samples as "track", one row
  /// of 4 + D + 2 NC numbers each (t, bottom, omega, torque, centre, velocity, force), the
  /// impulse sum at the last sample "track_impulse" and its time, attribute "track_time".
  void declare_fields(mpm::FieldList& list) {
    constexpr std::size_t w = 4 + D + 2 * NC;
    list.add_series(
        "track",
        "rows of t [s], bottom [m], omega [rad/s], torque [N m], centre [m], velocity [m/s], force [N] (2D: torque "
        "and force per m or rad)",
        [this] {
          std::vector<double> flat;
          flat.reserve(track_.size() * w);
          for (const auto& t : track_) {
            flat.insert(flat.end(), {t.t, t.bottom, t.omega, t.torque});
            flat.insert(flat.end(), t.centre.data(), t.centre.data() + D);
            flat.insert(flat.end(), t.velocity.data(), t.velocity.data() + NC);
            flat.insert(flat.end(), t.force.data(), t.force.data() + NC);
          }
          return flat;
        },
        [this](const std::vector<double>& flat) {
          track_.clear();
          for (std::size_t o = 0; o + w <= flat.size(); o += w) {
            Sample t;
            t.t = flat[o];
            t.bottom = flat[o + 1];
            t.omega = flat[o + 2];
            t.torque = flat[o + 3];
            for (int k = 0; k < D; ++k) t.centre[k] = flat[o + 4 + k];
            for (int k = 0; k < NC; ++k) t.velocity[k] = flat[o + 4 + D + k];
            for (int k = 0; k < NC; ++k) t.force[k] = flat[o + 4 + D + NC + k];
            track_.push_back(t);
          }
        });
    list.add_values("track_impulse", {impulse_.data(), NC}, "N s");
    list.add_attribute("track_time", time_, "s");
  }

 private:
  const scene::BuiltScene<G>& scene_;
  std::vector<Sample> track_;
  Vn impulse_ = Vn::Zero();  ///< the contact pair's impulse sum at the previous sample
  double time_ = 0.0;        ///< time of the previous sample
};

/// Lowest coordinate along the last axis of the analysed body's points, lowered by half a point
/// spacing: the flat end of the intruder or rod, not its lowest point.
template <class G>
double body_tip(const scene::SceneConfig& cfg, const scene::BuiltScene<G>& scene) {
  const scene::ThirdBody& tb = scene.analysed_body();
  const double tip = body_totals(*scene.solver, tb.body).lowest_m;  // (decomposed: every rank's points)
  return tip - 0.5 * cfg.grid.cell_size_m / tb.cfg->points_per_cell;
}

}  // namespace oobleck::run
