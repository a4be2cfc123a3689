// Coarse versions of the paper's scenes (scenes/paper/*.toml) asserting their qualitative claims,
// so that regressions are caught by CI. The full-resolution runs and figures: `oobleck reproduce`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_runner.hpp"
#include "oobleck/analysis/annular.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/build.hpp"
#include "oobleck/scene/config.hpp"

using namespace oobleck;

namespace {
nlohmann::json run_paper_scene(const std::string& scene, const std::string& out, const std::vector<std::string>& sets) {
  run::RunOptions o;
  o.out_dir = out;
  o.quiet = true;
  o.threads = 1;
  return run::run_scene(scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/" + scene, sets), o);
}

/// A paper scene run once uninterrupted (into dir/full) and once stopped after `stop_after` steps
/// and restarted (dir/part), one thread: both summaries and, with checkpoints every `every` > 0
/// steps, both runs' last checkpoints.
// Its implicit move constructor is noexcept, as nlohmann::json's (declared noexcept) is; clang-tidy
// finds an allocating path in json's value constructor that a move (which leaves null) never takes.
// NOLINTNEXTLINE(bugprone-exception-escape)
struct Restarted {
  nlohmann::json full, part;
  io::Checkpoint full_cp, part_cp;
};
Restarted run_and_restart(const std::string& scene, const std::vector<std::string>& sets, long every, long stop_after,
                          const std::string& dir) {
  const std::string file = std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/" + scene;
  run::RunOptions o;
  o.quiet = true;
  o.threads = 1;
  o.checkpoint_every = every;
  o.out_dir = dir + "/full";
  Restarted r;
  r.full = run::run_scene(scene::load_scene(file, sets), o);
  o.out_dir = dir + "/part";
  o.stop_after_steps = stop_after;
  run::run_scene(scene::load_scene(file, sets), o);
  o.stop_after_steps = -1;
  o.restart = true;
  r.part = run::run_scene(scene::load_scene(run::stored_scene_path(dir + "/part")), o);
  if (every > 0) {
    r.full_cp = io::read_checkpoint(run::checkpoint_path(dir + "/full"));
    r.part_cp = io::read_checkpoint(run::checkpoint_path(dir + "/part"));
  }
  return r;
}

/// Every state array of two checkpoints is bitwise equal.
void expect_same_state(const io::Checkpoint& a, const io::Checkpoint& b) {
  ASSERT_EQ(a.names(), b.names());
  for (const auto& n : a.names()) {
    if (n == "granular/regime") {
      EXPECT_EQ(a.bytes(n), b.bytes(n));
    } else {
      EXPECT_EQ(a.doubles(n), b.doubles(n)) << n;
    }
  }
}
}  // namespace

TEST(PaperScenes, AnnularShearFastBobGrowsAJammedCoRotatingBand) {
  // S1 at u_i = 84 mm/s on a 2 mm grid for 25 ms (0.17 rad): a band of material dragged along
  // by the bob grows outward. Newtonian annular flow never moves faster than the bob surface
  // (v_theta/u_i <= 1 for A r + B/r); a co-rotating (jammed) band does (rigid rotation gives r/r_0).
  clitest::TempDir d;
  const auto s = run_paper_scene("annular_shear.toml", d / "run", {"grid.cell_size=0.002", "duration=0.025"});
  const auto& prof = s["profiles"];
  ASSERT_GE(prof.size(), 2u);
  const auto v = prof[1]["v_over_ui"].get<std::vector<double>>();  // 0.1 rad
  EXPECT_GT(*std::max_element(v.begin(), v.end()), 1.05);
  const auto ann = analysis::newtonian_annulus(0.0125, 1.0, 0.0485);
  EXPECT_LE(ann.v_theta(0.02), 1.0);  // the Newtonian reference indeed stays below the bob speed
  // The front moves out from the bob at a speed of several u_i.
  const auto r = s["front"]["value"].get<std::vector<double>>();
  EXPECT_GT(r.back() - r.front(), 0.008);
  EXPECT_GT(s["front_speed"].get<double>(), 2 * 0.084);
  // No steady flow at the bed's phi turns the bob this fast: the flow curve at phi 0.505 never
  // shears faster than a few tenths of 1/s (at least the E14 DST rate, 0.255 1/s by hand), so
  // steady Couette flow allows only a few mm/s at the bob; torque balance (the exact 1D limit)
  // allows less than the simple radial-line bound, and at least the DST asymptote's
  // gamma_dot_DST r_0 ln(r_o/r_0).
  const auto& sf = s["steady_flow"];
  EXPECT_FALSE(sf["steady_flow_possible"].get<bool>());
  EXPECT_NEAR(sf["shear_rate_dst"].get<double>(), 0.255, 0.001);
  const double limit = sf["bob_speed_limit"].get<double>();
  const double bound = sf["bob_speed_bound"].get<double>();
  EXPECT_GE(limit, 0.255 * 0.0125 * std::log(0.0485 / 0.0125));
  EXPECT_LT(limit, bound);
  EXPECT_LT(bound, 0.084 / 10);
}

TEST(PaperScenes, AnnularShearSlowBobAdmitsASteadyFlow) {
  // S1 at u_i = 0.84 mm/s: below the fastest steady flow of the bed (see the fast case above).
  clitest::TempDir d;
  const auto s =
      run_paper_scene("annular_shear.toml", d / "run", {"grid.cell_size=0.002", "duration=0.01", "u_inner=0.00084"});
  const auto& sf = s["steady_flow"];
  EXPECT_TRUE(sf["steady_flow_possible"].get<bool>());
  EXPECT_GT(sf["bob_speed_limit"].get<double>(), 0.00084);
  EXPECT_NEAR(sf["bob_speed"].get<double>(), 0.00084, 1e-15);
}

TEST(PaperScenes, AnnularShearBandIsDraggedOutThenReleased) {
  // S1 fast bob on a 2 mm grid for 0.1 s (0.67 rad): the co-rotating band grows and drags the
  // outer half of the gap along (its mean rotation reaches a good fraction of the bob's); then the
  // co-rotation fades, the outer half comes almost to rest (below 10% of that peak) and the
  // profile turns Newtonian-like. The jammed structure itself never recedes: f >= f_m/2 spreads
  // monotonically and reaches the outer wall, after the velocity band's farthest extent and
  // before the arrest. Measured at 1 mm: band farthest at r = 34.8 mm at 48 ms, structure at the
  // wall at 55 ms, outer half below 10% at 66 ms (docs/results.md).
  clitest::TempDir d;
  const auto s = run_paper_scene("annular_shear.toml", d / "run", {"grid.cell_size=0.002", "duration=0.1"});
  const auto& a = s["outer_arrest"];
  std::printf(
      "[ measured ] coarse annular: outer rotation peak %.3f at %.3f s, arrest at %s s, front farthest %.4f m "
      "at %.3f s, structure at the wall at %s s\n",
      a["peak"].get<double>(), a["peak_time"].get<double>(), a["time"].dump().c_str(),
      s["front_farthest"].get<double>(), s["front_farthest_time"].get<double>(),
      s["structure_front_wall_time"].dump().c_str());
  EXPECT_GT(a["peak"].get<double>(), 0.2);
  ASSERT_TRUE(a["time"].is_number());
  EXPECT_GT(a["time"].get<double>(), a["peak_time"].get<double>());
  // The front advanced steadily before: fitted up to its farthest extent.
  EXPECT_GT(s["front_fit"]["r_squared"].get<double>(), 0.95);
  EXPECT_GT(s["front_speed"].get<double>(), 2 * 0.084);
  const auto& prof = s["profiles"];
  ASSERT_EQ(prof.size(), 6u);  // 0, 0.1, 0.2, 0.31, 0.45, 0.6 rad
  // The structure front (f_m(0.505)/2 = 0.15 for hermes2016) only advances, and reaches the wall
  // between the band's farthest extent and the arrest.
  EXPECT_NEAR(s["structure_front_threshold"].get<double>(), 0.5 * (0.505 - 0.535) / (0.436 - 0.535), 1e-12);
  const auto radii = s["structure_front"]["value"].get<std::vector<double>>();
  ASSERT_GT(radii.size(), 10u);
  for (std::size_t k = 1; k < radii.size(); ++k) EXPECT_GE(radii[k], radii[k - 1] - 1e-12) << "frame " << k;
  ASSERT_TRUE(s["structure_front_wall_time"].is_number());
  const double t_wall = s["structure_front_wall_time"].get<double>();
  EXPECT_GT(t_wall, s["front_farthest_time"].get<double>());
  EXPECT_LT(t_wall, a["time"].get<double>());
}

TEST(PaperScenes, FastWheelRidesHigherAndTravelsFurtherThanTheSlowOne) {
  // S4 on a 50 x 25 grid for 1 s, same parameters, only omega changes (the coarse grid of
  // `reproduce --quick`): at 1 rad/s the wheel sinks below the bed surface and hardly moves; at
  // 10 rad/s the paddles jam the material they strike: it ends higher and travels forward.
  // Δt = 2e-4 s: on this grid APIC's outcome depends on Δt (smaller steps lift both wheels; at
  // 2e-5 s the slow one ends 2 cm above the surface), unlike at the paper's resolution
  // (docs/results.md, S4 "Time step and transfer").
  clitest::TempDir d;
  const std::vector<std::string> coarse{"cells=[50,25]", "time.dt=2e-4", "duration=1.0"};
  auto with = [&](const std::string& omega) {
    auto sets = coarse;
    sets.push_back("omega=" + omega);
    return sets;
  };
  const auto fast = run_paper_scene("wheel.toml", d / "fast", with("10"));
  const auto slow = run_paper_scene("wheel.toml", d / "slow", with("1"));
  std::printf(
      "[ measured ] coarse wheel: omega 10: hub %.3f m, distance %.3f m; omega 1: hub %.3f m, distance %.3f m\n",
      fast["hub_height_final"].get<double>(), fast["distance"].get<double>(), slow["hub_height_final"].get<double>(),
      slow["distance"].get<double>());
  const double surface = slow["bed_surface"].get<double>();
  EXPECT_NEAR(surface, 0.5, 0.02);
  EXPECT_LT(slow["hub_height_final"].get<double>(), surface);  // the slow wheel sinks
  EXPECT_GT(fast["hub_height_final"].get<double>(), slow["hub_height_final"].get<double>() + 0.02);
  EXPECT_GT(fast["distance"].get<double>(), 0.2);
  EXPECT_GT(fast["distance"].get<double>(), 5.0 * std::abs(slow["distance"].get<double>()));
  // The motor held the mean angular velocity (after spin-up).
  const auto tw = fast["omega_measured"]["time"].get<std::vector<double>>();
  const auto w = fast["omega_measured"]["value"].get<std::vector<double>>();
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < w.size(); ++k) {
    if (tw[k] > 0.1) {
      sum += w[k];
      ++n;
    }
  }
  ASSERT_GT(n, 10);
  EXPECT_NEAR(sum / n, 10.0, 0.5);
  // The SI figure's measure: one pressure-scatter sample per frame (every 0.05 s from t = 0, the
  // wheel above the bed's grains from the start), pooled over the frames after t = 0.
  const auto& series = fast["pressure_scatter"]["series"];
  ASSERT_EQ(series.size(), 21u);
  std::int64_t pooled = 0;
  for (std::size_t k = 0; k < series.size(); ++k) {
    EXPECT_NEAR(series[k]["time"].get<double>(), 0.05 * static_cast<double>(k), 1e-9);
    if (k > 0) pooled += series[k]["points"].get<std::int64_t>();
  }
  EXPECT_EQ(fast["pressure_scatter"]["pooled"]["points"].get<std::int64_t>(), pooled);
}

TEST(PaperScenes, WheelRunRestartsWithTheSameMeasurements) {
  // Coarse fast wheel stopped at step 1700 (0.34 s, between frames) and restarted: hub track and
  // the per-frame pressure scatter (checkpointed) as in the uninterrupted run.
  clitest::TempDir d;
  const auto r = run_and_restart("wheel.toml", {"cells=[50,25]", "time.dt=2e-4", "duration=0.6", "omega=10"}, 500, 1700,
                                 d / "wheel");
  ASSERT_EQ(r.full["pressure_scatter"]["series"].size(), 13u);
  EXPECT_EQ(r.full["pressure_scatter"], r.part["pressure_scatter"]);
  EXPECT_EQ(r.full["hub_height"], r.part["hub_height"]);
  EXPECT_EQ(r.full["distance"], r.part["distance"]);
  ASSERT_EQ(r.full_cp.step(), 3000);
  expect_same_state(r.full_cp, r.part_cp);
}

TEST(PaperScenes, IntruderRampsUpToSpeedAlongTheClosedFormPath) {
  // `ramp_time` T: the prescribed intruder starts from rest, v = v0 min(1, t/T), so its tip has
  // moved v0 t^2/(2T) at t < T and v0 (t - T/2) after (a 2.5 mm grid, 2 ms into a 4 ms ramp and
  // 1 ms past a 1 ms one). The velocity per step is taken at the step's midpoint, which makes
  // the path exact while it ramps (at the step's start it would be off by v0 t dt/(2T)).
  clitest::TempDir d;
  const double v0 = 0.2, z0 = 0.0325;  // the box's centre, 30-35 mm
  struct Case {
    double ramp, duration;
  };
  for (const Case c : {Case{0.004, 0.002}, Case{0.001, 0.002}}) {
    const auto s = run_paper_scene(
        "intrusion.toml", d / "ramp",
        {"cell_size=0.0025", fmt::format("duration={}", c.duration), fmt::format("ramp_time={}", c.ramp)});
    const double t = s["time"].get<double>();
    const double expected = t < c.ramp ? v0 * t * t / (2 * c.ramp) : v0 * (t - 0.5 * c.ramp);
    const auto& body = s["bodies"]["intruder"];
    // Exact while ramping; the step across T errs by at most v0 dt^2/(8T) (midpoint of a kink).
    const double dt = s["dt"].get<double>();
    const double tol = (t < c.ramp ? 0.0 : v0 * dt * dt / (8 * c.ramp)) + 1e-9 * expected;
    EXPECT_NEAR(z0 - body["centre"][1].get<double>(), expected, tol) << c.ramp;
    EXPECT_DOUBLE_EQ(body["ramp_time"].get<double>(), c.ramp);
    const double v_end = v0 * std::min(1.0, (t - 0.5 * dt) / c.ramp);  // last step's midpoint
    EXPECT_NEAR(body["velocity"][1].get<double>(), -v_end, 1e-12) << c.ramp;
  }
}

TEST(PaperScenes, RestartInsideTheRampContinuesBitForBit) {
  // The ramped velocity is a function of the (checkpointed) time: stopping inside the ramp and
  // restarting gives the uninterrupted run's state bit for bit.
  clitest::TempDir d;
  const auto r = run_and_restart("intrusion.toml", {"cell_size=0.0025", "duration=0.003", "ramp_time=0.004"}, 200, 100,
                                 d / "ramp");
  ASSERT_EQ(r.full_cp.step(), r.part_cp.step());
  ASSERT_GE(r.full_cp.step(), 200);
  expect_same_state(r.full_cp, r.part_cp);
}

TEST(PaperScenes, IntruderDrivesAPlugThatGrowsAheadAndSideways) {
  // S3 on the paper's 1 mm grid for 5 ms (v0 = 0.2 m/s, phi = 0.47): after the impact transient
  // (the u_z >= 0.5 v0 region jumps about 8 mm ahead of the tip within 1 ms), the region moving
  // with the intruder keeps growing ahead of the tip and sideways past its edge (measured from 2 to
  // 5 ms: 8.5 -> 9.7 mm ahead, 1.6 -> 3.4 mm past the edge). The ratio k_l/k_t is not asserted
  // here: it is the claim under study (docs/results.md, S3), and on the coarser 2.5 mm grid an
  // earlier version of this test used, the region recedes after 1 ms once the contact normal under
  // the flat face is -e_z (test Contact.NormalUnderAFlatFaceIsMinusEzAtEveryRadius; the tilted
  // normal had pushed the grains sideways next to the axis).
  clitest::TempDir d;
  const auto s = run_paper_scene("intrusion.toml", d / "run", {"duration=0.005"});
  const auto& frames = s["velocity_front"]["series"]["frames"];
  ASSERT_GT(frames.size(), 45u);
  const auto& early = frames[20];  // 2 ms
  const auto& late = frames.back();
  EXPECT_NEAR(early["time"].get<double>(), 0.002, 1e-4);
  ASSERT_TRUE(early["longitudinal"]["found"].get<bool>());
  ASSERT_TRUE(late["longitudinal"]["found"].get<bool>());
  ASSERT_TRUE(late["transverse"]["found"].get<bool>());
  const double a2 = early["longitudinal"]["ahead"].get<double>(), a5 = late["longitudinal"]["ahead"].get<double>();
  const double e2 = early["transverse"]["from_edge"].get<double>(), e5 = late["transverse"]["from_edge"].get<double>();
  std::printf("[ measured ] intrusion 1 mm: ahead %.2f -> %.2f mm, past the edge %.2f -> %.2f mm (2 -> 5 ms)\n",
              1e3 * a2, 1e3 * a5, 1e3 * e2, 1e3 * e5);
  EXPECT_GT(a5, a2 + 0.5e-3);
  EXPECT_GT(e5, e2 + 1.0e-3);
  // The intruder moved exactly at v0 and the drive had to push (the mixture resists: F_z > 0).
  EXPECT_NEAR(s["bodies"]["intruder"]["velocity"][1].get<double>(), -0.2, 1e-12);
  EXPECT_GT(s["bodies"]["intruder"]["contact_force_last_step"][1].get<double>(), 0.0);
}

TEST(PaperScenes, LinearShapeFunctionsRunTheIntruderAndTheWheel) {
  // grid.shape_function = "linear" on the intruder (phi 0.49, v0 0.5, the paper's 1 mm grid, to
  // 2 ms) and the coarse fast wheel (50 x 25, 0.3 s). Without the nodal mass floor
  // (grid.linear_mass_floor = 0) both stop on a non-finite state: the intruder at 1.45 ms, where a
  // row of grains under its face crosses a grid line and leaves a node with a sliver of their
  // mass; the wheel at its first steps, its points lying on grid lines. With the default floor
  // (cfl^2 of a full node's mass) both run, and the intruder's plug moves with it.
  clitest::TempDir d;
  const std::vector<std::string> intruder{"phi=0.49", "v0=0.5", "duration=0.002", "grid.shape_function=linear"};
  const std::vector<std::string> wheel{"omega=10", "cells=[50,25]", "time.dt=2e-4", "duration=0.3",
                                       "grid.shape_function=linear"};
  auto without_floor = [](std::vector<std::string> sets) {
    sets.push_back("grid.linear_mass_floor=0");
    return sets;
  };
  EXPECT_THROW(run_paper_scene("intrusion.toml", d / "i0", without_floor(intruder)), NumericalError);
  EXPECT_THROW(run_paper_scene("wheel.toml", d / "w0", without_floor(wheel)), NumericalError);
  const auto i = run_paper_scene("intrusion.toml", d / "i", intruder);
  EXPECT_TRUE(i["complete"].get<bool>());
  const auto& late = i["velocity_front"]["series"]["frames"].back();
  ASSERT_TRUE(late["longitudinal"]["found"].get<bool>());
  EXPECT_GT(late["longitudinal"]["ahead"].get<double>(), 0.002);  // a plug ahead of the tip
  const auto w = run_paper_scene("wheel.toml", d / "w", wheel);
  EXPECT_TRUE(w["complete"].get<bool>());
  EXPECT_GT(w["hub_height_final"].get<double>(), 0.4);  // on the bed (surface 0.5 m), not through it
  EXPECT_LT(w["hub_height_final"].get<double>(), 0.7);
  EXPECT_GT(w["distance"].get<double>(), 0.0);
}

TEST(PaperScenes, RodDeceleratesSharplyAtImpactThenSinksSlowly) {
  // S2 on a 5 mm grid for 20 ms (v0 = 1 m/s, 0.3 kg): the contact force decelerates the rod at
  // many g right after impact, it loses most of its speed within 10 ms and then keeps sinking
  // slowly; |dz| below the rod falls off roughly linearly with depth (a growing solid plug).
  clitest::TempDir d;
  const auto s = run_paper_scene("rod_impact.toml", d / "run",
                                 {"cell_size=0.005", "duration=0.02", "analysis.snapshot_times=[0.02]"});
  const double g = 9.81;
  EXPECT_GT(s["peak_deceleration_from_force"]["peak_deceleration"].get<double>(), 10 * g);
  EXPECT_LT(s["peak_deceleration_from_force"]["peak_deceleration_time"].get<double>(), 0.005);
  const auto t = s["rod_velocity"]["time"].get<std::vector<double>>();
  const auto v = s["rod_velocity"]["value"].get<std::vector<double>>();
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] > 0.01) {
      EXPECT_GT(v[k], -0.5) << "t = " << t[k];  // slowed below v0/2 after 10 ms
    }
  }
  EXPECT_LT(v.back(), -0.02);  // still sinking
  EXPECT_GT(s["final_depth"].get<double>(), 0.003);
  const auto& prof = s["displacement_below_rod"];
  EXPECT_GT(prof["fit"]["r_squared"].get<double>(), 0.9);
  EXPECT_LT(prof["fit"]["slope"].get<double>(), 0.0);  // |dz| decreases with depth
  // The contact force and the rod's momentum agree: M dv = (F - M g) dt summed over the run.
  const auto F = s["contact_force"]["value"].get<std::vector<double>>();
  const auto tf = s["contact_force"]["time"].get<std::vector<double>>();
  const double M = s["rod_mass"].get<double>() / (2 * M_PI);
  double impulse = 0.0;
  for (std::size_t k = 0; k < F.size(); ++k) impulse += F[k] * (tf[k] - (k ? tf[k - 1] : 0.0));
  EXPECT_NEAR(M * (v.back() - v.front()), impulse - M * g * tf.back(), 1e-9 * M);
}

TEST(PaperScenes, Rod3dCylinderHasTheVolumeCentroidAndLowestPointOfItsShape) {
  // The 3D rod (rod_impact_3d.toml) tilted by 30 deg, on a fine point lattice (0.625 mm spacing
  // for a 9.5 mm radius): its points' volume approaches pi r^2 L, their centroid lies on the
  // axis half a length above the bottom face's centre, their lowest point on the free surface.
  const auto c = scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/paper/rod_impact_3d.toml",
                                   {"cell_size=0.005", "tilt_deg=30", "body.0.points_per_cell=8"});
  const auto s = scene::build_scene<mpm::ThreeD>(c, 1);
  const auto& rod = s.solver->body(s.third[0].body);
  const auto& b = c.bodies[0];
  const auto f = scene::cylinder_frame(b);
  double V = 0.0, M = 0.0, zmin = INFINITY;
  mpm::Vec<3> xc = mpm::Vec<3>::Zero();
  for (std::size_t p = 0; p < rod.x_m.size(); ++p) {
    V += rod.volume_m3[p];
    M += rod.mass_kg[p];
    xc += rod.volume_m3[p] * rod.x_m[p];
    zmin = std::min(zmin, rod.x_m[p][2]);
  }
  xc /= V;
  const double spacing = 0.005 / 8;
  EXPECT_NEAR(V / (M_PI * b.radius_m * b.radius_m * b.length_m), 1.0, 0.02);
  EXPECT_NEAR(M, 0.3, 1e-12);  // `mass` is the whole rod's
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(xc[a], f.base_m[a] + 0.5 * b.length_m * f.axis[a], 0.5 * spacing) << a;
  EXPECT_NEAR(zmin, 0.1, spacing);  // the lowest rim point on the surface (z = 0.1), within a spacing
  EXPECT_GE(zmin, 0.1 - 1e-12);
}

TEST(PaperScenes, WidthPeriodicWheel3dIsThePlaneStrainWheel) {
  // S4 in the 3D solver, bed and wheel periodic across the width (wheel_3d.toml's width_periodic)
  // against wheel.toml in plane strain, 60 x 30 cells (4 across the width), 100 steps: every
  // field is uniform along y, so the two solve one problem; the hub's height, distance and the
  // motor's measured omega agree to round-off. (Contact force: plane strain per metre of depth.)
  clitest::TempDir d;
  const auto ps = run_paper_scene("wheel.toml", d / "ps",
                                  {"cells=[60, 30]", "duration=0.002", "analysis.snapshot_times=[]",
                                   "output.frame_interval=0", "analysis.sample_interval=0.001"});
  const auto w3 = run_paper_scene("wheel_3d.toml", d / "w3",
                                  {"width_periodic=true", "cells=[60, 4, 30]", "duration=0.002",
                                   "output.frame_interval=0", "analysis.sample_interval=0.001"});
  ASSERT_EQ(ps["steps"], w3["steps"]);
  EXPECT_NEAR(w3["hub_height_final"].get<double>(), ps["hub_height_final"].get<double>(), 1e-12);
  // distance: a fraction of a micrometre after 100 steps
  EXPECT_NEAR(w3["distance"].get<double>(), ps["distance"].get<double>(), 1e-12);
  EXPECT_GT(std::fabs(ps["distance"].get<double>()), 1e-9);
  const auto wp = ps["omega_measured"]["value"].get<std::vector<double>>();
  const auto w = w3["omega_measured"]["value"].get<std::vector<double>>();
  ASSERT_EQ(w.size(), wp.size());
  for (std::size_t k = 0; k < w.size(); ++k) EXPECT_NEAR(w[k], wp[k], 1e-12) << k;
  const double width = w3["bodies"]["wheel"]["mass"].get<double>() / ps["bodies"]["wheel"]["mass"].get<double>();
  EXPECT_NEAR(width, 2.0 / 15.0, 1e-12);  // the slab's width [m]: the 3D wheel is that much plane-strain wheel
}

TEST(PaperScenes, RodRunRestartsBitForBit) {
  // A free rigid body's velocity, its contact impulse sum and the analysis track are part of the
  // checkpoint: an interrupted rod run continues exactly.
  clitest::TempDir d;
  const auto r = run_and_restart("rod_impact.toml", {"cell_size=0.005", "duration=0.002"}, 300, 150, d / "rod");
  ASSERT_EQ(r.full_cp.step(), 300);
  ASSERT_EQ(r.part_cp.step(), 300);
  EXPECT_TRUE(r.full_cp.has("third0/rigid_velocity"));
  EXPECT_TRUE(r.full_cp.has("analysis/track"));
  expect_same_state(r.full_cp, r.part_cp);
}

TEST(PaperScenes, RestartedIntrusionReportsTheSameFronts) {
  // The sampled u_z and f fields are part of the checkpoint: the fronts, their fits and k_l/k_t
  // of a run interrupted and restarted equal those of the uninterrupted run exactly.
  clitest::TempDir d;
  const auto [full, part, c1, c2] = run_and_restart(
      "intrusion.toml", {"cell_size=0.0025", "duration=0.004", "analysis.sample_interval=2e-4"}, -1, 700, d / "r");
  EXPECT_EQ(full["velocity_front"], part["velocity_front"]);
  EXPECT_EQ(full["f_front"], part["f_front"]);
  ASSERT_TRUE(full["k_l_over_k_t"].is_number());
  EXPECT_EQ(full["k_l_over_k_t"], part["k_l_over_k_t"]);
}

TEST(PaperScenes, RestartedAnnularRunReportsTheSameProfilesAndFront) {
  clitest::TempDir d;
  const auto [full, part, c1, c2] =
      run_and_restart("annular_shear.toml", {"grid.cell_size=0.002", "duration=0.016"}, -1, 400, d / "r");
  ASSERT_GE(full["profiles"].size(), 2u);
  EXPECT_EQ(full["profiles"], part["profiles"]);
  EXPECT_EQ(full["front"], part["front"]);
  // The sampled structure field is checkpointed too.
  ASSERT_TRUE(full.contains("structure_front"));
  EXPECT_GE(full["structure_front"]["value"].size(), 2u);
  EXPECT_EQ(full["structure_front"], part["structure_front"]);
}
