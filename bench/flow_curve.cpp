// Benchmark (not a test): steady flow-curve generation (E11 sweep) per preset, and the
// xi_dot_eps > 0 variant that needs a scalar root per point. Reports points per second.
// BM_FlowCurveColumns does, in C++, the work of the Python module's flow_curve (python/src/
// bind_rheology.cpp): rheology::flow_curve_columns, the sweep with the DST rate (E14) and the 9
// columns filled into one block; it splits the Python overhead of bench/flow_curve_python.py into
// this work and the Python boundary.
#include <span>
#include <vector>

#include <benchmark/benchmark.h>

#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/params.hpp"

using namespace oobleck;

static void BM_FlowCurve(benchmark::State& state, const char* preset, double phi, double xi_dot_eps) {
  auto p = rheology::load_preset(preset);
  p.steady.xi_dot_eps = xi_dot_eps;
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto c = rheology::flow_curve(p.steady, phi, n);
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["points/s"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

static void BM_FlowCurveColumns(benchmark::State& state, const char* preset, double phi) {
  const auto p = rheology::load_preset(preset);
  const int n = static_cast<int>(state.range(0));
  const auto r = static_cast<std::size_t>(n);
  for (auto _ : state) {
    std::vector<double> c(9 * r);  // the module allocates a fresh (9, rows) array per call
    rheology::flow_curve_columns(p.steady, std::span<const double>(&phi, 1), n, c);
    benchmark::DoNotOptimize(c.data());
    benchmark::ClobberMemory();
  }
  state.counters["points/s"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_FlowCurve, hermes2016_dst, "hermes2016", 0.47, 0.0)->Arg(400)->Arg(200);
BENCHMARK_CAPTURE(BM_FlowCurve, singh2018b_s_shape, "singh2018b", 0.56, 0.0)->Arg(400);
BENCHMARK_CAPTURE(BM_FlowCurve, frith1996_cst, "frith1996", 0.50, 0.0)->Arg(400);
BENCHMARK_CAPTURE(BM_FlowCurve, hermes2016_brownian, "hermes2016", 0.47, 1.0)->Arg(400);
BENCHMARK_CAPTURE(BM_FlowCurveColumns, hermes2016_dst, "hermes2016", 0.47)->Arg(200);

BENCHMARK_MAIN();
