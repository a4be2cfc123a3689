// P2G and G2P (docs/mpm.md, "The step": phases 2 and 6) against the textbook node-by-node sums.
//
// The solver's transfers factorise the tensor-product shape functions row by row in 2D and compute
// the shape functions inside P2G; here every nodal and point quantity is summed again directly,
// node by node, from the per-node accessors of a cache filled by compute_shape_cache
// (N_ip = ∏ N_a, ∇N_ip, x_i − x_p), for each kernel, both transfers, with and without the
// fluid's pressure split and the mixture fields, in plane strain and axisymmetric mode, across a
// periodic seam and next to walls.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

#include "oobleck/mpm/transfer.hpp"
#include "solver_phases.hpp"

using namespace oobleck::mpm;

namespace {

template <class G>
struct Setup {
  static constexpr int D = G::dim, NC = G::ncomp;
  Grid<D> grid;
  Body<G> body;
  explicit Setup(unsigned seed) : grid(Vec<D>(0.1, -0.2), 0.05, {12, 9}, {!G::has_hoop_terms, false}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0), s(-1.0, 1.0);
    body.name = "test";
    for (int q = 0; q < 300; ++q) {
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = grid.origin_m[a] + (0.02 + 0.96 * u(rng)) * grid.length(a);
      if (q % 7 == 0) x[0] = grid.origin_m[0] + 1e-3 * u(rng);  // at the seam / inner wall
      Vec<NC> v;
      for (int c = 0; c < NC; ++c) v[c] = s(rng);
      body.add_point(x, 1e-4 * (0.5 + u(rng)), 1000.0 + 500.0 * u(rng), v);
      const std::size_t p = body.x_m.size() - 1;
      for (int c = 0; c < NC; ++c) {
        for (int a = 0; a < D; ++a) body.C_1_s[p](c, a) = 10.0 * s(rng);
        body.f_ext_N[p][c] = 0.1 * s(rng);
      }
      Mat3 S;
      for (int i = 0; i < 9; ++i) S.data()[i] = 1e3 * s(rng);
      body.stress_Pa[p] = 0.5 * (S + S.transpose());
    }
  }
};

// Random nodal velocities (new and old), mixture flux and porosity in [0.4, 0.6] for G2P.
template <class G>
struct RandomNodes {
  static constexpr int NC = G::ncomp;
  GridField<G> field;
  std::vector<double> porosity;
  std::vector<Vec<NC>> flux;
  explicit RandomNodes(int nn) : porosity(nn), flux(nn) {
    field.resize(nn, 1);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> s(-1.0, 1.0), u(0.0, 1.0);
    for (int i = 0; i < nn; ++i)
      for (int c = 0; c < NC; ++c) {
        field.velocity[i][c] = s(rng);
        field.velocity_old[i][c] = s(rng);
        flux[i][c] = s(rng);
        porosity[i] = 0.4 + 0.2 * u(rng);
      }
  }
};

double max_abs(double a, double b) { return std::max(std::fabs(a), std::fabs(b)); }

template <class G, class Kernel>
void check_p2g(const Kernel& kernel, bool apic, bool split) {
  constexpr int D = G::dim, NC = G::ncomp, S = Kernel::support;
  constexpr int K = S * S;
  Setup<G> st(7u + (apic ? 1u : 0u) + (split ? 2u : 0u));
  const auto& b = st.body;
  const int nn = st.grid.node_count();
  GridField<G> field;
  field.resize(nn, 1);
  ShapeCache<D> cache;
  ASSERT_EQ((phases::particles_to_grid<G, K>(b, st.grid, kernel, cache, field, apic, split)), 0);
  ShapeCache<D> ref_cache;
  ASSERT_EQ(compute_shape_cache(st.grid, kernel, b.x_m, ref_cache), 0);
  // The cache P2G leaves for the rest of the step is compute_shape_cache's, bit for bit.
  for (std::int64_t p = 0; p < b.size(); ++p) {
    EXPECT_EQ(cache.inv_D[p], ref_cache.inv_D[p]);
    for (int k = 0; k < cache.K; ++k) {
      ASSERT_EQ(cache.node(p, k), ref_cache.node(p, k));
      ASSERT_EQ(cache.weight(p, k), ref_cache.weight(p, k));
      ASSERT_EQ(cache.gradient(p, k), ref_cache.gradient(p, k));
      ASSERT_EQ(cache.offset(p, k), ref_cache.offset(p, k));
    }
  }
  std::vector<double> m(nn, 0.0), vol(nn, 0.0);
  std::vector<Vec<NC>> mv(nn, Vec<NC>::Zero()), f(nn, Vec<NC>::Zero()), fp(nn, Vec<NC>::Zero());
  for (std::int64_t p = 0; p < b.size(); ++p) {
    Mat3 sig = b.stress_Pa[p];
    const double pres = -sig.trace() / 3.0;
    if (split) sig += pres * Mat3::Identity();
    const Vec<D>& x = b.x_m[p];
    Vec<NC> fpt = b.f_ext_N[p];
    Vec<NC> fp_hoop = Vec<NC>::Zero();
    if constexpr (G::has_hoop_terms) {
      fpt += G::hoop_force(sig, x, b.volume_m3[p]) + b.mass_kg[p] * G::inertial_acceleration(x, b.v_m_s[p]);
      if (split) fp_hoop = G::hoop_force(-pres * Mat3::Identity(), x, b.volume_m3[p]);  // σ = −p 1
    }
    for (int k = 0; k < ref_cache.K; ++k) {
      const int i = ref_cache.node(p, k);
      const double w = ref_cache.weight(p, k);
      const Vec<D> g = ref_cache.gradient(p, k), off = ref_cache.offset(p, k);
      m[i] += w * b.mass_kg[p];
      Vec<NC> vel = b.v_m_s[p];
      if (apic) vel += b.C_1_s[p] * off;
      mv[i] += w * b.mass_kg[p] * vel;
      f[i] += -b.volume_m3[p] * sig.template topLeftCorner<NC, D>() * g + w * fpt;
      if (split) {
        for (int a = 0; a < D; ++a) fp[i][a] += b.volume_m3[p] * pres * g[a];
        fp[i] += w * fp_hoop;
        vol[i] += w * b.volume_m3[p];
      }
    }
  }
  double m_scale = 0, mv_scale = 0, f_scale = 0, fp_scale = 0, vol_scale = 0;
  for (int i = 0; i < nn; ++i) {
    m_scale = std::max(m_scale, m[i]);
    mv_scale = std::max(mv_scale, mv[i].cwiseAbs().maxCoeff());
    f_scale = std::max(f_scale, f[i].cwiseAbs().maxCoeff());
    fp_scale = std::max(fp_scale, fp[i].cwiseAbs().maxCoeff());
    vol_scale = std::max(vol_scale, vol[i]);
  }
  ASSERT_GT(f_scale, 0.0);
  for (int i = 0; i < nn; ++i) {
    ASSERT_NEAR(field.mass_kg[i], m[i], 1e-13 * m_scale) << "node " << i;
    for (int c = 0; c < NC; ++c) {
      ASSERT_NEAR(field.momentum[i][c], mv[i][c], 1e-13 * mv_scale) << "node " << i << " c " << c;
      ASSERT_NEAR(field.force_N[i][c], f[i][c], 1e-13 * f_scale) << "node " << i << " c " << c;
      if (split) {
        ASSERT_NEAR(field.pressure_force_N[i][c], fp[i][c], 1e-13 * fp_scale) << "node " << i;
      }
    }
    if (split) {
      ASSERT_NEAR(field.volume_m3[i], vol[i], 1e-13 * vol_scale) << "node " << i;
    }
  }
}

template <class G, class Kernel>
void check_g2p(const Kernel& kernel, Transfer transfer, bool mixture) {
  constexpr int D = G::dim, NC = G::ncomp, S = Kernel::support;
  constexpr int K = S * S;
  Setup<G> st(21u + (mixture ? 1u : 0u));
  auto& b = st.body;
  const int nn = st.grid.node_count();
  RandomNodes<G> rn(nn);
  GridField<G>& field = rn.field;
  const std::vector<double>& porosity = rn.porosity;
  const std::vector<Vec<NC>>& flux = rn.flux;
  if (mixture) {
    b.phi.assign(b.x_m.size(), 0.0);
    b.div_q_1_s.assign(b.x_m.size(), 0.0);
  }
  ShapeCache<D> cache;
  ASSERT_EQ(compute_shape_cache(st.grid, kernel, b.x_m, cache), 0);
  const Body<G> before = [&] {
    Body<G> c;
    c.x_m = b.x_m, c.v_m_s = b.v_m_s, c.volume_m3 = b.volume_m3;
    return c;
  }();
  const double alpha = 0.95, dt = 1e-3;
  const std::int64_t bad =
      phases::grid_to_particles<G, K>(b, cache, field, st.grid, transfer, alpha, dt,
                                      mixture ? porosity.data() : nullptr, mixture ? flux.data() : nullptr);
  EXPECT_EQ(bad, kAllFinite);
  for (std::int64_t p = 0; p < b.size(); ++p) {
    Vec<NC> v_pic = Vec<NC>::Zero(), dv = Vec<NC>::Zero(), q = Vec<NC>::Zero();
    Mat<NC, D> grad = Mat<NC, D>::Zero(), B = Mat<NC, D>::Zero();
    double n = 0.0, div_q = 0.0;
    for (int k = 0; k < cache.K; ++k) {
      const int i = cache.node(p, k);
      const double w = cache.weight(p, k);
      const Vec<D> g = cache.gradient(p, k), off = cache.offset(p, k);
      v_pic += w * field.velocity[i];
      dv += w * (field.velocity[i] - field.velocity_old[i]);
      grad += field.velocity[i] * g.transpose();
      B += w * field.velocity[i] * off.transpose();
      n += w * porosity[i];
      q += w * flux[i];
      div_q += flux[i].template head<D>().dot(g);
    }
    const Vec<D>& x0 = before.x_m[p];
    Vec<D> x = x0 + dt * v_pic.template head<D>();
    st.grid.wrap(x);
    for (int a = 0; a < D; ++a) ASSERT_NEAR(b.x_m[p][a], x[a], 1e-14) << "point " << p;
    Vec<NC> v = v_pic;
    if (transfer == Transfer::FlipPicBlend) v = alpha * (before.v_m_s[p] + dv) + (1.0 - alpha) * v_pic;
    for (int c = 0; c < NC; ++c) ASSERT_NEAR(b.v_m_s[p][c], v[c], 1e-13) << "point " << p;
    if (transfer == Transfer::Apic) {
      Mat<NC, D> C = grad;
      if (!Kernel::apic_by_gradient) C = B * cache.inv_D[p].asDiagonal();
      for (int c = 0; c < NC; ++c)
        for (int a = 0; a < D; ++a) ASSERT_NEAR(b.C_1_s[p](c, a), C(c, a), 1e-11 * std::max(1.0, std::fabs(C(c, a))));
    }
    const Mat3 L = G::velocity_gradient(grad, x0, v_pic);
    for (int k = 0; k < 9; ++k)
      ASSERT_NEAR(b.L_1_s[p].data()[k], L.data()[k], 1e-11 * std::max(1.0, L.cwiseAbs().maxCoeff()));
    ASSERT_NEAR(b.volume_m3[p], before.volume_m3[p] * std::exp(dt * L.trace()), 1e-14 * before.volume_m3[p]);
    if (mixture) {
      if constexpr (G::has_hoop_terms) div_q += G::div_extra(q, x0);
      ASSERT_NEAR(b.phi[p], 1.0 - n, 1e-14);
      ASSERT_NEAR(b.div_q_1_s[p], div_q, 1e-11 * max_abs(div_q, 1.0));
    }
  }
}

template <class G>
void check_all_kernels() {
  for (bool apic : {true, false})
    for (bool split : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "apic " << apic << " split " << split);
      check_p2g<G>(QuadraticBSplineKernel{}, apic, split);
      check_p2g<G>(CubicBSplineKernel{}, apic, split);
      check_p2g<G>(LinearKernel{}, apic, split);
      check_p2g<G>(UGimpKernel{0.25}, apic, split);
    }
  for (Transfer t : {Transfer::Apic, Transfer::FlipPicBlend})
    for (bool mix : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "apic " << (t == Transfer::Apic) << " mixture " << mix);
      check_g2p<G>(QuadraticBSplineKernel{}, t, mix);
      check_g2p<G>(CubicBSplineKernel{}, t, mix);
      check_g2p<G>(LinearKernel{}, t, mix);
      check_g2p<G>(UGimpKernel{0.25}, t, mix);
    }
}

}  // namespace

TEST(Transfer, PlaneStrainP2GAndG2PEqualTheNodeByNodeSums) { check_all_kernels<PlaneStrain>(); }

TEST(Transfer, AxisymmetricP2GAndG2PEqualTheNodeByNodeSums) { check_all_kernels<Axisymmetric>(); }

// Step 3 inside P2G: with gravity_m_s2, the nodal forces are those of P2G followed by a separate
// add_gravity pass, bit for bit, on one thread (the separate pass) and on two (gravity in the pass
// that sums the threads' copies); masses and momenta are untouched.
template <class G>
void check_gravity_in_p2g(int threads) {
  constexpr int D = G::dim, NC = G::ncomp, K = 9;
  Setup<G> st(21u);
  const int nn = st.grid.node_count();
  const QuadraticBSplineKernel kernel{};
  Vec<NC> g = Vec<NC>::Zero();
  g[1] = -9.81;
  g[0] = 0.37;  // a second component, so that both lanes of the pairs are checked
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  GridField<G> with, sep;
  with.resize(nn, threads);
  sep.resize(nn, threads);
  ShapeCache<D> c1, c2;
  ASSERT_EQ((phases::particles_to_grid<G, K>(st.body, st.grid, kernel, c1, with, true, true, &g)), 0);
  ASSERT_EQ((phases::particles_to_grid<G, K>(st.body, st.grid, kernel, c2, sep, true, true)), 0);
  for (int i = 0; i < nn; ++i) sep.force_N[i] += sep.mass_kg[i] * g;  // step 3 as a separate pass
  omp_set_num_threads(saved);
  double f_max = 0.0;
  for (int i = 0; i < nn; ++i) {
    ASSERT_EQ(with.mass_kg[i], sep.mass_kg[i]) << "node " << i;
    for (int c = 0; c < NC; ++c) {
      ASSERT_EQ(with.momentum[i][c], sep.momentum[i][c]) << "node " << i;
      ASSERT_EQ(with.force_N[i][c], sep.force_N[i][c]) << "node " << i << ", component " << c;
      f_max = std::max(f_max, std::fabs(with.force_N[i][c]));
    }
  }
  // and gravity is there: the total force is the points' total weight plus the internal and
  // external forces, which P2G without gravity gives
  GridField<G> none;
  none.resize(nn, threads);
  ShapeCache<D> c3;
  ASSERT_EQ((phases::particles_to_grid<G, K>(st.body, st.grid, kernel, c3, none, true, true)), 0);
  Vec<NC> F_with = Vec<NC>::Zero(), F_none = Vec<NC>::Zero();
  for (int i = 0; i < nn; ++i) {
    F_with += with.force_N[i];
    F_none += none.force_N[i];
  }
  const Vec<NC> W = st.body.total_mass() * g;
  for (int c = 0; c < NC; ++c) EXPECT_NEAR(F_with[c] - F_none[c], W[c], 1e-12 * (f_max * nn + std::fabs(W[c])));
}

TEST(Transfer, GravityInP2GEqualsTheSeparatePassOnOneAndTwoThreads) {
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    check_gravity_in_p2g<PlaneStrain>(threads);
    check_gravity_in_p2g<Axisymmetric>(threads);
  }
}

// Axisymmetric beds without swirl: P2G leaves out the θ terms of points with zero θ entries of v,
// C, σ and f_ext, and G2P the θ sums when no node has a θ velocity or flux. Both give the general
// kernels' values bit for bit (the θ results stay +0), here on a body that mixes points with and
// without swirl.
namespace {
void zero_swirl(Body<Axisymmetric>& b, std::int64_t p) {
  b.v_m_s[p][2] = 0.0;
  b.C_1_s[p].row(2).setZero();
  b.f_ext_N[p][2] = 0.0;
  Mat3& s = b.stress_Pa[p];
  s(0, 2) = s(2, 0) = s(1, 2) = s(2, 1) = 0.0;
}
}  // namespace

TEST(Transfer, AxisymmetricWithoutSwirlEqualsTheGeneralKernelsBitForBit) {
  using G = Axisymmetric;
  constexpr int NC = G::ncomp, K = 9;
  ::Setup<G> st(33u);
  auto& b = st.body;
  std::int64_t without = 0;
  for (std::int64_t p = 0; p < b.size(); ++p)
    if (p % 3 != 0) zero_swirl(b, p);
  for (std::int64_t p = 0; p < b.size(); ++p) without += detail::point_without_swirl(b, p) ? 1 : 0;
  ASSERT_EQ(without, b.size() - (b.size() + 2) / 3);
  const int nn = st.grid.node_count();
  const QuadraticBSplineKernel kernel{};
  for (bool apic : {true, false})
    for (bool split : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "apic " << apic << " split " << split);
      GridField<G> field;
      field.resize(nn, 1);
      ShapeCache<2> cache;
      ASSERT_EQ((phases::particles_to_grid<G, K>(b, st.grid, kernel, cache, field, apic, split)), 0);
      std::vector<double> m(nn, 0.0), vol(nn, 0.0);
      std::vector<Vec<NC>> mv(nn, Vec<NC>::Zero()), f(nn, Vec<NC>::Zero()), fp(nn, Vec<NC>::Zero());
      for (std::int64_t p = 0; p < b.size(); ++p) {
        auto general = [&]<bool A, bool Sp>() {
          detail::particles_to_grid_point<G, K, A, Sp, false>(b, cache, p, m.data(), mv.data()->data(),
                                                              f.data()->data(), fp.data()->data(), vol.data());
        };
        if (apic && split) general.operator()<true, true>();
        if (apic && !split) general.operator()<true, false>();
        if (!apic && split) general.operator()<false, true>();
        if (!apic && !split) general.operator()<false, false>();
      }
      for (int i = 0; i < nn; ++i) {
        ASSERT_EQ(field.mass_kg[i], m[i]);
        for (int c = 0; c < NC; ++c) {
          ASSERT_EQ(field.momentum[i][c], mv[i][c]) << "node " << i << " c " << c;
          ASSERT_EQ(field.force_N[i][c], f[i][c]) << "node " << i << " c " << c;
          if (split) {
            ASSERT_EQ(field.pressure_force_N[i][c], fp[i][c]) << "node " << i << " c " << c;
            ASSERT_FALSE(std::signbit(field.pressure_force_N[i][c]) != std::signbit(fp[i][c]));
          }
          ASSERT_FALSE(std::signbit(field.momentum[i][c]) != std::signbit(mv[i][c]));
          ASSERT_FALSE(std::signbit(field.force_N[i][c]) != std::signbit(f[i][c]));
        }
        if (split) {
          ASSERT_EQ(field.volume_m3[i], vol[i]);
        }
      }
    }
  // G2P on nodes without θ velocity (new and old) and θ flux, of either sign of zero.
  GridField<G> field;
  field.resize(nn, 1);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> s(-1.0, 1.0);
  std::vector<double> porosity(nn);
  std::vector<Vec<NC>> flux(nn);
  for (int i = 0; i < nn; ++i) {
    const double zero = i % 2 == 0 ? 0.0 : -0.0;
    field.velocity[i] = Vec<NC>(s(rng), s(rng), zero);
    field.velocity_old[i] = Vec<NC>(s(rng), s(rng), -zero);
    flux[i] = Vec<NC>(s(rng), s(rng), zero);
    porosity[i] = 0.5 + 0.1 * s(rng);
  }
  b.phi.assign(b.x_m.size(), 0.0);
  b.div_q_1_s.assign(b.x_m.size(), 0.0);
  ShapeCache<2> cache;
  ASSERT_EQ(compute_shape_cache(st.grid, kernel, b.x_m, cache), 0);
  for (Transfer t : {Transfer::Apic, Transfer::FlipPicBlend})
    for (bool mix : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "apic " << (t == Transfer::Apic) << " mixture " << mix);
      ::Setup<G> s1(33u), s2(33u);  // (bodies are not copyable: the same points twice)
      Body<G>&b1 = s1.body, &b2 = s2.body;
      for (Body<G>* x : {&b1, &b2}) {
        for (std::int64_t p = 0; p < x->size(); ++p)
          if (p % 3 != 0) zero_swirl(*x, p);
        x->phi.assign(x->x_m.size(), 0.0);
        x->div_q_1_s.assign(x->x_m.size(), 0.0);
      }
      const double* n = mix ? porosity.data() : nullptr;
      const Vec<NC>* q = mix ? flux.data() : nullptr;
      // Both kernels compiled here (the library's own instance may be built for another CPU level,
      // with other contractions).
      auto both = [&]<bool A, bool Mix>() {
        const std::int64_t blocks = (b.size() + oobleck::numerics::kMathBlock - 1) / oobleck::numerics::kMathBlock;
        const G2PArgs<G> a1{&b1, &cache, &field, &st.grid, 0.95, 1e-3, n, q};
        const G2PArgs<G> a2{&b2, &cache, &field, &st.grid, 0.95, 1e-3, n, q};
        const std::int64_t r1 = detail::grid_to_particles_kernel<G, K, A, false, Mix, true>(a1, 0, blocks);
        const std::int64_t r2 = detail::grid_to_particles_kernel<G, K, A, false, Mix, false>(a2, 0, blocks);
        return std::min(r1, r2);  // (kAllFinite only if both are)
      };
      std::int64_t bad = 0;
      if (t == Transfer::Apic && mix) bad = both.operator()<true, true>();
      if (t == Transfer::Apic && !mix) bad = both.operator()<true, false>();
      if (t != Transfer::Apic && mix) bad = both.operator()<false, true>();
      if (t != Transfer::Apic && !mix) bad = both.operator()<false, false>();
      ASSERT_EQ(bad, kAllFinite);
      auto same = [](const double* x, const double* y, std::size_t count) {
        for (std::size_t k = 0; k < count; ++k)
          if (std::bit_cast<std::uint64_t>(x[k]) != std::bit_cast<std::uint64_t>(y[k])) return false;
        return true;
      };
      const auto np = static_cast<std::size_t>(b.size());
      EXPECT_TRUE(same(b1.x_m.data()->data(), b2.x_m.data()->data(), 2 * np));
      EXPECT_TRUE(same(b1.v_m_s.data()->data(), b2.v_m_s.data()->data(), NC * np));
      EXPECT_TRUE(same(b1.C_1_s.data()->data(), b2.C_1_s.data()->data(), 2 * NC * np));
      EXPECT_TRUE(same(b1.L_1_s.data()->data(), b2.L_1_s.data()->data(), 9 * np));
      EXPECT_TRUE(same(b1.volume_m3.data(), b2.volume_m3.data(), np));
      if (mix) {
        EXPECT_TRUE(same(b1.phi.data(), b2.phi.data(), np));
        EXPECT_TRUE(same(b1.div_q_1_s.data(), b2.div_q_1_s.data(), np));
      }
    }
}

namespace {

// The solver runs G2P's blocks in static shares with stealing, several bodies in one parallel
// region (Solver::update_points): a block's result must not depend on which blocks ran before
// it, or on which thread runs it.
template <class G>
void check_g2p_blocks_in_any_order() {
  constexpr int NC = G::ncomp, K = 9;
  const QuadraticBSplineKernel kernel{};
  for (Transfer t : {Transfer::Apic, Transfer::FlipPicBlend}) {
    SCOPED_TRACE(::testing::Message() << "apic " << (t == Transfer::Apic));
    ::Setup<G> s1(41u), s2(41u);  // the same points twice
    const RandomNodes<G> rn(s1.grid.node_count());
    const GridField<G>& field = rn.field;
    const std::vector<double>& porosity = rn.porosity;
    const std::vector<Vec<NC>>& flux = rn.flux;
    for (Body<G>* b : {&s1.body, &s2.body}) {
      b->phi.assign(b->x_m.size(), 0.0);
      b->div_q_1_s.assign(b->x_m.size(), 0.0);
    }
    ShapeCache<G::dim> cache;
    ASSERT_EQ(compute_shape_cache(s1.grid, kernel, s1.body.x_m, cache), 0);
    // A point whose velocity turns NaN: the guard must name the lowest such index whatever the
    // order of the blocks (two bad points, in different blocks).
    const std::int64_t bad_lo = 70, bad_hi = 250;
    for (Body<G>* b : {&s1.body, &s2.body}) {
      b->v_m_s[bad_hi][0] = std::nan("");
      b->v_m_s[bad_lo][0] = std::nan("");
    }
    const std::int64_t whole =
        phases::grid_to_particles<G, K>(s1.body, cache, field, s1.grid, t, 0.95, 1e-3, porosity.data(), flux.data());
    const G2PTask<G> task =
        make_g2p_task<G, K>(s2.body, cache, field, s2.grid, t, 0.95, 1e-3, porosity.data(), flux.data());
    ASSERT_EQ(task.blocks, (s2.body.size() + oobleck::numerics::kMathBlock - 1) / oobleck::numerics::kMathBlock);
    ASSERT_GE(task.blocks, 3);
    std::int64_t bad = kAllFinite;
    // Backwards, in ranges of 1 and 2 blocks.
    for (std::int64_t b1 = task.blocks; b1 > 0;) {
      const std::int64_t b0 = std::max<std::int64_t>(0, b1 - (b1 % 2 == 0 ? 2 : 1));
      bad = std::min(bad, task.run(b0, b1));
      b1 = b0;
    }
    if (t == Transfer::FlipPicBlend) {  // (APIC does not read the old velocity)
      EXPECT_EQ(whole, bad_lo);
      EXPECT_EQ(bad, bad_lo);
    } else {
      EXPECT_EQ(whole, kAllFinite);
      EXPECT_EQ(bad, kAllFinite);
    }
    const auto np = static_cast<std::size_t>(s1.body.size());
    auto same = [](const double* x, const double* y, std::size_t count) {
      return std::memcmp(x, y, count * sizeof(double)) == 0;
    };
    EXPECT_TRUE(same(s1.body.x_m.data()->data(), s2.body.x_m.data()->data(), G::dim * np));
    EXPECT_TRUE(same(s1.body.v_m_s.data()->data(), s2.body.v_m_s.data()->data(), NC * np));
    EXPECT_TRUE(same(s1.body.C_1_s.data()->data(), s2.body.C_1_s.data()->data(), G::dim * NC * np));
    EXPECT_TRUE(same(s1.body.L_1_s.data()->data(), s2.body.L_1_s.data()->data(), 9 * np));
    EXPECT_TRUE(same(s1.body.volume_m3.data(), s2.body.volume_m3.data(), np));
    EXPECT_TRUE(same(s1.body.phi.data(), s2.body.phi.data(), np));
    EXPECT_TRUE(same(s1.body.div_q_1_s.data(), s2.body.div_q_1_s.data(), np));
  }
}

}  // namespace

TEST(Transfer, G2PBlocksInAnyOrderEqualTheWholeBodyG2P) {
  check_g2p_blocks_in_any_order<PlaneStrain>();
  check_g2p_blocks_in_any_order<Axisymmetric>();
}
