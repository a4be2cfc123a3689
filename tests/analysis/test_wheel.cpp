// S4 wheel: unwrapped distance on the periodic track, verdicts, free surface from phi.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "oobleck/analysis/wheel.hpp"
#include "oobleck/core/error.hpp"

using namespace oobleck::analysis;
using oobleck::InputError;

namespace {
constexpr double kL = 2.0;  // track length [m]

HubTrack track(double x0, double speed, double y0, double sink_rate, double t_end, double dt) {
  HubTrack h;
  for (int k = 0; k * dt <= t_end + 1e-12; ++k) {
    const double t = k * dt;
    const double x = x0 + speed * t;
    h.time_s.push_back(t);
    h.x_m.push_back(x - kL * std::floor(x / kL));  // wrapped into [0, L)
    h.y_m.push_back(y0 - sink_rate * t);
  }
  return h;
}
}  // namespace

TEST(Wheel, UnwrapsThePeriodicTrack) {
  const HubTrack h = track(0.3, 1.7, 0.65, 0.0, 2.0, 0.01);  // travels 3.4 m = 1.7 laps
  const std::vector<double> u = unwrap_periodic(h.x_m, kL);
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], 0.3 + 1.7 * h.time_s[k], 1e-12);
  const HubTrack back = track(0.3, -1.1, 0.65, 0.0, 2.0, 0.01);
  const std::vector<double> ub = unwrap_periodic(back.x_m, kL);
  EXPECT_NEAR(ub.back() - ub.front(), -2.2, 1e-12);
  EXPECT_THROW(unwrap_periodic(h.x_m, 0.0), InputError);
}

TEST(Wheel, FastWheelRunsOnTheSurface) {
  const HubTrack h = track(1.5, 1.2, 0.65, 0.03, 2.0, 0.005);
  WheelCriteria c;  // L = 2 m, R = 0.15 m, bed surface 0.5 m
  const WheelSummary s = summarize_wheel(h, c);
  EXPECT_NEAR(s.duration_s, 2.0, 1e-12);
  EXPECT_NEAR(s.hub_height_initial_m, 0.65, 1e-15);
  EXPECT_NEAR(s.hub_height_final_m, 0.59, 1e-12);
  EXPECT_NEAR(s.hub_height_min_m, 0.59, 1e-12);
  EXPECT_NEAR(s.hub_height_min_time_s, 2.0, 1e-12);
  EXPECT_NEAR(s.height_loss_m, 0.06, 1e-12);
  EXPECT_NEAR(s.distance_m, 2.4, 1e-12);
  EXPECT_NEAR(s.mean_forward_speed_m_per_s, 1.2, 1e-12);
  EXPECT_TRUE(s.runs_on_surface);  // lowest hub 0.59 m >= 0.65 - 0.15/2
  EXPECT_NEAR(s.runs_on_surface_lowest_hub_m, 0.575, 1e-15);
  EXPECT_FALSE(s.sinks);
  EXPECT_FALSE(s.ever_below_surface);
}

TEST(Wheel, RunsAndSinksAreHalfARadiusApart) {
  // A hub that drops 0.1 m (less than one radius, more than half of one) ends above the bed
  // surface: it neither runs on the surface nor sinks. Dropping 0.06 m it runs; 0.16 m, it sinks.
  const WheelCriteria c;  // R = 0.15 m, surface 0.5 m; the hub starts at 0.65 m
  const WheelSummary between = summarize_wheel(track(1.5, 1.2, 0.65, 0.10, 1.0, 0.01), c);
  EXPECT_FALSE(between.runs_on_surface);
  EXPECT_FALSE(between.sinks);
  EXPECT_TRUE(summarize_wheel(track(1.5, 1.2, 0.65, 0.06, 1.0, 0.01), c).runs_on_surface);
  const WheelSummary deep = summarize_wheel(track(1.5, 1.2, 0.65, 0.16, 1.0, 0.01), c);
  EXPECT_TRUE(deep.sinks);
  EXPECT_FALSE(deep.runs_on_surface);
}

TEST(Wheel, SlowWheelSinks) {
  const HubTrack h = track(1.0, 0.05, 0.65, 0.2, 1.5, 0.01);
  const WheelSummary s = summarize_wheel(h, WheelCriteria{});
  EXPECT_NEAR(s.hub_height_final_m, 0.35, 1e-12);
  EXPECT_FALSE(s.runs_on_surface);
  EXPECT_TRUE(s.sinks);
  EXPECT_TRUE(s.ever_below_surface);
  // A wheel that holds its height but does not move forward does not "run on the surface".
  const WheelSummary still = summarize_wheel(track(1.0, 0.0, 0.65, 0.0, 1.5, 0.01), WheelCriteria{});
  EXPECT_FALSE(still.runs_on_surface);
}

TEST(Wheel, RejectsBadTracks) {
  HubTrack h = track(0.3, 1.0, 0.65, 0.0, 1.0, 0.1);
  h.y_m.pop_back();
  EXPECT_THROW(summarize_wheel(h, WheelCriteria{}), InputError);
  h = track(0.3, 1.0, 0.65, 0.0, 1.0, 0.1);
  std::swap(h.time_s[2], h.time_s[3]);
  EXPECT_THROW(summarize_wheel(h, WheelCriteria{}), InputError);
  EXPECT_THROW(summarize_wheel(HubTrack{}, WheelCriteria{}), InputError);
}

TEST(Wheel, FreeSurfaceFromVolumeFraction) {
  // 2 m x 1 m plane-strain grid of 150 x 75 cells; bed surface H(x) = 0.5 + 0.05 sin(pi x),
  // phi falling linearly (over 5 cells) from 0.5 to 0 through 0.1 at H.
  GridField2D phi;
  phi.h = 2.0 / 150.0;
  phi.nx = 151;
  phi.ny = 76;
  phi.values.resize(phi.nx * phi.ny);
  const double ramp = 5.0 * phi.h;
  auto height = [](double x) { return 0.5 + 0.05 * std::sin(std::numbers::pi * x); };
  for (std::size_t j = 0; j < phi.ny; ++j)
    for (std::size_t i = 0; i < phi.nx; ++i)
      phi.at(i, j) = std::clamp(0.1 - 0.5 * (phi.y(j) - height(phi.x(i))) / ramp, 0.0, 0.5);
  // Column 10: empty; column 20: full to the top.
  for (std::size_t j = 0; j < phi.ny; ++j) {
    phi.at(10, j) = 0.0;
    phi.at(20, j) = 0.5;
  }
  const SurfaceProfile s = free_surface(phi, 0.1);
  ASSERT_EQ(s.height_m.size(), 151u);
  for (std::size_t i = 0; i < phi.nx; ++i) {
    if (i == 10) {
      EXPECT_FALSE(s.has_material[i]);
      EXPECT_TRUE(std::isnan(s.height_m[i]));
    } else if (i == 20) {
      EXPECT_NEAR(s.height_m[i], 1.0, 1e-12);
    } else {
      ASSERT_TRUE(s.has_material[i]);
      EXPECT_NEAR(s.height_m[i], height(s.x_m[i]), 1e-12) << "column " << i;
    }
  }
}

namespace {
/// Points 2 × 2 per cell of size h (at h/4 and 3h/4 of each cell), cells [0, nx) × [0, ny) from
/// the origin, with pressure p(x, y, sub) where sub = 0..3 numbers the point within its cell.
template <class P>
void cell_points(int nx, int ny, double h, P p, std::vector<double>& x, std::vector<double>& y,
                 std::vector<double>& v) {
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) {
          const double px = (i + 0.25 + 0.5 * a) * h, py = (j + 0.25 + 0.5 * b) * h;
          x.push_back(px);
          y.push_back(py);
          v.push_back(p(px, py, a + 2 * b));
        }
}
ScatterWindow window(double x_centre, double half_width, double y_max, double cell, double period = 0.0) {
  ScatterWindow w;
  w.x_centre_m = x_centre;
  w.half_width_m = half_width;
  w.y_min_m = 0.0;
  w.y_max_m = y_max;
  w.cell_m = cell;
  w.period_m = period;
  return w;
}
}  // namespace

TEST(Wheel, PressureScatterOfALinearFieldIsItsGradientAcrossACell) {
  // p = p0 + gx x + gy y: each point deviates from its cell's mean (the centre value) by
  // ±gx h/4 ± gy h/4, so the rms deviation is (h/4) sqrt(gx² + gy²) whatever p0.
  const double h = 0.1, gx = 300.0, gy = -500.0;
  std::vector<double> x, y, p;
  cell_points(
      20, 10, h, [&](double px, double py, int) { return 4000.0 + gx * px + gy * py; }, x, y, p);
  const ScatterWindow w = window(1.0, 1.0, 1.0, h);
  const PressureScatter s = pressure_scatter(x, y, p, w);
  EXPECT_EQ(s.points, 800);
  EXPECT_EQ(s.cells, 200);
  EXPECT_NEAR(s.rms_deviation_Pa, 0.25 * h * std::hypot(gx, gy), 1e-9);
  double p2 = 0.0;
  for (double v : p) p2 += v * v;
  EXPECT_NEAR(s.rms_Pa, std::sqrt(p2 / 800.0), 1e-9);
  EXPECT_NEAR(s.relative, s.rms_deviation_Pa / s.rms_Pa, 1e-15);
}

TEST(Wheel, PressureScatterOfPointToPointNoiseIsItsAmplitude) {
  // The ringing pattern: p0 (1 ± eps) alternating from point to point within each cell, cell
  // means p0 — rms deviation eps p0, relative scatter eps / sqrt(1 + eps²).
  const double h = 0.05, p0 = 2500.0, eps = 0.3;
  std::vector<double> x, y, p;
  cell_points(
      8, 6, h, [&](double, double, int sub) { return p0 * (1.0 + ((sub == 0 || sub == 3) ? eps : -eps)); }, x, y, p);
  const ScatterWindow w = window(0.2, 0.2, 0.3, h);
  const PressureScatter s = pressure_scatter(x, y, p, w);
  EXPECT_NEAR(s.rms_deviation_Pa, eps * p0, 1e-9);
  EXPECT_NEAR(s.relative, eps / std::sqrt(1.0 + eps * eps), 1e-12);
}

TEST(Wheel, PressureScatterWindowWrapsAroundThePeriodicTrack) {
  // Track 2 m of 20 cells; a window centred on x = 0 reaches the last two columns through the
  // seam: columns 18, 19, 0, 1 of 10 rows, 4 points each. A point alone in its cell is left out.
  const double h = 0.1;
  std::vector<double> x, y, p;
  cell_points(
      20, 10, h, [](double px, double, int) { return px < 0.4 || px > 1.8 ? 100.0 : 1e6; }, x, y, p);
  x.push_back(0.02);  // outside the grid rows above: its own cell (row 10)
  y.push_back(1.02);
  p.push_back(5e6);
  ScatterWindow w = window(0.0, 0.2, 1.1, h, 2.0);
  const PressureScatter s = pressure_scatter(x, y, p, w);
  EXPECT_EQ(s.points, 160);
  EXPECT_EQ(s.cells, 40);
  EXPECT_DOUBLE_EQ(s.rms_Pa, 100.0);
  EXPECT_DOUBLE_EQ(s.rms_deviation_Pa, 0.0);
  w.period_m = 0.0;  // not periodic: only columns 0 and 1
  EXPECT_EQ(pressure_scatter(x, y, p, w).points, 80);
}

TEST(Wheel, PressureScatterRejectsBadInput) {
  const std::vector<double> a = {0.1, 0.2}, b = {0.1};
  ScatterWindow w;
  w.half_width_m = 1.0;
  w.y_max_m = 1.0;
  w.cell_m = 0.1;
  EXPECT_THROW(pressure_scatter(a, b, a, w), InputError);
  EXPECT_THROW(pressure_scatter(a, a, a, ScatterWindow{}), InputError);  // cell size 0
  const std::vector<double> pair = {0.11, 0.12}, p = {1.0, 3.0};
  EXPECT_EQ(pressure_scatter(pair, pair, p, w).points, 2);  // two points in one cell
  EXPECT_DOUBLE_EQ(pressure_scatter(pair, pair, p, w).rms_deviation_Pa, 1.0);
  w.x_centre_m = 5.0;  // nothing in the window: no sample, not an error
  EXPECT_EQ(pressure_scatter(pair, pair, p, w).points, 0);
}

TEST(Wheel, PooledPressureScatterWeighsEachSampleByItsPoints) {
  // Two samples: 100 points with deviations 3 Pa around rms 10 Pa, 300 points with 1 Pa around
  // 20 Pa: pooled rms deviation sqrt((100·9 + 300·1)/400), rms sqrt((100·100 + 300·400)/400).
  PressureScatter a, b, empty;
  a.points = 100;
  a.cells = 25;
  a.rms_deviation_Pa = 3.0;
  a.rms_Pa = 10.0;
  b.points = 300;
  b.cells = 75;
  b.rms_deviation_Pa = 1.0;
  b.rms_Pa = 20.0;
  const std::vector<PressureScatter> v = {a, empty, b};
  const PressureScatter r = pool(v);
  EXPECT_EQ(r.points, 400);
  EXPECT_EQ(r.cells, 100);
  EXPECT_DOUBLE_EQ(r.rms_deviation_Pa, std::sqrt(1200.0 / 400.0));
  EXPECT_DOUBLE_EQ(r.rms_Pa, std::sqrt(130000.0 / 400.0));
  EXPECT_DOUBLE_EQ(r.relative, std::sqrt(1200.0 / 130000.0));
  EXPECT_EQ(pool(std::vector<PressureScatter>{}).points, 0);
}
