// numerics/vector_math: the block exp and log (libmvec where available) against libm's scalar
// functions, including the special values the NaN guards of a step rely on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "oobleck/numerics/vector_math.hpp"

namespace {

using oobleck::numerics::kMathBlock;

/// Distance in units in the last place between two finite doubles of the same sign.
std::int64_t ulps(double a, double b) {
  std::int64_t ia, ib;
  std::memcpy(&ia, &a, sizeof a);
  std::memcpy(&ib, &b, sizeof b);
  return ia > ib ? ia - ib : ib - ia;
}

/// Applies `block` to xs in blocks (the tail padded with 1) and returns the results.
template <class F>
std::vector<double> blocked(const std::vector<double>& xs, F block) {
  std::vector<double> ys(xs.size());
  for (std::size_t i0 = 0; i0 < xs.size(); i0 += kMathBlock) {
    double x[kMathBlock], y[kMathBlock];
    for (int j = 0; j < kMathBlock; ++j) x[j] = i0 + j < xs.size() ? xs[i0 + j] : 1.0;
    block(x, y);
    for (int j = 0; j < kMathBlock && i0 + j < xs.size(); ++j) ys[i0 + j] = y[j];
  }
  return ys;
}

}  // namespace

TEST(VectorMath, ExpWithinFourUlpOfLibm) {
  // the step's arguments (Δt tr L, Δt div q / n: |x| << 1) and the whole normal range
  std::vector<double> xs;
  xs.reserve(8000);
  for (int k = 0; k < 4000; ++k) xs.push_back(1e-3 * std::sin(0.37 * k) * std::pow(10.0, -(k % 12)));
  for (int k = 0; k < 4000; ++k) xs.push_back(-700.0 + 1400.0 * k / 3999.0);
  const std::vector<double> ys = blocked(xs, oobleck::numerics::exp_block);
  std::int64_t worst = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) worst = std::max(worst, ulps(ys[i], std::exp(xs[i])));
  EXPECT_LE(worst, 4) << "largest distance from libm's exp in ulp";
}

TEST(VectorMath, LogWithinFourUlpOfLibm) {
  // the fluid's J = ρ_f0/ρ_f near 1 (both sides), and values over the whole normal range
  std::vector<double> xs;
  xs.reserve(8000);
  for (int k = 0; k < 4000; ++k) xs.push_back(1.0 + 1e-2 * std::sin(0.37 * k) * std::pow(10.0, -(k % 14)));
  for (int k = 0; k < 4000; ++k) xs.push_back(std::pow(10.0, -300.0 + 600.0 * k / 3999.0));
  const std::vector<double> ys = blocked(xs, oobleck::numerics::log_block);
  std::int64_t worst = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double ref = std::log(xs[i]);
    if (ref == 0.0) {
      EXPECT_EQ(ys[i], 0.0) << "log(1) at x = " << xs[i];
      continue;
    }
    EXPECT_EQ(std::signbit(ys[i]), std::signbit(ref)) << "x = " << xs[i];
    worst = std::max(worst, ulps(ys[i], ref));
  }
  EXPECT_LE(worst, 4) << "largest distance from libm's log in ulp";
}

TEST(VectorMath, SpecialValuesPropagateAsInLibm) {
  // what the NaN guards downstream rely on: NaN in, NaN out; overflow to +inf; log of 0 and < 0
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  double x[kMathBlock], y[kMathBlock];
  for (int j = 0; j < kMathBlock; ++j) x[j] = 0.0;
  x[1] = nan;
  x[2] = 1000.0;
  x[3] = -inf;
  x[4] = inf;
  oobleck::numerics::exp_block(x, y);
  EXPECT_EQ(y[0], 1.0);
  EXPECT_TRUE(std::isnan(y[1]));
  EXPECT_EQ(y[2], inf);
  EXPECT_EQ(y[3], 0.0);
  EXPECT_EQ(y[4], inf);
  for (int j = 0; j < kMathBlock; ++j) x[j] = 1.0;
  x[1] = nan;
  x[2] = 0.0;
  x[3] = -1.0;
  x[4] = inf;
  oobleck::numerics::log_block(x, y);
  EXPECT_EQ(y[0], 0.0);
  EXPECT_TRUE(std::isnan(y[1]));
  EXPECT_EQ(y[2], -inf);
  EXPECT_TRUE(std::isnan(y[3]));
  EXPECT_EQ(y[4], inf);
}
