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

TEST(Wheel, FastWheelStaysAtTheSurface) {
  const HubTrack h = track(1.5, 1.2, 0.65, 0.05, 2.0, 0.005);
  WheelCriteria c;  // L = 2 m, R = 0.15 m, bed surface 0.5 m
  const WheelSummary s = summarize_wheel(h, c);
  EXPECT_NEAR(s.duration_s, 2.0, 1e-12);
  EXPECT_NEAR(s.hub_height_initial_m, 0.65, 1e-15);
  EXPECT_NEAR(s.hub_height_final_m, 0.55, 1e-12);
  EXPECT_NEAR(s.hub_height_min_m, 0.55, 1e-12);
  EXPECT_NEAR(s.hub_height_min_time_s, 2.0, 1e-12);
  EXPECT_NEAR(s.height_loss_m, 0.10, 1e-12);
  EXPECT_NEAR(s.distance_m, 2.4, 1e-12);
  EXPECT_NEAR(s.mean_forward_speed_m_per_s, 1.2, 1e-12);
  EXPECT_TRUE(s.stays_at_surface);
  EXPECT_FALSE(s.sinks);
  EXPECT_FALSE(s.ever_below_surface);
}

TEST(Wheel, SlowWheelSinks) {
  const HubTrack h = track(1.0, 0.05, 0.65, 0.2, 1.5, 0.01);
  const WheelSummary s = summarize_wheel(h, WheelCriteria{});
  EXPECT_NEAR(s.hub_height_final_m, 0.35, 1e-12);
  EXPECT_FALSE(s.stays_at_surface);
  EXPECT_TRUE(s.sinks);
  EXPECT_TRUE(s.ever_below_surface);
  // A wheel that holds its height but does not move forward does not "stay at the surface".
  const WheelSummary still = summarize_wheel(track(1.0, 0.0, 0.65, 0.0, 1.5, 0.01), WheelCriteria{});
  EXPECT_FALSE(still.stays_at_surface);
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
