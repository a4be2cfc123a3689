#pragma once
// The parallel layer of the MPM step: the one place that decides which thread runs which range.
//
// The kernels (P2G and G2P in transfer.hpp, the grid pass, the laws' update_chunk) are plain
// functions over an index range with no OpenMP inside. The solver's phases call them through
// this layer: a region (one fork), each thread's static share of a range, static shares with
// stealing, dynamic hand-out, barriers. Every unit of work is independent of the others, so the
// results do not depend on which thread runs it; P2G's per-thread copies are summed in thread
// order, so its sums are reproducible for a fixed thread count.
//
// Why static shares: a point's data stay in the caches of the core that scatters it in P2G and
// maps it in G2P when both use the same split (Team::share). Costly, uneven work (the granular
// law) is stolen at the end of the shares (StealingShares) so that no thread waits long.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

namespace oobleck::mpm::parallel {

/// First unit of share u when n units are split over `team` threads as OpenMP's schedule(static)
/// splits them (the first n mod team shares are one unit longer).
constexpr std::int64_t share_begin(std::int64_t n, int team, int u) {
  const std::int64_t q = n / team, r = n % team;
  return u * q + std::min<std::int64_t>(u, r);
}

/// A half-open range of units [begin, end).
struct Range {
  std::int64_t begin = 0, end = 0;
};

/// The calling thread's view of the enclosing region (made by region()).
class Team {
 public:
  Team() : size_(omp_get_num_threads()), rank_(omp_get_thread_num()) {}
  int size() const { return size_; }
  int rank() const { return rank_; }
  /// This thread's static share of n units.
  Range share(std::int64_t n) const { return {share_begin(n, size_, rank_), share_begin(n, size_, rank_ + 1)}; }
  /// Every thread of the region waits here.
  void barrier() const {
#pragma omp barrier
  }
  /// f() on one thread; the others wait at its end.
  template <class F>
  void single(F&& f) const {
#pragma omp single
    f();
  }
  /// f() on one thread (the first to arrive); the others go on.
  template <class F>
  void single_nowait(F&& f) const {
#pragma omp single nowait
    f();
  }
  /// f(i) for i in [0, n), handed out `chunk` units at a time to whichever thread asks; no
  /// barrier at the end.
  template <class F>
  void dynamic(std::int64_t n, std::int64_t chunk, F&& f) const {
#pragma omp for schedule(dynamic, chunk) nowait
    for (std::int64_t i = 0; i < n; ++i) f(i);
  }

 private:
  int size_, rank_;
};

/// f(team) on every thread of one parallel region (serial when `parallel` is false: a region on a
/// small grid costs more than its work).
template <class F>
void region(F&& f, bool parallel = true) {
#pragma omp parallel if (parallel)
  {
    const Team team;
    f(team);
  }
}

/// Threads of the regions that follow (0: OpenMP's default).
inline void set_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}
/// Threads a region gets by default.
inline int max_threads() { return omp_get_max_threads(); }
/// Wall-clock time [s] (for the step's timings).
inline double wall_time() { return omp_get_wtime(); }

/// x ← min(x, v), x ← x | v and x ← x + v, safe against the other threads' updates of x.
inline void atomic_min(std::int64_t& x, std::int64_t v) {
  std::atomic_ref<std::int64_t> a(x);
  std::int64_t cur = a.load(std::memory_order_relaxed);
  while (v < cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}
inline void atomic_or(std::uint64_t& x, std::uint64_t v) {
  std::atomic_ref<std::uint64_t>(x).fetch_or(v, std::memory_order_relaxed);
}
inline void atomic_add(std::int64_t& x, std::int64_t v) {
  std::atomic_ref<std::int64_t>(x).fetch_add(v, std::memory_order_relaxed);
}

/// Static shares with stealing over several ranges ("sets"): set k's n_k units are split as
/// Team::share splits them; each thread runs its own share from the front, `grain` units at a
/// time, then what is left of the other threads' shares (a slower core's units move to another
/// only at the end of its share). Every unit is run exactly once.
class StealingShares {
 public:
  /// Ranges for `sets` sets on a team of `team` threads; then start(k, n_k) for each. One thread
  /// calls these, and a barrier follows before run().
  void resize(int sets, int team) {
    team_ = team;
    const auto need = static_cast<std::size_t>(sets) * static_cast<std::size_t>(team);
    if (next_.size() < need) next_ = std::vector<Counter>(need);
  }
  void start(int set, std::int64_t n) {
    for (int u = 0; u < team_; ++u)
      next_[index(set, u)].next.store(share_begin(n, team_, u), std::memory_order_relaxed);
  }
  /// f(begin, end) over the calling thread's share of set `set` (n units, as given to start), then
  /// over the others' remaining units.
  template <class F>
  void run(const Team& team, int set, std::int64_t n, std::int64_t grain, F&& f) {
    for (int k = 0; k < team_; ++k) {
      const int u = (team.rank() + k) % team_;
      const std::int64_t end = share_begin(n, team_, u + 1);
      std::atomic<std::int64_t>& next = next_[index(set, u)].next;
      for (;;) {
        const std::int64_t c = next.fetch_add(grain, std::memory_order_relaxed);
        if (c >= end) break;
        f(c, std::min(c + grain, end));
      }
    }
  }

 private:
  struct alignas(64) Counter {  ///< next unit of one thread's share (its own cache line)
    std::atomic<std::int64_t> next{0};
  };
  std::size_t index(int set, int u) const { return static_cast<std::size_t>(set) * team_ + u; }
  std::vector<Counter> next_;
  int team_ = 1;
};

}  // namespace oobleck::mpm::parallel
