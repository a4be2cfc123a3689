#pragma once
// The verdict rule of `oobleck reproduce`'s report.md (apps/cmd_reproduce.cpp) and of
// docs/results.md: a claim the paper makes for a set of runs (every phi, every launch speed) is
// "met" only if every run meets the report's criterion; a claim met by a subset of the runs is
// "not met", with the subset named. Header-only so that tests/cli can check the rule without the
// CLI's objects.
#include <cstddef>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace oobleck::cli {

/// One run of a claim's set: its label (e.g. "phi 0.47, v0 0.2") and whether it meets the criterion.
struct RunOutcome {
  std::string label;
  bool meets = false;
};

/// "met (all N runs: CRITERION)" when every run meets the criterion; otherwise
/// "not met: K of N runs CRITERION (LABELS)" or "not met: none of the N runs CRITERION".
/// An empty set is "not met: no runs".
inline std::string subset_verdict(const std::vector<RunOutcome>& runs, const std::string& criterion) {
  std::vector<std::string> meeting;
  for (const auto& r : runs)
    if (r.meets) meeting.push_back(r.label);
  const std::size_t n = runs.size();
  if (n == 0) return "not met: no runs";
  if (meeting.size() == n) return fmt::format("met (all {} runs: {})", n, criterion);
  if (meeting.empty()) return fmt::format("not met: none of the {} runs {}", n, criterion);
  return fmt::format("not met: {} of {} runs {} ({})", meeting.size(), n, criterion, fmt::join(meeting, "; "));
}

/// The verdict of a claim about one run: "met" or "not met: WHY".
inline std::string single_verdict(bool meets, const std::string& why_not) {
  return meets ? std::string("met") : fmt::format("not met: {}", why_not);
}

}  // namespace oobleck::cli
