// Three non-linear joints of different kinds on a frame from a Gmsh mesh (frame.toml), identified
// at once from noisy sine tests (docs/three_joints.md):
//  1. the tests: the 12 that `jointid design` chose for these joints (README, "Experiment
//     design"), simulated by time integration from rest (Newmark, exact stick–slip friction) to
//     the periodic steady state;
//  2. one realisation with 1 % noise on every channel (force, displacement, velocity), identified:
//     a table of true and identified values with their 95 % intervals;
//  3. Monte Carlo over the noise (fixed seeds): the coverage of the 95 % intervals and the bias of
//     every parameter, and a figure of the coverage (needs an X display: run under xvfb-run -a).
// Usage: three_joints [--reps N] [--noise L] [--png FILE]
#include "cli/terminal_progress.hpp"
#include "frf/substructure.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/sine_tests.hpp"
#include "io/model_file.hpp"
#include "report/chart.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace jointid;

int main(int argc, char** argv) {
  int reps = 200;
  double noise = 0.01;
  std::string png;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
      reps = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--noise") && i + 1 < argc)
      noise = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--png") && i + 1 < argc)
      png = argv[++i];
    else {
      fmt::print(stderr, "usage: three_joints [--reps N] [--noise L] [--png FILE]\n");
      return 2;
    }
  }
  const io::ModelFile file = io::read_model(JOINTID_THREE_JOINTS_MODEL);
  const frf::Substructure sub = file.substructure();
  const fem::NodeDof force_at = io::resolve_node_dof(file, "corner:ux");
  const std::vector<joints::Joint>& truth = file.joints;

  // 1. The tests `jointid design examples/three_joints/frame.toml --force corner:ux --freq 2:1:60
  //    --amplitude 1000,3000,10000,30000 -n 12 --harmonics 1,2,3` chose.
  const std::vector<identify::SineTestPlan> plans{{21, 1e4}, {23, 1e4}, {23, 3e4}, {24, 1e4},
                                                  {24, 3e4}, {25, 3e4}, {26, 3e4}, {27, 3e4},
                                                  {28, 1e4}, {28, 3e4}, {30, 1e4}, {32, 1e4}};
  identify::SimulationOptions so;
  so.periods = 8;
  so.steps_per_period = 2048;
  so.samples_per_period = 256;
  const auto clean = identify::simulate_sine_tests(sub, truth, force_at, plans, so);
  for (const auto& t : clean) {
    if (!t.status.ok()) {
      fmt::print(stderr, "three_joints: {}\n", t.status.reason);
      return 1;
    }
    for (const auto& w : t.warnings)
      fmt::print("warning: {}\n", w);
  }
  identify::FitOptions fo;
  fo.harmonics = {1, 2, 3};
  auto identify_once = [&](int r) {
    std::vector<identify::SineTest> tests;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      identify::Record rec = clean[i].record;
      identify::add_noise(rec, noise, 2654435761ull * static_cast<unsigned long long>(r) + i);
      tests.emplace_back(std::move(rec));
    }
    return identify::fit(sub, truth, identify::measure(tests, identify::measure_options(fo)), fo);
  };

  // 2. One realisation.
  const identify::FitResult one = identify_once(0);
  if (!one.status.ok()) {
    fmt::print(stderr, "three_joints: {}\n", one.status.reason);
    return 1;
  }
  fmt::print("Frame of examples/three_joints/frame.toml, 12 sine tests at corner:ux, noise {:g} % "
             "RMS on every channel, harmonics 1-3\n\n",
             100.0 * noise);
  fmt::print("| joint | term | true | identified | 95 % interval | error / std |\n"
             "|---|---|---:|---:|---|---:|\n");
  for (std::size_t j = 0; j < truth.size(); ++j)
    for (std::size_t t = 0; t < truth[j].terms.size(); ++t) {
      const auto& e = one.joints[j].terms[t];
      fmt::print("| {} | {} | {:.6g} | {:.6g} | [{:.6g}, {:.6g}] | {:+.2f} |\n", truth[j].name,
                 joints::term_name(e.term), truth[j].values[t], e.value, e.ci_low, e.ci_high,
                 (e.value - truth[j].values[t]) / e.std);
    }
  fmt::print("\nequations {}, condition number {:.3g}, chi2 per degree of freedom {:.3g}, "
             "intervals: {}\n",
             one.equations, one.condition_number, one.chi2_per_dof, one.interval_method);
  for (const auto& w : one.warnings)
    fmt::print("warning: {}\n", w);
  for (const auto& s : one.identifiability)
    fmt::print("identifiability: {}\n", s);

  // 3. Monte Carlo.
  std::vector<std::string> names;
  std::vector<double> covered, bias, square, stds;
  for (std::size_t j = 0; j < truth.size(); ++j)
    for (std::size_t t = 0; t < truth[j].terms.size(); ++t)
      names.push_back(fmt::format("{} {}", truth[j].name, joints::term_name(truth[j].terms[t])));
  covered.assign(names.size(), 0.0);
  bias = square = stds = covered;
  const cli::TerminalProgress progress("three_joints: Monte Carlo");
  for (int r = 0; r < reps; ++r) {
    progress.show(static_cast<double>(r) / reps);
    const identify::FitResult fit = identify_once(r);
    std::size_t q = 0;
    for (std::size_t j = 0; j < truth.size(); ++j)
      for (std::size_t t = 0; t < truth[j].terms.size(); ++t, ++q) {
        const auto& e = fit.joints[j].terms[t];
        const double v = truth[j].values[t];
        covered[q] += (e.ci_low <= v && v <= e.ci_high) ? 1.0 / reps : 0.0;
        bias[q] += (e.value - v) / v / reps;
        square[q] += std::pow((e.value - v) / v, 2) / reps;
        stds[q] += e.std / std::abs(v) / reps;
      }
  }
  progress.clear();
  fmt::print("\nMonte Carlo, {} repetitions:\n\n| parameter | coverage of the 95 % intervals | "
             "bias | scatter | mean reported std |\n|---|---:|---:|---:|---:|\n",
             reps);
  for (std::size_t q = 0; q < names.size(); ++q)
    fmt::print("| {} | {:.1f} % | {:+.3g} % | {:.3g} % | {:.3g} % |\n", names[q],
               100.0 * covered[q], 100.0 * bias[q],
               100.0 * std::sqrt(std::max(0.0, square[q] - bias[q] * bias[q])), 100.0 * stds[q]);

  if (!png.empty()) {
    std::string why;
    if (!report::can_render_charts(&why)) {
      fmt::print("no picture: {} (run under xvfb-run -a)\n", why);
      return 0;
    }
    report::Chart c;
    c.title = fmt::format("Coverage of the 95 % intervals, {} noisy repetitions ({:g} % noise)",
                          reps, 100.0 * noise);
    c.y_label = "coverage (%)";
    c.x_categories = names;
    report::Series bars{"coverage", {}, {}, report::Series::Style::bars};
    for (double v : covered)
      bars.y.push_back(100.0 * v);
    c.series.push_back(bars);
    const double x0 = 0.5, x1 = static_cast<double>(names.size()) + 0.5;
    c.series.push_back(
        {"95 % (nominal)", {x0, x1}, {95.0, 95.0}, report::Series::Style::line, {0, 0, 0}});
    c.series.push_back(
        {"90 % and 98 %", {x0, x1}, {90.0, 90.0}, report::Series::Style::dashed, {120, 120, 120}});
    c.series.push_back(
        {"", {x0, x1}, {98.0, 98.0}, report::Series::Style::dashed, {120, 120, 120}});
    report::Figure f;
    f.width = 1400;
    f.height = 700;
    f.charts.push_back(c);
    report::write_chart_png(png, f);
    fmt::print("wrote {}\n", png);
  }
  return 0;
}
