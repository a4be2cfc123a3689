// The glibc-hwcaps CPU variants of the library (CMakeLists.txt, OOBLECK_HWCAPS): the loader picks
// the best variant the CPU supports, `--version` and summary.json name the one that ran, and the
// baseline x86-64 library (forced by a --glibc-hwcaps-mask that names no variant) runs the same scene to
// round-off of the optimised one (they differ only by FMA contraction and vector width).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace {

[[maybe_unused]] constexpr const char* kLoader = "/lib64/ld-linux-x86-64.so.2";

[[maybe_unused]] std::vector<double> last_row(const std::string& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  std::string cell;
  while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
  return v;
}

[[maybe_unused]] nlohmann::json summary(const std::string& dir) {
  std::ifstream in(std::filesystem::path(dir) / "summary.json");
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(CpuVariants, VersionNamesTheLibraryThatRuns) {
  const auto r = clitest::run("--version");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(std::regex_search(
      r.output, std::regex(R"(^oobleck \d+\.\d+\.\d+ \(library: (x86-64(-v[234])?|other)(, -march=native)?\))")))
      << r.output;
}

TEST(CpuVariants, BaselineLibraryRunsTheSceneOfTheBestVariantToRoundOff) {
#ifndef OOBLECK_HWCAPS_LEVELS
  GTEST_SKIP() << "built without OOBLECK_HWCAPS (static library, one variant)";
#else
  if (!std::filesystem::exists(kLoader)) GTEST_SKIP() << kLoader << " not found";
  // The best built level the loader reports as supported on this CPU, else the baseline.
  std::string expected = "x86-64";
  {
    const auto help = clitest::shell(std::string(kLoader) + " --help");
    ASSERT_EQ(help.status, 0) << help.output;
    const std::string& text = help.output;
    const std::string built = OOBLECK_HWCAPS_LEVELS;
    for (const char* level : {"x86-64-v2", "x86-64-v3", "x86-64-v4"})
      if (built.find(level) != std::string::npos &&
          text.find(std::string(level) + " (supported, searched)") != std::string::npos)
        expected = level;
  }
  clitest::TempDir d;
  const std::string scene = std::string(OOBLECK_SOURCE_DIR) + "/bench/scenes/intruder_authors_setup.toml";
  const std::string args = " --set time.duration=2e-5 --threads 1 --quiet --out ";
  const auto best = clitest::run("run " + scene + args + d / "best");
  ASSERT_EQ(best.status, 0) << best.output;
  const auto base =
      clitest::run("run " + scene + args + d / "base", std::string(kLoader) + " --glibc-hwcaps-mask baseline");
  ASSERT_EQ(base.status, 0) << base.output;
  EXPECT_EQ(summary(d / "best")["library_instruction_set"], expected);
  EXPECT_EQ(summary(d / "base")["library_instruction_set"], "x86-64");
  const auto a = last_row(d / "best/series.csv"), b = last_row(d / "base/series.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 10u);
  EXPECT_EQ(a[1], 20.0);  // step
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-9 * std::abs(a[k]) + 1e-30) << "column " << k;
  EXPECT_GT(a[2], 0.0);  // the grains move: the comparison is not of zeros
#endif
}
