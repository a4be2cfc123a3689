// Granular return map (model.md E16–E24) throughput on one core for a realistic mix of regimes:
// steadily flowing points (f_1 and f_1 + f_3 active), relaxing points (compaction), jammed
// elastic points and separated (tensile) points, at an MPM-like time step of 1e-6 s.
#include <random>
#include <vector>

#include <Eigen/QR>
#include <benchmark/benchmark.h>

#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/params.hpp"

using namespace oobleck;

namespace {

struct Case {
  material::GranularState state;
  Eigen::Matrix3d D, W;
  double phi;
};

const material::GranularLaw& law() {
  static const material::GranularLaw l(rheology::load_preset("hermes2016"));
  return l;
}

/// A steady simple-shear state at (phi, rate), rotated into a random frame.
Case flowing(std::mt19937_64& rng, double phi, double rate, bool stop) {
  material::ShearOptions o;
  o.phi = phi;
  o.shear_rate = rate;
  o.duration = 40.0 / rate;
  o.dt = 0.02 / rate;
  o.samples = 2;
  const auto r = material::run_shear(law(), o);
  Eigen::Matrix3d D, W;
  material::simple_shear_rates(rate, D, W);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A(i, j) = n(rng);
  const Eigen::Matrix3d Q = A.householderQr().householderQ();
  Case c;
  c.state.sigma = Q * r.state.sigma * Q.transpose();
  c.state.f = r.state.f;
  c.D = stop ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(Q * D * Q.transpose());
  c.W = stop ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(Q * W * Q.transpose());
  c.phi = phi;
  return c;
}

std::vector<Case> make_mix(int n) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Case> pool;
  for (double phi : {0.40, 0.44, 0.48, 0.52})
    for (double rate : {0.1, 1.0, 10.0}) pool.push_back(flowing(rng, phi, rate, false));
  std::vector<Case> relaxing;
  for (double phi : {0.44, 0.52}) relaxing.push_back(flowing(rng, phi, 1.0, true));
  std::vector<Case> out;
  for (int k = 0; k < n; ++k) {
    const double r = U(rng);
    Case c;
    if (r < 0.5) {  // flowing
      c = pool[static_cast<std::size_t>(U(rng) * static_cast<double>(pool.size()))];
    } else if (r < 0.7) {  // relaxing after cessation
      c = relaxing[static_cast<std::size_t>(U(rng) * static_cast<double>(relaxing.size()))];
    } else if (r < 0.9) {  // jammed solid, elastic: phi > phi_m, small deviator, slow deformation
      c.phi = 0.54 + 0.02 * U(rng);
      c.state.f = U(rng);
      c.state.sigma = -100.0 * Eigen::Matrix3d::Identity();
      c.state.sigma(0, 1) = c.state.sigma(1, 0) = 10.0 * U(rng);
      c.D = 1e-3 * Eigen::Matrix3d::Identity();
      c.W.setZero();
    } else {  // separated: tensile
      c.phi = 0.3 + 0.2 * U(rng);
      c.state.f = U(rng);
      c.state.sigma = 10.0 * Eigen::Matrix3d::Identity();
      c.D = 1.0 * Eigen::Matrix3d::Identity();
      c.W.setZero();
    }
    out.push_back(c);
  }
  return out;
}

const material::GranularLaw& law_staggered() {
  material::GranularOptions o;
  o.structure_update = material::StructureUpdate::kStaggered;
  static const material::GranularLaw l(rheology::load_preset("hermes2016"), o);
  return l;
}

void run(benchmark::State& bs, const std::vector<Case>& cases, const material::GranularLaw& L = law()) {
  const double dt = 1e-6;
  std::size_t i = 0;
  long failures = 0, implicit = 0;
  for (auto _ : bs) {
    const Case& c = cases[i];
    material::GranularState s = c.state;
    const material::GranularUpdate u = L.update(s, c.D, c.W, dt, c.phi);
    failures += u.ok() ? 0 : 1;
    implicit += u.structure_iterations > 0 ? 1 : 0;
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(u.iterations);
    if (++i == cases.size()) i = 0;
  }
  bs.SetItemsProcessed(bs.iterations());
  bs.counters["failures"] = static_cast<double>(failures);
  bs.counters["implicit_f"] = static_cast<double>(implicit) / static_cast<double>(bs.iterations());
}

void BM_GranularUpdateMix(benchmark::State& bs) {
  static const std::vector<Case> cases = make_mix(4096);
  run(bs, cases);
}
BENCHMARK(BM_GranularUpdateMix);

// Same mix with the staggered structure update only (no implicit f solve at stiff points).
void BM_GranularUpdateMixStaggered(benchmark::State& bs) {
  static const std::vector<Case> cases = make_mix(4096);
  run(bs, cases, law_staggered());
}
BENCHMARK(BM_GranularUpdateMixStaggered);

void BM_GranularUpdateFlowing(benchmark::State& bs) {
  static const std::vector<Case> cases = [] {
    std::mt19937_64 rng(7);
    std::vector<Case> v;
    for (double phi : {0.40, 0.44, 0.48, 0.52})
      for (double rate : {0.1, 1.0, 10.0}) v.push_back(flowing(rng, phi, rate, false));
    return v;
  }();
  run(bs, cases);
}
BENCHMARK(BM_GranularUpdateFlowing);

}  // namespace

BENCHMARK_MAIN();
