// S1 annular shear: Newtonian profile, profile extraction at bob angles, a rigid band growing at a
// known speed, flow stop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "oobleck/analysis/annular.hpp"
#include "oobleck/core/error.hpp"

using namespace oobleck::analysis;
using oobleck::InputError;

namespace {
constexpr double kR0 = 0.0125, kRo = 0.0485, kUi = 0.084, kH = 1e-3;

AnnularGeometry geometry() {
  AnnularGeometry g;
  g.bob_radius_m = kR0;
  g.outer_radius_m = kRo;
  g.bob_speed_m_per_s = kUi;
  g.sample_z_m = 0.0035;
  return g;
}

// scenes.md S1 grid offset to r_0: 36 cells in r; a few rows in z are enough here.
GridField2D grid() {
  GridField2D f;
  f.origin_x = kR0;
  f.h = kH;
  f.nx = 37;
  f.ny = 5;
  f.values.assign(f.nx * f.ny, 0.0);
  return f;
}

double newtonian(double r) { return kUi * kR0 * (kRo * kRo / r - r) / (kRo * kRo - kR0 * kR0); }

// Rigid rotation out to r_f, then v/(omega r) falls linearly (width 4 mm) through 0.5 at r_f.
ShearFrame band_frame(double t, double r_front) {
  ShearFrame fr;
  fr.time_s = t;
  fr.v_theta = grid();
  const double omega = kUi / kR0;
  for (std::size_t j = 0; j < fr.v_theta.ny; ++j)
    for (std::size_t i = 0; i < fr.v_theta.nx; ++i) {
      const double r = fr.v_theta.x(i);
      fr.v_theta.at(i, j) = omega * r * std::clamp(0.5 - (r - r_front) / 4e-3, 0.0, 1.0);
    }
  return fr;
}
}  // namespace

TEST(AnnularShear, NewtonianProfileMeetsBothWalls) {
  const NewtonianAnnulus n = newtonian_annulus(kR0, kUi, kRo);
  EXPECT_NEAR(n.v_theta(kR0), kUi, 1e-15);
  EXPECT_NEAR(n.v_theta(kRo), 0.0, 1e-15);
  for (double r : {0.015, 0.03, 0.045}) EXPECT_NEAR(n.v_theta(r), newtonian(r), 1e-15);
  // Torque balance: r^2 tau_r_theta = const, tau ~ r d(v/r)/dr = -2 B / r^2.
  EXPECT_LT(n.A_per_s, 0.0);
  EXPECT_GT(n.B_m2_per_s, 0.0);
  EXPECT_THROW(newtonian_annulus(kRo, kUi, kR0), InputError);
}

TEST(AnnularShear, DistanceFromNewtonianProfile) {
  std::vector<double> r, v;
  for (int i = 0; i <= 36; ++i) {
    r.push_back(kR0 + i * kH);
    v.push_back(newtonian(r.back()) / kUi);
  }
  EXPECT_NEAR(newtonian_distance(r, v, kR0, kRo), 0.0, 1e-14);
  for (double& x : v) x += 0.03;
  EXPECT_NEAR(newtonian_distance(r, v, kR0, kRo), 0.03, 1e-12);
  EXPECT_THROW(newtonian_distance(r, std::vector<double>(3, 0.0), kR0, kRo), InputError);
}

TEST(AnnularShear, ProfilesAtBobAnglesInterpolateInTime) {
  // v_theta = Newtonian(r) * t / 0.05 s, frames every 2 ms: linear in time, so exact.
  std::vector<ShearFrame> frames;
  for (int k = 0; k <= 25; ++k) {
    ShearFrame fr;
    fr.time_s = k * 2e-3;
    fr.v_theta = grid();
    for (std::size_t j = 0; j < fr.v_theta.ny; ++j)
      for (std::size_t i = 0; i < fr.v_theta.nx; ++i)
        fr.v_theta.at(i, j) = newtonian(fr.v_theta.x(i)) * fr.time_s / 0.05;
    frames.push_back(fr);
  }
  const AnnularGeometry g = geometry();
  const std::vector<ShearProfile> p = surface_profiles(frames, g, {0.0, 0.1, 0.2, 0.31});
  ASSERT_EQ(p.size(), 4u);
  for (const ShearProfile& q : p) {
    EXPECT_NEAR(q.time_s, q.angle_rad * kR0 / kUi, 1e-15);
    ASSERT_EQ(q.r_m.size(), 37u);
    for (std::size_t i = 0; i < q.r_m.size(); ++i)
      EXPECT_NEAR(q.v_over_ui[i], newtonian(q.r_m[i]) / kUi * q.time_s / 0.05, 1e-12);
  }
  // theta = 0.31 rad -> t = 46.1 ms: profile = 0.922 x Newtonian, distance 0.078 x |N/u_i|_2.
  EXPECT_GT(newtonian_distance(p[3], g), 0.0);
  EXPECT_LT(newtonian_distance(p[3], g), newtonian_distance(p[1], g));
  EXPECT_THROW(surface_profiles(frames, g, {0.5}), InputError);  // t = 74 ms > last frame
}

TEST(AnnularShear, RigidBandGrowsAtAKnownSpeed) {
  // r_f = r_0 + 2 mm + 0.05 m/s t: reaches the outer wall (48.5 mm) at t = 0.68 s.
  std::vector<ShearFrame> frames;
  for (int k = 0; k <= 40; ++k) {
    const double t = k * 0.02;
    frames.push_back(band_frame(t, kR0 + 2e-3 + 0.05 * t));
  }
  const AnnularGeometry g = geometry();
  const std::vector<ShearFront> fronts = jammed_front_series(frames, g);
  for (std::size_t k = 0; k < 30; ++k) {
    ASSERT_TRUE(fronts[k].found);
    EXPECT_NEAR(fronts[k].radius_m, kR0 + 2e-3 + 0.05 * frames[k].time_s, 0.01 * kH);
  }
  EXPECT_TRUE(fronts.back().at_wall);
  FrontFitOptions o;
  o.wall_margin_m = 2.5e-3;
  const LinearFit fit = front_speed(fronts, g, o);
  EXPECT_NEAR(fit.slope, 0.05, 1e-9);
  EXPECT_NEAR(fit.r_squared, 1.0, 1e-12);
  EXPECT_EQ(fit.points, 32u);  // t = 0 ... 0.62 s (r_f = 45.5 mm); at 0.64 s the front is 2 mm from the wall
  EXPECT_EQ(front_radius_series(fronts).size(), 41u);

  const FlowStop stop = flow_stop_time(frames, g, 1e-6, 0.5e-3);
  ASSERT_TRUE(stop.time_s.has_value());
  EXPECT_NEAR(*stop.time_s, 0.68, 1e-12);
  EXPECT_TRUE(stop.by_front);
  EXPECT_FALSE(stop.by_velocity);
}

TEST(AnnularShear, FlowStopsWhenTheGapComesToRest) {
  std::vector<ShearFrame> frames;
  for (int k = 0; k <= 10; ++k) {
    ShearFrame fr;
    fr.time_s = 0.1 * k;
    fr.v_theta = grid();
    for (std::size_t j = 0; j < fr.v_theta.ny; ++j) {
      fr.v_theta.at(0, j) = kUi;  // the bob keeps its prescribed speed
      for (std::size_t i = 1; i < fr.v_theta.nx; ++i) fr.v_theta.at(i, j) = k < 3 ? newtonian(fr.v_theta.x(i)) : 1e-9;
    }
    frames.push_back(fr);
  }
  const FlowStop stop = flow_stop_time(frames, geometry(), 1e-6);
  ASSERT_TRUE(stop.time_s.has_value());
  EXPECT_NEAR(*stop.time_s, 0.3, 1e-12);
  EXPECT_TRUE(stop.by_velocity);
  EXPECT_FALSE(stop.by_front);
  EXPECT_FALSE(
      flow_stop_time(std::vector<ShearFrame>(frames.begin(), frames.begin() + 3), geometry(), 1e-6).time_s.has_value());
}

TEST(AnnularShear, OuterHalfRotationAndItsArrest) {
  // Rigid rotation at a fraction s(t) of the bob's angular velocity: the outer half's rotation is
  // s(t) exactly. s rises to 0.6 at t = 0.5 s, then falls linearly to 0 at t = 1 s: below 10% of
  // the peak (0.06) first at the frame after t = 0.95 s, i.e. t = 0.96 s (frames every 0.04 s).
  const double omega = kUi / kR0;
  auto s_of_t = [](double t) { return t <= 0.5 ? 1.2 * t : 0.6 * (1.0 - t) / 0.5; };
  std::vector<ShearFrame> frames;
  for (int k = 0; k <= 25; ++k) {
    ShearFrame fr;
    fr.time_s = 0.04 * k;
    fr.v_theta = grid();
    for (std::size_t j = 0; j < fr.v_theta.ny; ++j)
      for (std::size_t i = 0; i < fr.v_theta.nx; ++i) fr.v_theta.at(i, j) = s_of_t(fr.time_s) * omega * fr.v_theta.x(i);
    frames.push_back(fr);
  }
  const TimeSeries outer = outer_rotation_series(frames, geometry());
  ASSERT_EQ(outer.size(), frames.size());
  for (std::size_t k = 0; k < outer.size(); ++k) EXPECT_NEAR(outer.value[k], s_of_t(frames[k].time_s), 1e-12);
  const OuterArrest a = outer_arrest(outer, 0.1);
  EXPECT_NEAR(a.peak, 0.6 * 0.48 / 0.5, 1e-12);  // the frame nearest the peak: t = 0.48 s (s = 0.576)
  EXPECT_NEAR(a.peak_time_s, 0.48, 1e-12);
  ASSERT_TRUE(a.arrest_time_s.has_value());
  EXPECT_NEAR(*a.arrest_time_s, 0.96, 1e-12);  // s(0.96) = 0.048 < 0.0576; s(0.92) = 0.096
  EXPECT_NEAR(a.final_value, 0.0, 1e-12);
  // Without the fall there is no arrest; the band of RigidBandGrowsAtAKnownSpeed never reaches
  // the outer half (r >= 30.5 mm) in its first frame, so that frame's rotation is 0.
  EXPECT_FALSE(outer_arrest(TimeSeries{{0.0, 1.0}, {0.1, 0.2}}).arrest_time_s.has_value());
  EXPECT_NEAR(outer_rotation_series({band_frame(0.0, kR0 + 2e-3)}, geometry()).value[0], 0.0, 1e-15);
  EXPECT_THROW(outer_arrest(outer, 1.5), InputError);
}

TEST(AnnularShear, StructureFrontFollowsTheSpreadOfF) {
  // f = 0.3 out to r_s, then falling linearly to 0 over 6 mm: f = 0.15 (the threshold) exactly
  // 3 mm beyond r_s. r_s = r_0 + 0.03 m/s t reaches the wall's last 1 mm margin (f = 0.15 at
  // r >= 47.5 mm) at t = (47.5 - 3 - 12.5) mm / 0.03 m/s = 1.0667 s.
  auto frame = [](double t) {
    ShearFrame fr = band_frame(t, kR0 + 2e-3);
    fr.f = grid();
    const double r_s = kR0 + 0.03 * t;
    for (std::size_t j = 0; j < fr.f.ny; ++j)
      for (std::size_t i = 0; i < fr.f.nx; ++i)
        fr.f.at(i, j) = 0.3 * std::clamp(1.0 - (fr.f.x(i) - r_s) / 6e-3, 0.0, 1.0);
    return fr;
  };
  std::vector<ShearFrame> frames;
  for (int k = 0; k <= 14; ++k) frames.push_back(frame(0.1 * k));
  const AnnularGeometry g = geometry();
  const std::vector<ShearFront> fronts = structure_front_series(frames, g, 0.15);
  for (std::size_t k = 0; k < 11; ++k) {
    ASSERT_TRUE(fronts[k].found);
    EXPECT_NEAR(fronts[k].radius_m, kR0 + 3e-3 + 0.03 * frames[k].time_s, 1e-12);
  }
  const auto t_wall = front_at_wall_time(fronts, g, 1e-3);
  ASSERT_TRUE(t_wall.has_value());
  EXPECT_NEAR(*t_wall, 1.1, 1e-12);    // the first frame at or after 1.0667 s
  EXPECT_TRUE(fronts.back().at_wall);  // r_s = 54.5 mm: f >= 0.15 everywhere in the gap
  EXPECT_FALSE(front_at_wall_time(std::vector<ShearFront>(fronts.begin(), fronts.begin() + 10), g, 1e-3).has_value());
  // The velocity front of the same frames stays where band_frame put it: the two are independent.
  EXPECT_NEAR(jammed_front(frames[5], g).radius_m, kR0 + 2e-3, 1e-12);
  EXPECT_THROW(structure_front(band_frame(0.0, 0.02), g, 0.15), InputError);  // no f sampled
  EXPECT_THROW(front_at_wall_time(fronts, g, -1.0), InputError);
}

TEST(AnnularShear, RejectsBadInput) {
  std::vector<ShearFrame> frames{band_frame(0.0, 0.02), band_frame(0.0, 0.021)};
  EXPECT_THROW(jammed_front_series(frames, geometry()), InputError);  // equal times
  AnnularGeometry g = geometry();
  g.outer_radius_m = 0.06;  // beyond the grid
  EXPECT_THROW(jammed_front(frames[0], g), InputError);
  g = geometry();
  g.bob_speed_m_per_s = 0.0;
  EXPECT_THROW(jammed_front(frames[0], g), InputError);
  EXPECT_THROW(surface_profiles({}, geometry(), {0.1}), InputError);
  EXPECT_THROW(front_speed({}, geometry()), InputError);
}

TEST(AnnularShear, SteadyBobSpeedLimitIsTheUniformShearProfile) {
  // The flow that reaches the bound shears at the maximum rate everywhere:
  // omega(r) = gamma (ln(r_o) - ln(r)), v = r omega, vanishing at the wall. Its bob speed, and
  // its shear rate r |d omega/dr| by central differences, check the bound independently.
  AnnularGeometry g;
  g.bob_radius_m = 0.0125;
  g.outer_radius_m = 0.0485;
  const double gamma = 0.387;
  const double limit = steady_bob_speed_limit(gamma, g);
  auto omega = [&](double r) { return gamma * std::log(g.outer_radius_m / r); };
  EXPECT_NEAR(limit, g.bob_radius_m * omega(g.bob_radius_m), 1e-15);
  EXPECT_EQ(omega(g.outer_radius_m), 0.0);
  for (double r = 0.013; r < 0.048; r += 0.005) {
    const double h = 1e-6;
    EXPECT_NEAR(r * std::fabs(omega(r + h) - omega(r - h)) / (2 * h), gamma, 1e-8);
  }
  EXPECT_THROW(steady_bob_speed_limit(0.0, g), InputError);
  EXPECT_THROW(steady_bob_speed_limit(NAN, g), InputError);
  g.outer_radius_m = g.bob_radius_m;
  EXPECT_THROW(steady_bob_speed_limit(gamma, g), InputError);
}

TEST(AnnularShear, SteadyCouetteLimitMatchesClosedForms) {
  // Exact 1D Couette: omega_bob(tau_0) = (1/2) integral of gamma_dot(tau)/tau dtau over
  // [k tau_0, tau_0], k = (r_0/r_o)^2.
  AnnularGeometry g;
  g.bob_radius_m = 0.0125;
  g.outer_radius_m = 0.0485;
  const double k = std::pow(g.bob_radius_m / g.outer_radius_m, 2);
  // (a) A flow curve with a hump: gamma_dot = g_m (tau/tau_p) e^(1 - tau/tau_p), so
  // omega(tau_0) = (e g_m/2)(e^(-k tau_0/tau_p) - e^(-tau_0/tau_p)), largest at
  // tau_0 = tau_p ln(1/k)/(1 - k).
  const double gm = 0.4, tp = 5.0;
  std::vector<double> tau, rate;
  for (int i = 0; i <= 20000; ++i) {
    const double t = tp * std::pow(10.0, -6.0 + 9.0 * i / 20000.0);
    tau.push_back(t);
    rate.push_back(gm * t / tp * std::exp(1.0 - t / tp));
  }
  const double t_star = tp * std::log(1.0 / k) / (1.0 - k);
  const double u_star =
      0.5 * std::exp(1.0) * gm * (std::exp(-k * t_star / tp) - std::exp(-t_star / tp)) * g.bob_radius_m;
  const auto c = steady_couette_limit(tau, rate, g);
  EXPECT_NEAR(c.bob_speed_m_per_s, u_star, 1e-6 * u_star);
  EXPECT_NEAR(c.bob_stress_Pa, t_star, 2e-3 * t_star);
  EXPECT_FALSE(c.at_end);
  // Torque balance keeps it below the simple bound (the whole gap at the peak rate g_m).
  EXPECT_LT(c.bob_speed_m_per_s, steady_bob_speed_limit(gm, g));
  // (b) A curve rising to an asymptote: gamma_dot = g_inf tau/(tau + tau_c), omega(tau_0) =
  // (g_inf/2) ln((tau_0 + tau_c)/(k tau_0 + tau_c)), increasing: the last sample decides.
  const double ginf = 0.3, tc = 2.0;
  for (std::size_t i = 0; i < tau.size(); ++i) rate[i] = ginf * tau[i] / (tau[i] + tc);
  const auto d = steady_couette_limit(tau, rate, g);
  const double t_end = tau.back();
  EXPECT_TRUE(d.at_end);
  EXPECT_NEAR(d.bob_speed_m_per_s, 0.5 * ginf * std::log((t_end + tc) / (k * t_end + tc)) * g.bob_radius_m, 1e-8);
  EXPECT_LT(d.bob_speed_m_per_s, steady_bob_speed_limit(ginf, g));
  // Bad input.
  EXPECT_THROW(steady_couette_limit({1.0}, {1.0}, g), InputError);
  EXPECT_THROW(steady_couette_limit({1.0, 2.0}, {1.0}, g), InputError);
  EXPECT_THROW(steady_couette_limit({2.0, 1.0, 3.0}, {1.0, 1.0, 1.0}, g), InputError);  // not increasing
  EXPECT_THROW(steady_couette_limit({1.0, 2.0}, {1.0, -1.0}, g), InputError);
  EXPECT_THROW(steady_couette_limit({1.0, 2.0}, {1.0, 1.0}, g), InputError);  // spans less than (r_o/r_0)^2
}
