#pragma once
// Run progress on stderr. Three modes, chosen once at construction:
//   bar     stderr is a terminal: one line redrawn in place (at most 10 times a second) with a
//           bar, percentage, steps, rate, ETA and simulated time;
//   lines   stderr is a file or pipe (batch jobs, logs): one plain line every N seconds;
//   silent  the environment variable CI is set (non-empty) or the caller asks for quiet.
// update() is cheap enough to call every step (one clock read; output only when due).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

namespace oobleck::io {

enum class ProgressMode { bar, lines, silent };

struct ProgressOptions {
  bool quiet = false;                ///< --quiet: silent whatever the terminal
  double line_interval_s = 10.0;     ///< seconds between lines in `lines` mode
  double points_per_step = 0.0;      ///< > 0: also show material-point updates per second
  std::string label = "oobleck";     ///< prefix of every line
  std::FILE* stream = stderr;        ///< where to write (tests pass a temporary file)
  std::optional<ProgressMode> mode;  ///< force a mode (tests); otherwise detected
};

/// The mode the environment asks for: silent if quiet or CI is set, bar if `stream` is a
/// terminal, lines otherwise.
ProgressMode detect_progress_mode(bool quiet, std::FILE* stream = stderr);

/// "1:02:03", "4:05" (m:ss below an hour), "--:--" when unknown.
std::string format_duration(double seconds);

class Progress {
 public:
  explicit Progress(std::uint64_t total_steps, ProgressOptions options = {});
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress();  // calls finish() if needed (completes the bar line)

  /// `done` steps of total are complete; `sim_time` (s) is shown when finite.
  void update(std::uint64_t done, double sim_time = std::numeric_limits<double>::quiet_NaN());
  /// Final line with the total wall time and mean rate; idempotent.
  void finish();

  ProgressMode mode() const { return mode_; }
  double elapsed_seconds() const;

 private:
  using Clock = std::chrono::steady_clock;
  std::string status_text(std::uint64_t done, double sim_time, double elapsed) const;
  void emit(std::uint64_t done, double sim_time, double elapsed, bool final);

  std::uint64_t total_;
  ProgressOptions opt_;
  ProgressMode mode_;
  Clock::time_point start_;
  double last_output_ = -1.0;
  std::uint64_t last_done_ = 0;
  double last_sim_time_ = std::numeric_limits<double>::quiet_NaN();
  std::size_t last_width_ = 0;
  bool finished_ = false;
};

}  // namespace oobleck::io
