// Times response curves by harmonic balance with continuation (frf::trace_response) on the
// README's hardening cantilever (examples/response/hardening_tip.toml: the paper's cantilever
// with k = 4800 N/m, c = 2 N s/m, k3 = 1.6e8 N/m³ at the tip), 15 → 30 Hz at 80 N (two folds),
// with and without the Floquet stability of each point, for K = 5 and 9 harmonics. Counters:
// points traced and time per point. And one steady hysteresis loop of a 100-slider iwan
// (joints::steady_loop, the AFT force of every harmonic-balance residual with an iwan) at 64 and
// 512 samples, with and without its derivative. Results: docs/benchmarks.md.
#include "frf/continuation.hpp"
#include "joints/hysteresis.hpp"
#include "support/cantilever.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace jointid;
using joints::Term;

namespace {

// Times the curve of joint j at the tip under `force` N over 15 → 30 Hz. Counters: its points,
// folds, points whose multipliers were computed, unstable points, and the time per point.
void time_curve(benchmark::State& state, const frf::Substructure& sub, const joints::Joint& j,
                double force, const frf::ContinuationOptions& o) {
  std::size_t points = 0, folds = 0, checked = 0, unstable = 0;
  for (auto _ : state) {
    const frf::ResponseCurves c =
        frf::response_curves(sub, {j}, {7, fem::Dof::uy}, {force}, 15.0, 30.0, o);
    points = c.curves[0].points.size();
    folds = c.curves[0].folds.size();
    checked = unstable = 0;
    for (const auto& p : c.curves[0].points)
      checked += p.stability_checked, unstable += p.stable.has_value() && !*p.stable;
    benchmark::DoNotOptimize(c);
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["folds"] = static_cast<double>(folds);
  state.counters["checked"] = static_cast<double>(checked);
  state.counters["unstable"] = static_cast<double>(unstable);
  state.counters["per_point"] = benchmark::Counter(static_cast<double>(points),
                                                   benchmark::Counter::kIsIterationInvariantRate |
                                                       benchmark::Counter::kInvert);
}

void BM_ResponseCurve(benchmark::State& state) {
  const frf::Substructure sub{test::paper_cantilever()};
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, Term::k3}, {4800.0, 2.0, 1.6e8},
                  {},    {}};
  j.fixed.assign(3, true);
  frf::ContinuationOptions o;
  o.hb.harmonics = static_cast<int>(state.range(0));
  o.stability = state.range(1) != 0;
  time_curve(state, sub, j, 80.0, o);
}

// The same cantilever and band with each hysteretic or non-smooth joint kind at the tip (k = 4800
// N/m, c = 2 N s/m beside it), K = 5: range(0) 0 a Jenkins element (kt 5000 N/m, fs 2 N) at
// 20 N, 1 an Iwan (fs 5 N, kt 1e4 N/m, chi −0.5, beta 0.1: 100 sliders) at 20 N, 2 a gap
// (delta 1 mm, kg 1e5 N/m) at 20 N; range(1): 1 with stability.
void BM_ResponseCurveKind(benchmark::State& state) {
  const frf::Substructure sub{test::paper_cantilever()};
  const int kind = static_cast<int>(state.range(0));
  const Term term = kind == 0 ? Term::jenkins : kind == 1 ? Term::iwan : Term::gap;
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, term}, {4800.0, 2.0, 1.0}, {}, {}};
  j.fixed.assign(3, true);
  if (kind == 0) j.set_parameters(2, {5000.0, 2.0});
  if (kind == 1) j.set_parameters(2, {5.0, 1.0e4, -0.5, 0.1});
  if (kind == 2) j.set_parameters(2, {1e-3, 1e5});
  frf::ContinuationOptions o;
  o.hb.harmonics = 5;
  o.stability = state.range(1) != 0;
  time_curve(state, sub, j, 20.0, o);
}

// range(0): samples a period; range(1): 1 with the derivative. The deformation: a fundamental
// of 0.2 mm (about a tenth of the iwan's phi_max: microslip) with a third harmonic of a tenth.
void BM_SteadyLoopIwan100(benchmark::State& state) {
  const joints::Sliders s = joints::iwan_sliders(3.0, 1.0e4, -0.5, 0.1, 100);
  const int N = static_cast<int>(state.range(0));
  std::vector<double> y(static_cast<std::size_t>(N)), g(y.size());
  for (int n = 0; n < N; ++n) {
    const double th = 2.0 * std::numbers::pi * n / N;
    y[static_cast<std::size_t>(n)] = 2e-4 * (std::sin(th + 0.3) + 0.1 * std::sin(3.0 * th));
  }
  joints::LoopWork work;
  std::vector<joints::LoopEntry> entries;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        joints::steady_loop(s, y, false, g, state.range(1) ? &entries : nullptr, work));
    benchmark::DoNotOptimize(g.data());
  }
}

} // namespace

BENCHMARK(BM_SteadyLoopIwan100)->ArgsProduct({{64, 512}, {0, 1}});
BENCHMARK(BM_ResponseCurve)
    ->Args({5, 0})
    ->Args({5, 1})
    ->Args({9, 0})
    ->Args({9, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ResponseCurveKind)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
