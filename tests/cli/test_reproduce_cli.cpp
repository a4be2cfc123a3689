// `oobleck reproduce --quick --only PART`: the named part alone, every claim row of it in
// report.md with a verdict that is "met" or "not met" and measured numbers beside it.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

TEST(ReproduceCli, OnlyS3RunsTheIntruderSweepAndReportsEveryClaimWithAVerdict) {
  clitest::TempDir d;
  const auto r = clitest::run("reproduce --quick --only S3 --threads 1 --out " + d / "rep");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string md = clitest::read_text(d / "rep/report.md");
  // Only S3's runs: no steady, verification, S1, S2 or S4 rows.
  for (const char* other : {"| S1 ", "| S2 ", "| S4 ", "| V3", "| V4"})
    EXPECT_EQ(md.find(other), std::string::npos) << other;
  std::vector<std::string> rows;
  std::istringstream lines(md);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("| S3", 0) == 0) rows.push_back(line);
  ASSERT_EQ(rows.size(), 3u) << md;  // Fig. 9, the sweep to the farthest extent, the sweep over the whole run
  const std::regex verdict(R"(\| (met|not met)[^|]*\|$)"), number(R"(\d\.\d\d \(R² \d\.\d\d/\d\.\d\d\))");
  for (const auto& row : rows) {
    EXPECT_TRUE(std::regex_search(row, verdict)) << row;
    EXPECT_TRUE(std::regex_search(row, number)) << row;
  }
}

TEST(ReproduceCli, OnlyRefusesAnUnknownPart) {
  clitest::TempDir d;
  const auto r = clitest::run("reproduce --quick --only S9 --out " + d / "rep");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("S9"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(d / "rep/report.md"));
}
