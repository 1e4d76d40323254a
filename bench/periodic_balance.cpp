// Times one steady state of a periodic broadband test by harmonic balance: the paper's
// cantilever with a joint at the tip that has friction with its own stiffness and a clearance
// (k 4800 N/m, c 20 N s/m, jenkins kt 5000 N/m fs 5 N, gap ±1 cm kg 5000 N/m — the stop closes
// at the larger levels), driven at the tip by a multisine of period 4 s (base 0.25 Hz), lines
// 1-4 Hz (13 lines, Schroeder phases, 60 N RMS), solved with K harmonics of the base frequency:
// K = 64, 128, 256 (lines up to 16, 32, 64 Hz; the multisine has even lines, so every harmonic
// is solved: 2K + 1 = 129, 257, 513 unknowns, as in discovery's re-simulation of a multisine
// record); and K = 1024, 4096, 9216 (lines to 256 Hz, 1 kHz, 2.3 kHz: a ground-vibration test's
// record of 20 s periods has as many). state.range(1), the route: 0 the sample tables and the
// dense Newton (Equations::fft_from and matrix_free_from out of reach: the route before); 1 the
// transforms and the hysteretic loop's derivative by FFT, dense Newton; 2 Newton–Krylov, no
// matrix (matrix_free_from = 1). By default the route is 0 below 96 unknowns a block, 1 below
// 1024, then 2. Counters: Newton iterations and unknowns. Results: docs/benchmarks.md,
// "Harmonic balance of many lines".
#include "frf/harmonic_balance.hpp"
#include "frf/hb_equations.hpp"
#include "frf/substructure.hpp"
#include "support/cantilever.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

using namespace jointid;
using joints::Term;

namespace {

joints::Joint tip_joint() {
  joints::Joint j{"tip",
                  7,
                  0,
                  fem::Dof::uy,
                  {Term::k, Term::c, Term::jenkins, Term::gap},
                  {4800.0, 20.0, 1.0, 1.0},
                  {},
                  {}};
  j.fixed.assign(j.terms.size(), false);
  j.parameters.resize(4);
  j.set_parameters(2, {5000.0, 5.0});
  j.set_parameters(3, {0.01, 5000.0});
  return j;
}

// The multisine's harmonics of the base 0.25 Hz: lines 4 … 16 (1-4 Hz), Schroeder phases,
// `rms` N in all (rows 0 … K).
Eigen::MatrixXcd multisine(int K, double rms) {
  Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(K + 1, 1);
  const int first = 4, last = 16, n = last - first + 1;
  const double a = rms * std::sqrt(2.0 / n); // each line's amplitude
  for (int l = first; l <= last; ++l) {
    const int i = l - first;
    const double phase = -std::numbers::pi * i * (i + 1) / n;
    F(l, 0) = std::polar(a, phase);
  }
  return F;
}

void BM_PeriodicHarmonicBalance(benchmark::State& state) {
  const int K = static_cast<int>(state.range(0));
  const int route = static_cast<int>(state.range(1));
  static const frf::Substructure sub(test::paper_cantilever());
  const int tip = sub.dofs().equation({7, fem::Dof::uy});
  const frf::ModalSynthesis H = sub.synthesis({tip}, 0.25 * (K + 1));
  const std::vector<joints::Joint> j{tip_joint()};
  using frf::detail::Equations;
  const int fft_from = Equations::fft_from, free_from = Equations::matrix_free_from;
  Equations::fft_from = route == 0 ? 1 << 30 : fft_from;
  Equations::matrix_free_from = route == 2 ? 1 : 1 << 30;
  const frf::HarmonicBalance hb(H, j, sub.dofs(), {tip}, {tip}, 0.25, {.harmonics = K});
  const Eigen::MatrixXcd F = multisine(K, 60.0);
  frf::HarmonicBalanceResult r;
  for (auto _ : state) {
    r = hb.solve(j, F);
    benchmark::DoNotOptimize(r);
  }
  Equations::fft_from = fft_from, Equations::matrix_free_from = free_from;
  if (!r.status.ok()) state.SkipWithError(r.status.reason.c_str());
  state.counters["iterations"] = static_cast<double>(r.iterations);
  state.counters["sum_abs_Y_mm"] = 1e3 * r.Y.col(0).cwiseAbs().sum();
}

} // namespace

BENCHMARK(BM_PeriodicHarmonicBalance)
    ->ArgsProduct({{64, 128, 256, 512}, {0, 1, 2}})
    ->ArgsProduct({{1024, 4096, 9216}, {2}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
