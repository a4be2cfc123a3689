// What a second thread gains on this host, without oobleck: how much more work per second two
// threads of *perfectly* parallel loops get than one on this machine.
//
// The two-thread target of issue 4 (≥ 1.7× the one-thread updates/s) presumes a machine on which
// independent work doubles with a second core. Shared or virtualised hosts need not give that:
// when two cores are busy the clock drops (turbo), and cores may share caches, memory paths or,
// behind a hypervisor, a physical core. Each kernel here has no sharing at all between threads
// (private arrays, no atomics, no barriers inside the timed loop), so its aggregate rate on two
// threads over its rate on one is what that kind of loop can gain on this host at that minute:
//
//   compute    independent multiply-add chains in registers (bound by the FP units and the clock)
//   stream_l2  a = b + s c on private arrays of 3 × 32 KiB per thread (fits each core's L2)
//   stream_l3  the same on 3 × 1 MiB per thread (the size of the bench set-ups' point arrays)
//   stream_mem the same on 3 × 32 MiB per thread (main memory)
//
// Read the `items_per_second` column: it is the rate summed over the threads (Google Benchmark adds
// the items of all threads and divides by the wall time). Compare it with the one-thread row: the
// ratio for `compute` bounds the speed-up of compute-bound work (no program beats a loop with
// nothing shared); the stream ratios are reference points for memory-bound loops (P2G and G2P
// are partly that). `bash bench/host_ceiling.sh` prints the ratios; docs/mpm.md "Performance"
// gives them for the machine of the tenth session. They vary from minute to minute on shared
// hosts: measure them in the same minutes as the runs they are compared with.
#include <benchmark/benchmark.h>

#include <array>
#include <cstddef>
#include <vector>

namespace {

// 16 independent chains x ← x·m + c (|m| < 1: bounded, never denormal): enough independent work to
// fill the FP pipelines of any current x86 or Arm core, in 2- or 4-wide vectors as compiled.
void BM_Compute(benchmark::State& state) {
  constexpr int kChains = 16;
  constexpr long kInner = 1 << 16;
  std::array<double, kChains> x;
  for (int k = 0; k < kChains; ++k) x[k] = 1.0 + 0.01 * k;
  const double m = 0.999999, c = 1e-7;
  for (auto _ : state) {
    for (long i = 0; i < kInner; ++i) {
      for (int k = 0; k < kChains; ++k) x[k] = x[k] * m + c;
    }
    benchmark::DoNotOptimize(x);
  }
  state.SetItemsProcessed(state.iterations() * kInner * kChains);  // multiply-adds
}

// a = b + s·c on three private arrays of n doubles each; items are bytes moved (24 per element).
void stream(benchmark::State& state, std::size_t n) {
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);  // per thread, first-touched by it
  const double s = 0.5;
  for (auto _ : state) {
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n) * 24);
}
void BM_StreamL2(benchmark::State& state) { stream(state, (32u << 10) / 8); }
void BM_StreamL3(benchmark::State& state) { stream(state, (1u << 20) / 8); }
void BM_StreamMem(benchmark::State& state) { stream(state, (32u << 20) / 8); }

}  // namespace

BENCHMARK(BM_Compute)->Name("compute")->ThreadRange(1, 2)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_StreamL2)->Name("stream_l2")->ThreadRange(1, 2)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_StreamL3)->Name("stream_l3")->ThreadRange(1, 2)->UseRealTime()->MinTime(0.5);
BENCHMARK(BM_StreamMem)->Name("stream_mem")->ThreadRange(1, 2)->UseRealTime()->MinTime(1.0);

BENCHMARK_MAIN();
