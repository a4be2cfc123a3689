#pragma once
// Internal helpers of the analysis: sampling a line of nodal values and finding where a
// thresholded quantity drops below its threshold along a search line.
#include <string>
#include <vector>

#include "oobleck/analysis/fronts.hpp"

namespace oobleck::analysis {

/// Linear interpolation of nodal `values` (node n at origin + n h) at coordinate c. Throws
/// InputError naming `what` if c is outside [origin, origin + (size-1) h] (1e-9 h tolerance).
double sample_line(const std::vector<double>& values, double origin, double h, double c, const std::string& what);

/// Result of a threshold search along a line.
struct LineCrossing {
  bool found = false;     ///< g >= threshold somewhere on the line (contiguous: at the start)
  bool at_end = false;    ///< g >= threshold up to the last node: front placed there
  double position = 0.0;  ///< search coordinate of the front
};

/// Search along a line that starts at coordinate s0 with value g0 and continues through nodes
/// s[k] (strictly increasing, all > s0) with values g[k]. contiguous: the first drop below
/// `threshold` walking from s0, linearly interpolated; not found (position s0) if g0 < threshold.
/// farthest: the last node with g >= threshold (or s0 if only g0 qualifies), interpolated with
/// the following node; not found if no point qualifies.
LineCrossing search_front(double s0, double g0, const std::vector<double>& s, const std::vector<double>& g,
                          double threshold, FrontSearch mode);

}  // namespace oobleck::analysis
