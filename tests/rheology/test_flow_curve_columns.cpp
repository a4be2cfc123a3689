// rheology::flow_curve_columns, the table that `oobleck rheology flow-curve`, oobleck.flow_curve and
// bench/flow_curve.cpp share: the column-major layout of flow_curve's rows one phi after the other,
// the DST rate column against the paper's closed form E14 (paper_tables.hpp, independent of src/)
// and NaN below phi_c, every row a steady state of E11 (paper::gamma_dot_of_f).
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"
#include "paper_tables.hpp"

using namespace oobleck;

namespace {
const paper::Fit& hermes2016() {
  for (const auto& f : paper::fits())
    if (f.name == "hermes2016") return f;
  throw std::logic_error("no hermes2016 in paper::fits()");
}
}  // namespace

TEST(FlowCurveColumns, LayoutDstColumnAndSteadyRowsE11E14) {
  const paper::Fit& fit = hermes2016();
  const auto p = rheology::load_preset("hermes2016");
  const std::vector<double> phis = {0.40, 0.47};  // below phi_c = 0.436 (no DST), on the DST branch
  const int points = 7;
  const std::size_t rows = phis.size() * points;
  const std::vector<double> c = rheology::flow_curve_columns(p.steady, phis, points);
  ASSERT_EQ(c.size(), 9 * rows);
  EXPECT_EQ(rheology::kFlowCurveColumns.front(), "phi");
  EXPECT_EQ(rheology::kFlowCurveColumns.back(), "shear_rate_dst");
  for (std::size_t i = 0; i < rows; ++i) {
    const double phi = phis[i / points];
    SCOPED_TRACE("row " + std::to_string(i));
    EXPECT_EQ(c[i], phi);
    const double f = c[rows + i], rate = c[2 * rows + i], stress = c[3 * rows + i];
    // the last row lies 1e-10 f_u below f_u: the closed form's f_m - f loses digits there
    const double tol = (i + 1) % points == 0 ? 1e-5 : 1e-9;
    EXPECT_NEAR(rate, paper::gamma_dot_of_f(fit, phi, f), tol * rate);                   // E11
    EXPECT_NEAR(c[6 * rows + i], stress / rate, 1e-12 * stress / rate);                  // viscosity
    EXPECT_NEAR(c[7 * rows + i], stress / (fit.eta_0 * rate), 1e-12 * c[7 * rows + i]);  // eta_r
    const double dst = c[8 * rows + i];
    if (phi < fit.phi_c) {
      EXPECT_TRUE(std::isnan(dst));
    } else {
      EXPECT_NEAR(dst, paper::gamma_dot_dst(fit, phi), 1e-12 * dst);  // E14
    }
  }
  // each phi's rows in order of increasing f
  for (std::size_t i = 1; i < rows; ++i) {
    if (i % points != 0) {
      EXPECT_GT(c[rows + i], c[rows + i - 1]);
    }
  }
}

TEST(FlowCurveColumns, OutputOfTheWrongSizeIsRejected) {
  const auto p = rheology::load_preset("hermes2016");
  const std::vector<double> phis = {0.40};
  std::vector<double> out(9 * 5 - 1);
  EXPECT_THROW(rheology::flow_curve_columns(p.steady, phis, 5, out), std::invalid_argument);
}
