#include "oobleck/run/stop.hpp"

#include <atomic>

#include <fmt/format.h>

namespace oobleck::run {

namespace {

constexpr int kNone = -1;
std::atomic<int> g_stop{kNone};  // the requesting signal, 0 for a call, kNone for no request
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

extern "C" void on_stop_signal(int signal) {
  int expected = kNone;
  if (!g_stop.compare_exchange_strong(expected, signal)) {
    // A second signal while the run is stopping: end the process as the signal would have.
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

}  // namespace

void request_stop(int signal) noexcept { g_stop.store(signal); }
bool stop_requested() noexcept { return g_stop.load() != kNone; }
int stop_signal() noexcept {
  const int s = g_stop.load();
  return s == kNone ? 0 : s;
}
void clear_stop() noexcept { g_stop.store(kNone); }

std::string stop_reason(int signal) {
  switch (signal) {
    case 0: return "request";
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return fmt::format("signal {}", signal);
  }
}

StopOnSignals::StopOnSignals() {
  clear_stop();
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;  // a write interrupted by the signal resumes
  sigaction(SIGINT, &sa, &previous_int_);
  sigaction(SIGTERM, &sa, &previous_term_);
}

StopOnSignals::~StopOnSignals() {
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

}  // namespace oobleck::run
