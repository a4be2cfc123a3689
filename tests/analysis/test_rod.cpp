// S2 rod impact: finite differences on a parabola, force-based acceleration, impact detection,
// displacement vs depth below the rod.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "oobleck/analysis/rod.hpp"
#include "oobleck/core/error.hpp"

using namespace oobleck::analysis;
using oobleck::InputError;

namespace {
// z(t) = z0 + v0 t + a t^2 / 2: a rod moving down (v0 < 0) and decelerated (a > 0).
constexpr double kZ0 = 0.11, kV0 = -1.0, kA = 50.0, kDt = 1e-4;
TimeSeries parabola(std::size_t n) {
  TimeSeries s;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * kDt;
    s.time.push_back(t);
    s.value.push_back(kZ0 + kV0 * t + 0.5 * kA * t * t);
  }
  return s;
}
}  // namespace

TEST(RodImpact, MidpointDifferencesAreExactOnAParabola) {
  const RodKinematics k = rod_kinematics(parabola(200), 5, DifferenceTime::midpoint);
  ASSERT_EQ(k.velocity.size(), 195u);
  ASSERT_EQ(k.acceleration.size(), 190u);
  for (std::size_t i = 0; i < k.velocity.size(); ++i)
    EXPECT_NEAR(k.velocity.value[i], kV0 + kA * k.velocity.time[i], 1e-10);
  EXPECT_NEAR(k.velocity.time[0], 2.5 * kDt, 1e-15);
  for (std::size_t i = 0; i < k.acceleration.size(); ++i) EXPECT_NEAR(k.acceleration.value[i], kA, 1e-6);
  EXPECT_NEAR(k.acceleration.time[0], 5.0 * kDt, 1e-15);
}

TEST(RodImpact, ForwardDifferencesAreFirstOrderWithTheKnownError) {
  // Forward difference over L intervals at t_k: v(t_k) + a L dt / 2.
  for (std::size_t L : {1u, 4u, 10u}) {
    const TimeSeries v = finite_difference(parabola(100), L, DifferenceTime::forward);
    for (std::size_t i = 0; i < v.size(); ++i)
      EXPECT_NEAR(v.value[i] - (kV0 + kA * v.time[i]), kA * static_cast<double>(L) * kDt / 2.0, 1e-9);
    const TimeSeries b = finite_difference(parabola(100), L, DifferenceTime::backward);
    for (std::size_t i = 0; i < b.size(); ++i)
      EXPECT_NEAR(b.value[i] - (kV0 + kA * b.time[i]), -kA * static_cast<double>(L) * kDt / 2.0, 1e-9);
  }
  // The acceleration of a parabola is exact for every placement.
  const RodKinematics k = rod_kinematics(parabola(100), 3, DifferenceTime::forward);
  for (double a : k.acceleration.value) EXPECT_NEAR(a, kA, 1e-6);
}

TEST(RodImpact, NonUniformSampling) {
  TimeSeries s;
  for (double t : {0.0, 0.001, 0.0015, 0.003, 0.0042, 0.005}) {
    s.time.push_back(t);
    s.value.push_back(kZ0 + kV0 * t + 0.5 * kA * t * t);
  }
  const TimeSeries v = finite_difference(s, 2, DifferenceTime::midpoint);
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_NEAR(v.value[i], kV0 + kA * v.time[i], 1e-12);
}

TEST(RodImpact, AccelerationFromForce) {
  // F = m (a + g) for a rod of 0.3 kg decelerating at 200 m/s^2.
  const double m = 0.3, g = 9.81;
  const TimeSeries f{{0.0, 1e-3, 2e-3}, {0.0, m * (200.0 + g), m * (-5.0 + g)}};
  const TimeSeries a = acceleration_from_force(f, m, g);
  EXPECT_NEAR(a.value[0], -g, 1e-12);
  EXPECT_NEAR(a.value[1], 200.0, 1e-12);
  EXPECT_NEAR(a.value[2], -5.0, 1e-12);
  EXPECT_NEAR(acceleration_from_force(f, m, 0.0).value[1], 200.0 + g, 1e-12);
  EXPECT_THROW(acceleration_from_force(f, 0.0), InputError);
}

TEST(RodImpact, PeakDecelerationAndItsTime) {
  TimeSeries a;
  for (int k = 0; k <= 100; ++k) {
    const double t = k * 1e-4;
    a.time.push_back(t);
    a.value.push_back(-9.81 + 500.0 * std::exp(-std::pow((t - 0.003) / 0.0005, 2)));
  }
  const PeakDeceleration p = peak_deceleration(a, -1.0);
  EXPECT_NEAR(p.deceleration_m_per_s2, 500.0 - 9.81, 1e-9);
  EXPECT_NEAR(p.time_s, 0.003, 1e-12);
  EXPECT_EQ(p.index, 30u);
  // For a rod moving up, the deceleration is -a: the largest is gravity.
  EXPECT_NEAR(peak_deceleration(a, 1.0).deceleration_m_per_s2, 9.81, 1e-9);
}

TEST(RodImpact, ImpactTimeFromForceAndFromPosition) {
  // Contact force ramps up from t_i = 1.25 ms at c N/s.
  const double t_i = 1.25e-3, c = 2000.0;
  TimeSeries f;
  for (int k = 0; k <= 40; ++k) {
    const double t = k * 1e-4;
    f.time.push_back(t);
    f.value.push_back(-c * std::max(0.0, t - t_i));  // sign does not matter: |F| is used
  }
  const auto t_f = impact_time_from_force(f, c * 2e-4);
  ASSERT_TRUE(t_f.has_value());
  EXPECT_NEAR(*t_f, t_i + 2e-4, 1e-12);
  const auto t_0 = impact_time_from_force(f, 0.0);
  ASSERT_TRUE(t_0.has_value());
  EXPECT_NEAR(*t_0, 1.2e-3, 1e-12);  // last sample before contact: contact lies in (1.2, 1.3] ms
  EXPECT_FALSE(impact_time_from_force(f, 1e6).has_value());

  const TimeSeries tip = [] {
    TimeSeries s;
    for (int k = 0; k <= 30; ++k) {
      s.time.push_back(k * 7e-4);
      s.value.push_back(0.11 - 1.0 * k * 7e-4);
    }
    return s;
  }();
  const auto t_p = impact_time_from_position(tip, 0.10, -1.0);
  ASSERT_TRUE(t_p.has_value());
  EXPECT_NEAR(*t_p, 0.010, 1e-12);
  EXPECT_FALSE(impact_time_from_position(tip, 0.0, -1.0).has_value());
}

TEST(RodImpact, DisplacementIsLinearInDepthBelowTheRod) {
  // Axisymmetric 100 x 100 mm grid, surface at z = 0.1 m; |dz| = 0.02 - 0.15 depth on the axis.
  GridField2D u;
  u.h = 1e-3;
  u.nx = 11;
  u.ny = 101;
  u.values.resize(u.nx * u.ny);
  for (std::size_t j = 0; j < u.ny; ++j)
    for (std::size_t i = 0; i < u.nx; ++i) {
      const double depth = 0.1 - u.y(j);
      u.at(i, j) = -(0.02 - 0.15 * depth) * (1.0 - 10.0 * u.x(i));  // decays with r
    }
  const DepthProfile p = displacement_below_rod(u, 0.0905, 0.1, -1.0, 0.0);
  ASSERT_EQ(p.depth_m.size(), 92u);  // the tip at 9.5 mm depth, then nodes z = 90 ... 0 mm
  EXPECT_NEAR(p.depth_m.front(), 0.0095, 1e-12);
  EXPECT_NEAR(p.displacement_m.front(), 0.02 - 0.15 * 0.0095, 1e-12);
  EXPECT_NEAR(p.depth_m.back(), 0.1, 1e-12);
  EXPECT_NEAR(p.fit.slope, -0.15, 1e-10);
  EXPECT_NEAR(p.fit.intercept, 0.02, 1e-10);
  EXPECT_NEAR(p.fit.r_squared, 1.0, 1e-12);
  // Down to a given end only.
  EXPECT_EQ(displacement_below_rod(u, 0.0905, 0.1, -1.0, 0.0, 0.05).depth_m.size(), 42u);
  EXPECT_THROW(displacement_below_rod(u, 0.0905, 0.1, -1.0, 0.0, 0.095), InputError);
}

TEST(RodImpact, RejectsBadInput) {
  EXPECT_THROW(finite_difference(parabola(5), 0), InputError);
  EXPECT_THROW(finite_difference(parabola(5), 5), InputError);
  EXPECT_THROW(rod_kinematics(parabola(10), 5), InputError);  // needs 2 L + 1 samples
  TimeSeries bad = parabola(10);
  bad.time[4] = bad.time[3];
  EXPECT_THROW(finite_difference(bad, 1), InputError);
  EXPECT_THROW(peak_deceleration(TimeSeries{}, -1.0), InputError);
  EXPECT_THROW(peak_deceleration(parabola(3), 0.0), InputError);
  EXPECT_THROW(impact_time_from_force(TimeSeries{{0.0, 1.0}, {1.0}}), InputError);
}
