// Times response curves by harmonic balance with continuation (frf::trace_response) on the
// README's hardening cantilever (examples/response/hardening_tip.toml: the paper's cantilever
// with k = 4800 N/m, c = 2 N s/m, k3 = 1.6e8 N/m³ at the tip), 15 → 30 Hz at 80 N (two folds),
// with and without the Floquet stability of each point, for K = 5 and 9 harmonics. Counters:
// points traced and time per point. Results: docs/benchmarks.md.
#include "frf/continuation.hpp"
#include "support/cantilever.hpp"

#include <benchmark/benchmark.h>

using namespace jointid;
using joints::Term;

namespace {

void BM_ResponseCurve(benchmark::State& state) {
  const frf::Substructure sub{test::paper_cantilever()};
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, Term::k3}, {4800.0, 2.0, 1.6e8},
                  {},    {}};
  j.fixed.assign(3, true);
  frf::ContinuationOptions o;
  o.hb.harmonics = static_cast<int>(state.range(0));
  o.stability = state.range(1) != 0;
  std::size_t points = 0, folds = 0;
  for (auto _ : state) {
    const frf::ResponseCurves c =
        frf::response_curves(sub, {j}, {7, fem::Dof::uy}, {80.0}, 15.0, 30.0, o);
    points = c.curves[0].points.size();
    folds = c.curves[0].folds.size();
    benchmark::DoNotOptimize(c);
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["folds"] = static_cast<double>(folds);
  state.counters["per_point"] = benchmark::Counter(static_cast<double>(points),
                                                   benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
}

} // namespace

BENCHMARK(BM_ResponseCurve)
    ->Args({5, 0})
    ->Args({5, 1})
    ->Args({9, 0})
    ->Args({9, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
