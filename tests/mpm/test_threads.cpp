// The solver on two OpenMP threads. Most solver tests run one thread; these run small scenes on
// two, through every threaded part of the step (P2G's per-thread copies and their sums, the grid
// pass with contact's scatters on one thread, the walls, G2P and the laws' stolen shares, the
// run loop's finite check), and assert
//   * two runs on 2 threads are bit for bit the same (nothing depends on the schedule: every unit
//     of work is independent, and the per-thread copies are summed in thread order);
//   * a run on 1 thread agrees with them to round-off: every array within `tol` times its
//     largest magnitude (only P2G's summation order differs: one copy, not two). Not bit for
//     bit: a node's sum of two copies rounds differently from one copy's running sum.
// They are the threaded tests of the ThreadSanitizer check (scripts/hardening, step tsan).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "../cli/cli_runner.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"
#include "oobleck/run/runner.hpp"
#include "oobleck/scene/config.hpp"

using namespace oobleck;
using namespace oobleck::mpm;
using oobleck::material::LinearElasticParams;

namespace {

/// Named arrays of a run's final state (integer arrays as doubles: exact at these sizes).
using State = std::map<std::string, std::vector<double>>;

/// Every array of a checkpoint.
State checkpoint_state(const io::Checkpoint& cp) {
  State s;
  for (const auto& n : cp.names()) {
    std::vector<double>& out = s[n];
    try {
      out = cp.doubles(n);
      continue;
    } catch (const InputError&) {
    }
    try {
      const auto& v = cp.int64s(n);
      out.assign(v.begin(), v.end());
      continue;
    } catch (const InputError&) {
    }
    const auto& v = cp.bytes(n);
    out.assign(v.begin(), v.end());
  }
  return s;
}

/// scenes/<scene> with `sets`, run for `steps` steps on `threads` threads: the arrays of the
/// checkpoint it leaves (every body, law, contact and analysis state).
State scene_state(const std::string& scene, const std::vector<std::string>& sets, long steps, int threads) {
  clitest::TempDir d;
  run::RunOptions o;
  o.out_dir = d / "run";
  o.quiet = true;
  o.threads = threads;
  o.checkpoint_every = steps;
  o.stop_after_steps = steps;
  run::run_scene(scene::load_scene(std::string(OOBLECK_SOURCE_DIR) + "/scenes/" + scene, sets), o);
  const io::Checkpoint cp = io::read_checkpoint(run::checkpoint_path(o.out_dir));
  EXPECT_EQ(cp.step(), steps);
  return checkpoint_state(cp);
}

/// The per-point state of every body of a solver.
template <class G>
State solver_state(Solver<G>& s) {
  State st;
  for (int b = 0; b < s.body_count(); ++b) {
    const Body<G>& body = s.body(b);
    auto add = [&](const std::string& name, const auto& values) {
      std::vector<double>& out = st[body.name + "/" + name];
      for (const auto& v : values) out.insert(out.end(), v.data(), v.data() + v.size());
    };
    add("x", body.x_m);
    add("v", body.v_m_s);
    add("C", body.C_1_s);
    add("stress", body.stress_Pa);
    st[body.name + "/volume"] = body.volume_m3;
  }
  return st;
}

/// Every array bit for bit the same.
void expect_identical(const State& a, const State& b) {
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, va] : a) {
    ASSERT_EQ(b.count(name), 1U) << name;
    const auto& vb = b.at(name);
    ASSERT_EQ(va.size(), vb.size()) << name;
    std::size_t differ = 0, first = 0;
    for (std::size_t i = 0; i < va.size(); ++i)
      if (std::bit_cast<std::uint64_t>(va[i]) != std::bit_cast<std::uint64_t>(vb[i]) && differ++ == 0) first = i;
    EXPECT_EQ(differ, 0U) << name << ": " << differ << " of " << va.size() << " values differ, first at " << first;
  }
}

/// Every array within tol × (its largest magnitude) of the other's; returns the largest such
/// relative difference seen (for the messages).
double expect_close(const State& a, const State& b, double tol) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (const auto& [name, va] : a) {
    if (b.count(name) == 0) {
      ADD_FAILURE() << "missing " << name;
      continue;
    }
    const auto& vb = b.at(name);
    EXPECT_EQ(va.size(), vb.size()) << name;
    if (va.size() != vb.size()) continue;
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < va.size(); ++i) {
      scale = std::max(scale, std::fabs(va[i]));
      diff = std::max(diff, std::fabs(va[i] - vb[i]));
    }
    const double rel = scale > 0.0 ? diff / scale : diff;
    worst = std::max(worst, rel);
    EXPECT_LE(rel, tol) << name << ": max |1 thread - 2 threads| = " << diff << " of max |value| " << scale;
  }
  return worst;
}

/// Two runs on 2 threads identical, the run on 1 thread within tol (relative to each array's
/// largest magnitude) of them.
template <class Run>
void check_threads(double tol, Run&& run) {
  const State two = run(2), again = run(2), one = run(1);
  {
    SCOPED_TRACE("2 threads twice");
    expect_identical(two, again);
  }
  SCOPED_TRACE("1 thread vs 2");
  const double worst = expect_close(one, two, tol);
  std::printf("largest relative difference, 1 thread vs 2: %.3g\n", worst);
}

}  // namespace

// Scenes: the paper's on coarse grids (each grid above the 1 024 nodes from which the mixture's
// node pass runs on both threads), a few tens of steps.

TEST(Threads, IntruderScene) {
  // Axisymmetric mixture, prescribed rigid intruder with friction; 45 × 33 nodes. 1 thread vs 2:
  // 3.8e-14 (measured).
  check_threads(
      1e-12, [](int threads) { return scene_state("paper/intrusion.toml", {"grid.cell_size=0.00125"}, 30, threads); });
}

TEST(Threads, WheelScene) {
  // Plane strain, periodic in x: mixture bed, elastic wheel driven by the motor, contact. 1 thread
  // vs 2: 2.7e-14.
  check_threads(1e-12,
                [](int threads) { return scene_state("paper/wheel.toml", {"grid.cells=[60, 30]"}, 30, threads); });
}

TEST(Threads, AnnularCellScene) {
  // Axisymmetric with swirl: the bob's prescribed wall velocity shears the mixture; 41 × 55 nodes.
  // 1 thread vs 2: 3.0e-15.
  check_threads(1e-12, [](int threads) { return scene_state("paper/annular_shear.toml", {}, 20, threads); });
}

TEST(Threads, RodImpactScene) {
  // Axisymmetric: a free rigid rod launched onto the settled bed (free rigid contact); 30 × 35
  // nodes. 1 thread vs 2: 1.2e-12 (GCC -O3; 1.5e-13 clang -O1), in the granular law's structure
  // variable f (the impact drives the law's implicit solves, which amplify the last bits).
  check_threads(
      1e-11, [](int threads) { return scene_state("paper/rod_impact.toml", {"grid.cell_size=0.004"}, 30, threads); });
}

TEST(Threads, ElasticDiskDroppedOntoAnElasticBed) {
  // Plane strain without fluid (the solids' own grid pass, here on one thread of the region): a
  // falling, spinning elastic disk meets an elastic bed through frictional contact, walls on three
  // sides; cubic B-splines, FLIP/PIC blend. 1 thread vs 2: 2.2e-14.
  check_threads(1e-12, [](int threads) {
    const double h = 0.02, rho = 1000.0;
    Grid<2> grid(Vec<2>(0.0, 0.0), h, {50, 40});
    SolverOptions<PlaneStrain> opt;
    opt.shape = ShapeKind::CubicBSpline;
    opt.transfer = Transfer::FlipPicBlend;
    opt.flip_fraction = 0.95;
    opt.threads = threads;
    opt.gravity_m_s2 = Vec<2>(0.0, -9.81);
    opt.dt_s = 1.0;  // replaced by the stable step below
    LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e6;
    ep.poisson_ratio = 0.3;
    Solver<PlaneStrain> s(grid, opt);
    s.boundaries()[0].type = WallType::NoSlip;
    s.boundaries()[1].type = WallType::Slip;
    s.boundaries()[2].type = WallType::NoSlip;
    auto& disk = s.add_body("disk");
    const Vec<2> c(0.5, 0.45);
    const double dx = h / 2.0;
    for (int i = -10; i < 10; ++i)
      for (int j = -10; j < 10; ++j) {
        const Vec<2> r((i + 0.5) * dx, (j + 0.5) * dx);
        if (r.norm() <= 0.1) disk.add_point(c + r, dx * dx, 2 * rho, Vec<2>(0.2 - 3.0 * r[1], -1.0 + 3.0 * r[0]));
      }
    disk.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    auto& bed = s.add_body("bed", Phase::Grains);
    bed.set_law(std::make_unique<LinearElasticLaw<PlaneStrain>>(ep));
    fill_box(bed, Vec<2>(0.0, 0.0), Vec<2>(1.0, 0.34), h, 2, rho, [](const Vec<2>&) { return Vec<2>::Zero(); });
    s.add_contact(0, 0.3);
    s.options().dt_s = s.stable_dt(0.3);
    for (int i = 0; i < 40; ++i) s.step();
    return solver_state(s);
  });
}

TEST(Threads, SpinningBlockIn3D) {
  // 3D: a spinning elastic block falls onto a slip floor; 35³ nodes, above the 32 768 from which
  // the solids' velocity pass runs on both threads. 1 thread vs 2: 2.9e-15.
  check_threads(1e-12, [](int threads) {
    const double h = 0.1, rho = 1000.0;
    Grid<3> grid(Vec<3>(-1.5, -1.5, 0.0), h, {30, 30, 30});
    SolverOptions<ThreeD> opt;
    opt.threads = threads;
    opt.gravity_m_s2 = Vec<3>(0.0, 0.0, -9.81);
    LinearElasticParams ep;
    ep.youngs_modulus_Pa = 1e5;
    opt.dt_s = 0.2 * h / std::sqrt(ep.p_wave_modulus_Pa() / rho);
    Solver<ThreeD> s(grid, opt);
    s.boundaries()[4].type = WallType::Slip;  // floor (axis 2 lower)
    auto& b = s.add_body("block");
    b.set_law(std::make_unique<LinearElasticLaw<ThreeD>>(ep));
    const Vec<3> w(0.5, -1.0, 2.0);
    fill_box(b, Vec<3>(-0.3, -0.3, 0.05), Vec<3>(0.3, 0.3, 0.65), h, 2, rho, [&](const Vec<3>& x) {
      Vec<3> v = w.cross(x);
      v[0] += 0.1;
      v[2] -= 1.0;
      return v;
    });
    for (int i = 0; i < 20; ++i) s.step();
    return solver_state(s);
  });
}
