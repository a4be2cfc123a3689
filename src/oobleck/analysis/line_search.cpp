#include "oobleck/analysis/line_search.hpp"

#include <cmath>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::analysis {

double sample_line(const std::vector<double>& values, double origin, double h, double c, const std::string& what) {
  if (values.size() < 2 || !(h > 0.0))
    throw InputError(fmt::format("{}: a line needs at least 2 nodes and h > 0", what));
  const double last = origin + static_cast<double>(values.size() - 1) * h;
  const double tol = 1e-9 * h;
  if (!std::isfinite(c) || c < origin - tol || c > last + tol)
    throw InputError(fmt::format("{}: coordinate {} m lies outside the grid [{}, {}] m", what, c, origin, last));
  double s = (c - origin) / h;
  if (s < 0.0) s = 0.0;
  const double smax = static_cast<double>(values.size() - 1);
  if (s >= smax) return values.back();
  const double fl = std::floor(s);
  const auto n = static_cast<std::size_t>(fl);
  const double w = s - fl;
  return (1.0 - w) * values[n] + w * values[n + 1];
}

LineCrossing search_front(double s0, double g0, const std::vector<double>& s, const std::vector<double>& g,
                          double threshold, FrontSearch mode) {
  LineCrossing out;
  out.position = s0;
  if (mode == FrontSearch::contiguous) {
    if (g0 < threshold) return out;
    out.found = true;
    double sp = s0, gp = g0;
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (g[k] < threshold) {
        out.position = interpolate_crossing(sp, gp, s[k], g[k], threshold);
        return out;
      }
      sp = s[k];
      gp = g[k];
    }
    out.at_end = true;
    out.position = sp;
    return out;
  }
  // farthest
  std::size_t last = s.size();
  for (std::size_t k = s.size(); k-- > 0;)
    if (g[k] >= threshold) {
      last = k;
      break;
    }
  if (last == s.size()) {  // no node qualifies
    if (g0 < threshold) return out;
    out.found = true;
    if (s.empty()) {
      out.at_end = true;
      return out;
    }
    out.position = interpolate_crossing(s0, g0, s[0], g[0], threshold);
    return out;
  }
  out.found = true;
  if (last + 1 == s.size()) {
    out.at_end = true;
    out.position = s[last];
    return out;
  }
  out.position = interpolate_crossing(s[last], g[last], s[last + 1], g[last + 1], threshold);
  return out;
}

}  // namespace oobleck::analysis
