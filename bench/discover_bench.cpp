// Times model discovery on the paper's cantilever (21 sine tests: 2–5 Hz × 3 levels, made by time
// integration with 1 % noise) with a hidden cubic stiffness, and with a hidden cubic stiffness
// and Coulomb friction; with a hidden jenkins, iwan or gap (each with the library's terms as
// candidates, and with the coefficient terms alone: what the parametric candidates cost);
// discovery on a stepped-sine table of 492 tests (a bolted beam's stand-in, read from its CSV
// file as `jointid discover` reads it); and one steady-state point by harmonic balance against
// time integration. Results: docs/benchmarks.md.
#include "discover/discover.hpp"
#include "fem/time_integration.hpp"
#include "identify/sine_tests.hpp"
#include "io/files.hpp"
#include "io/record_csv.hpp"
#include "support/bolted_beam.hpp"
#include "support/cantilever.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <sys/resource.h>
#include <unistd.h>

using namespace jointid;
using joints::Term;

namespace {

joints::Joint joint(std::vector<Term> terms, std::vector<double> values) {
  joints::Joint j{"tip", 7, 0, fem::Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

std::vector<identify::Measurement> tests(const frf::Substructure& sub, const joints::Joint& truth,
                                         const std::vector<double>& levels) {
  std::vector<identify::SineTestPlan> plans;
  for (double f : {2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0})
    for (double a : levels)
      plans.push_back({f, a});
  identify::SimulationOptions o;
  o.steps_per_period = 1024;
  o.samples_per_period = 256;
  std::vector<identify::Measurement> out;
  int seed = 1;
  for (auto& t : identify::simulate_sine_tests(sub, {truth}, {7, fem::Dof::uy}, plans, o)) {
    if (!t.status.ok()) throw std::runtime_error(t.status.reason);
    identify::add_noise(t.record, 0.01, seed++);
    out.push_back(identify::measure(t.record, {.harmonics = 3}));
  }
  return out;
}

struct Data {
  frf::Substructure sub{test::paper_cantilever()};
  std::vector<identify::Measurement> k3 =
      tests(sub, joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8}), {10.0, 40.0, 80.0});
  std::vector<identify::Measurement> k3fc =
      tests(sub, joint({Term::k, Term::c, Term::k3, Term::fc}, {4800.0, 20.0, 1.6e8, 3.0}),
            {20.0, 50.0, 100.0});
  joints::Joint start = [] {
    joints::Joint j = joint({Term::k, Term::c}, {0.0, 0.0});
    j.given.assign(2, false);
    return j;
  }();
};

const Data& data() {
  static const Data d;
  return d;
}

// state.range(0): points of the report's response curves (0: none).
void BM_DiscoverHiddenCubicStiffness(benchmark::State& state) {
  const Data& d = data();
  discover::Options o;
  o.curve_points = static_cast<int>(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(discover::discover(d.sub, {d.start}, d.k3, o));
}

void BM_DiscoverHiddenCubicStiffnessAndFriction(benchmark::State& state) {
  const Data& d = data();
  discover::Options o;
  o.curve_points = static_cast<int>(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(discover::discover(d.sub, {d.start}, d.k3fc, o));
}

// A parametric term hidden at the tip beside k and c (the discover tests' values): range(0) 0
// jenkins (kt 5000 N/m, fs 5 N), 1 iwan (fs 100 N, kt 3000 N/m, chi -0.5, beta 0.1), 2 gap
// (delta 1 cm, kg 5000 N/m); made once each.
const std::vector<identify::Measurement>& parametric_tests(int which) {
  static std::map<int, std::vector<identify::Measurement>> made;
  auto& m = made[which];
  if (m.empty()) {
    const Term term = which == 0 ? Term::jenkins : which == 1 ? Term::iwan : Term::gap;
    const std::vector<double> parameters = which == 0 ? std::vector<double>{5000.0, 5.0}
                                           : which == 1
                                               ? std::vector<double>{100.0, 3000.0, -0.5, 0.1}
                                               : std::vector<double>{0.01, 5000.0};
    joints::Joint truth = joint({Term::k, Term::c, term}, {4800.0, 20.0, 1.0});
    truth.parameters.resize(3);
    truth.set_parameters(2, parameters);
    m = tests(data().sub, truth, {10.0, 40.0, 80.0});
  }
  return m;
}

// User and system time of every thread of the process, s.
double process_cpu_seconds() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

// A discovery's counters: every thread's CPU time (Google Benchmark's CPU column counts the
// main thread only: on a shared machine, the time this run would take alone on one core), the
// tests, steps and gaps; its label, the terms added in order.
void describe(benchmark::State& state, const discover::Result& r, double cpu_before) {
  state.counters["cpu_all_threads_s"] = process_cpu_seconds() - cpu_before;
  state.counters["tests"] = r.tests;
  state.counters["steps"] = static_cast<double>(r.steps.size());
  state.counters["gap_start"] = r.gap.front();
  state.counters["gap_final"] = r.gap.back();
  std::string added;
  for (const auto& s : r.steps)
    added += (added.empty() ? "" : ", ") + s.added.name();
  state.SetLabel(added);
  // JOINTID_BENCH_RANKINGS=1: each step's candidates, best first, on standard error.
  if (!std::getenv("JOINTID_BENCH_RANKINGS")) return;
  auto print = [](const std::string& what, const std::vector<discover::Candidate>& ranking) {
    std::fprintf(stderr, "%s\n", what.c_str());
    for (const auto& c : ranking)
      std::fprintf(stderr, "  %-28s gap %.4g criterion %.6g cv %.4g %s\n", c.name().c_str(), c.gap,
                   c.criterion, c.cv_gap, c.rejected.c_str());
  };
  for (std::size_t i = 0; i < r.steps.size(); ++i)
    print("step " + std::to_string(i + 1) + ": + " + r.steps[i].added.name(), r.steps[i].ranking);
  print("last: " + r.stop_reason, r.last_ranking);
}

// range(1): 1 every term of the library as a candidate, 0 the coefficient terms alone.
void BM_DiscoverHiddenParametricTerm(benchmark::State& state) {
  const Data& d = data();
  const auto& measured = parametric_tests(static_cast<int>(state.range(0)));
  discover::Options o;
  o.curve_points = 0;
  if (state.range(1) == 0)
    o.terms.assign(joints::coefficient_terms.begin(), joints::coefficient_terms.end());
  discover::Result r;
  const double cpu_before = process_cpu_seconds();
  for (auto _ : state)
    r = discover::discover(d.sub, {d.start}, measured, o);
  describe(state, r, cpu_before);
}

// The bolted beam's stepped-sine table (tests/support/bolted_beam.hpp: a hidden softening
// cubic stiffness and cubic damping): 12 force levels from 0.1 to 1.5 N (evenly in ratio) × 41
// frequencies from 66 to 86 Hz around the first mode, force and drive-point acceleration, 1 %
// noise on every phasor; written once to a CSV file in the temporary directory.
struct Table {
  fem::Model model = test::bolted_beam();
  frf::Substructure sub{model};
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("jointid_bench_bolted_beam_" + std::to_string(::getpid()) + ".csv");
  Table() {
    const identify::SteppedSineTable table = test::stepped_sine_table(
        model, test::bolt_truth(), test::stepped_sine_plan(12, 0.1, 1.5, 41, 66.0, 86.0));
    io::write_file_atomically(path, io::stepped_sine_csv(table, {"bolted beam stand-in"}));
  }
  ~Table() { std::filesystem::remove(path); }
};

const Table& table() {
  static const Table t;
  return t;
}

// As `jointid discover MODEL TABLE` runs it: the table read and measured (harmonics 1, 2, 3
// asked, a table gives the fundamental), the library's default options; state.range(0): points
// of the report's response curves (30: the default; 0: none). The report's pictures are not
// drawn.
void BM_DiscoverSteppedSineTable(benchmark::State& state) {
  const Table& t = table();
  discover::Options o;
  o.curve_points = static_cast<int>(state.range(0));
  discover::Result r;
  const double cpu_before = process_cpu_seconds();
  for (auto _ : state) {
    const std::vector<identify::Measurement> measured =
        identify::measure(io::read_tests({t.path}), {.harmonics = 3});
    r = discover::discover(t.sub, {test::bolt_start()}, measured, o);
  }
  describe(state, r, cpu_before);
}

// One steady state at 4 Hz, 80 N (near the joined structure's first mode) with the joint k + c
// + k3 (range 0) or k + c + k3 + fc (range 1).
joints::Joint point_joint(int friction) {
  return friction ? joint({Term::k, Term::c, Term::k3, Term::fc}, {4800.0, 20.0, 1.6e8, 3.0})
                  : joint({Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8});
}

void BM_SteadyStateHarmonicBalance(benchmark::State& state) {
  const Data& d = data();
  const int tip = d.sub.dofs().equation({7, fem::Dof::uy});
  const frf::ModalSynthesis H = d.sub.synthesis({tip}, 0.0);
  const std::vector<joints::Joint> j{point_joint(static_cast<int>(state.range(0)))};
  const frf::HarmonicBalance hb(H, j, d.sub.dofs(), {tip}, {tip}, 4.0, {.harmonics = 15});
  for (auto _ : state)
    benchmark::DoNotOptimize(hb.solve(j, frf::sine_force(80.0)));
}

void BM_SteadyStateTimeIntegration(benchmark::State& state) {
  const Data& d = data();
  const int tip = d.sub.dofs().equation({7, fem::Dof::uy});
  const fem::Outcome<fem::SparseMatrix> damping = d.sub.damping_matrix();
  if (!damping.status.ok()) {
    state.SkipWithError(damping.status.reason.c_str());
    return;
  }
  const fem::SparseMatrix& C = damping.value;
  const joints::JointForces forces({point_joint(static_cast<int>(state.range(0)))}, d.sub.dofs());
  const std::array<int, 1> out{tip};
  fem::SteadyStateOptions o;
  o.steps_per_period = 1024;
  o.output_periods = 1;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        fem::steady_state(*d.sub.system(), C, &forces, {tip, 80.0, 4.0}, out, o));
}

} // namespace

BENCHMARK(BM_DiscoverHiddenCubicStiffness)
    ->Arg(0)
    ->Arg(30)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK(BM_DiscoverHiddenCubicStiffnessAndFriction)
    ->Arg(0)
    ->Arg(30)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK(BM_DiscoverHiddenParametricTerm)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK(BM_DiscoverSteppedSineTable)->Arg(30)->Arg(0)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_SteadyStateHarmonicBalance)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SteadyStateTimeIntegration)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
