// Message times of this host's MPI (docs/mpi.md "Scaling", bench/mpi_model.py): two ranks swap
// buffers of 8 B to 8 MB with comm::sendrecv (the call of the nodal exchanges), and a one-value
// allreduce (the per-step reductions). The time per exchange gives the latency α (small messages)
// and the bandwidth β (large ones) of the efficiency model.
//   mpirun --allow-run-as-root -np 2 build/release/bench/bench_mpi_exchange
// (Without mpirun it swaps with itself: a copy.) Each benchmark runs a fixed number of
// iterations so that both ranks make the same calls; rank 0 prints.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <vector>

#include "oobleck/core/comm.hpp"

namespace {

void Exchange(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<double> send(n, 1.0), recv(n, 0.0);
  const int partner = oobleck::comm::size() > 1 ? 1 - oobleck::comm::rank() : 0;
  for (auto _ : state) {
    oobleck::comm::sendrecv(send, partner, recv, partner, 7);
    benchmark::DoNotOptimize(recv.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * n * sizeof(double)));
}
BENCHMARK(Exchange)->RangeMultiplier(8)->Range(1, 1 << 20)->Iterations(2000)->Unit(benchmark::kMicrosecond);

void Allreduce(benchmark::State& state) {
  double x = 1.0;
  for (auto _ : state) benchmark::DoNotOptimize(x = oobleck::comm::max(x));
}
BENCHMARK(Allreduce)->Iterations(20000)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  oobleck::comm::init(argc, argv);
  if (oobleck::comm::size() > 2) {
    std::fprintf(stderr, "bench_mpi_exchange: run it on 1 or 2 ranks\n");
    oobleck::comm::abort(2);
  }
  if (!oobleck::comm::is_root()) (void)std::freopen("/dev/null", "w", stdout);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  oobleck::comm::finalize();
  return 0;
}
