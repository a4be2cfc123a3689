#pragma once
// The units a run writes (docs/output.md, "Units"): each field, series column and checkpoint
// array names its unit where it is declared, as for a 3D body ("kg", "m^3", "N"); an amount
// carried by the points of a 2D run is per metre of depth (plane strain) or per radian
// (axisymmetric), which `in_measure` appends.
#include <array>
#include <string>
#include <string_view>
#include <type_traits>

#include "oobleck/mpm/geometry.hpp"

namespace oobleck::run {

/// Units of the amounts that sum over material points: mass, volume, force, impulse or momentum,
/// energy, torque.
inline constexpr std::array<std::string_view, 6> kAmountUnits = {"kg", "m^3", "N", "N s", "J", "N m"};

/// `unit` in the points' measure of geometry G: an amount (kAmountUnits) gets "/m" in plane
/// strain and "/rad" in axisymmetric runs ("kg" -> "kg/rad"); any other unit, and every unit of
/// a 3D run, is returned as it is.
template <class G>
std::string in_measure(std::string_view unit) {
  std::string u(unit);
  if constexpr (G::dim == 3) {
    return u;
  } else {
    for (std::string_view amount : kAmountUnits)
      if (unit == amount) return u + (std::is_same_v<G, mpm::Axisymmetric> ? "/rad" : "/m");
    return u;
  }
}

}  // namespace oobleck::run
