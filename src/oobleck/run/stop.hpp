#pragma once
// A cooperative stop of a running scene. A stop is requested by a signal (SIGINT, SIGTERM, while a
// StopOnSignals is alive: the CLI's `oobleck run`, the Python module's `oobleck.run`) or by a call
// to request_stop. The run loop (runner.cpp) checks it after every step: it finishes that step's
// output, writes a checkpoint and a summary.json with "complete": false and "stopped_by", and
// throws Stopped, so `--restart` continues from exactly there.
#include <csignal>
#include <stdexcept>
#include <string>

namespace oobleck::run {

/// Ask the running scene to stop after its current step; `signal` names why (a signal number,
/// or 0 for a caller's request, reported as "request"). Async-signal-safe.
void request_stop(int signal) noexcept;
/// Whether a stop was requested (and not cleared).
bool stop_requested() noexcept;
/// The signal of the pending request (0: a caller's request or none).
int stop_signal() noexcept;
/// Forget a pending request (a new run starts clean).
void clear_stop() noexcept;
/// "SIGINT", "SIGTERM", "signal N" or "request".
std::string stop_reason(int signal);

/// While alive (from a clean state: it clears a pending request), SIGINT and SIGTERM request a stop instead of ending
/// the process; a second one before the run has stopped ends the process at once (the previous checkpoint stays valid:
/// every file is replaced atomically). The previous handlers are restored on destruction.
class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

/// Thrown by run_scene after a requested stop, once the checkpoint and summary.json are written.
/// The CLI exits with 128 + signal (130 for SIGINT, 143 for SIGTERM).
class Stopped : public std::runtime_error {
 public:
  Stopped(const std::string& what, int signal) : std::runtime_error(what), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

}  // namespace oobleck::run
