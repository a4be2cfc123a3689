// Plain data of the analysis: grid fields, time series, least-squares lines.
#include <gtest/gtest.h>

#include <cmath>

#include "oobleck/analysis/data.hpp"
#include "oobleck/core/error.hpp"

using namespace oobleck::analysis;
using oobleck::InputError;

namespace {
GridField2D plane(double a, double bx, double by) {
  GridField2D f;
  f.origin_x = 0.01;
  f.origin_y = -0.02;
  f.h = 0.002;
  f.nx = 6;
  f.ny = 5;
  f.values.resize(f.nx * f.ny);
  for (std::size_t j = 0; j < f.ny; ++j)
    for (std::size_t i = 0; i < f.nx; ++i) f.at(i, j) = a + bx * f.x(i) + by * f.y(j);
  return f;
}
}  // namespace

TEST(AnalysisData, GridFieldIsRowMajorAndInterpolatesLinearly) {
  GridField2D f = plane(1.0, 2.0, 3.0);
  EXPECT_NO_THROW(f.validate("f"));
  EXPECT_DOUBLE_EQ(f.values[2 * f.nx + 3], 1.0 + 2.0 * f.x(3) + 3.0 * f.y(2));
  const double y = -0.0153;
  const std::vector<double> row = f.row_at(y, "row");
  ASSERT_EQ(row.size(), f.nx);
  for (std::size_t i = 0; i < f.nx; ++i) EXPECT_NEAR(row[i], 1.0 + 2.0 * f.x(i) + 3.0 * y, 1e-13);
  const double x = 0.0171;
  const std::vector<double> col = f.column_at(x, "col");
  ASSERT_EQ(col.size(), f.ny);
  for (std::size_t j = 0; j < f.ny; ++j) EXPECT_NEAR(col[j], 1.0 + 2.0 * x + 3.0 * f.y(j), 1e-13);
  // The last row/column are reachable exactly.
  EXPECT_NEAR(f.row_at(f.y_max(), "row")[0], f.at(0, f.ny - 1), 1e-14);
  EXPECT_NEAR(f.column_at(f.x_max(), "col")[0], f.at(f.nx - 1, 0), 1e-14);
}

TEST(AnalysisData, GridFieldRejectsBadInput) {
  GridField2D f = plane(0, 0, 0);
  f.values.pop_back();
  EXPECT_THROW(f.validate("f"), InputError);
  f = plane(0, 0, 0);
  f.h = 0;
  EXPECT_THROW(f.validate("f"), InputError);
  f = plane(0, 0, 0);
  f.values[3] = NAN;
  EXPECT_THROW(f.validate("f"), InputError);
  f = plane(0, 0, 0);
  EXPECT_THROW((void)f.row_at(1.0, "row"), InputError);
  EXPECT_THROW((void)f.column_at(0.0, "col"), InputError);
}

TEST(AnalysisData, TimeSeriesValidation) {
  EXPECT_THROW((TimeSeries{{}, {}}.validate("s")), InputError);
  EXPECT_THROW((TimeSeries{{0, 1}, {1}}.validate("s")), InputError);
  EXPECT_THROW((TimeSeries{{0, 1, 1}, {1, 2, 3}}.validate("s")), InputError);
  EXPECT_THROW((TimeSeries{{0, 2, 1}, {1, 2, 3}}.validate("s")), InputError);
  EXPECT_THROW((TimeSeries{{0, 1}, {1, NAN}}.validate("s")), InputError);
  EXPECT_NO_THROW((TimeSeries{{0, 1, 2}, {1, 2, 3}}.validate("s", 3)));
  EXPECT_THROW((TimeSeries{{0, 1, 2}, {1, 2, 3}}.validate("s", 4)), InputError);
}

TEST(AnalysisData, FitLineOnExactLine) {
  std::vector<double> x, y;
  for (int k = 0; k < 11; ++k) {
    x.push_back(0.1 * k);
    y.push_back(-3.0 + 2.5 * 0.1 * k);
  }
  const LinearFit f = fit_line(x, y);
  EXPECT_NEAR(f.slope, 2.5, 1e-13);
  EXPECT_NEAR(f.intercept, -3.0, 1e-13);
  EXPECT_NEAR(f.r_squared, 1.0, 1e-13);
  EXPECT_NEAR(f.slope_stderr, 0.0, 1e-7);
  EXPECT_EQ(f.points, 11u);
}

TEST(AnalysisData, FitLineMatchesHandComputedStatistics) {
  // x = 0..3, y = 0,1,1,2: slope 0.6, intercept 0.1, SS_res 0.2, SS_tot 2, S_xx 5.
  const LinearFit f = fit_line({0, 1, 2, 3}, {0, 1, 1, 2});
  EXPECT_NEAR(f.slope, 0.6, 1e-14);
  EXPECT_NEAR(f.intercept, 0.1, 1e-14);
  EXPECT_NEAR(f.r_squared, 0.9, 1e-14);
  EXPECT_NEAR(f.slope_stderr, std::sqrt(0.1 / 5.0), 1e-14);
  EXPECT_NEAR(f.intercept_stderr, std::sqrt(0.1 * (0.25 + 2.25 / 5.0)), 1e-14);
}

TEST(AnalysisData, FitLineRejectsDegenerateInput) {
  EXPECT_THROW(fit_line({1.0}, {2.0}), InputError);
  EXPECT_THROW(fit_line({1.0, 1.0}, {2.0, 3.0}), InputError);
  EXPECT_THROW(fit_line({1.0, 2.0}, {2.0}), InputError);
  const TimeSeries s{{0, 1, 2, 3}, {0, 1, 2, 3}};
  EXPECT_THROW(fit_line(s, 2.5, 10.0), InputError);  // one point in the interval
  EXPECT_NEAR(fit_line(s, 0.5, 3.0).slope, 1.0, 1e-14);
}

TEST(AnalysisData, CutBeforeBoundaryStopsAtFirstApproach) {
  const TimeSeries s{{0, 1, 2, 3, 4}, {0.0, 0.4, 0.8, 0.6, 0.9}};
  const TimeSeries c = cut_before_boundary(s, 1.0, 0.25);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.time.back(), 1.0);
  EXPECT_EQ(cut_before_boundary(s, 1.0, 0.0).size(), 5u);
  EXPECT_THROW(cut_before_boundary(s, 1.0, -1.0), InputError);
}
