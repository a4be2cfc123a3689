#pragma once
// Initial states (issue 4 §5): the hydrostatic settled bed.
//
// A bed of grains and fluid with a flat free surface at height `surface_m` on the vertical axis
// (the last grid axis: y in plane strain, z in axisymmetric and 3D), under gravity of magnitude
// g along −vertical. At depth s = surface − x_vert:
//   fluid     p_f = ρ_f0 g s         (J = exp(−p_f/κ), E26; the point mass is scaled by 1/J so the
//                                     point still fills its volume at the compressed density)
//   grains    σ̃_vv = −φ (ρ_s − ρ_f0) g s   (the skeleton carries the buoyant weight, E28),
//             σ̃ of the other normal directions = K0 σ̃_vv (lateral earth pressure coefficient).
// φ is taken per grain point as m_p/(ρ_s V_p). Fluid points get body.phi from the grain fraction
// `phi_bed` (until the first G2P sets it from the nodes).
#include <cmath>

#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/laws.hpp"

namespace oobleck::mpm {

struct HydrostaticBed {
  double surface_m = 0.0;        ///< free-surface height on the vertical axis [m]
  double g_m_s2 = 9.81;          ///< gravity magnitude [m/s²]
  double rho_s_kg_m3 = 1620.0;   ///< grain true density
  double rho_f0_kg_m3 = 1000.0;  ///< fluid rest density
  double K0 = 0.5;               ///< lateral/vertical effective stress ratio [-]
  double phi_bed = 0.5;          ///< volume fraction assigned to fluid points' φ [-]
};

/// Set the settled hydrostatic state on a grain body (may be null) and a fluid body with a
/// FluidLaw (may be null).
template <class G>
void set_hydrostatic_bed(const HydrostaticBed& bed, Body<G>* grains, Body<G>* fluid) {
  constexpr int v = G::dim - 1;  // vertical axis
  if (fluid) {
    auto* law = dynamic_cast<FluidLaw<G>*>(fluid->law.get());
    const double kappa = law ? law->params().kappa_Pa : INFINITY;
    for (std::int64_t p = 0; p < fluid->size(); ++p) {
      const double depth = std::max(bed.surface_m - fluid->x_m[p][v], 0.0);
      const double pf = bed.rho_f0_kg_m3 * bed.g_m_s2 * depth;
      const double ln_J = -pf / kappa;  // E26
      if (law) law->ln_J[p] = ln_J;
      fluid->mass_kg[p] /= std::exp(ln_J);
      fluid->stress_Pa[p] = -pf * Mat3::Identity();
      fluid->phi[p] = bed.phi_bed;
    }
  }
  if (grains) {
    for (std::int64_t p = 0; p < grains->size(); ++p) {
      const double depth = std::max(bed.surface_m - grains->x_m[p][v], 0.0);
      const double phi = grains->mass_kg[p] / (bed.rho_s_kg_m3 * grains->volume_m3[p]);
      const double svv = -phi * (bed.rho_s_kg_m3 - bed.rho_f0_kg_m3) * bed.g_m_s2 * depth;
      Mat3 s = Mat3::Zero();
      s.diagonal().setConstant(bed.K0 * svv);
      s(v, v) = svv;
      grains->stress_Pa[p] = s;
    }
  }
}

}  // namespace oobleck::mpm
