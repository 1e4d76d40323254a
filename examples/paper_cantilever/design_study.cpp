// Experiment design on the paper's cantilever (docs/experiment_design.md): the 10 tests that
// `jointid design` chooses from a grid of candidates (1–30 Hz in 0.2 Hz steps × 10–80 N) against
// the paper's cases I–IV, for models I and II, with 1 % noise on force, displacement and
// velocity. For each design: the standard deviation the design predicts, and the Monte Carlo
// error of the identification (noise added to the records, identified; RMS over
// the repetitions, bias included). Records by time integration from rest (Newmark, 2048 steps a
// period, to the periodic steady state), 8 periods of 256 samples. Prints a Markdown table.
#include "cli/terminal_progress.hpp"
#include "frf/substructure.hpp"
#include "identify/design.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/sine_tests.hpp"
#include "io/model_file.hpp"
#include "paper_cases.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

using namespace jointid;
using joints::Term;

namespace {

struct Named {
  std::string name;
  std::vector<identify::SineTestPlan> tests;
};

// The paper's cases, named as in the table.
std::vector<Named> paper_cases() {
  std::vector<Named> out;
  for (const examples::PaperCase& c : examples::paper_cases())
    out.push_back({"case " + c.name + " (" + c.description + ")", c.tests});
  return out;
}

} // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::atoi(argv[1]) : 200;
  const io::ModelFile file = io::read_model(JOINTID_PAPER_MODEL);
  const frf::Substructure sub = file.substructure();
  const fem::NodeDof tip{7, fem::Dof::uy};
  const double noise = 0.01;
  struct Model {
    const char* name;
    std::vector<Term> terms;
    std::vector<double> values;
  };
  const std::vector<Model> models{
      {"I", {Term::k, Term::c, Term::c2, Term::k3}, {4800.0, 20.0, 500.0, 1.6e8}},
      {"II", {Term::k, Term::c, Term::fc, Term::k3}, {4800.0, 20.0, 3.0, 1.6e8}}};
  std::vector<identify::SineTestPlan> grid;
  for (int i = 0; i <= 145; ++i)
    for (int a = 1; a <= 8; ++a)
      grid.push_back({1.0 + 0.2 * i, 10.0 * a});

  fmt::print("Noise {:g} % RMS on force, displacement and velocity; 8 periods of 256 samples a "
             "record, averaged; {} repetitions.\n",
             100.0 * noise, reps);
  for (const Model& m : models) {
    joints::Joint j{"tip", 7, 0, fem::Dof::uy, m.terms, m.values, {}, {}};
    j.fixed.assign(m.terms.size(), false);
    const std::vector<joints::Joint> joints{j};
    const auto unknowns = identify::design_unknowns(joints);
    for (const std::vector<int>& harmonics : {std::vector<int>{1}, std::vector<int>{1, 2, 3}}) {
      identify::DesignOptions d;
      d.harmonics = harmonics;
      d.noise = noise;
      d.max_misfit = argc > 2 ? std::atof(argv[2]) : d.max_misfit;
      std::vector<Named> designs = paper_cases();
      std::vector<std::vector<identify::CandidateTest>> pools;
      pools.push_back(identify::predict_candidates(sub, joints, tip, grid, d));
      const identify::Design best = identify::choose_tests(pools[0], unknowns, 10);
      // The paper's cases are predicted whatever their misfit, so that their bias shows.
      identify::DesignOptions as_given = d;
      as_given.max_misfit = std::numeric_limits<double>::infinity();
      for (const auto& c : designs)
        pools.push_back(identify::predict_candidates(sub, joints, tip, c.tests, as_given));
      Named optimal{"D-optimal 10", {}};
      for (int i : best.chosen)
        optimal.tests.push_back(grid[static_cast<std::size_t>(i)]);
      designs.insert(designs.begin(), optimal);

      fmt::print("\n### Model {}, harmonics {}\n\n", m.name, fmt::join(harmonics, ","));
      fmt::print("D-optimal tests (Hz × N): {}\n\n", [&] {
        std::vector<std::string> t;
        for (const auto& p : optimal.tests)
          t.push_back(fmt::format("{:g}×{:g}", p.frequency_hz, p.amplitude));
        return fmt::format("{}", fmt::join(t, ", "));
      }());
      std::string head = "| design |", rule = "|---|";
      for (const auto& u : unknowns) {
        head += fmt::format(" {} predicted std (bias) | {} MC error |", joints::term_name(u.term),
                            joints::term_name(u.term));
        rule += "---:|---:|";
      }
      fmt::print("{} log det |\n{}---:|\n", head, rule);
      for (std::size_t di = 0; di < designs.size(); ++di) {
        const Named& design = designs[di];
        // Predicted: the candidates of this design.
        std::vector<int> idx = best.chosen;
        if (di > 0) idx = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
        const auto& pool = pools[di];
        Eigen::VectorXd scale(static_cast<Eigen::Index>(unknowns.size()));
        for (std::size_t u = 0; u < unknowns.size(); ++u)
          scale(static_cast<Eigen::Index>(u)) = unknowns[u].prior;
        // A case whose tests include one with coexisting responses has no prediction.
        Eigen::VectorXd sd = Eigen::VectorXd::Constant(scale.size(), std::nan(""));
        double logdet = std::nan("");
        Eigen::VectorXd bias = sd;
        std::string unpredicted;
        for (int i : idx)
          if (const auto& c = pool[static_cast<std::size_t>(i)]; !c.usable)
            unpredicted += fmt::format("{}{:g} Hz {:g} N: {}", unpredicted.empty() ? "" : "; ",
                                       c.plan.frequency_hz, c.plan.amplitude,
                                       c.reason.substr(0, c.reason.find(" (")));
        if (unpredicted.empty()) {
          sd = identify::predicted_std(pool, idx);
          bias = identify::predicted_bias(pool, idx);
          logdet = identify::log_det_information(pool, idx, scale);
        }
        // Monte Carlo.
        identify::SimulationOptions so;
        so.method = identify::SimulationMethod::time_integration; // from rest, as a test
        so.periods = 8;
        so.steps_per_period = 2048;
        so.samples_per_period = 256;
        const auto clean = identify::simulate_sine_tests(sub, joints, tip, design.tests, so);
        for (const auto& t : clean)
          if (!t.status.ok()) throw std::runtime_error(t.status.reason);
        identify::FitOptions fo;
        fo.harmonics = harmonics;
        Eigen::VectorXd square = Eigen::VectorXd::Zero(scale.size());
        int failed = 0;
        const cli::TerminalProgress progress("paper_design_study: " + design.name);
        for (int r = 0; r < reps; ++r) {
          progress.show(static_cast<double>(r) / reps);
          std::vector<identify::SineTest> tests;
          for (std::size_t i = 0; i < clean.size(); ++i) {
            identify::Record rec = clean[i].record;
            identify::add_noise(rec, noise, 1000003ull * static_cast<unsigned long long>(r) + i);
            tests.emplace_back(std::move(rec));
          }
          try {
            const identify::FitResult fit = identify::fit(
                sub, joints, identify::measure(tests, identify::measure_options(fo)), fo);
            if (!fit.status.ok()) throw std::invalid_argument(fit.status.reason);
            for (Eigen::Index u = 0; u < scale.size(); ++u)
              square(u) += std::pow(
                  fit.joints[0].terms[static_cast<std::size_t>(u)].value / scale(u) - 1.0, 2);
          } catch (const std::invalid_argument&) {
            ++failed;
          }
        }
        progress.clear();
        std::string row = "| " + design.name + " |";
        for (Eigen::Index u = 0; u < scale.size(); ++u) {
          const double rms = std::sqrt(square(u) / std::max(1, reps - failed));
          row += fmt::format(" {:.3g} % ({:+.2g} %) | {:.3g} % |", 100.0 * sd(u) / scale(u),
                             100.0 * bias(u) / scale(u), 100.0 * rms);
        }
        row += fmt::format(" {:.1f} |", logdet);
        if (failed > 0) row += fmt::format(" ({} of {} fits refused)", failed, reps);
        if (!unpredicted.empty()) row += " (not predicted: " + unpredicted + ")";
        fmt::print("{}\n", row);
      }
    }
  }
  return 0;
}
