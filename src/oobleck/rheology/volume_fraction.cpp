#include "oobleck/rheology/volume_fraction.hpp"

#include <cmath>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::rheology {

double volume_fraction(const MassFractionInput& in) {
  const double w = in.mass_fraction;
  return (1.0 + in.lambda) * (1.0 - in.beta) /
         ((1.0 - in.beta) + ((1.0 - w) / w) * (in.rho_cs / in.rho_liquid) + in.beta * in.rho_cs / in.rho_water);
}

void validate_mass_fraction_input(const MassFractionInput& in) {
  auto need = [](bool ok, const char* opt, double v, const char* rule) {
    if (!ok || !std::isfinite(v)) throw InputError(fmt::format("option {} = {}: {}", opt, v, rule));
  };
  need(in.mass_fraction > 0.0 && in.mass_fraction < 1.0, "--mass-fraction", in.mass_fraction, "must lie in (0, 1)");
  need(in.rho_cs > 0.0, "--rho-cs", in.rho_cs, "must be positive [kg/m^3]");
  need(in.rho_liquid > 0.0, "--rho-liquid", in.rho_liquid, "must be positive [kg/m^3]");
  need(in.rho_water > 0.0, "--rho-water", in.rho_water, "must be positive [kg/m^3]");
  need(in.lambda >= 0.0, "--lambda", in.lambda, "must be >= 0");
  need(in.beta >= 0.0 && in.beta < 1.0, "--beta", in.beta, "must lie in [0, 1)");
}

}  // namespace oobleck::rheology
