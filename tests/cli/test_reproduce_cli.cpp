// `oobleck reproduce --quick` (all parts, or `--only PART`): every claim row in report.md with
// measured numbers and a verdict that is "met" or "not met".
#include <gtest/gtest.h>

#include <filesystem>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace {

/// The claim rows of report.md ("| claim | paper | measured | verdict |"), header rows left out.
std::vector<std::string> claim_rows(const std::string& md) {
  std::vector<std::string> rows;
  std::istringstream lines(md);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("| ", 0) == 0 && line.rfind("| claim ", 0) != 0) rows.push_back(line);
  return rows;
}

/// The four cells of a claim row.
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::size_t at = 1;
  for (std::size_t next; (next = row.find(" | ", at)) != std::string::npos; at = next + 2)
    out.push_back(row.substr(at + 1, next - at - 1));
  out.push_back(row.substr(at + 1, row.size() - at - 3));
  return out;
}

}  // namespace

// What CI runs of `reproduce` (about 2 minutes on one thread; one thread, as oversubscribed OpenMP
// teams of the parallel ctest run would slow it many times): every claim of the paper that
// oobleck measures has its row, in order, with measured numbers and a verdict "met" or "not met"
// (the one model calculation says so instead).
TEST(ReproduceCli, QuickReportsEveryClaimWithNumbersAndAVerdict) {
  clitest::TempDir d;
  const auto r = clitest::run("reproduce --quick --threads 1 --out " + d / "rep");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto rows = claim_rows(clitest::read_text(d / "rep/report.md"));
  const std::vector<std::string> expected = {"V4 settling",
                                             "V3 torque",
                                             "S1 fast bob: a band grows",
                                             "S1 fast bob: the band rotates rigidly",
                                             "S1 fast bob: flow stops",
                                             "S1 fast bob: jammed structure",
                                             "S1 slow bob",
                                             "S1: steady 1D Couette",
                                             "S3 Fig. 9 run",
                                             "S3 k_l/k_t of the u_z = 0.5 v0 front up to its farthest extent",
                                             "S3 the same over the whole run",
                                             "S2 |dz| vs depth",
                                             "S2 rod dynamics",
                                             "S4 wheel at omega = 10",
                                             "S4 wheel at omega = 1",
                                             "S4 fast vs slow",
                                             "SI: pressure under the wheel"};
  ASSERT_EQ(rows.size(), expected.size()) << clitest::read_text(d / "rep/report.md");
  const std::regex verdict(R"(^(met|not met)\b)"), number(R"(\d\.\d)");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto c = cells(rows[i]);
    ASSERT_EQ(c.size(), 4U) << rows[i];
    EXPECT_EQ(c[0].rfind(expected[i], 0), 0U) << "row " << i << ": " << rows[i];
    EXPECT_TRUE(std::regex_search(c[2], number)) << "no measured number: " << rows[i];
    if (expected[i] == "S1: steady 1D Couette") {
      EXPECT_EQ(c[3].rfind("model prediction", 0), 0U) << rows[i];
    } else {
      EXPECT_TRUE(std::regex_search(c[3], verdict)) << "verdict: " << rows[i];
    }
  }
  // Every figure the report lists exists.
  std::istringstream lines(clitest::read_text(d / "rep/report.md"));
  int figures = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("- `", 0) != 0 || line.find(".png`") == std::string::npos) continue;
    const std::string png = line.substr(3, line.find('`', 3) - 3);
    EXPECT_TRUE(std::filesystem::exists(d / ("rep/" + png))) << png;
    ++figures;
  }
  EXPECT_GE(figures, 20);
}

TEST(ReproduceCli, OnlyRunsTheNamedPartAlone) {
  clitest::TempDir d;
  const auto r = clitest::run("reproduce --quick --only V --threads 1 --out " + d / "rep");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto rows = claim_rows(clitest::read_text(d / "rep/report.md"));
  ASSERT_EQ(rows.size(), 2U) << clitest::read_text(d / "rep/report.md");
  EXPECT_EQ(rows[0].rfind("| V4 settling", 0), 0U) << rows[0];
  EXPECT_EQ(rows[1].rfind("| V3 torque", 0), 0U) << rows[1];
}

TEST(ReproduceCli, OnlyRefusesAnUnknownPart) {
  clitest::TempDir d;
  const auto r = clitest::run("reproduce --quick --only S9 --out " + d / "rep");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("S9"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(d / "rep/report.md"));
}
