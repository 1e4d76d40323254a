// Output-error identification (maximum likelihood under the records' noise) against known
// truth: it converges from a wrong start to the values that made the records, and over noisy
// copies its scatter matches the standard deviations it reports (the Cramér–Rao bound of its
// data model: (JᵀJ)⁻¹) and is smaller than the equation-error fit's.
#include "identify/output_error.hpp"

#include "identify/sine_tests.hpp"
#include "support/cantilever.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace jointid {
namespace {

using joints::Term;

// The paper's cantilever with k, c, k3 at the tip; 8 tests across its first resonance (2–5 Hz,
// 10 and 40 N), made by the harmonic balance (15 harmonics, as the output-error model) and
// sampled 256 times a period over 8 periods, displacement and velocity at the tip.
struct Study {
  frf::Substructure sub{test::paper_cantilever()};
  std::vector<joints::Joint> truth{
      {"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, Term::k3}, {4800.0, 20.0, 1.6e8}, {}, {}}};
  std::vector<identify::SimulatedTest> clean;
  Study() {
    truth[0].fixed.assign(3, false);
    std::vector<identify::SineTestPlan> plans;
    for (double f : {2.0, 2.6, 3.2, 3.8})
      for (double a : {10.0, 40.0})
        plans.push_back({f, a});
    identify::SimulationOptions so;
    so.method = identify::SimulationMethod::harmonic_balance;
    so.balance.harmonics = 15;
    so.steps_per_period = 256;
    so.samples_per_period = 256;
    so.periods = 8;
    clean = identify::simulate_sine_tests(sub, truth, {7, fem::Dof::uy}, plans, so);
  }
  std::vector<identify::Measurement> noisy(double level, std::uint64_t seed) const {
    std::vector<identify::Measurement> out;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      identify::Record r = clean[i].record;
      identify::add_noise(r, level, seed * 1000 + i);
      out.push_back(identify::measure(r, {.harmonics = 3}));
    }
    return out;
  }
};

const identify::FitOptions equation_error{.harmonics = {1, 2, 3}};

TEST(OutputError, ConvergesFromAWrongStartToTheTruth) {
  // Noise of 1e-6 (so that its variance is known), the equation-error values spoiled by 5–20 %:
  // output error comes back to the truth within its own interval, and the interval is tiny.
  const Study s;
  const auto tests = s.noisy(1e-6, 1);
  identify::FitResult start = identify::fit(s.sub, s.truth, tests, equation_error);
  ASSERT_TRUE(start.status.ok());
  start.joints[0].terms[0].value *= 1.05;
  start.joints[0].terms[1].value *= 0.8;
  start.joints[0].terms[2].value *= 1.2;
  std::vector<int> equations{s.sub.dofs().equation({7, fem::Dof::uy})};
  const frf::ModalSynthesis H = s.sub.synthesis(equations, 200.0);
  const identify::FitResult r = identify::output_error(H, s.sub.dofs(), s.truth, tests, start);
  ASSERT_EQ(r.joints.size(), 1u);
  EXPECT_EQ(r.interval_method, "output error");
  EXPECT_EQ(r.equations, 8 * 3 * 2 * 2); // 8 tests × harmonics 1–3 × (re, im) × (x, v) at the tip
  EXPECT_EQ(r.unknowns, 3 + 8 * 2);      // k, c, k3 and each test's force fundamental
  for (std::size_t t = 0; t < 3; ++t) {
    const double truth = s.truth[0].values[t], value = r.joints[0].terms[t].value,
                 sd = r.joints[0].terms[t].std;
    EXPECT_LT(std::abs(value - truth), 4.0 * sd) << t;
    EXPECT_LT(sd, 1e-4 * truth) << t;
  }
  EXPECT_LT(r.chi2_per_dof, 3.0);
}

TEST(OutputError, ScatterMatchesItsReportedBoundAndBeatsEquationError) {
  // 40 noisy copies at 1 % RMS on every channel (force included). For each parameter: the rms
  // of the estimates about the truth against the mean reported standard deviation (sampling
  // error of an rms over 40 copies: about 11 %, so within ×/÷ 1.4), coverage of the 95 %
  // intervals at least 85 % (3 binomial standard deviations below 95 %), and a scatter below the
  // equation-error fit's (which does not reach the bound: docs/identification_uncertainty.md).
  const Study s;
  constexpr int copies = 40;
  double rms_oe[3]{}, rms_ee[3]{}, mean_sd[3]{};
  int covered[3]{};
  for (int c = 0; c < copies; ++c) {
    const auto tests = s.noisy(0.01, 100 + static_cast<std::uint64_t>(c));
    const identify::FitResult r = identify::output_error(s.sub, s.truth, tests, equation_error);
    const identify::FitResult e = identify::fit(s.sub, s.truth, tests, equation_error);
    for (std::size_t t = 0; t < 3; ++t) {
      const double truth = s.truth[0].values[t];
      const identify::TermEstimate& te = r.joints[0].terms[t];
      rms_oe[t] += std::pow((te.value - truth) / truth, 2) / copies;
      rms_ee[t] += std::pow((e.joints[0].terms[t].value - truth) / truth, 2) / copies;
      mean_sd[t] += te.std / truth / copies;
      covered[t] += te.ci_low <= truth && truth <= te.ci_high;
    }
  }
  for (std::size_t t = 0; t < 3; ++t) {
    const double oe = std::sqrt(rms_oe[t]), ee = std::sqrt(rms_ee[t]);
    std::printf("term %zu: output error rms %.3g (mean std %.3g, coverage %d/%d), equation error "
                "rms %.3g\n",
                t, oe, mean_sd[t], covered[t], copies, ee);
    EXPECT_GT(oe / mean_sd[t], 1.0 / 1.4) << t;
    EXPECT_LT(oe / mean_sd[t], 1.4) << t;
    EXPECT_GE(covered[t], 34) << t;
    EXPECT_LT(oe, ee) << t;
  }
}

TEST(OutputError, TablesWithoutNoiseAreRefused) {
  const Study s;
  auto tests = s.noisy(0.01, 7);
  tests[2].fundamental_only = true;
  tests[2].source = "table.csv:4";
  try {
    (void)identify::output_error(s.sub, s.truth, tests, {.harmonics = {1}});
    ADD_FAILURE() << "a table was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "table.csv:4: output error needs the record's noise (a stepped-sine "
                           "table's is unknown)");
  }
}

} // namespace
} // namespace jointid

namespace jointid {
namespace {

TEST(OutputError, AHarmonicBalanceThatFailsAtTheStartIsAStatusNamingTheTest) {
  // One Newton iteration and one load step cannot solve the hardening cubic's harmonic balance
  // at the equation-error estimate: a numerical outcome, the status not_converging naming the
  // first test, with the harmonic balance's reason and no estimates.
  const Study s;
  const auto tests = s.noisy(1e-6, 1);
  const identify::FitResult start = identify::fit(s.sub, s.truth, tests, equation_error);
  ASSERT_TRUE(start.status.ok()) << start.status.reason;
  identify::OutputErrorOptions o;
  o.balance.max_iterations = 1;
  o.balance.continuation_steps = 1;
  const std::vector<int> equations{s.sub.dofs().equation({7, fem::Dof::uy})};
  const frf::ModalSynthesis H = s.sub.synthesis(equations, 200.0);
  const identify::FitResult r = identify::output_error(H, s.sub.dofs(), s.truth, tests, start, o);
  EXPECT_EQ(r.status.code, fem::Status::Code::not_converging);
  EXPECT_EQ(r.status.reason.rfind(tests[0].source +
                                      ": output error: the harmonic balance does not converge at "
                                      "the equation-error estimate: no convergence: relative "
                                      "residual ",
                                  0),
            0u)
      << r.status.reason;
  EXPECT_TRUE(r.joints.empty());
  // A start whose status is not ok is passed up as it is.
  identify::FitResult failed;
  failed.status = fem::Status::failure(fem::Status::Code::not_separable, "k and k3 together");
  const identify::FitResult passed =
      identify::output_error(H, s.sub.dofs(), s.truth, tests, failed, o);
  EXPECT_EQ(passed.status.code, fem::Status::Code::not_separable);
  EXPECT_EQ(passed.status.reason, "k and k3 together");
}

} // namespace
} // namespace jointid
