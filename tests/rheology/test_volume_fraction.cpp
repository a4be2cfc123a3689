// E15: volume fraction of swelling starch from its mass fraction (paper SI).
#include <gtest/gtest.h>

#include "oobleck/core/error.hpp"
#include "oobleck/rheology/volume_fraction.hpp"

using namespace oobleck::rheology;

TEST(VolumeFraction, ReducesToPlainConversionWithoutCorrections) {
  // lambda = beta = 0: phi = (m_cs/rho_cs)/(m_cs/rho_cs + m_l/rho_l).
  MassFractionInput in{0.4, 1630.0, 1000.0, 1000.0, 0.0, 0.0};
  const double v_cs = 0.4 / 1630.0, v_l = 0.6 / 1000.0;
  EXPECT_NEAR(volume_fraction(in), v_cs / (v_cs + v_l), 1e-15);
}

TEST(VolumeFraction, MatchesTheSwellingFormula) {
  // Mass form of the SI equation: phi = (1+l)(1-b)(m_cs/r_cs) / ((1-b) m_cs/r_cs + m_l/r_l + b m_cs/r_w),
  // evaluated for 44 g starch + 56 g liquid.
  const double m_cs = 44, m_l = 56, r_cs = 1630, r_l = 1250, r_w = 997, l = 0.3, b = 0.1;
  const double expected = (1 + l) * (1 - b) * (m_cs / r_cs) / ((1 - b) * m_cs / r_cs + m_l / r_l + b * m_cs / r_w);
  MassFractionInput in{0.44, r_cs, r_l, r_w, l, b};
  EXPECT_NEAR(volume_fraction(in), expected, 1e-14);
}

TEST(VolumeFraction, RejectsOutOfRangeInput) {
  EXPECT_THROW(validate_mass_fraction_input({1.2, 1630, 1000, 1000, 0.3, 0.1}), oobleck::InputError);
  EXPECT_THROW(validate_mass_fraction_input({0.4, -1, 1000, 1000, 0.3, 0.1}), oobleck::InputError);
  EXPECT_NO_THROW(validate_mass_fraction_input({0.4, 1630, 1000, 1000, 0.3, 0.1}));
}
