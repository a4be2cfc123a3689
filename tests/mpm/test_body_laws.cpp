// The body laws' chunked update (StressLaw::chunk_count / update_chunk / end_update), which the
// solver runs for all bodies in one parallel loop with a dynamic schedule: the chunks must cover
// every point once, be independent of each other (any order gives the whole-body update bit for
// bit), and the NaN guard must report the lowest bad index over all chunks.
#include <gtest/gtest.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include "oobleck/core/error.hpp"
#include "oobleck/mpm/granular_body_law.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/rheology/params.hpp"
#include "solver_phases.hpp"

using namespace oobleck;
using namespace oobleck::mpm;

namespace {

// A plane-strain body of n points near a dense packing (φ ≈ 0.5 from m/(ρ_s V)), with random
// in-plane velocity gradients and compressive stresses; the fluid fields phi and div q as well.
Body<PlaneStrain> random_body(std::int64_t n, unsigned seed, double rho_s) {
  Body<PlaneStrain> b;
  b.name = "test";
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::int64_t p = 0; p < n; ++p) {
    const double V = 1e-6;
    b.add_point(Vec<2>(0.01 * static_cast<double>(p), 0.0), V, 0.5 * rho_s * (1.0 + 0.02 * u(gen)));
    Mat3 L = Mat3::Zero();
    L(0, 0) = 20.0 * u(gen);
    L(0, 1) = 50.0 * u(gen);
    L(1, 0) = 50.0 * u(gen);
    L(1, 1) = 20.0 * u(gen);
    b.L_1_s[p] = L;
    Mat3 s = Mat3::Zero();
    const double pres = 200.0 * (1.0 + u(gen));
    s(0, 0) = -pres + 30.0 * u(gen);
    s(1, 1) = -pres + 30.0 * u(gen);
    s(2, 2) = -pres;
    s(0, 1) = s(1, 0) = 40.0 * u(gen);
    b.stress_Pa[p] = s;
  }
  b.phi.assign(static_cast<std::size_t>(n), 0.0);
  b.div_q_1_s.assign(static_cast<std::size_t>(n), 0.0);
  for (std::int64_t p = 0; p < n; ++p) {
    b.phi[static_cast<std::size_t>(p)] = 0.45 + 0.05 * u(gen);
    b.div_q_1_s[static_cast<std::size_t>(p)] = 5.0 * u(gen);
  }
  return b;
}

template <class Law>
void run_chunks_backwards(Law& law, Body<PlaneStrain>& b, double dt) {
  std::int64_t bad = kAllFinite;
  for (std::int64_t c = law.chunk_count(b) - 1; c >= 0; --c) bad = std::min(bad, law.update_chunk(b, dt, c));
  law.end_update(b, dt, bad);
}

void expect_same_stresses(const Body<PlaneStrain>& a, const Body<PlaneStrain>& b, const Body<PlaneStrain>& before) {
  ASSERT_EQ(a.size(), b.size());
  std::int64_t changed = 0;
  for (std::int64_t p = 0; p < a.size(); ++p) {
    for (int e = 0; e < 9; ++e) ASSERT_EQ(a.stress_Pa[p].data()[e], b.stress_Pa[p].data()[e]) << "point " << p;
    if (a.stress_Pa[p] != before.stress_Pa[p]) ++changed;
  }
  EXPECT_EQ(changed, a.size());  // every chunk ran: every point's stress moved
}

}  // namespace

TEST(BodyLaws, FluidChunksInAnyOrderEqualTheWholeBodyUpdate) {
  material::FluidParams fp;
  fp.rho_f0_kg_m3 = 1620.0;
  fp.kappa_Pa = 1e6;
  const std::int64_t n = 2500;  // not a multiple of the chunk size
  constexpr unsigned kSeed = 7;
  constexpr double kRho = 1620.0;
  const Body<PlaneStrain> start = random_body(n, kSeed, kRho);
  Body<PlaneStrain> a = random_body(n, kSeed, kRho), b = random_body(n, kSeed, kRho);  // (Body is not copyable)
  FluidLaw<PlaneStrain> la(fp, 0.2), lb(fp, 0.2);
  la.resize(n);
  lb.resize(n);
  EXPECT_GE(la.chunk_count(a), 2);
  phases::update_stress(la, a, 1e-5);
  run_chunks_backwards(lb, b, 1e-5);
  expect_same_stresses(a, b, start);
  for (std::int64_t p = 0; p < n; ++p) ASSERT_EQ(la.ln_J[p], lb.ln_J[p]);
  EXPECT_EQ(la.first_non_finite_stress(), kAllFinite);
  EXPECT_EQ(lb.first_non_finite_stress(), kAllFinite);
}

TEST(BodyLaws, GranularChunksInAnyOrderEqualTheWholeBodyUpdate) {
  const rheology::Preset preset = rheology::load_preset("hermes2016");
  const std::int64_t n = 1000;  // 3 full chunks and a partial one
  constexpr unsigned kSeed = 11;
  const double kRho = preset.granular.rho_s;
  const Body<PlaneStrain> start = random_body(n, kSeed, kRho);
  Body<PlaneStrain> a = random_body(n, kSeed, kRho), b = random_body(n, kSeed, kRho);  // (Body is not copyable)
  GranularBodyLaw<PlaneStrain> la(preset), lb(preset);
  la.resize(n);
  lb.resize(n);
  for (std::int64_t p = 0; p < n; ++p) la.f[p] = lb.f[p] = 0.1 + 0.8 * static_cast<double>(p % 7) / 7.0;
  EXPECT_GE(la.chunk_count(a), 4);
  phases::update_stress(la, a, 1e-5);
  run_chunks_backwards(lb, b, 1e-5);
  expect_same_stresses(a, b, start);
  for (std::int64_t p = 0; p < n; ++p) {
    ASSERT_EQ(la.f[p], lb.f[p]);
    ASSERT_EQ(la.gamma_dot_p[p], lb.gamma_dot_p[p]);
  }
}

TEST(BodyLaws, TheGuardReportsTheLowestBadPointOverAllChunks) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  {
    material::FluidParams fp;
    Body<PlaneStrain> b = random_body(2500, 3, 1000.0);
    b.L_1_s[2300](0, 0) = nan;  // last chunk
    b.L_1_s[1500](0, 1) = nan;  // a middle chunk
    FluidLaw<PlaneStrain> law(fp, 0.2);
    law.resize(b.size());
    run_chunks_backwards(law, b, 1e-5);
    EXPECT_EQ(law.first_non_finite_stress(), 1500);
  }
  {
    const rheology::Preset preset = rheology::load_preset("hermes2016");
    Body<PlaneStrain> b = random_body(1000, 5, preset.granular.rho_s);
    b.L_1_s[900](0, 0) = nan;
    b.L_1_s[700](1, 1) = nan;
    GranularBodyLaw<PlaneStrain> law(preset);
    law.resize(b.size());
    try {
      phases::update_stress(law, b, 1e-5);
      FAIL() << "a non-finite velocity gradient must stop the granular law";
    } catch (const NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("point 700 "), std::string::npos) << e.what();
    }
  }
}

// The registry of persistent fields (mpm/fields.hpp): a body and its law declare their arrays
// once, with the checkpoint datasets and frame names that the run output uses.
TEST(PersistentFields, BodyAndLawsDeclareTheirArrays) {
  auto names = [](Body<PlaneStrain>& b) {
    FieldList list;
    list.group("body0");
    b.declare_fields(list);
    b.law->declare_fields(b, list);
    std::string ck, frame;
    for (const auto& f : list.fields())
      if (f.in_checkpoint) ck += f.dataset() + fmt::format(":{} ", f.width);
    for (const auto* f : list.frame_fields()) frame += f->shown_as() + " ";
    return ck + "| " + frame;
  };
  Body<PlaneStrain> grains = random_body(10, 1, 2500.0);
  grains.set_law(std::make_unique<GranularBodyLaw<PlaneStrain>>(rheology::load_preset("hermes2016")));
  EXPECT_EQ(names(grains),
            "body0/mass:1 body0/volume:1 body0/volume0:1 body0/x:2 body0/v:2 body0/C:4 body0/L:9 "
            "body0/stress:9 body0/f_ext:2 body0/phi:1 body0/div_q:1 granular/f:1 granular/regime:1 "
            "granular/gamma_dot_p:1 | position velocity stress pressure mass volume f phi tau_bar regime gamma_dot_p ");
  Body<PlaneStrain> fluid = random_body(10, 2, 1000.0);
  material::FluidParams fp;
  fluid.set_law(std::make_unique<FluidLaw<PlaneStrain>>(fp, 0.2));
  EXPECT_EQ(names(fluid),
            "body0/mass:1 body0/volume:1 body0/volume0:1 body0/x:2 body0/v:2 body0/C:4 body0/L:9 "
            "body0/stress:9 body0/f_ext:2 body0/phi:1 body0/div_q:1 fluid/ln_J:1 "
            "| position velocity stress fluid_pressure mass volume phi J ");
}
