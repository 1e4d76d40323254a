// The identification's uncertainty, measured: Monte Carlo over the measurement noise (white,
// on force and response channels alike) of sine tests made by time integration, for
//  - the paper's cantilever, model I (k, c, c2, k3 at the tip), case I (80 N, 1.0–4.6 Hz), and
//  - two joints on it (tip: k, c; mid-span: k, c, k3), 18 tests (2–7 Hz × 10, 40, 80 N).
// For each: the coverage of the 95 % intervals, the bias and the scatter of the estimates, with
// ordinary least squares and residual intervals (the method before) and with the noise
// propagated (generalised least squares), with and without averaging the records' periods; and
// the scatter against the Cramér–Rao bound of the same tests and noise (errors in variables: the
// force's fundamental a nuisance parameter of every test, measured with its own noise).
// Results: docs/identification_uncertainty.md.
//
//   bench_identify_uncertainty [repetitions (200)] [harmonics|two|oe]   (harmonics: the
//   harmonics study; two: the two-joint study alone; oe: output error against GLS and the bound)
#include "cli/terminal_progress.hpp"
#include "frf/harmonic_balance.hpp"
#include "identify/fit.hpp"
#include "identify/output_error.hpp"
#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

using namespace jointid;
using joints::Term;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

joints::Joint joint(std::string name, int node, std::vector<Term> terms,
                    std::vector<double> values) {
  joints::Joint j{std::move(name),   node, 0, fem::Dof::uy, std::move(terms),
                  std::move(values), {},   {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

struct Study {
  std::string name;
  std::vector<joints::Joint> truth;
  std::vector<identify::SineTestPlan> plans;
};

struct Stats {
  std::vector<double> coverage, bias, rms, mean_std;
};

// The output-error fit's harmonics compared (OE_HARMONICS in the environment; default 7) and
// its harmonic balance (twice as many, at least 15).
int oe_harmonics = 7;
identify::OutputErrorOptions oe_options() {
  identify::OutputErrorOptions o;
  o.harmonics.clear();
  for (int k = 1; k <= oe_harmonics; ++k)
    o.harmonics.push_back(k);
  o.balance.harmonics = std::max(15, 2 * oe_harmonics);
  return o;
}

// Monte Carlo: `reps` noisy copies of the clean records, identified with these options.
Stats monte_carlo(const frf::Substructure& sub, const Study& s,
                  const std::vector<identify::SimulatedTest>& clean, double level, int reps,
                  const identify::FitOptions& fo, bool output_error = false) {
  std::vector<std::pair<std::size_t, std::size_t>> params;
  for (std::size_t j = 0; j < s.truth.size(); ++j)
    for (std::size_t t = 0; t < s.truth[j].terms.size(); ++t)
      params.push_back({j, t});
  const std::size_t np = params.size();
  Stats st{std::vector<double>(np), std::vector<double>(np), std::vector<double>(np),
           std::vector<double>(np)};
  const cli::TerminalProgress progress("Monte Carlo");
  for (int r = 0; r < reps; ++r) {
    progress.show(static_cast<double>(r) / reps);
    std::vector<identify::SineTest> tests;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      identify::Record rec = clean[i].record;
      identify::add_noise(rec, level, 7919ull * static_cast<unsigned long long>(r) + i);
      tests.emplace_back(std::move(rec));
    }
    // Output error compares harmonics 1 … 7 (a joint's higher harmonics pass near the second
    // mode); its start, the equation-error fit, uses fo's.
    identify::MeasureOptions mo = identify::measure_options(fo);
    if (output_error) mo.harmonics = std::max(mo.harmonics, oe_harmonics);
    const auto measured = identify::measure(tests, mo);
    const identify::FitResult fit =
        output_error ? identify::output_error(sub, s.truth, measured, fo, oe_options())
                     : identify::fit(sub, s.truth, measured, fo);
    for (std::size_t q = 0; q < np; ++q) {
      const auto& te = fit.joints[params[q].first].terms[params[q].second];
      const double truth = s.truth[params[q].first].values[params[q].second];
      st.coverage[q] += (te.ci_low <= truth && truth <= te.ci_high) ? 1.0 / reps : 0.0;
      st.bias[q] += (te.value - truth) / truth / reps;
      st.rms[q] += std::pow((te.value - truth) / truth, 2) / reps;
      st.mean_std[q] += te.std / std::abs(truth) / reps;
    }
  }
  progress.clear();
  for (double& v : st.rms)
    v = std::sqrt(v);
  return st;
}

// The Cramér–Rao bound (relative standard deviations) of the parameters from the harmonics
// 0 … K_info of the displacement and velocity channels at the joints' DOFs and the force DOF,
// with white noise of `level` × each channel's RMS on n samples, and each test's force
// fundamental a nuisance parameter measured with its own noise. Sensitivities by harmonic
// balance (central differences).
std::vector<double> cramer_rao(const frf::Substructure& sub, const Study& s,
                               const std::vector<identify::SimulatedTest>& clean, double level) {
  constexpr int K_info = 15, n = 8 * 256;
  const auto& dofs = sub.dofs();
  std::vector<std::pair<std::size_t, std::size_t>> params;
  for (std::size_t j = 0; j < s.truth.size(); ++j)
    for (std::size_t t = 0; t < s.truth[j].terms.size(); ++t)
      params.push_back({j, t});
  const auto np = static_cast<Eigen::Index>(params.size());
  std::vector<int> outputs = joints::joint_dof_set(s.truth, dofs);
  const int force_eq = dofs.equation({7, fem::Dof::uy});
  if (std::find(outputs.begin(), outputs.end(), force_eq) == outputs.end())
    outputs.push_back(force_eq);
  double f_max = 0.0;
  for (const auto& p : s.plans)
    f_max = std::max(f_max, p.frequency_hz);
  const frf::ModalSynthesis H = sub.synthesis(outputs, frf::synthesis_band_hz(f_max, 31));
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(np, np);
  for (std::size_t i = 0; i < s.plans.size(); ++i) {
    const auto& plan = s.plans[i];
    const double omega = two_pi * plan.frequency_hz;
    const frf::HarmonicBalance hb(H, s.truth, dofs, {force_eq}, outputs, plan.frequency_hz,
                                  {.harmonics = 31});
    // The first solve starts from the clean record's joint deformations (the branch the time
    // integration reached: from the linear response the harmonic balance of two tests, 5 Hz at
    // 10 N and 6 Hz at 80 N, does not converge), every perturbed solve from that solution.
    Eigen::MatrixXcd Y0 = Eigen::MatrixXcd::Zero(32, static_cast<Eigen::Index>(s.truth.size()));
    {
      const identify::Measurement m0 = identify::measure(clean[i].record, {.harmonics = 31});
      const std::vector<int> set2 = joints::joint_dof_set(s.truth, dofs);
      const Eigen::MatrixXd B = joints::joint_coordinates_on(s.truth, dofs, set2);
      for (std::size_t d = 0; d < set2.size(); ++d)
        if (const int r = m0.response_index(dofs.node_dof(set2[d])); r >= 0)
          for (int k = 1; k <= 31; ++k)
            Y0.row(k) +=
                m0.X(k, r) * B.row(static_cast<Eigen::Index>(d)).cast<std::complex<double>>();
    }
    bool first = true;
    auto simulate = [&](const std::vector<joints::Joint>& js, std::complex<double> F1) {
      Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(2, 1);
      F(1, 0) = F1;
      const auto r = hb.solve(js, F, &Y0);
      if (!r.status.ok())
        std::fprintf(stderr, "CRB: %g Hz, %g N: %s\n", plan.frequency_hz, plan.amplitude,
                     r.status.reason.c_str());
      if (first) Y0 = r.Y, first = false;
      // Data: x and v harmonics 0 … K_info at every output (v_k = ikω x_k).
      Eigen::VectorXcd d(2 * (K_info + 1) * static_cast<Eigen::Index>(outputs.size()));
      Eigen::Index at = 0;
      for (Eigen::Index o = 0; o < r.X.cols(); ++o)
        for (int k = 0; k <= K_info; ++k) {
          d(at++) = r.X(k, o);
          d(at++) = std::complex<double>(0.0, k * omega) * r.X(k, o);
        }
      return d;
    };
    const std::complex<double> F1(0.0, -plan.amplitude);
    const Eigen::VectorXcd d0 = simulate(s.truth, F1);
    // Noise variance of each datum: level × the channel's RMS per sample; E|δ|² = 4σ²/n (k ≥ 1),
    // σ²/n for the mean (real).
    const auto nd = d0.size();
    Eigen::VectorXd var(nd);
    const Eigen::Index per_output = 2 * (K_info + 1);
    for (Eigen::Index o = 0; o * per_output < nd; ++o)
      for (int c = 0; c < 2; ++c) {
        double ms = 0.0; // mean square of the channel about its mean: Σ_k≥1 |X_k|²/2
        for (int k = 1; k <= K_info; ++k)
          ms += std::norm(d0(o * per_output + 2 * k + c)) / 2.0;
        const double sigma2 = level * level * ms;
        for (int k = 0; k <= K_info; ++k)
          var(o * per_output + 2 * k + c) = (k == 0 ? 1.0 : 4.0) * sigma2 / n;
      }
    // Sensitivities to the parameters and to Re, Im of the force (the nuisance).
    Eigen::MatrixXcd J(nd, np + 2);
    for (Eigen::Index q = 0; q < np; ++q) {
      auto js = s.truth;
      const double v = js[params[q].first].values[params[q].second], h = 1e-5 * std::abs(v);
      js[params[q].first].values[params[q].second] = v + h;
      const Eigen::VectorXcd up = simulate(js, F1);
      js[params[q].first].values[params[q].second] = v - h;
      J.col(q) = (up - simulate(js, F1)) / (2.0 * h);
    }
    const double hF = 1e-6 * plan.amplitude;
    J.col(np) = (simulate(s.truth, F1 + hF) - simulate(s.truth, F1 - hF)) / (2.0 * hF);
    J.col(np + 1) = (simulate(s.truth, F1 + std::complex<double>(0.0, hF)) -
                     simulate(s.truth, F1 - std::complex<double>(0.0, hF))) /
                    (2.0 * hF);
    // Fisher information of circular complex data: 2 Re(Jᴴ W J), W = diag(1/var) (the mean's
    // imaginary part carries nothing: a real datum counts Re only, with 1/var).
    Eigen::MatrixXd I = Eigen::MatrixXd::Zero(np + 2, np + 2);
    for (Eigen::Index e = 0; e < nd; ++e) {
      const bool mean = (e % per_output) < 2;
      const Eigen::RowVectorXcd row = J.row(e);
      if (mean) {
        const Eigen::RowVectorXd re = row.real();
        I += re.transpose() * re / var(e);
      } else {
        I += 2.0 * (row.adjoint() * row).real() / var(e);
      }
    }
    // The force channel measures F1 with E|δF|² = 4σ_f²/n, σ_f = level × F0/√2.
    const double varF = 4.0 * std::pow(level * plan.amplitude / std::sqrt(2.0), 2) / n;
    I(np, np) += 2.0 / varF;
    I(np + 1, np + 1) += 2.0 / varF;
    // Eliminate the nuisance (Schur complement).
    const Eigen::MatrixXd A = I.topLeftCorner(np, np), Bm = I.topRightCorner(np, 2),
                          D = I.bottomRightCorner(2, 2);
    fisher += A - Bm * D.inverse() * Bm.transpose();
  }
  const Eigen::MatrixXd crb = fisher.inverse();
  std::vector<double> out;
  for (Eigen::Index q = 0; q < np; ++q)
    out.push_back(std::sqrt(crb(q, q)) /
                  std::abs(s.truth[params[q].first].values[params[q].second]));
  return out;
}

// A study's substructure, its clean records (time integration, 1024 steps and 256 samples a
// period, 8 periods) and the names of its parameters.
struct Prepared {
  frf::Substructure sub{test::paper_cantilever()};
  std::vector<identify::SimulatedTest> clean;
  std::vector<std::string> names;
  explicit Prepared(const Study& s) {
    identify::SimulationOptions so;
    so.steps_per_period = 1024;
    so.samples_per_period = 256;
    so.periods = 8;
    clean = identify::simulate_sine_tests(sub, s.truth, {7, fem::Dof::uy}, s.plans, so);
    for (const auto& t : clean)
      if (!t.status.ok()) throw std::runtime_error(t.status.reason);
    for (const auto& j : s.truth)
      for (Term t : j.terms)
        names.push_back(std::string(joints::term_name(t)) + " of '" + j.name + "'");
  }
};

void report(const Study& s, int reps) {
  const Prepared p(s);
  const auto& [sub, clean, names] = p;
  std::printf("\n### %s (%zu tests, %d repetitions)\n", s.name.c_str(), s.plans.size(), reps);
  for (double level : {0.01, 0.05}) {
    identify::FitOptions ols;
    ols.harmonics = {1, 2, 3};
    ols.propagate_noise = false;
    identify::FitOptions gls = ols;
    gls.propagate_noise = true;
    identify::FitOptions raw = gls;
    raw.average_periods = false;
    const Stats a = monte_carlo(sub, s, clean, level, reps, ols);
    const Stats b = monte_carlo(sub, s, clean, level, reps, gls);
    const Stats c = monte_carlo(sub, s, clean, level, reps, raw);
    const std::vector<double> crb = cramer_rao(sub, s, clean, level);
    std::printf("\nNoise %.0f %% RMS on every channel.\n\n", 100 * level);
    std::printf("| parameter | OLS, residual intervals: coverage / bias / rms | propagated noise "
                "(GLS): coverage / bias / rms / mean std | GLS without period averaging: bias / "
                "rms | Cramér–Rao std | GLS rms / CRB |\n|---|---|---|---|---|---|\n");
    for (std::size_t q = 0; q < names.size(); ++q)
      std::printf("| %s | %.1f %% / %+.2e / %.2e | %.1f %% / %+.2e / %.2e / %.2e | %+.2e / %.2e "
                  "| %.2e | %.2f |\n",
                  names[q].c_str(), 100 * a.coverage[q], a.bias[q], a.rms[q], 100 * b.coverage[q],
                  b.bias[q], b.rms[q], b.mean_std[q], c.bias[q], c.rms[q], crb[q],
                  b.rms[q] / crb[q]);
    std::fflush(stdout);
  }
}

// Output error against the equation-error fit (GLS) and the Cramér–Rao bound.
void output_error_report(const Study& s, int reps, const std::vector<double>& levels) {
  const Prepared p(s);
  const auto& [sub, clean, names] = p;
  std::printf("\n### Output error: %s (%zu tests, %d repetitions)\n", s.name.c_str(),
              s.plans.size(), reps);
  for (double level : levels) {
    identify::FitOptions gls;
    gls.harmonics = {1, 2, 3};
    const Stats b = monte_carlo(sub, s, clean, level, reps, gls);
    const Stats e = monte_carlo(sub, s, clean, level, reps, gls, true);
    const std::vector<double> crb = cramer_rao(sub, s, clean, level);
    std::printf("\nNoise %.0f %% RMS on every channel.\n\n", 100 * level);
    std::printf("| parameter | GLS: coverage / bias / rms | output error: coverage / bias / rms / "
                "mean std | Cramér–Rao std | GLS rms / CRB | output error rms / CRB |\n"
                "|---|---|---|---|---|---|\n");
    for (std::size_t q = 0; q < names.size(); ++q)
      std::printf("| %s | %.1f %% / %+.2e / %.2e | %.1f %% / %+.2e / %.2e / %.2e | %.2e | %.2f | "
                  "%.2f |\n",
                  names[q].c_str(), 100 * b.coverage[q], b.bias[q], b.rms[q], 100 * e.coverage[q],
                  e.bias[q], e.rms[q], e.mean_std[q], crb[q], b.rms[q] / crb[q], e.rms[q] / crb[q]);
    std::fflush(stdout);
  }
}

// Harmonics 1 … K against the fundamental alone, on a study at 1 % noise: the scatter of every
// parameter and the condition number of the weighted equations.
void harmonics_study(const Study& s, int reps) {
  const frf::Substructure sub(test::paper_cantilever());
  identify::SimulationOptions so;
  so.steps_per_period = 1024;
  so.samples_per_period = 256;
  so.periods = 8;
  const auto clean = identify::simulate_sine_tests(sub, s.truth, {7, fem::Dof::uy}, s.plans, so);
  for (const auto& t : clean)
    if (!t.status.ok()) throw std::runtime_error(t.status.reason);
  std::printf("\n### Harmonics used: %s, 1 %% noise, %d repetitions\n\n", s.name.c_str(), reps);
  std::printf("| harmonics | equations | mean condition number |");
  for (const auto& j : s.truth)
    for (Term t : j.terms)
      std::printf(" rms %s of '%s' |", std::string(joints::term_name(t)).c_str(), j.name.c_str());
  std::printf("\n|---|---|---|");
  for (const auto& j : s.truth)
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      std::printf("---|");
  std::printf("\n");
  for (const std::vector<int>& harmonics :
       {std::vector<int>{1}, std::vector<int>{1, 2, 3}, std::vector<int>{1, 2, 3, 4, 5}}) {
    identify::FitOptions fo;
    fo.harmonics = harmonics;
    std::vector<double> square;
    double condition = 0.0;
    int equations = 0;
    for (int r = 0; r < reps; ++r) {
      std::vector<identify::SineTest> tests;
      for (std::size_t i = 0; i < clean.size(); ++i) {
        identify::Record rec = clean[i].record;
        identify::add_noise(rec, 0.01, 7919ull * static_cast<unsigned long long>(r) + i);
        tests.emplace_back(std::move(rec));
      }
      const auto fit =
          identify::fit(sub, s.truth, identify::measure(tests, identify::measure_options(fo)), fo);
      condition += fit.condition_number / reps;
      equations = fit.equations;
      std::size_t q = 0;
      for (std::size_t j = 0; j < s.truth.size(); ++j)
        for (std::size_t t = 0; t < s.truth[j].terms.size(); ++t, ++q) {
          if (square.size() <= q) square.push_back(0.0);
          const double truth = s.truth[j].values[t];
          square[q] += std::pow((fit.joints[j].terms[t].value - truth) / truth, 2) / reps;
        }
    }
    std::printf("| %d … %d | %d | %.3g |", harmonics.front(), harmonics.back(), equations,
                condition);
    for (double v : square)
      std::printf(" %.2e |", std::sqrt(v));
    std::printf("\n");
    std::fflush(stdout);
  }
}

} // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::atoi(argv[1]) : 200;
  if (const char* k = std::getenv("OE_HARMONICS")) oe_harmonics = std::max(1, std::atoi(k));
  Study model_I{
      "Paper model I, case I",
      {joint("tip", 7, {Term::k, Term::c, Term::c2, Term::k3}, {4800.0, 20.0, 500.0, 1.6e8})},
      {}};
  for (int i = 0; i < 10; ++i)
    model_I.plans.push_back({1.0 + 0.4 * i, 80.0});
  Study two{"Two joints: tip (k, c) and mid-span (k, c, k3)",
            {joint("tip", 7, {Term::k, Term::c}, {4800.0, 20.0}),
             joint("mid", 4, {Term::k, Term::c, Term::k3}, {2e4, 10.0, 2e9})},
            {}};
  for (double f : {2.0, 3.0, 4.0, 5.0, 6.0, 7.0})
    for (double a : {10.0, 40.0, 80.0})
      two.plans.push_back({f, a});
  if (argc > 2 && std::string(argv[2]) == "harmonics") {
    harmonics_study(two, reps);
    harmonics_study(model_I, reps);
    return 0;
  }
  if (argc > 2 && std::string(argv[2]) == "oe") {
    output_error_report(model_I, reps, {0.01, 0.05});
    output_error_report(two, reps, {0.01});
    return 0;
  }
  if (argc > 2 && std::string(argv[2]) == "oe-two") {
    output_error_report(two, reps, {0.01});
    return 0;
  }
  const bool only_two = argc > 2 && std::string(argv[2]) == "two";
  if (!only_two) report(model_I, reps);
  report(two, reps);
}
