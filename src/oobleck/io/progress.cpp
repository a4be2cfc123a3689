#include "oobleck/io/progress.hpp"

#include <cmath>
#include <cstdlib>

#include <fmt/format.h>
#include <unistd.h>

namespace oobleck::io {

ProgressMode detect_progress_mode(bool quiet, std::FILE* stream) {
  const char* ci = std::getenv("CI");
  if (quiet || (ci != nullptr && *ci != '\0')) return ProgressMode::silent;
  if (stream != nullptr && ::isatty(::fileno(stream))) return ProgressMode::bar;
  return ProgressMode::lines;
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const auto s = static_cast<long long>(std::llround(seconds));
  if (s >= 3600) return fmt::format("{}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{}:{:02d}", s / 60, s % 60);
}

namespace {
std::string rate_text(double per_second, const char* unit) {
  if (per_second >= 1e6) return fmt::format("{:.2f} M{}/s", per_second / 1e6, unit);
  if (per_second >= 1e3) return fmt::format("{:.1f} k{}/s", per_second / 1e3, unit);
  return fmt::format("{:.1f} {}/s", per_second, unit);
}
}  // namespace

Progress::Progress(std::uint64_t total_steps, ProgressOptions options)
    : total_(total_steps),
      opt_(std::move(options)),
      mode_(opt_.mode ? *opt_.mode : detect_progress_mode(opt_.quiet, opt_.stream)),
      start_(Clock::now()) {
  if (opt_.quiet) mode_ = ProgressMode::silent;
  if (opt_.stream == nullptr) mode_ = ProgressMode::silent;
}

Progress::~Progress() {
  if (!finished_) finish();
}

double Progress::elapsed_seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

std::string Progress::status_text(std::uint64_t done, double sim_time, double elapsed) const {
  const double frac = total_ > 0 ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  const double eta = rate > 0 && done <= total_ ? static_cast<double>(total_ - done) / rate : NAN;
  std::string s = fmt::format("{:5.1f}%  step {}/{}  {}", 100.0 * frac, done, total_, rate_text(rate, "steps"));
  if (opt_.points_per_step > 0) s += "  " + rate_text(rate * opt_.points_per_step, "pt");
  s += "  ETA " + format_duration(eta);
  if (std::isfinite(sim_time)) s += fmt::format("  t={:.4g} s", sim_time);
  return s;
}

void Progress::emit(std::uint64_t done, double sim_time, double elapsed, bool final) {
  if (mode_ == ProgressMode::silent) return;
  std::string line;
  if (final) {
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
    line = fmt::format("{}: {} steps in {} ({})", opt_.label, done, format_duration(elapsed), rate_text(rate, "steps"));
    if (opt_.points_per_step > 0) line += ", " + rate_text(rate * opt_.points_per_step, "pt");
  } else if (mode_ == ProgressMode::bar) {
    constexpr int width = 28;
    const double frac = total_ > 0 ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0;
    const int filled = static_cast<int>(frac * width);
    line =
        fmt::format("{} [{}{}] {}", opt_.label, std::string(static_cast<std::size_t>(filled), '#'),
                    std::string(static_cast<std::size_t>(width - filled), '.'), status_text(done, sim_time, elapsed));
  } else {
    line = fmt::format("{}: {}", opt_.label, status_text(done, sim_time, elapsed));
  }
  if (mode_ == ProgressMode::bar) {
    // Redraw in place; pad with spaces over a longer previous line.
    const std::size_t width = line.size();
    if (width < last_width_) line += std::string(last_width_ - width, ' ');
    last_width_ = width;
    std::fprintf(opt_.stream, "\r%s%s", line.c_str(), final ? "\n" : "");
  } else {
    std::fprintf(opt_.stream, "%s\n", line.c_str());
  }
  std::fflush(opt_.stream);
}

void Progress::update(std::uint64_t done, double sim_time) {
  last_done_ = done;
  last_sim_time_ = sim_time;
  if (mode_ == ProgressMode::silent || finished_) return;
  const double now = elapsed_seconds();
  const double interval = mode_ == ProgressMode::bar ? 0.1 : opt_.line_interval_s;
  if (last_output_ >= 0 && now - last_output_ < interval) return;
  if (last_output_ < 0 && mode_ == ProgressMode::lines && now < interval) return;  // no line at t = 0
  last_output_ = now;
  emit(done, sim_time, now, false);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  emit(last_done_, last_sim_time_, elapsed_seconds(), true);
}

}  // namespace oobleck::io
