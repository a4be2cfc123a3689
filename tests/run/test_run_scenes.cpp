// `oobleck run` end to end on the verification scenes: the measured quantity written into
// summary.json against its analytic value (V3 torque, V4 settling), exact mass conservation,
// restart equality, and refusal of invalid scenes before any output.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_runner.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/io/csv.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"
#include "oobleck/run/finite_check.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

namespace fs = std::filesystem;
using namespace oobleck;

namespace {
const std::string kScenes = std::string(OOBLECK_SOURCE_DIR) + "/scenes/verification/";

nlohmann::json run_verification(const std::string& scene, const std::string& out,
                                const std::vector<std::string>& sets = {}, run::RunOptions o = {}) {
  o.out_dir = out;
  o.quiet = true;
  if (o.threads == 0) o.threads = 1;
  return run::run_scene(scene::load_scene(kScenes + scene, sets), o);
}
double rel(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

/// The settling scene run to step 359 with checkpoints every 100 steps ("full"), and run to step
/// 150 ("part"), its checkpoint passed to `edit` (the path), then restarted to the end. Returns the
/// two checkpoints of step 300.
std::pair<io::Checkpoint, io::Checkpoint> restarted_settling(const clitest::TempDir& d,
                                                             const std::function<void(const std::string&)>& edit,
                                                             std::vector<std::string> overrides = {}) {
  run::RunOptions o;
  o.checkpoint_every = 100;
  o.threads = 1;
  overrides.insert(overrides.begin(), "time.duration=0.01");
  run_verification("settling.toml", d / "full", overrides, o);  // 359 steps, checkpoint at 300
  o.stop_after_steps = 150;
  run_verification("settling.toml", d / "part", overrides, o);  // stops at 150 with a checkpoint
  edit(run::checkpoint_path(d / "part"));
  o.stop_after_steps = -1;
  o.restart = true;
  o.out_dir = d / "part";
  o.quiet = true;
  run::run_scene(scene::load_scene(run::stored_scene_path(d / "part")), o);
  return {io::read_checkpoint(run::checkpoint_path(d / "full")), io::read_checkpoint(run::checkpoint_path(d / "part"))};
}

/// Rewrite the settling scene's checkpoint `path` as an older version wrote it: every attribute
/// and array kept, except that `older(name, values)` may rename an array and change its values
/// (it returns the name to store them under).
void rewrite_as_older(const std::string& path,
                      const std::function<std::string(const std::string&, std::vector<double>&)>& older) {
  const auto cp = io::read_checkpoint(path);
  io::CheckpointWriter w(path);
  w.set_step(cp.step());
  w.set_time(cp.time());
  w.set_config(cp.config());
  w.attribute("dt", cp.real_attribute("dt"));
  w.attribute("settle_sum", cp.real_attribute("settle_sum"));
  for (const char* k : {"threads", "settle_samples", "next_snapshot"}) w.attribute(k, cp.int_attribute(k));
  for (const auto& n : cp.names()) {
    if (n == "granular/regime") {
      w.array(n, cp.bytes(n), cp.shape(n));
      continue;
    }
    std::vector<double> values = cp.doubles(n);
    const std::string name = older(n, values);
    w.array(name, values, cp.shape(n));
  }
  w.commit();
}
}  // namespace

TEST(RunScenes, SettlingVelocityMatchesDragBuoyancyBalanceV4) {
  clitest::TempDir d;
  const auto s = run_verification("settling.toml", d / "run");
  EXPECT_LT(rel(s["settling_velocity"].get<double>(), s["settling_velocity_analytic"].get<double>()), 0.01);
  // Independent check of the analytic value in the Stokes limit written out here (Beetstra F at
  // Re -> 0: 10 phi/(1-phi)^2 + (1-phi)^2 (1 + 1.5 sqrt(phi))); the finite-Re term is < 2 % here.
  const double phi = 0.1, d_m = 1e-4, eta = 1e-3, drho = 620.0, g = 9.81;
  const double F0 = 10 * phi / std::pow(1 - phi, 2) + std::pow(1 - phi, 2) * (1 + 1.5 * std::sqrt(phi));
  const double u_stokes = (1 - phi) * drho * g * d_m * d_m / (18 * eta * F0);
  EXPECT_LT(rel(s["settling_velocity_analytic"].get<double>(), u_stokes), 0.02);
  EXPECT_EQ(s["parameters"]["phi"].get<double>(), 0.1);
  EXPECT_EQ(s["parameters"]["rho_f"].get<double>(), 1000.0);
  for (const char* key : {"points", "steps", "wall_seconds", "point_updates_per_second", "threads"}) {
    EXPECT_TRUE(s.contains(key)) << key;
  }
  // Mass is carried by the points: the series' total masses are constant to the last bit.
  const auto series = io::read_csv(d / "run/series.csv");
  for (const char* col : {"mass_grains", "mass_fluid"}) {
    const auto m = series.column(col);
    for (double v : m) ASSERT_EQ(v, m.front()) << col;
  }
  EXPECT_TRUE(fs::exists(d / "run/frames.xmf"));
  EXPECT_TRUE(fs::exists(d / "run/summary.json"));
}

TEST(RunScenes, SettlingIn3D) {
  clitest::TempDir d;
  const auto s = run_verification("settling_3d.toml", d / "run", {"time.duration=0.012"});
  EXPECT_EQ(s["geometry"].get<std::string>(), "3d");
  EXPECT_LT(rel(s["settling_velocity"].get<double>(), s["settling_velocity_analytic"].get<double>()), 0.01);
}

TEST(RunScenes, TaylorCouetteTorquesV3) {
  clitest::TempDir d;
  run::RunOptions o;
  o.threads = 1;
  const auto s = run_verification("couette_axisym.toml", d / "run", {}, o);
  const double M = s["torque_analytic"].get<double>();
  // Independent analytic torque: M = 4 pi eta B H, B = U r_i r_o^2/(r_o^2 - r_i^2).
  const double ri = 0.01, ro = 0.02, U = 0.01, H = 0.004, eta = 1.0;
  EXPECT_LT(rel(M, 4 * M_PI * eta * U * ri * ro * ro / (ro * ro - ri * ri) * H), 1e-12);
  EXPECT_LT(rel(s["torque_inner"].get<double>(), M), 0.01);
  EXPECT_LT(rel(s["torque_outer"].get<double>(), M), 0.01);
  EXPECT_LT(s["velocity_profile_rms_error"].get<double>(), 0.01);
  EXPECT_EQ(s["parameters"]["r_inner"].get<double>(), ri);
  EXPECT_EQ(s["parameters"]["r_outer"].get<double>(), ro);
  EXPECT_EQ(s["parameters"]["u_inner"].get<double>(), U);
}

TEST(RunScenes, RestartContinuesBitForBit) {
  clitest::TempDir d;
  const auto [a, b] = restarted_settling(d, [](const std::string&) {});
  ASSERT_EQ(a.step(), 300);
  ASSERT_EQ(b.step(), 300);
  EXPECT_EQ(a.time(), b.time());
  ASSERT_EQ(a.names(), b.names());
  for (const auto& n : a.names()) {
    if (n == "granular/regime") {
      EXPECT_EQ(a.bytes(n), b.bytes(n));
    } else {
      EXPECT_EQ(a.doubles(n), b.doubles(n)) << n;  // bitwise equality of every state array
    }
  }
  // The series of the restarted run continues without duplicate rows.
  const auto s = io::read_csv(d / "part/series.csv").column("step");
  for (std::size_t i = 1; i < s.size(); ++i) ASSERT_GT(s[i], s[i - 1]);
}

TEST(RunScenes, RestartReadsAnOlderCheckpointWithJ) {
  // Checkpoints before the fluid's state became ln J stored J = ρ_f0/ρ_f as "fluid/J": such a
  // file restarts through the logarithm, and the run continues within that logarithm's round-off.
  clitest::TempDir d;
  const auto [a, b] = restarted_settling(d, [](const std::string& path) {
    ASSERT_TRUE(io::read_checkpoint(path).has("fluid/ln_J"));
    rewrite_as_older(path, [](const std::string& n, std::vector<double>& values) {  // J for ln J
      if (n != "fluid/ln_J") return n;
      for (double& x : values) x = std::exp(x);
      return std::string("fluid/J");
    });
  });
  ASSERT_EQ(b.step(), 300);
  ASSERT_TRUE(b.has("fluid/ln_J"));
  for (const char* n : {"fluid/ln_J", "body0/x", "body1/x", "body1/stress"}) {
    const auto& x = a.doubles(n);
    const auto& y = b.doubles(n);
    ASSERT_EQ(x.size(), y.size()) << n;
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      scale = std::max(scale, std::fabs(x[i]));
      diff = std::max(diff, std::fabs(x[i] - y[i]));
    }
    EXPECT_GT(scale, 0.0) << n;
    EXPECT_LE(diff, 1e-9 * scale) << n;
  }
  EXPECT_NE(a.doubles("fluid/ln_J"), b.doubles("fluid/ln_J"));  // (the logarithm's round-off: not the same file)
}

TEST(RunScenes, RestartReadsAnOlderCheckpointWithTheSnapshotsX0) {
  // Checkpoints before the grains' reference positions (the snapshots' displacements) lived in
  // their body stored them as "analysis/x0_grains": such a file restarts bit for bit, and the
  // snapshot after the restart (t = 9 ms; the restart is at step 150, 4.2 ms) shows the same
  // displacements as the uninterrupted run's.
  clitest::TempDir d;
  std::string x0;
  const auto [a, b] = restarted_settling(d,
                                         [&](const std::string& path) {
                                           rewrite_as_older(path, [&](const std::string& n, std::vector<double>&) {
                                             if (!n.ends_with("/x0")) return n;
                                             x0 = n;
                                             return std::string("analysis/x0_grains");
                                           });
                                         },
                                         {"analysis.snapshot_times=[0.002, 0.009]"});
  ASSERT_FALSE(x0.empty());  // the grains' body holds its x0 when snapshots are taken
  ASSERT_EQ(a.names(), b.names());
  for (const auto& n : a.names()) {
    if (n != "granular/regime") {
      EXPECT_EQ(a.doubles(n), b.doubles(n)) << n;
    }
  }
  const auto read = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string full = read(d / "full/snapshot_1.csv"), part = read(d / "part/snapshot_1.csv");
  EXPECT_GT(full.size(), 1000u);
  EXPECT_EQ(full, part);
  // The grains settle: their displacement is not zero in the snapshot.
  const auto disp = io::read_csv(d / "full/snapshot_1.csv").column("displacement_y");
  EXPECT_LT(*std::min_element(disp.begin(), disp.end()), -1e-6);
}

TEST(RunScenes, InvalidScenesAreRefusedBeforeAnyOutput) {
  clitest::TempDir d;
  std::string text;
  {
    std::ifstream in(kScenes + "settling.toml");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  struct Case {
    std::string from, to, message;
  };
  const Case cases[] = {
      {"kappa = 2.0e5", "kappa = 2.0e5\nviscosity = 1", "unknown key"},
      {"G = 1.0e4", "G = -1.0e4", "granular.G"},
      {"cell_size = 0.001", "cell_size = \"1 mm\"", "must be a number"},
      {"duration = 0.02", "duration = 0.02\ndt = 0.01", "stable"},
  };
  for (const auto& c : cases) {
    std::string t = text;
    t.replace(t.find(c.from), c.from.size(), c.to);
    std::ofstream(d / "bad.toml") << t;
    const auto r = clitest::run("run " + d / "bad.toml" + " --out " + d / "new/out" + " --quiet");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("bad.toml"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(d / "new")) << c.message;  // not even the missing parent folder
  }
}

TEST(RunScenes, RunFolderIsCreatedWithItsParents) {
  // `--out out/NAME` in a fresh checkout (no out/ yet) runs; a file where a parent folder should
  // be is an error naming it.
  clitest::TempDir d;
  const std::string scene = kScenes + "settling.toml";
  const auto ok =
      clitest::run("run " + scene + " --out " + d / "a/b/run" + " --quiet --threads 1 --set time.duration=0.006");
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(fs::exists(d / "a/b/run/summary.json")) << ok.output;
  std::ofstream(d / "file") << "x";
  const auto bad =
      clitest::run("run " + scene + " --out " + d / "file/run" + " --quiet --threads 1 --set time.duration=0.006");
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("cannot create the run folder"), std::string::npos) << bad.output;
}

// The guards fused into the step (G2P checks the new x, v, V; the elastic and fluid laws their new
// stress) answer what the runner's full scan would: the runner scans a body only when one of them
// did not check or found something.
TEST(RunScenes, FusedNonFiniteGuardsAgreeWithTheFullScan) {
  using namespace mpm;
  const Grid<2> grid(Vec<2>(0.0, 0.0), 0.1, {10, 10});
  SolverOptions<PlaneStrain> opt;
  opt.dt_s = 1e-4;
  opt.threads = 2;
  material::LinearElasticParams ep;
  ep.youngs_modulus_Pa = 1e5;
  ep.poisson_ratio = 0.3;
  Solver<PlaneStrain> s(grid, opt);
  auto& b = s.add_body("block");
  b.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) b.add_point(Vec<2>(0.3 + 0.05 * (i + 0.5), 0.3 + 0.05 * (j + 0.5)), 0.0025, 1000.0);
  // three more, away from the block: a tail block of G2P's blocks of 32 (67 points)
  for (int i = 0; i < 3; ++i) b.add_point(Vec<2>(0.8, 0.15 + 0.05 * i), 0.0025, 1000.0);
  EXPECT_EQ(s.first_non_finite_kinematics(0), kNotChecked);  // no step yet
  s.step();
  EXPECT_EQ(s.first_non_finite_kinematics(0), kAllFinite);
  EXPECT_EQ(b.law->first_non_finite_stress(), kAllFinite);
  EXPECT_FALSE(run::first_non_finite(b).has_value());
  b.v_m_s[45][1] = NAN;  // spreads through the nodes of point 45 to its neighbours in this step
  s.step();
  const auto full = run::first_non_finite(b);
  ASSERT_TRUE(full.has_value());
  EXPECT_LE(full->point, 45);
  EXPECT_GT(full->point, 0);
  EXPECT_EQ(s.first_non_finite_kinematics(0), full->point);
  EXPECT_EQ(b.law->first_non_finite_stress(), full->point);
}

TEST(RunScenes, NonFiniteGuardFindsTheFirstBadPointAndWhatIsBad) {
  mpm::Body<mpm::PlaneStrain> b;
  b.name = "grains";
  for (int p = 0; p < 1000; ++p) b.add_point(mpm::Vec<2>(0.001 * p, 0.0), 1e-6, 1000.0);
  EXPECT_FALSE(run::first_non_finite(b).has_value());
  b.stress_Pa[700](1, 2) = NAN;
  b.v_m_s[900][1] = INFINITY;
  b.stress_Pa[901](0, 0) = 1e308;
  b.stress_Pa[901](1, 1) = 1e308;  // finite parts, infinite sum
  auto bad = run::first_non_finite(b);
  ASSERT_TRUE(bad.has_value());
  EXPECT_EQ(bad->point, 700);
  EXPECT_STREQ(bad->what, "stress");
  b.stress_Pa[700](1, 2) = 0.0;
  bad = run::first_non_finite(b);
  EXPECT_EQ(bad->point, 900);
  EXPECT_STREQ(bad->what, "velocity");
  b.v_m_s[900][1] = 0.0;
  EXPECT_STREQ(run::first_non_finite(b)->what, "state (overflow of finite values)");
}
