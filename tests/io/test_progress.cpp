// Progress reporting: mode detection (CI, quiet, terminal), line and bar output, ETA text.
#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>

#include "io_test_util.hpp"
#include "oobleck/io/progress.hpp"

using namespace oobleck::io;
using oobleck::test::read_text;
using oobleck::test::TempDir;

namespace {
/// Set or unset CI for the lifetime of the guard.
class CiGuard {
 public:
  explicit CiGuard(const char* value) {
    const char* old = std::getenv("CI");
    had_ = old != nullptr;
    if (had_) old_ = old;
    if (value)
      ::setenv("CI", value, 1);
    else
      ::unsetenv("CI");
  }
  ~CiGuard() {
    if (had_)
      ::setenv("CI", old_.c_str(), 1);
    else
      ::unsetenv("CI");
  }

 private:
  bool had_ = false;
  std::string old_;
};
}  // namespace

TEST(Progress, FormatDuration) {
  EXPECT_EQ(format_duration(0), "0:00");
  EXPECT_EQ(format_duration(65.4), "1:05");
  EXPECT_EQ(format_duration(3723), "1:02:03");
  EXPECT_EQ(format_duration(-1), "--:--");
  EXPECT_EQ(format_duration(std::numeric_limits<double>::infinity()), "--:--");
}

TEST(Progress, ModeFollowsCiQuietAndTerminal) {
  TempDir dir;
  std::FILE* file = std::fopen(dir.file("log").c_str(), "w");
  ASSERT_NE(file, nullptr);
  {
    CiGuard ci("true");
    EXPECT_EQ(detect_progress_mode(false, file), ProgressMode::silent);
  }
  {
    CiGuard ci(nullptr);
    EXPECT_EQ(detect_progress_mode(true, file), ProgressMode::silent);
    EXPECT_EQ(detect_progress_mode(false, file), ProgressMode::lines);  // a file is no terminal
  }
  {
    CiGuard ci("");  // set but empty counts as unset
    EXPECT_EQ(detect_progress_mode(false, file), ProgressMode::lines);
  }
  std::fclose(file);
}

TEST(Progress, LinesModeWritesPlainLines) {
  TempDir dir;
  std::FILE* file = std::fopen(dir.file("log").c_str(), "w");
  ASSERT_NE(file, nullptr);
  {
    ProgressOptions o;
    o.stream = file;
    o.mode = ProgressMode::lines;
    o.line_interval_s = 0.0;  // a line on every update
    o.points_per_step = 12000;
    Progress p(100, o);
    p.update(50, 0.5);
    p.update(100, 1.0);
    p.finish();
    p.finish();  // idempotent
  }
  std::fclose(file);
  const std::string log = read_text(dir.file("log"));
  EXPECT_EQ(log.find('\r'), std::string::npos) << log;
  EXPECT_NE(log.find("oobleck:  50.0%  step 50/100"), std::string::npos) << log;
  EXPECT_NE(log.find("ETA "), std::string::npos) << log;
  EXPECT_NE(log.find("t=0.5 s"), std::string::npos) << log;
  EXPECT_NE(log.find("pt/s"), std::string::npos) << log;
  EXPECT_NE(log.find("oobleck: 100 steps in"), std::string::npos) << log;
  std::size_t lines = 0;
  for (char c : log) lines += c == '\n';
  EXPECT_EQ(lines, 3u) << log;
}

TEST(Progress, BarModeRedrawsOneLine) {
  TempDir dir;
  std::FILE* file = std::fopen(dir.file("log").c_str(), "w");
  ASSERT_NE(file, nullptr);
  {
    ProgressOptions o;
    o.stream = file;
    o.mode = ProgressMode::bar;
    Progress p(10, o);
    p.update(5);
  }  // destructor finishes the line
  std::fclose(file);
  const std::string log = read_text(dir.file("log"));
  EXPECT_EQ(log.rfind("\roobleck [##############..............]  50.0%  step 5/10", 0), 0u) << log;
  EXPECT_EQ(log.back(), '\n');
}

TEST(Progress, SilentWritesNothing) {
  TempDir dir;
  std::FILE* file = std::fopen(dir.file("log").c_str(), "w");
  ASSERT_NE(file, nullptr);
  {
    ProgressOptions o;
    o.stream = file;
    o.quiet = true;
    o.mode = ProgressMode::lines;  // quiet wins
    Progress p(10, o);
    EXPECT_EQ(p.mode(), ProgressMode::silent);
    p.update(10);
  }
  std::fclose(file);
  EXPECT_EQ(read_text(dir.file("log")), "");
}
