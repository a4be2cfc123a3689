// The verdict rule of `oobleck reproduce`'s report (apps/verdict.hpp): a claim over a set of runs
// is met only by all of them; a subset is "not met", with the subset named.
#include <gtest/gtest.h>

#include "../../apps/verdict.hpp"

namespace {
using oobleck::cli::RunOutcome;
using oobleck::cli::single_verdict;
using oobleck::cli::subset_verdict;

TEST(ReproduceVerdict, EveryRunMeetingIsMet) {
  EXPECT_EQ(subset_verdict({{"a", true}, {"b", true}}, "in [1.5, 2.5]"), "met (all 2 runs: in [1.5, 2.5])");
}

TEST(ReproduceVerdict, ASubsetIsNotMetAndNamesTheSubset) {
  // The S3 sweep as docs/results.md reports it: 3 of 10 runs in range.
  std::vector<RunOutcome> runs;
  for (const char* v : {"0.2", "0.5"})
    for (const char* phi : {"0.46", "0.47", "0.48", "0.49", "0.50"})
      runs.push_back({std::string("phi ") + phi + ", v0 " + v, std::string(v) == "0.2" && std::string(phi) < "0.49"});
  EXPECT_EQ(subset_verdict(runs, "with k_l/k_t in [1.5, 2.5]"),
            "not met: 3 of 10 runs with k_l/k_t in [1.5, 2.5] (phi 0.46, v0 0.2; phi 0.47, v0 0.2; phi 0.48, v0 0.2)");
  // S2 Fig. 8: one launch speed of three.
  EXPECT_EQ(subset_verdict({{"v0 0.5", false}, {"v0 1", false}, {"v0 2", true}}, "meet it"),
            "not met: 1 of 3 runs meet it (v0 2)");
}

TEST(ReproduceVerdict, NoRunMeetingAndNoRunsAreNotMet) {
  EXPECT_EQ(subset_verdict({{"a", false}, {"b", false}}, "meet it"), "not met: none of the 2 runs meet it");
  EXPECT_EQ(subset_verdict({}, "meet it"), "not met: no runs");
}

TEST(ReproduceVerdict, SingleRun) {
  EXPECT_EQ(single_verdict(true, "why"), "met");
  EXPECT_EQ(single_verdict(false, "hub loses 0.187 m"), "not met: hub loses 0.187 m");
}
}  // namespace
