// Granular return map (E16–E24, docs/equations.md) throughput on one core for a realistic mix of regimes:
// steadily flowing points (f_1 and f_1 + f_3 active), relaxing points (compaction), jammed
// elastic points and separated (tensile) points, at an MPM-like time step of 1e-6 s.
#include <cmath>
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

void run(benchmark::State& bs, const std::vector<Case>& cases, const material::GranularLaw& L = law(),
         double dt = 1e-6) {
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

/// The MPM adapter's forms: advance() point by point, or advance_batch() over all cases at once
/// (the f_1 and p_tr <= 0 Newton solves in lanes across points). Items: point updates.
void run_hot(benchmark::State& bs, const std::vector<Case>& cases, const material::GranularLaw& L, double dt,
             bool batch) {
  const auto n = static_cast<std::int64_t>(cases.size());
  std::vector<Eigen::Matrix3d> sigma0(cases.size()), sigma(cases.size()), Lv(cases.size());
  std::vector<double> f0(cases.size()), f(cases.size()), phi(cases.size());
  std::vector<material::GranularStep> step(cases.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    sigma0[k] = cases[k].state.sigma;
    f0[k] = cases[k].state.f;
    for (int i = 0; i < 9; ++i) Lv[k].data()[i] = cases[k].D.data()[i] + cases[k].W.data()[i];
    phi[k] = cases[k].phi;
  }
  for (auto _ : bs) {
    sigma = sigma0;
    f = f0;
    if (batch) {
      L.advance_batch(n, sigma.data(), f.data(), Lv.data(), phi.data(), dt, step.data());
    } else {
      for (std::size_t k = 0; k < cases.size(); ++k) {
        material::GranularState s{sigma[k], f[k]};
        Eigen::Matrix3d D, W;  // as in advance_batch
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) {
            D(i, j) = 0.5 * (Lv[k](i, j) + Lv[k](j, i));
            W(i, j) = 0.5 * (Lv[k](i, j) - Lv[k](j, i));
          }
        step[k] = L.advance(s, D, W, dt, phi[k]);
        sigma[k] = s.sigma;
        f[k] = s.f;
      }
    }
    benchmark::DoNotOptimize(sigma.data());
    benchmark::DoNotOptimize(f.data());
  }
  bs.SetItemsProcessed(bs.iterations() * n);
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

// States of a loose bed nearly at rest, as in bench/scenes/{intruder,wheel}_authors_setup.toml:
// phi = 0.47/0.482 < phi_m, f ~ 0, tiny stresses (p, tau_bar 1e-12..1e-2 Pa) and small strain
// rates (1e-5..1e-2 1/s, dilating or compacting: p_tr of either sign), so every point is in the
// shear (mostly p_tr <= 0: pressure created by dilatancy) or the shear+compaction regime.
struct LooseBed {
  double G, K, K_0, eta_0, phi, dt;
};

material::GranularLaw loose_bed_law(const LooseBed& b) {
  rheology::Preset P = rheology::load_preset("hermes2016");
  P.granular.G = b.G;
  P.granular.K = b.K;
  P.granular.K_0 = b.K_0;
  P.steady.eta_0 = b.eta_0;
  return material::GranularLaw(P);
}

std::vector<Case> make_loose_bed(const LooseBed& b, int n) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  auto log_uniform = [&](double lo, double hi) {
    return std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * U(rng));
  };
  auto random_sym = [&] {
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = N(rng);
    return Eigen::Matrix3d(0.5 * (m + m.transpose()));
  };
  std::vector<Case> out;
  for (int k = 0; k < n; ++k) {
    Case c;
    c.phi = b.phi;
    c.state.f = U(rng) < 0.2 ? 0.0 : log_uniform(1e-22, 1e-11);
    const double p0 = log_uniform(1e-12, 1e-2);
    Eigen::Matrix3d s = random_sym();
    s.diagonal().array() -= s.trace() / 3.0;
    c.state.sigma = std::sqrt(2.0) * (0.5 + 2.5 * U(rng)) * p0 * s / s.norm();
    c.state.sigma.diagonal().array() -= p0;
    const double rate = log_uniform(1e-5, 1e-2);
    // mostly uniaxial (settling bed): +-rate n n^T (60 % dilating: p_tr < 0) plus a smaller random part
    Eigen::Vector3d nv(N(rng), N(rng), N(rng));
    nv.normalize();
    const Eigen::Matrix3d R = random_sym();
    c.D = rate * ((U(rng) < 0.6 ? 1.0 : -1.0) * nv * nv.transpose() + 0.3 * R / R.norm());
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    A(0, 1) = N(rng);
    A(1, 0) = -A(0, 1);
    c.W = 0.5 * rate * A;
    out.push_back(c);
  }
  return out;
}

void loose_bed(benchmark::State& bs, const LooseBed& b) {
  const material::GranularLaw L = loose_bed_law(b);
  const std::vector<Case> cases = make_loose_bed(b, 4096);
  long tension = 0, shear = 0, shear_iter = 0;
  for (const Case& c : cases) {
    material::GranularState s = c.state;
    const material::GranularUpdate u = L.update(s, c.D, c.W, b.dt, c.phi);
    shear += u.regime == material::GranularRegime::kShear ? 1 : 0;
    tension += (u.regime == material::GranularRegime::kShear && u.p_trial <= 0.0) ? 1 : 0;
    shear_iter += u.regime == material::GranularRegime::kShear ? u.iterations : 0;
  }
  run(bs, cases, L, b.dt);
  bs.counters["shear"] = static_cast<double>(shear) / static_cast<double>(cases.size());
  bs.counters["shear_ptr_le0"] = static_cast<double>(tension) / static_cast<double>(cases.size());
  bs.counters["shear_iterations"] = shear > 0 ? static_cast<double>(shear_iter) / static_cast<double>(shear) : 0.0;
}

// intruder bed: G = 3.8e7, K = 8.3e7 Pa, K_0 = 0.2, eta_0 = 4.6e-3 Pa s, phi = 0.47, dt = 1e-6 s
void BM_GranularUpdateLooseBedIntruder(benchmark::State& bs) { loose_bed(bs, {3.8e7, 8.3e7, 0.2, 4.6e-3, 0.47, 1e-6}); }
BENCHMARK(BM_GranularUpdateLooseBedIntruder);

// wheel bed: G = 3.8e5, K = 8.3e5 Pa, K_0 = 1, eta_0 = 1e-3 Pa s, phi = 0.482, dt = 2e-5 s
void BM_GranularUpdateLooseBedWheel(benchmark::State& bs) { loose_bed(bs, {3.8e5, 8.3e5, 1.0, 1e-3, 0.482, 2e-5}); }
BENCHMARK(BM_GranularUpdateLooseBedWheel);

// The same beds and the mix through the MPM adapter's calls: advance() per point vs advance_batch().
void loose_bed_hot(benchmark::State& bs, const LooseBed& b, bool batch) {
  const material::GranularLaw L = loose_bed_law(b);
  static std::vector<Case> cases;
  cases = make_loose_bed(b, 4096);
  run_hot(bs, cases, L, b.dt, batch);
}
void BM_AdvanceLooseBedWheel(benchmark::State& bs) { loose_bed_hot(bs, {3.8e5, 8.3e5, 1.0, 1e-3, 0.482, 2e-5}, false); }
void BM_AdvanceBatchLooseBedWheel(benchmark::State& bs) {
  loose_bed_hot(bs, {3.8e5, 8.3e5, 1.0, 1e-3, 0.482, 2e-5}, true);
}
void BM_AdvanceLooseBedIntruder(benchmark::State& bs) {
  loose_bed_hot(bs, {3.8e7, 8.3e7, 0.2, 4.6e-3, 0.47, 1e-6}, false);
}
void BM_AdvanceBatchLooseBedIntruder(benchmark::State& bs) {
  loose_bed_hot(bs, {3.8e7, 8.3e7, 0.2, 4.6e-3, 0.47, 1e-6}, true);
}
void BM_AdvanceMix(benchmark::State& bs) { run_hot(bs, make_mix(4096), law(), 1e-6, false); }
void BM_AdvanceBatchMix(benchmark::State& bs) { run_hot(bs, make_mix(4096), law(), 1e-6, true); }
BENCHMARK(BM_AdvanceLooseBedWheel);
BENCHMARK(BM_AdvanceBatchLooseBedWheel);
BENCHMARK(BM_AdvanceLooseBedIntruder);
BENCHMARK(BM_AdvanceBatchLooseBedIntruder);
BENCHMARK(BM_AdvanceMix);
BENCHMARK(BM_AdvanceBatchMix);

}  // namespace

BENCHMARK_MAIN();
