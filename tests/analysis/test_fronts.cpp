// S3 intrusion fronts on synthetic u_z fields whose fronts move at known speeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "oobleck/analysis/fronts.hpp"
#include "oobleck/core/error.hpp"

using namespace oobleck::analysis;
using oobleck::InputError;

namespace {

constexpr double kH = 1e-3;         // cell size [m]
constexpr double kSurface = 0.030;  // bed surface = tip z at t = 0 [m]
constexpr double kRadius = 0.005;   // intruder radius [m]
constexpr double kV0 = -0.2;        // intruder velocity along z (downward) [m/s]
constexpr double kRamp = 4e-3;      // width of the linear ramp of u_z/v_0 across a front [m]

double ramp(double s, double s_front) { return std::clamp(0.5 - (s - s_front) / kRamp, 0.0, 1.0); }

// The (r, z) grid of scenes.md S3: r 0-50 mm, z 0-35 mm, 1 mm cells.
GridField2D empty_grid() {
  GridField2D f;
  f.h = kH;
  f.nx = 51;
  f.ny = 36;
  f.values.assign(f.nx * f.ny, 0.0);
  return f;
}

struct Synthetic {
  double k_l, k_t;       // propagation factors of the synthetic fronts
  double ahead0 = 3e-3;  // front ahead of the tip at t = 0 [m]
  double edge0 = 3e-3;   // transverse front beyond the edge at t = 0 [m]
  bool tanh_profile = false;
  double tip_z(double t) const { return kSurface + kV0 * t; }
  double ahead(double t) const { return ahead0 + k_l * std::abs(kV0) * t; }
  double edge(double t) const { return edge0 + k_t * std::abs(kV0) * t; }
  double g_line(double s, double s_front) const {
    return tanh_profile ? 0.5 * (1.0 - std::tanh((s - s_front) / (2.0 * kH))) : ramp(s, s_front);
  }
  // u_z = v_0 min(G_l(ahead of the tip), G_t(r)), G = 1 behind the tip (inside the intruder).
  IntrusionFrame frame(double t, double scale = kV0) const {
    IntrusionFrame fr;
    fr.time_s = t;
    fr.tip_z_m = tip_z(t);
    fr.field = empty_grid();
    for (std::size_t j = 0; j < fr.field.ny; ++j)
      for (std::size_t i = 0; i < fr.field.nx; ++i) {
        const double s = fr.tip_z_m - fr.field.y(j);
        const double gl = s <= 0.0 ? 1.0 : g_line(s, ahead(t));
        const double gt = g_line(fr.field.x(i) - kRadius, edge(t));
        fr.field.at(i, j) = scale * std::min(gl, gt);
      }
    return fr;
  }
  std::vector<IntrusionFrame> run(double t_end, double dt, double scale = kV0) const {
    std::vector<IntrusionFrame> frames;
    for (int k = 0; k * dt <= t_end + 1e-12; ++k) frames.push_back(frame(k * dt, scale));
    return frames;
  }
};

FrontGeometry geometry() {
  FrontGeometry g;
  g.direction = -1.0;
  g.intruder_radius_m = kRadius;
  return g;
}

}  // namespace

TEST(IntrusionFronts, PositionsMatchSyntheticFrontsToTheCell) {
  const Synthetic syn{2.0, 1.0};
  for (double t : {0.0, 0.0031, 0.0077}) {
    const FrontPosition p = measure_front(syn.frame(t).field, syn.tip_z(t), velocity_front(kV0), geometry());
    ASSERT_TRUE(p.longitudinal_found);
    ASSERT_TRUE(p.transverse_found);
    EXPECT_FALSE(p.longitudinal_at_boundary);
    EXPECT_NEAR(p.longitudinal_ahead_m, syn.ahead(t), 0.01 * kH);
    EXPECT_NEAR(p.longitudinal_z_m, syn.tip_z(t) - syn.ahead(t), 0.01 * kH);
    EXPECT_NEAR(p.transverse_from_edge_m, syn.edge(t), 0.01 * kH);
    EXPECT_NEAR(p.transverse_r_m, kRadius + syn.edge(t), 0.01 * kH);
  }
}

TEST(IntrusionFronts, SmoothTanhFrontIsFoundWithinOnePercentOfACell) {
  Synthetic syn{2.0, 1.0};
  syn.tanh_profile = true;
  syn.ahead0 = 6e-3;
  syn.edge0 = 6e-3;
  for (double t : {0.0, 0.0023, 0.0061}) {
    const FrontPosition p = measure_front(syn.frame(t).field, syn.tip_z(t), velocity_front(kV0), geometry());
    EXPECT_NEAR(p.longitudinal_ahead_m, syn.ahead(t), 0.01 * kH) << "t = " << t;
    EXPECT_NEAR(p.transverse_from_edge_m, syn.edge(t), 0.01 * kH) << "t = " << t;
  }
}

TEST(IntrusionFronts, RecoversPropagationFactors) {
  const Synthetic syn{2.0, 1.0};
  const FrontSeries series = measure_front_series(syn.run(0.010, 5e-4), velocity_front(kV0), geometry());
  ASSERT_EQ(series.frames.size(), 21u);
  EXPECT_DOUBLE_EQ(series.reference_z_m, kSurface);
  const FrontSpeeds s = front_speeds(series, kV0);
  EXPECT_NEAR(s.v_fl_m_per_s, 3.0 * 0.2, 1e-9);
  EXPECT_NEAR(s.v_ft_m_per_s, 1.0 * 0.2, 1e-9);
  EXPECT_NEAR(s.k_l, 2.0, 1e-8);
  EXPECT_NEAR(s.k_t, 1.0, 1e-8);
  EXPECT_NEAR(s.ratio, 2.0, 1e-8);
  EXPECT_LT(s.ratio_stderr, 1e-6);
  EXPECT_NEAR(s.longitudinal.r_squared, 1.0, 1e-12);
  EXPECT_EQ(s.longitudinal.points, 21u);
  // Distance ahead of the tip grows at (v_fl - v_0) = k_l v_0.
  const LinearFit ahead = fit_line(series.longitudinal_ahead());
  EXPECT_NEAR(ahead.slope / 0.2, 2.0, 1e-8);
  const LinearFit edge = fit_line(series.transverse_from_edge());
  EXPECT_NEAR(edge.slope / 0.2, 1.0, 1e-8);
  EXPECT_NEAR(edge.intercept, 3e-3, 1e-10);
}

TEST(IntrusionFronts, ToFarthestFitsTheAdvancingPhaseOfAFrontThatRecedes) {
  // k_l = 3, k_t = 1.5 (ratio 2) for 4 ms, then both fronts fall back (k_l = -0.5: the front still
  // moves down in the lab frame, at half the tip's speed, while the tip catches up; k_t = -0.5) for
  // 6 ms: the whole-run fit mixes the two phases; the fit up to the farthest extent (measured
  // ahead of the tip) recovers the advancing speeds exactly, both fronts over the same window.
  const double tp = 4e-3, dt = 5e-4;
  const Synthetic run{3.0, 1.5};
  Synthetic back{-0.5, -0.5};
  back.ahead0 = run.ahead0 + (run.k_l - back.k_l) * 0.2 * tp;
  back.edge0 = run.edge0 + (run.k_t - back.k_t) * 0.2 * tp;
  std::vector<IntrusionFrame> frames;
  for (int k = 0; k * dt <= 0.010 + 1e-12; ++k)
    frames.push_back(k * dt <= tp + 1e-12 ? run.frame(k * dt) : back.frame(k * dt));
  const FrontSeries series = measure_front_series(frames, velocity_front(kV0), geometry());
  const FrontSpeeds whole = front_speeds(series, kV0);
  EXPECT_LT(whole.k_l, 1.0);  // the falling-back phase pulls the whole-run fit down
  FrontFitOptions o;
  o.to_farthest = true;
  const FrontSpeeds adv = front_speeds(series, kV0, o);
  EXPECT_NEAR(adv.k_l, 3.0, 1e-8);
  EXPECT_NEAR(adv.k_t, 1.5, 1e-8);
  EXPECT_NEAR(adv.ratio, 2.0, 1e-8);
  EXPECT_NEAR(adv.longitudinal_t_end_s, tp, 1e-12);
  EXPECT_NEAR(adv.transverse_t_end_s, tp, 1e-12);
  // The longitudinal front alone falls back (k_t stays 1.5): both fits still end at its farthest.
  Synthetic back_l{-0.5, 1.5};
  back_l.ahead0 = back.ahead0;
  back_l.edge0 = run.edge0;
  frames.clear();
  for (int k = 0; k * dt <= 0.010 + 1e-12; ++k)
    frames.push_back(k * dt <= tp + 1e-12 ? run.frame(k * dt) : back_l.frame(k * dt));
  const FrontSpeeds one = front_speeds(measure_front_series(frames, velocity_front(kV0), geometry()), kV0, o);
  EXPECT_NEAR(one.transverse_t_end_s, tp, 1e-12);
  EXPECT_NEAR(one.k_t, 1.5, 1e-8);
  // Fronts that keep advancing are fitted whole.
  const FrontSeries steady = measure_front_series(run.run(0.010, dt), velocity_front(kV0), geometry());
  const FrontSpeeds all = front_speeds(steady, kV0), far = front_speeds(steady, kV0, o);
  EXPECT_EQ(far.longitudinal.points, all.longitudinal.points);
  EXPECT_EQ(far.k_l, all.k_l);
}

TEST(IntrusionFronts, StructureFrontUsesTheSameSearch) {
  // f in [0, 1] with the same geometry as u_z/v_0: the f >= 0.5 front is the same front.
  const Synthetic syn{1.6, 0.8};
  const FrontSeries series = measure_front_series(syn.run(0.010, 5e-4, 1.0), scalar_front(0.5), geometry());
  const FrontSpeeds s = front_speeds(series, kV0);
  EXPECT_NEAR(s.k_l, 1.6, 1e-8);
  EXPECT_NEAR(s.k_t, 0.8, 1e-8);
  EXPECT_NEAR(s.ratio, 2.0, 1e-8);
}

TEST(IntrusionFronts, FitStopsBeforeTheFrontMeetsTheBottom) {
  // k_l = 5: the front is at z = 27 mm - 1.2 m/s t and reaches the bottom (z = 0) at 22.5 ms.
  const Synthetic syn{5.0, 1.0};
  const FrontSeries series = measure_front_series(syn.run(0.030, 5e-4), velocity_front(kV0), geometry());
  EXPECT_TRUE(series.frames.back().longitudinal_at_boundary);
  EXPECT_DOUBLE_EQ(series.longitudinal_wall_z_m, 0.0);
  FrontFitOptions o;
  o.wall_margin_m = 2e-3;
  const FrontSpeeds s = front_speeds(series, kV0, o);
  EXPECT_NEAR(s.k_l, 5.0, 1e-8);
  EXPECT_NEAR(s.k_t, 1.0, 1e-8);
  // Cut at the first frame with z_front <= 2 mm: 27 mm - 1.2 t <= 2 mm -> t >= 20.83 ms.
  EXPECT_NEAR(s.longitudinal_t_end_s, 0.0205, 1e-12);
  EXPECT_NEAR(s.transverse_t_end_s, 0.030, 1e-12);
  // Without a margin only the frames whose front reached the bottom node are dropped.
  const FrontSpeeds uncut = front_speeds(series, kV0);
  EXPECT_GE(uncut.longitudinal_t_end_s, 0.022 - 1e-12);
  EXPECT_LE(uncut.longitudinal_t_end_s, 0.0225 + 1e-12);
  EXPECT_NEAR(uncut.k_l, 5.0, 1e-8);
  // A time window restricts the fit.
  o.t_begin_s = 0.00499;
  o.t_end_s = 0.01001;
  const FrontSpeeds w = front_speeds(series, kV0, o);
  EXPECT_EQ(w.longitudinal.points, 11u);
  EXPECT_NEAR(w.longitudinal_t_begin_s, 0.005, 1e-12);
}

TEST(IntrusionFronts, NoFrontBeforeThePlugForms) {
  Synthetic syn{2.0, 1.0};
  IntrusionFrame fr = syn.frame(0.002);
  for (double& v : fr.field.values) v *= 0.3;  // u_z < 0.5 v_0 everywhere
  const FrontPosition p = measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), geometry());
  EXPECT_FALSE(p.longitudinal_found);
  EXPECT_FALSE(p.transverse_found);
  EXPECT_DOUBLE_EQ(p.longitudinal_ahead_m, 0.0);
  EXPECT_DOUBLE_EQ(p.transverse_r_m, kRadius);
}

TEST(IntrusionFronts, TipGapSkipsEmptyNodesInsideTheIntruder) {
  // Tip at 29.7 mm; the nodes inside the intruder (z > tip, r <= R) carry no material: u_z = 0.
  const Synthetic syn{2.0, 1.0};
  IntrusionFrame fr = syn.frame(0.0015);
  ASSERT_NEAR(fr.tip_z_m, 0.0297, 1e-12);
  for (std::size_t j = 0; j < fr.field.ny; ++j)
    for (std::size_t i = 0; i < fr.field.nx; ++i)
      if (fr.field.y(j) > fr.tip_z_m && fr.field.x(i) <= kRadius + 1e-12) fr.field.at(i, j) = 0.0;
  FrontGeometry g = geometry();
  const FrontPosition at_tip = measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), g);
  EXPECT_FALSE(at_tip.longitudinal_found);  // 0.3 x 1 + 0.7 x 0 interpolated at the tip
  EXPECT_FALSE(at_tip.transverse_found);    // same at r = R on the tip-depth line
  g.tip_gap_m = 0.5e-3;                     // longitudinal search from 29.2 mm
  g.transverse_offset_m = 0.5e-3;           // transverse line at 29.2 mm
  const FrontPosition gap = measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), g);
  ASSERT_TRUE(gap.longitudinal_found);
  EXPECT_NEAR(gap.longitudinal_ahead_m, syn.ahead(0.0015), 0.01 * kH);
  EXPECT_NEAR(gap.transverse_from_edge_m, syn.edge(0.0015), 0.01 * kH);
  g.tip_gap_m = -1e-3;
  EXPECT_THROW(measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), g), InputError);
}

TEST(IntrusionFronts, FarthestSearchSkipsAGap) {
  // Along the axis: plug, a noisy dip below the threshold, then another patch above it.
  Synthetic syn{2.0, 1.0};
  IntrusionFrame fr = syn.frame(0.0);
  const std::size_t j_patch = 20;  // tip at z = 30 mm; front at 27 mm; patch at z = 18-22 mm
  for (std::size_t j = j_patch - 2; j <= j_patch + 2; ++j) fr.field.at(0, j) = kV0 * 0.9;
  FrontGeometry g = geometry();
  const FrontPosition contiguous = measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), g);
  EXPECT_NEAR(contiguous.longitudinal_ahead_m, 3e-3, 1e-12);  // the patch is not connected to the plug
  g.search = FrontSearch::farthest;
  const FrontPosition farthest = measure_front(fr.field, fr.tip_z_m, velocity_front(kV0), g);
  // Deepest node with g >= 0.5 is j = 18 (z = 18 mm, g = 0.9); next node j = 17 has g = 0.
  EXPECT_NEAR(farthest.longitudinal_z_m, 0.018 - (0.9 - 0.5) / 0.9 * kH, 1e-12);
}

TEST(IntrusionFronts, TimeFilterIsACenteredMovingAverage) {
  const Synthetic syn{2.0, 1.0};
  std::vector<IntrusionFrame> frames = syn.run(0.004, 1e-3);
  // Replace the fields by a field linear in time: the centered average reproduces it inside.
  for (IntrusionFrame& f : frames)
    for (std::size_t n = 0; n < f.field.values.size(); ++n)
      f.field.values[n] = 1.0 + 100.0 * f.time_s + 1e-3 * static_cast<double>(n);
  const std::vector<IntrusionFrame> out = time_filter(frames, 3);
  ASSERT_EQ(out.size(), frames.size());
  for (std::size_t k = 1; k + 1 < out.size(); ++k)
    for (std::size_t n = 0; n < out[k].field.values.size(); n += 97)
      EXPECT_NEAR(out[k].field.values[n], frames[k].field.values[n], 1e-12);
  // First frame: mean of frames 0 and 1.
  EXPECT_NEAR(out[0].field.values[5], 0.5 * (frames[0].field.values[5] + frames[1].field.values[5]), 1e-12);
  EXPECT_DOUBLE_EQ(out[2].tip_z_m, frames[2].tip_z_m);
  EXPECT_THROW(time_filter(frames, 2), InputError);
  EXPECT_THROW(time_filter(frames, 0), InputError);
  EXPECT_THROW(time_filter({}, 1), InputError);
}

TEST(IntrusionFronts, FilteringKeepsFrontSpeedsOfSteadilyMovingFronts) {
  const Synthetic syn{2.0, 1.0};
  const FrontSeries series = measure_front_series(syn.run(0.010, 5e-4), velocity_front(kV0), geometry(), 5);
  FrontFitOptions o;
  o.t_begin_s = 0.002;  // skip the truncated windows at the start
  o.t_end_s = 0.008;
  const FrontSpeeds s = front_speeds(series, kV0, o);
  // Averaging a front moving by < 1 cell over the window: speeds within a few percent.
  EXPECT_NEAR(s.k_l, 2.0, 0.1);
  EXPECT_NEAR(s.k_t, 1.0, 0.05);
}

TEST(IntrusionFronts, FactorsPropagateUncertainty) {
  LinearFit l, t;
  l.slope = 0.6;
  l.slope_stderr = 0.02;
  t.slope = 0.2;
  t.slope_stderr = 0.01;
  const FrontSpeeds s = front_factors(l, t, -0.2);
  EXPECT_NEAR(s.k_l, 2.0, 1e-14);
  EXPECT_NEAR(s.k_t, 1.0, 1e-14);
  EXPECT_NEAR(s.k_l_stderr, 0.1, 1e-14);
  EXPECT_NEAR(s.k_t_stderr, 0.05, 1e-14);
  EXPECT_NEAR(s.ratio, 2.0, 1e-14);
  EXPECT_NEAR(s.ratio_stderr, std::sqrt(0.1 * 0.1 + 0.1 * 0.1), 1e-14);
  t.slope = 0.0;
  EXPECT_TRUE(std::isnan(front_factors(l, t, 0.2).ratio));
  EXPECT_THROW(front_factors(l, t, 0.0), InputError);
}

TEST(IntrusionFronts, RejectsBadInput) {
  const Synthetic syn{2.0, 1.0};
  std::vector<IntrusionFrame> frames = syn.run(0.002, 1e-3);
  EXPECT_THROW(measure_front_series({}, velocity_front(kV0), geometry()), InputError);
  std::vector<IntrusionFrame> backwards = frames;
  std::swap(backwards[0].time_s, backwards[1].time_s);
  EXPECT_THROW(measure_front_series(backwards, velocity_front(kV0), geometry()), InputError);
  std::vector<IntrusionFrame> mixed = frames;
  mixed[1].field.values.pop_back();
  EXPECT_THROW(measure_front_series(mixed, velocity_front(kV0), geometry()), InputError);
  FrontGeometry g = geometry();
  g.direction = 0.5;
  EXPECT_THROW(measure_front(frames[0].field, frames[0].tip_z_m, velocity_front(kV0), g), InputError);
  EXPECT_THROW(measure_front(frames[0].field, 0.05, velocity_front(kV0), geometry()), InputError);  // tip above grid
  EXPECT_THROW(velocity_front(0.0), InputError);
  // Too few points to fit.
  const FrontSeries series = measure_front_series(frames, velocity_front(kV0), geometry());
  FrontFitOptions o;
  o.min_points = 5;
  EXPECT_THROW(front_speeds(series, kV0, o), InputError);
}

TEST(IntrusionFronts, FilterOverOneRingingPeriodRemovesIt) {
  // Elastic ringing: a uniform oscillation of u_z/v_0 with amplitude 0.1 and a period of exactly
  // 5 output frames moves the 0.5 contour by +-0.4 mm. A 5-frame window cancels it.
  const Synthetic syn{2.0, 1.0};
  std::vector<IntrusionFrame> frames = syn.run(0.012, 5e-4);
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (double& v : frames[k].field.values)
      v += kV0 * 0.1 * std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / 5.0 + 0.3);
  FrontFitOptions o;
  o.t_begin_s = 0.00099;  // frames with a complete window
  o.t_end_s = 0.01101;
  const FrontSpeeds raw = front_speeds(measure_front_series(frames, velocity_front(kV0), geometry()), kV0, o);
  EXPECT_GT(raw.k_l_stderr, 1e-3);
  EXPECT_GT(raw.ratio_stderr, 1e-3);
  const FrontSpeeds filtered = front_speeds(measure_front_series(frames, velocity_front(kV0), geometry(), 5), kV0, o);
  EXPECT_NEAR(filtered.k_l, 2.0, 1e-8);
  EXPECT_NEAR(filtered.k_t, 1.0, 1e-8);
  EXPECT_LT(filtered.ratio_stderr, 1e-6);
}
