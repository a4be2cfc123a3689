// Shape functions: partition of unity, ∑∇N = 0, linear reproduction and gradients that are the
// derivatives of the weights — for every kind, in 2D and 3D, in the interior, next to walls (ghost
// nodes) and across periodic seams.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "oobleck/mpm/shape.hpp"

using namespace oobleck::mpm;

namespace {

template <int D>
Grid<D> make_grid(bool periodic_first_axis) {
  std::array<int, D> cells{};
  std::array<bool, D> per{};
  for (int a = 0; a < D; ++a) cells[a] = 5 + a;
  per[0] = periodic_first_axis;
  Vec<D> origin;
  for (int a = 0; a < D; ++a) origin[a] = -0.3 + 0.1 * a;
  return Grid<D>(origin, 0.2, cells, per);
}

// Random points over the whole domain, with extra points within half a cell of every wall and
// exactly on walls and nodes.
template <int D>
std::vector<Vec<D>> sample_points(const Grid<D>& g, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec<D>> x;
  for (int q = 0; q < n; ++q) {
    Vec<D> p;
    for (int a = 0; a < D; ++a) {
      double r = u(rng);
      if (q % 4 == 1) r = 0.5 * u(rng) / g.cells[a];                           // near lower wall
      if (q % 4 == 2) r = 1.0 - 0.5 * u(rng) / g.cells[a];                     // near upper wall
      if (q % 4 == 3) r = std::floor(u(rng) * (g.cells[a] + 1)) / g.cells[a];  // on a node/wall
      if (g.periodic[a] && r >= 1.0) r = 0.0;
      p[a] = g.origin_m[a] + r * g.length(a);
    }
    x.push_back(p);
  }
  return x;
}

template <int D, class Kernel>
void check_kernel(const Kernel& kernel, bool periodic) {
  const Grid<D> g = make_grid<D>(periodic);
  const auto x = sample_points<D>(g, 400, 11u + (periodic ? 1u : 0u));
  ShapeCache<D> c;
  ASSERT_EQ(compute_shape_cache(g, kernel, x, c), 0);
  const int K = c.K;
  for (std::size_t p = 0; p < x.size(); ++p) {
    double sw = 0.0;
    Vec<D> sg = Vec<D>::Zero(), sx = Vec<D>::Zero();
    Eigen::Matrix<double, D, D> xg = Eigen::Matrix<double, D, D>::Zero();
    // The hot-loop traversal (for_each_node) and the per-node accessors give the same nodes and
    // values in the same order.
    int k = 0;
    for_each_node<D, Kernel::support>(c.template stencil<Kernel::support>(static_cast<std::int64_t>(p)),
                                      [&](int i, double w, const double* gr, const double* of) {
                                        const Vec<D> grad = Eigen::Map<const Vec<D>>(gr),
                                                     off = Eigen::Map<const Vec<D>>(of);
                                        EXPECT_EQ(i, c.node(p, k));
                                        EXPECT_EQ(w, c.weight(p, k));
                                        EXPECT_EQ(grad, c.gradient(p, k));
                                        EXPECT_EQ(off, c.offset(p, k));
                                        ++k;
                                        EXPECT_GE(w, -1e-15);
                                        sw += w;
                                        sg += grad;
                                        sx += w * off;
                                        xg += off * grad.transpose();
                                        // The cached offset is the node position minus the point position (unwrapped).
                                        Vec<D> xi = g.node_position(i);
                                        for (int a = 0; a < D; ++a) {
                                          double d = xi[a] - x[p][a] - off[a];
                                          if (g.periodic[a]) d -= g.length(a) * std::round(d / g.length(a));
                                          EXPECT_NEAR(d, 0.0, 1e-12);
                                        }
                                      });
    EXPECT_EQ(k, K);
    EXPECT_NEAR(sw, 1.0, 1e-13) << "partition of unity at p=" << p;
    EXPECT_NEAR(sg.norm(), 0.0, 1e-11) << "sum of gradients at p=" << p;
    EXPECT_NEAR(sx.norm(), 0.0, 1e-13) << "linear reproduction at p=" << p;
    // ∑ (x_i − x_p) ⊗ ∇N_i = I (gradient of a linear field is exact).
    EXPECT_NEAR((xg - Eigen::Matrix<double, D, D>::Identity()).norm(), 0.0, 1e-11);
  }
}

template <int D, class Kernel>
void check_gradient_by_finite_differences(const Kernel& kernel) {
  const Grid<D> g = make_grid<D>(false);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  const double eps = 1e-7 * g.h_m;
  for (int q = 0; q < 50; ++q) {
    Vec<D> x0;
    for (int a = 0; a < D; ++a) x0[a] = g.origin_m[a] + u(rng) * g.length(a);
    ShapeCache<D> c0;
    compute_shape_cache(g, kernel, std::vector<Vec<D>>{x0}, c0);
    for (int a = 0; a < D; ++a) {
      Vec<D> xp = x0, xm = x0;
      xp[a] += eps;
      xm[a] -= eps;
      ShapeCache<D> cp, cm;
      compute_shape_cache(g, kernel, std::vector<Vec<D>>{xp}, cp);
      compute_shape_cache(g, kernel, std::vector<Vec<D>>{xm}, cm);
      std::map<int, double> wp, wm;
      for (int k = 0; k < cp.K; ++k) wp[cp.node(0, k)] += cp.weight(0, k);
      for (int k = 0; k < cm.K; ++k) wm[cm.node(0, k)] += cm.weight(0, k);
      for (int k = 0; k < c0.K; ++k) {
        const double fd = (wp[c0.node(0, k)] - wm[c0.node(0, k)]) / (2 * eps);
        EXPECT_NEAR(c0.gradient(0, k)[a], fd, 1e-5 / g.h_m);
      }
    }
  }
}

}  // namespace

TEST(Shape, Linear2D) {
  check_kernel<2>(LinearKernel{}, false);
  check_kernel<2>(LinearKernel{}, true);
}
TEST(Shape, QuadraticBSpline2D) {
  check_kernel<2>(QuadraticBSplineKernel{}, false);
  check_kernel<2>(QuadraticBSplineKernel{}, true);
}
TEST(Shape, CubicBSpline2D) {
  check_kernel<2>(CubicBSplineKernel{}, false);
  check_kernel<2>(CubicBSplineKernel{}, true);
}
TEST(Shape, UGimp2D) {
  for (double l : {0.5, 0.25, 1.0 / 6.0}) {
    check_kernel<2>(UGimpKernel{l}, false);
    check_kernel<2>(UGimpKernel{l}, true);
  }
}
TEST(Shape, AllKinds3D) {
  check_kernel<3>(LinearKernel{}, true);
  check_kernel<3>(QuadraticBSplineKernel{}, false);
  check_kernel<3>(CubicBSplineKernel{}, true);
  check_kernel<3>(UGimpKernel{0.25}, false);
}
TEST(Shape, GradientsAreDerivativesOfWeights) {
  check_gradient_by_finite_differences<2>(LinearKernel{});
  check_gradient_by_finite_differences<2>(QuadraticBSplineKernel{});
  check_gradient_by_finite_differences<2>(CubicBSplineKernel{});
  check_gradient_by_finite_differences<2>(UGimpKernel{0.25});
  check_gradient_by_finite_differences<3>(CubicBSplineKernel{});
}

TEST(Shape, ClosedFormValuesAndApicInertia) {
  // 1D values at a node against the textbook splines: quadratic (1/8, 3/4, 1/8), cubic
  // (1/6, 2/3, 1/6, 0); APIC inertia D_p = h²/4 (quadratic) and h²/3 (cubic) everywhere.
  const Grid<1> g(Vec<1>(0.0), 0.5, {8});
  ShapeCache<1> q, cu;
  compute_shape_cache(g, QuadraticBSplineKernel{}, std::vector<Vec<1>>{Vec<1>(1.0), Vec<1>(1.37)}, q);
  EXPECT_NEAR(q.weight(0, 0), 0.125, 1e-15);
  EXPECT_NEAR(q.weight(0, 1), 0.75, 1e-15);
  EXPECT_NEAR(q.weight(0, 2), 0.125, 1e-15);
  compute_shape_cache(g, CubicBSplineKernel{}, std::vector<Vec<1>>{Vec<1>(1.0), Vec<1>(1.37)}, cu);
  EXPECT_NEAR(cu.weight(0, 0), 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(cu.weight(0, 1), 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(cu.weight(0, 2), 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(cu.weight(0, 3), 0.0, 1e-15);
  for (int p = 0; p < 2; ++p) {
    EXPECT_NEAR(1.0 / q.inv_D[p][0], 0.25 * 0.25, 1e-15);
    EXPECT_NEAR(1.0 / cu.inv_D[p][0], 0.25 / 3.0, 1e-15);
  }
}

// APIC's D_p = ∑_i N_ip (x_i − x_p)(x_i − x_p)ᵀ (diagonal for tensor-product kernels): the cache
// stores the constant h²/4 (quadratic) or h²/3 (cubic) B-spline value, uGIMP's computed per point.
// Check the stored 1/D_p against the moment summed from the cached weights and offsets, at points
// all over a 2D grid with a periodic axis (seam) and walls.
template <class Kernel>
void check_inertia_is_the_second_moment(const Kernel& kernel) {
  const Grid<2> g(Vec<2>(-0.3, 0.1), 0.25, {6, 5}, {true, false});
  std::vector<Vec<2>> x;
  x.reserve(157);
  for (int k = 0; k < 157; ++k)
    x.emplace_back(-0.3 + 1.5 * ((k * 0.6180339887) - std::floor(k * 0.6180339887)),
                   0.1 + 1.25 * ((k * 0.7548776662) - std::floor(k * 0.7548776662)));
  ShapeCache<2> c;
  ASSERT_EQ(compute_shape_cache(g, kernel, x, c), 0);
  for (std::int64_t p = 0; p < static_cast<std::int64_t>(x.size()); ++p) {
    Vec<2> m2 = Vec<2>::Zero();
    for (int k = 0; k < c.K; ++k) m2 += c.weight(p, k) * c.offset(p, k).cwiseProduct(c.offset(p, k));
    for (int a = 0; a < 2; ++a) EXPECT_NEAR(m2[a] * c.inv_D[p][a], 1.0, 1e-13) << "point " << p << " axis " << a;
  }
}
TEST(Shape, ApicInertiaIsTheSecondMomentOfTheWeights) {
  check_inertia_is_the_second_moment(QuadraticBSplineKernel{});
  check_inertia_is_the_second_moment(CubicBSplineKernel{});
  check_inertia_is_the_second_moment(UGimpKernel{0.25});
}

TEST(Shape, PointsFarOutsideAreReported) {
  const Grid<2> g(Vec<2>(0, 0), 1.0, {4, 4});
  ShapeCache<2> c;
  EXPECT_EQ(compute_shape_cache(g, CubicBSplineKernel{}, std::vector<Vec<2>>{Vec<2>(-0.9, 2.0)}, c), 0);
  EXPECT_EQ(compute_shape_cache(g, CubicBSplineKernel{}, std::vector<Vec<2>>{Vec<2>(-1.5, 2.0)}, c), 1);
  EXPECT_EQ(compute_shape_cache(g, QuadraticBSplineKernel{}, std::vector<Vec<2>>{Vec<2>(2.0, 5.4)}, c), 0);
}
