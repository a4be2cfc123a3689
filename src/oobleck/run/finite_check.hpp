#pragma once
// NaN/Inf guard of a run (issue 4, item 8): the first point of a body whose state is not finite,
// and which part of it, so the runner can stop with the body, point, law and step.
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/parallel.hpp"

namespace oobleck::run {

struct NonFinitePoint {
  std::int64_t point = 0;
  const char* what = "";  ///< "position", "velocity", "stress" or "volume"
};

/// The lowest-index point with a non-finite position, velocity, stress or volume (each thread of
/// a region its static share of the points, mpm/parallel.hpp; deterministic: the minimum index),
/// or nullopt.
template <class G>
std::optional<NonFinitePoint> first_non_finite(const mpm::Body<G>& body) {
  const std::int64_t n = body.size();
  std::int64_t bad = std::numeric_limits<std::int64_t>::max();
  mpm::parallel::region([&](const mpm::parallel::Team& team) {
    const mpm::parallel::Range r = team.share(n);
    for (std::int64_t p = r.begin; p < r.end; ++p) {
      // One test per point: the sum is finite only if every term is (NaN and ±Inf propagate).
      const double sum = body.x_m[p].sum() + body.v_m_s[p].sum() + body.stress_Pa[p].sum() + body.volume_m3[p];
      if (!std::isfinite(sum)) {
        mpm::parallel::atomic_min(bad, p);
        break;  // (the share's lowest index)
      }
    }
  });
  if (bad == std::numeric_limits<std::int64_t>::max()) return std::nullopt;
  const char* what = !body.x_m[bad].allFinite()            ? "position"
                     : !body.v_m_s[bad].allFinite()        ? "velocity"
                     : !body.stress_Pa[bad].allFinite()    ? "stress"
                     : !std::isfinite(body.volume_m3[bad]) ? "volume"
                                                           : "state (overflow of finite values)";
  return NonFinitePoint{bad, what};
}

}  // namespace oobleck::run
