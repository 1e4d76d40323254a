// Times the stages of the paper study (METHOD.md): modal analysis of the 6-element cantilever,
// FRF blocks by modal synthesis, one steady-state simulation with the model-I joint, and one
// identification from ten records (case I). Results: docs/benchmarks.md.
#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "frf/receptance.hpp"
#include "identify/fit.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <benchmark/benchmark.h>

#include <stdexcept>

using namespace jointid;

namespace {

struct Setup {
  fem::Model model = test::paper_cantilever();
  fem::Assembled system = fem::assemble(model);
  fem::Modes modes = fem::modal_analysis(system, {.num_modes = 0});
  fem::SparseMatrix C = fem::damping_matrix(system, model.damping, &modes);
  int tip = system.dofs.equation({7, fem::Dof::uy});
  joints::Joint joint{"tip",
                      7,
                      0,
                      fem::Dof::uy,
                      {joints::Term::k, joints::Term::c, joints::Term::c2, joints::Term::k3},
                      {4800.0, 20.0, 500.0, 1.6e8},
                      {false, false, false, false},
                      {}};
};

const Setup& setup() {
  static const Setup s;
  return s;
}

identify::Record record(const Setup& s, double f) {
  identify::SimulationOptions o;
  o.periods = 4;
  const identify::SimulatedTest t =
      identify::simulate_sine_tests(frf::Substructure(s.model), {s.joint}, {7, fem::Dof::uy},
                                    {{f, 80.0}}, o)
          .front();
  if (!t.status.ok()) throw std::runtime_error(t.status.reason);
  return t.record;
}

void BM_Assembly(benchmark::State& state) {
  const fem::Model m = test::paper_cantilever();
  for (auto _ : state)
    benchmark::DoNotOptimize(fem::assemble(m));
}

void BM_ModalAnalysisAllModes(benchmark::State& state) {
  const Setup& s = setup();
  for (auto _ : state)
    benchmark::DoNotOptimize(fem::modal_analysis(s.system, {.num_modes = 0}));
}

void BM_FrfBlocksTenFrequencies(benchmark::State& state) {
  const Setup& s = setup();
  const frf::Partition p{{s.system.dofs.equation({4, fem::Dof::uy})}, {s.tip}};
  for (auto _ : state) {
    const frf::ModalSynthesis H(s.system, s.modes, s.model.damping, {p.set1[0], p.set2[0]});
    for (int i = 0; i < 10; ++i)
      benchmark::DoNotOptimize(H.blocks(2.0 * M_PI * (1.0 + 0.4 * i), p));
  }
}

void BM_SteadyStateOneTest(benchmark::State& state) {
  const Setup& s = setup();
  for (auto _ : state)
    benchmark::DoNotOptimize(record(s, 3.0));
}

void BM_IdentifyCaseI(benchmark::State& state) {
  const Setup& s = setup();
  std::vector<identify::Record> records;
  for (int i = 0; i < 10; ++i)
    records.push_back(record(s, 1.0 + 0.4 * i));
  const frf::ModalSynthesis H(s.system, s.modes, s.model.damping, {s.tip});
  const identify::ReceptanceFn Hf = [&](double w, std::span<const int> r, std::span<const int> c) {
    return H.receptance(w, r, c);
  };
  for (auto _ : state)
    benchmark::DoNotOptimize(identify::fit(Hf, s.system.dofs, {s.joint}, records));
}

} // namespace

BENCHMARK(BM_Assembly)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ModalAnalysisAllModes)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrfBlocksTenFrequencies)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SteadyStateOneTest)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IdentifyCaseI)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
