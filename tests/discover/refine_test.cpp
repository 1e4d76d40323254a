// Output-error refinement on a substructure whose response is known in closed form: from wrong
// values it reaches the true joint, with intervals that hold it.
#include "discover/refine.hpp"

#include "one_mode.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace jointid {
namespace {

using namespace discover::detail;

TEST(Refine, FromWrongValuesReachesTheTrueJoint) {
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  // Noise of 1e-4 of the response's size (its variance known), none in the data: the misfit at
  // the truth is 0, so the values reached are the truth to the search's own tolerance.
  const auto tests = m.tests({2.5, 2.8, 3.0, 3.2, 3.5, 4.0}, 10.0, 1e-4);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const Simulator& sim = problem.simulator(1.0);
  const discover::State start = problem.evaluate({m.joint(300.0, 3.0)}, sim);
  ASSERT_GT(start.gap, 0.05);
  const discover::State refined = refine(problem, start, sim);
  ASSERT_TRUE(refined.converged);
  EXPECT_NEAR(refined.joints[0].values[0], m.k, 1e-4 * m.k);
  EXPECT_NEAR(refined.joints[0].values[1], m.c, 1e-4 * m.c);
  EXPECT_LT(refined.gap, 1e-5);
  ASSERT_EQ(refined.fit.joints.size(), 1u);
  for (const auto& te : refined.fit.joints[0].terms) {
    const double truth = te.term == joints::Term::k ? m.k : m.c;
    EXPECT_LE(te.ci_low, truth) << joints::term_name(te.term);
    EXPECT_GE(te.ci_high, truth) << joints::term_name(te.term);
    EXPECT_GT(te.std, 0.0);
  }
  // Nothing to identify: the start itself.
  const discover::State held = problem.evaluate({m.joint(300.0, 3.0, true)}, sim);
  EXPECT_EQ(refine(problem, held, sim).joints[0].values[0], 300.0);
}

TEST(Refine, NegativeDampingIsBroughtBackFirst) {
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({2.5, 3.0, 3.5, 4.0}, 10.0, 1e-4);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const Simulator& sim = problem.simulator(1.0);
  const discover::State refined =
      refine(problem, problem.evaluate({m.joint(380.0, -1.0)}, sim), sim);
  EXPECT_GE(refined.joints[0].values[1], 0.0);
  EXPECT_NEAR(refined.joints[0].values[0], m.k, 1e-3 * m.k);
  EXPECT_NEAR(refined.joints[0].values[1], m.c, 1e-3 * m.c);
}

TEST(Refine, AnAddedTermsSecondStartIsTheModelNowWithTheTermAtZero) {
  // A candidate that adds k3, its equation-error values off (k 300, c 3, k3 5e6): its second
  // start is the model now's k and c with k3 at 0, from which output error cannot end worse than
  // the model now. There is none for a parametric term, a refit, or a candidate that differs
  // from the model now in more than the term.
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  const auto tests = m.tests({2.5, 2.8, 3.0, 3.2, 3.5, 4.0}, 10.0, 1e-3);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const Simulator& sim = problem.simulator(1.0);
  const discover::State now = problem.evaluate({m.joint(0.9 * m.k, 1.2 * m.c)}, sim);
  joints::Joint with_k3 = m.joint(300.0, 3.0);
  with_k3.terms.push_back(joints::Term::k3);
  with_k3.values.push_back(5e6);
  with_k3.fixed.push_back(false);
  const discover::State candidate = problem.evaluate({with_k3}, sim);
  discover::Candidate c;
  c.joint = "tip";
  c.term = joints::Term::k3;
  const auto start = nested_start(c, candidate, now);
  ASSERT_TRUE(start.has_value());
  ASSERT_EQ(start->size(), 1u);
  EXPECT_EQ((*start)[0].terms, with_k3.terms);
  EXPECT_EQ((*start)[0].values, (std::vector<double>{0.9 * m.k, 1.2 * m.c, 0.0}));
  const discover::State refined = refine(problem, problem.evaluate(*start, sim), sim);
  ASSERT_TRUE(refined.converged);
  EXPECT_LE(refined.gap, now.gap);
  EXPECT_LT(refined.gap, 0.1 * now.gap); // the search moved: k and c towards the truth

  discover::Candidate refit = c;
  refit.refit = true;
  EXPECT_FALSE(nested_start(refit, candidate, now).has_value());
  discover::Candidate iwan = c;
  iwan.term = joints::Term::iwan;
  EXPECT_FALSE(nested_start(iwan, candidate, now).has_value());
  joints::Joint two = with_k3;
  two.terms.push_back(joints::Term::c3);
  two.values.push_back(1.0);
  two.fixed.push_back(false);
  EXPECT_FALSE(nested_start(c, problem.evaluate({two}, sim), now).has_value());
}

TEST(Refine, HeldOutTestsStayOutOfTheSearch) {
  // Six exact tests and a seventh measured as if k were 1.5 k: refined with the seventh held out
  // (a cross-validation fold's training set), the values reached are the truth to the search's
  // tolerance; with it in, they are pulled off the truth. The iterations are bounded by the scope.
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  auto tests = m.tests({2.5, 2.8, 3.0, 3.2, 3.5, 4.0}, 10.0, 1e-4);
  const std::complex<double> F1(0.0, -10.0);
  const double f = 3.1, sd = 1e-4 * std::abs(m.receptance(f, m.k, m.c) * F1);
  tests.push_back(test::measurement("corrupted", f, F1, {0.0, m.receptance(f, 1.5 * m.k, m.c) * F1},
                                    {sd * sd, sd * sd}, false));
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const Simulator& sim = problem.simulator(1.0);
  const discover::State start = problem.evaluate({m.joint(300.0, 3.0)}, sim);
  const discover::State held =
      refine(problem, start, sim, {.held_out = {6}, .iterations = 12, .intervals = false});
  EXPECT_NEAR(held.joints[0].values[0], m.k, 1e-4 * m.k);
  EXPECT_NEAR(held.joints[0].values[1], m.c, 1e-4 * m.c);
  EXPECT_TRUE(held.fit.joints.empty()); // no intervals asked: no output-error fit
  const discover::State all = refine(problem, start, sim);
  EXPECT_GT(std::abs(all.joints[0].values[0] - m.k), 1e-2 * m.k);
  // One iteration from the start does not reach the truth.
  const discover::State one = refine(problem, start, sim, {.held_out = {6}, .iterations = 1});
  EXPECT_GT(std::abs(one.joints[0].values[0] - m.k), 1e-3 * m.k);
}

TEST(Refine, AFirstStageOnASpreadEndsWhereTheSearchOnAllTestsDoes) {
  // 120 tests, each measured with 1 % noise (a fixed sequence): the minimum of the misfit is
  // not the truth. Refined in one stage on all of them, and with a first stage on a spread of
  // 12 that skips the others: both end at the same minimum of all the tests, to 1e-3 of the
  // values' standard deviation (the searches stop at a gain of 1e-5 of the misfit, which leaves
  // a few 1e-3 σ). A first stage alone would end at the spread's minimum, a sizeable share of a
  // σ away; the test asserts that it does (so that agreeing says something). The spread is half
  // the tests of largest response and an even spread of the rest (Problem::spread).
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  std::vector<identify::Measurement> tests;
  for (int i = 0; i < 120; ++i) {
    const double f = 2.5 + 1.5 * i / 119.0, sd = 1e-2 * std::abs(m.receptance(f, m.k, m.c) * 10.0);
    const std::complex<double> F1(0.0, -10.0),
        noise(sd * std::sin(12.9898 * i), sd * std::cos(78.233 * i));
    tests.push_back(test::measurement(std::to_string(i), f, F1,
                                      {0.0, m.receptance(f, m.k, m.c) * F1 + noise},
                                      {sd * sd, sd * sd}, false));
  }
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, test::fundamental_only());
  const Simulator& sim = problem.simulator(1.0);
  const discover::State start = problem.evaluate({m.joint(300.0, 3.0)}, sim);
  RefineScope all_tests, spread_first;
  all_tests.spread = 0, spread_first.spread = 12;
  const discover::State one = refine(problem, start, sim, all_tests);
  const discover::State two = refine(problem, start, sim, spread_first);
  ASSERT_EQ(one.fit.joints.size(), 1u);
  ASSERT_EQ(two.fit.joints.size(), 1u);
  std::vector<int> skipped;
  const std::vector<int> spread = problem.spread(12);
  ASSERT_EQ(spread.size(), 12u);
  EXPECT_TRUE(std::is_sorted(spread.begin(), spread.end()));
  EXPECT_EQ(std::adjacent_find(spread.begin(), spread.end()), spread.end());
  // Half of it the tests of largest measured response (here the six nearest the resonance),
  // the rest an even spread of the others, from the first to the last.
  std::vector<int> by_size(120);
  for (int i = 0; i < 120; ++i)
    by_size[static_cast<std::size_t>(i)] = i;
  std::sort(by_size.begin(), by_size.end(), [&](int a, int b) {
    return std::abs(tests[static_cast<std::size_t>(a)].X(1, 0)) >
           std::abs(tests[static_cast<std::size_t>(b)].X(1, 0));
  });
  for (std::size_t k = 0; k < 6; ++k)
    EXPECT_TRUE(std::binary_search(spread.begin(), spread.end(), by_size[k])) << by_size[k];
  EXPECT_EQ(spread.front(), 0);
  EXPECT_EQ(spread.back(), 119);
  for (int i = 0; i < 120; ++i)
    if (!std::binary_search(spread.begin(), spread.end(), i)) skipped.push_back(i);
  RefineScope first = all_tests;
  first.held_out = skipped, first.intervals = false;
  const discover::State on_spread = refine(problem, start, sim, first);
  for (std::size_t t = 0; t < 2; ++t) {
    const double sd = one.fit.joints[0].terms[t].std;
    ASSERT_GT(sd, 0.0);
    EXPECT_NEAR(two.joints[0].values[t], one.joints[0].values[t], 1e-3 * sd) << t;
    EXPECT_NEAR(two.fit.joints[0].terms[t].std, sd, 1e-3 * sd) << t;
    EXPECT_GT(std::abs(on_spread.joints[0].values[t] - one.joints[0].values[t]), 0.05 * sd) << t;
  }
  EXPECT_NEAR(two.gap, one.gap, 1e-6 * one.gap);
  // The first stage alone (a screened path's refinement): the spread's minimum, every test
  // simulated there and the intervals of all of them, near the full refinement's.
  RefineScope screened = spread_first;
  screened.spread_only = true;
  const discover::State alone = refine(problem, start, sim, screened);
  EXPECT_TRUE(alone.failed.empty());
  EXPECT_EQ(alone.X.size(), tests.size());
  EXPECT_TRUE(std::isfinite(alone.gap));
  EXPECT_GE(alone.chi2, one.chi2 * (1.0 - 1e-9)); // the minimum over all tests is the full one
  for (std::size_t t = 0; t < 2; ++t) {
    const double sd = one.fit.joints[0].terms[t].std;
    EXPECT_NEAR(alone.joints[0].values[t], on_spread.joints[0].values[t], 1e-3 * sd) << t;
    EXPECT_NEAR(alone.fit.joints[0].terms[t].std, sd, 0.05 * sd) << t;
  }
  // A state that skips tests: those not simulated, the others as every test's state has them.
  const discover::State skipping = problem.evaluate(one.joints, sim, nullptr, skipped);
  EXPECT_TRUE(skipping.failed.empty());
  for (int i : {0, 1, 60}) {
    const bool skip = std::binary_search(skipped.begin(), skipped.end(), i);
    EXPECT_EQ(skipping.Y[static_cast<std::size_t>(i)].size() == 0, skip) << i;
    if (!skip) {
      EXPECT_EQ(skipping.X[static_cast<std::size_t>(i)], one.X[static_cast<std::size_t>(i)]);
    }
  }
}

} // namespace
} // namespace jointid
