// The selection rule on inputs made by hand: the information criterion against hand-computed
// values in both its forms, and each admissibility rule rejecting a named candidate that every
// other rule admits, with the reason it gives; cross-validation's folds; a coefficient that varies
// per test, admitted only when its values disagree.
#include "discover/candidates.hpp"
#include "discover/selection.hpp"

#include "constructed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace jointid {
namespace {

using joints::Term;
using namespace discover::detail;
using discover::State;
using test::candidate;
using test::unknown;

Compared counted(int values, double measured2, bool noise_known) {
  Compared c;
  c.values = values;
  c.measured2 = measured2;
  c.noise_known = noise_known;
  return c;
}

TEST(InformationCriterion, WithKnownNoiseIsChi2PlusPLnN) {
  // N = 20 values, χ² = 30.5, p = 3: 30.5 + 3 ln 20, ln 20 = 2.995732273553991.
  const double bic = information_criterion(counted(20, 10.0, true), {0.8, 30.5}, 3, true);
  EXPECT_NEAR(bic, 30.5 + 3.0 * 2.995732273553991, 1e-12);
  // One parameter more costs ln N.
  EXPECT_NEAR(information_criterion(counted(20, 10.0, true), {0.8, 30.5}, 4, true) - bic,
              2.995732273553991, 1e-12);
}

TEST(InformationCriterion, WithUnknownNoiseIsNLnSOverNPlusPLnN) {
  // N = 20, S = 0.8, p = 3: 20 ln(0.04) + 3 ln 20 = 20 (−3.2188758248682006) + 3 (2.9957…).
  const double bic = information_criterion(counted(20, 10.0, false), {0.8, unknown}, 3, true);
  EXPECT_NEAR(bic, 20.0 * -3.2188758248682006 + 3.0 * 2.995732273553991, 1e-11);
  // A perfect fit (S = 0) is bounded by 1e-300 of Σ|X_meas|², not −∞.
  EXPECT_NEAR(information_criterion(counted(20, 10.0, false), {0.0, unknown}, 3, true),
              20.0 * std::log(1e-299 / 20.0) + 3.0 * std::log(20.0), 1e-9);
}

TEST(InformationCriterion, OfAModelThatDidNotConvergeIsInfinite) {
  EXPECT_EQ(information_criterion(counted(20, 10.0, true), {0.8, 30.5}, 3, false),
            std::numeric_limits<double>::infinity());
}

TEST(Score, AStateAgainstHandComputedGapChi2AndCriterion) {
  // One test, harmonics 0, 1, 2: measured 0.1, 1 + i, 0.2i with variances 0.01, 0.02, 0.04;
  // simulated 0, 1, 0. N = 1 + 2 + 2 = 5; errors 0.1, i, 0.2i: S = 0.01 + 1 + 0.04 = 1.05,
  // Σ|X_meas|² = 0.01 + 2 + 0.04 = 2.05; χ² = 1·0.01/0.01 + 2·1/0.02 + 2·0.04/0.04 = 103.
  const std::vector<std::complex<double>> X{0.1, {1.0, 1.0}, {0.0, 0.2}};
  State s = test::simulated({{0.0, 1.0, 0.0}}, 2);
  const Compared known =
      compared_values({test::measurement("a", 3.0, 10.0, X, {0.01, 0.02, 0.04})}, 2);
  score(s, known);
  EXPECT_NEAR(s.gap, std::sqrt(1.05 / 2.05), 1e-14);
  EXPECT_NEAR(s.chi2, 103.0, 1e-10);
  EXPECT_NEAR(s.criterion, 103.0 + 2.0 * std::log(5.0), 1e-10);
  // The noise unknown (a table): N ln(S/N) + p ln N.
  const Compared unknown_noise =
      compared_values({test::measurement("a", 3.0, 10.0, X, {unknown, unknown, unknown})}, 2);
  score(s, unknown_noise);
  EXPECT_TRUE(std::isnan(s.chi2));
  EXPECT_NEAR(s.criterion, 5.0 * std::log(1.05 / 5.0) + 2.0 * std::log(5.0), 1e-12);
}

// The model now: its gap and criterion.
State current(double gap, double criterion) {
  State now;
  now.gap = gap, now.criterion = criterion;
  return now;
}

// A state that converged with the candidate's joint and a fit that holds its estimate.
State with_estimate(Term term, double value, double ci_low, double ci_high, double c = 20.0) {
  State s;
  s.joints = {{"tip", 7, 0, fem::Dof::uy, {Term::k, Term::c, term}, {4800.0, c, value}, {}, {}}};
  s.joints[0].fixed.assign(3, false);
  identify::TermEstimate te;
  te.term = term, te.value = value, te.std = (ci_high - ci_low) / 3.92;
  te.ci_low = ci_low, te.ci_high = ci_high;
  s.fit.joints = {{"tip", {te}}};
  s.gap = 0.01, s.criterion = 50.0;
  return s;
}

TEST(Rule1, ACandidateWhoseReSimulationDidNotConvergeIsRejected) {
  discover::Candidate c = candidate(Term::k3, 0.0, 0.0);
  State s = with_estimate(Term::k3, 1.6e8, 1.5e8, 1.7e8);
  judge(c, s);
  EXPECT_EQ(c.rejected, "") << "a converged state with a clear interval is admissible";
  EXPECT_EQ(c.value, 1.6e8);
  s.converged = false; // and too many tests left out: not compared (score gives +∞)
  s.criterion = std::numeric_limits<double>::infinity();
  judge(c, s);
  EXPECT_EQ(c.rejected, "a re-simulation did not converge");
}

TEST(Rule1, NegativeDampingOrFrictionIsRejected) {
  discover::Candidate c = candidate(Term::c2, 0.0, 0.0);
  judge(c, with_estimate(Term::c2, 500.0, 400.0, 600.0, -2.0));
  EXPECT_EQ(c.rejected,
            "not physical: c of 'tip' came out negative (-2), a joint that gives energy");
  State s = with_estimate(Term::fc, -0.5, -0.7, -0.3);
  EXPECT_EQ(friction_problem(s.joints), "not physical: fc of 'tip' came out negative (-0.5)");
  std::vector<joints::Joint> clamped = s.joints;
  clamp_dissipative(clamped);
  EXPECT_EQ(clamped[0].values, (std::vector<double>{4800.0, 20.0, 0.0}));
}

TEST(Rule2, AnIntervalThatHoldsZeroRejectsATerm) {
  discover::Candidate c = candidate(Term::c3, 0.0, 0.0);
  judge(c, with_estimate(Term::c3, 1.0, -1.0, 3.0));
  EXPECT_EQ(c.rejected, "not significant: its 95 % interval [-1, 3] holds 0");
  judge(c, with_estimate(Term::c3, 1.0, unknown, unknown));
  EXPECT_EQ(c.rejected, "not determined: its 95 % interval could not be estimated");
  // The damping scale's "nothing" is 1.
  EXPECT_EQ(interval_problem(candidate(std::nullopt, 0.0, 0.0, 0.9, 1.2)),
            "not significant: its 95 % interval [0.9, 1.2] holds 1");
  EXPECT_EQ(interval_problem(candidate(std::nullopt, 0.0, 0.0, 1.1, 1.2)), "");
}

TEST(Rule3, ACandidateThatDoesNotLowerTheCriterionIsRejected) {
  // Explains 75 % of the squared gap, but its criterion (105) is above the model's (100).
  const State now = current(0.2, 100.0);
  std::vector<discover::Candidate> ranking{candidate(Term::c2, 0.1, 105.0)};
  screen(ranking, now, 0.05);
  EXPECT_NEAR(ranking[0].explained, 0.75, 1e-15);
  EXPECT_EQ(ranking[0].rejected, "not significant (information criterion 105 vs 100 now)");
  EXPECT_EQ(criterion_problem(candidate(Term::c2, 0.1, 100.0), 100.0),
            "not significant (information criterion 100 vs 100 now)")
      << "equal is not lower";
}

TEST(Rule4, ACandidateThatExplainsLessThanTheMinimumIsRejected) {
  // Its criterion falls (90 < 100), but the gap only from 0.2 to 0.198: 1 − 0.99² = 1.99 %.
  const State now = current(0.2, 100.0);
  std::vector<discover::Candidate> ranking{candidate(Term::fc, 0.198, 90.0)};
  screen(ranking, now, 0.05);
  EXPECT_NEAR(ranking[0].explained, 0.0199, 1e-14);
  EXPECT_EQ(ranking[0].rejected, "explains too little: 1.99 % of the gap (at least 5 % needed)");
  ranking[0].rejected.clear();
  screen(ranking, now, 0.01);
  EXPECT_EQ(ranking[0].rejected, "") << "1.99 % is enough when 1 % is asked";
}

TEST(Rule4, WithTheNoiseKnownAShareOfChi2IsEnoughWhereTheGapsIsNot) {
  // Tests at levels far apart: the largest decides the gap (it falls by 1.99 %), each its own
  // noise in χ² (it falls from 1000 to 600: 40 %). With χ² known the candidate is admitted; its
  // χ² on the same tests as the model's (chi2_now) is the one compared where set.
  State now = current(0.2, 100.0);
  now.chi2 = 1000.0;
  std::vector<discover::Candidate> ranking{candidate(Term::jenkins, 0.198, 90.0)};
  ranking[0].chi2 = 600.0;
  screen(ranking, now, 0.05);
  EXPECT_NEAR(ranking[0].chi2_explained, 0.4, 1e-14);
  EXPECT_EQ(ranking[0].rejected, "");
  // 3 % of χ² on the common tests (chi2_now 620 there): too little either way, both said.
  ranking[0].rejected.clear();
  ranking[0].chi2_now = 620.0;
  screen(ranking, now, 0.05);
  EXPECT_NEAR(ranking[0].chi2_explained, 1.0 - 600.0 / 620.0, 1e-14);
  EXPECT_EQ(ranking[0].rejected,
            "explains too little: 1.99 % of the gap and 3.23 % of χ² (at least 5 % needed)");
  // Without known noise (χ² NaN), the gap's share alone, as before.
  ranking[0].rejected.clear();
  ranking[0].chi2 = std::numeric_limits<double>::quiet_NaN(), ranking[0].chi2_now = -1.0;
  screen(ranking, now, 0.05);
  EXPECT_EQ(ranking[0].rejected, "explains too little: 1.99 % of the gap (at least 5 % needed)");
}

TEST(Rule5, ACandidateThatPredictsHeldOutTestsWorseIsRejectedAndTheNextChosen) {
  // k3 is first by the criterion, but its cross-validated gap (0.3) is above the model's (0.2);
  // c2 predicts better (0.1) and is chosen. The model's cross-validated gap is computed once.
  std::vector<discover::Candidate> ranking{candidate(Term::c2, 0.05, 80.0),
                                           candidate(Term::k3, 0.04, 70.0)};
  int model_cv = 0;
  const std::vector<double> cv{0.1, 0.3};
  const Choice choice = choose(
      ranking, {1, 0},
      [&](std::size_t) {
        return ++model_cv, CrossValidation{0.2, {}};
      },
      [&](std::size_t i) {
        return CrossValidation{cv[i], {}};
      });
  EXPECT_EQ(ranking[1].name(), "k3 at 'tip'");
  EXPECT_EQ(ranking[1].rejected,
            "does not predict held-out tests better (cross-validated gap 0.3 vs 0.2 now)");
  ASSERT_TRUE(choice.chosen.has_value());
  EXPECT_EQ(*choice.chosen, 0u);
  EXPECT_EQ(ranking[0].cv_gap, 0.1);
  EXPECT_EQ(choice.cv_now, 0.2);
  EXPECT_EQ(model_cv, 2) << "asked for each candidate walked to (the caller keeps the values)";
  EXPECT_EQ(cross_validation_problem({0.2, {}}, {0.2, {}}),
            "does not predict held-out tests better (cross-validated gap 0.2 vs 0.2 now)");
}

TEST(Rule5, WhenItCannotBeAppliedNothingIsAddedAndItSaysWhy) {
  // Not computable on either side (fewer than four tests, a fold that cannot be identified):
  // the addition is not checked, so it is not made, with the reason.
  EXPECT_EQ(cross_validation_problem({0.3, {}}, {-1.0, "3 tests, at least 4 needed"}),
            "cannot be checked against held-out tests: 3 tests, at least 4 needed");
  EXPECT_EQ(
      cross_validation_problem({-1.0, "without a.csv the terms cannot be identified"}, {0.2, {}}),
      "cannot be checked against held-out tests: without a.csv the terms cannot be "
      "identified");
  std::vector<discover::Candidate> ranking{candidate(Term::k3, 0.04, 70.0)};
  int candidate_cv = 0;
  const Choice choice = choose(
      ranking, {0},
      [](std::size_t) {
        return CrossValidation{-1.0, "2 tests, at least 4 needed"};
      },
      [&](std::size_t) {
        return ++candidate_cv, CrossValidation{0.1, {}};
      });
  EXPECT_FALSE(choice.chosen.has_value());
  EXPECT_EQ(ranking[0].rejected, "cannot be checked against held-out tests: 2 tests, at least 4 "
                                 "needed");
  EXPECT_TRUE(only_unchecked(ranking[0]));
  EXPECT_EQ(candidate_cv, 0) << "the candidate's is not computed when the model's cannot be";
  EXPECT_FALSE(choice.cv_now.has_value());
}

TEST(Selection, EachRuleRejectsItsCandidateAndTheAdmissibleOneIsAdded) {
  // Six candidates from a model with gap 0.2 and criterion 100, each failing one rule only, the
  // damping scale failing none. Ranked by the criterion, the damping scale comes last.
  const State now = current(0.2, 100.0);
  std::vector<discover::Candidate> ranking{
      candidate(Term::k2, 0.05, 60.0),                // rule 1: did not converge
      candidate(Term::c3, 0.05, 62.0),                // rule 2: interval holds 0
      candidate(Term::c2, 0.05, 101.0),               // rule 3: criterion above 100
      candidate(Term::fc, 0.198, 61.0),               // rule 4: explains 1.99 %
      candidate(Term::k3, 0.05, 63.0),                // rule 5: predicts worse
      candidate(std::nullopt, 0.06, 64.0, 1.5, 2.5)}; // admissible
  State unconverged = with_estimate(Term::k2, 1e4, 0.5e4, 1.5e4);
  unconverged.converged = false;
  unconverged.criterion = std::numeric_limits<double>::infinity();
  judge(ranking[0], unconverged);
  ranking[0].criterion = 60.0, ranking[0].gap = 0.05; // (as an unconverged state would not have)
  judge(ranking[1], with_estimate(Term::c3, 1.0, -1.0, 3.0));
  ranking[1].criterion = 62.0, ranking[1].gap = 0.05;
  const std::vector<std::size_t> order = screen(ranking, now, 0.05);
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 3, 1, 4, 5, 2}));
  const Choice choice = choose(
      ranking, order,
      [](std::size_t) {
        return CrossValidation{0.2, {}};
      },
      [](std::size_t i) {
        return CrossValidation{i == 4 ? 0.25 : 0.1, {}};
      });
  EXPECT_EQ(ranking[0].rejected, "a re-simulation did not converge");
  EXPECT_EQ(ranking[1].rejected, "not significant: its 95 % interval [-1, 3] holds 0");
  EXPECT_EQ(ranking[2].rejected, "not significant (information criterion 101 vs 100 now)");
  EXPECT_EQ(ranking[3].rejected, "explains too little: 1.99 % of the gap (at least 5 % needed)");
  EXPECT_EQ(ranking[4].rejected,
            "does not predict held-out tests better (cross-validated gap 0.25 vs 0.2 now)");
  ASSERT_TRUE(choice.chosen.has_value());
  EXPECT_EQ(ranking[*choice.chosen].name(), "substructure damping");
  EXPECT_FALSE(choice.outside.has_value());
}

TEST(Selection, FinalistsAreTheBestSimulatedAdditions) {
  std::vector<discover::Candidate> ranking{
      candidate(Term::k2, 0.1, 50.0), candidate(Term::k3, 0.1, 40.0),
      candidate(Term::c2, 0.1, 45.0), candidate(Term::c3, 0.1, 30.0),
      candidate(Term::fc, 0.1, std::numeric_limits<double>::infinity())};
  ranking[2].varies = discover::Variation{};
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{3, 1}));
  EXPECT_EQ(finalists(ranking, 5), (std::vector<std::size_t>{3, 1, 0}));
  // One that left a few tests out (not every re-simulation converged) is still compared, on
  // the others, and may be refined; one that could not be compared (+∞, fc here) may not.
  ranking[3].converged = false;
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{3, 1}));
}

TEST(Selection, TheBestParametricCandidateIsAFinalistBesidesTheCount) {
  // Its start (a describing-function fit) screens it; output error gives its parameters: the
  // best parametric candidate is refined besides the count where it ranks among count + 1.
  std::vector<discover::Candidate> ranking{
      test::candidate(Term::k3, 0.1, 10.0), test::candidate(Term::iwan, 0.2, 30.0),
      test::candidate(Term::c2, 0.1, 20.0), test::candidate(Term::jenkins, 0.2, 25.0),
      test::candidate(Term::gap, 0.3, 40.0)};
  EXPECT_EQ(finalists(ranking, 1), (std::vector<std::size_t>{0})); // jenkins third: not refined
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{0, 2, 3}));
  ranking[3].criterion = 5.0; // jenkins first: refined besides the count
  EXPECT_EQ(finalists(ranking, 1), (std::vector<std::size_t>{3, 0}));
  EXPECT_EQ(finalists(ranking, 0), (std::vector<std::size_t>{3}));
}

TEST(Selection, TheCoefficientTermWithTheSmallestEquationErrorIsAFinalistToo) {
  // A cubic stiffness whose equation error explains the joint's force best can re-simulate
  // worse than the start when a second effect is missing too (a ground-vibration test's k3
  // beside a hidden c2: its start's damping is the equation error's, 0.89 against 0.52 with
  // no term); output error would take it below. It is refined besides the count.
  std::vector<discover::Candidate> ranking{
      test::candidate(Term::c2, 0.50, 10.0), test::candidate(Term::c3, 0.49, 11.0),
      test::candidate(Term::k2, 0.66, 30.0), test::candidate(Term::k3, 0.89, 90.0)};
  const std::vector<double> residuals{0.110, 0.117, 0.140, 0.056};
  for (std::size_t i = 0; i < ranking.size(); ++i)
    ranking[i].equation_residual = residuals[i];
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{0, 1, 3}));
  // Already a finalist: counted once.
  ranking[3].criterion = 5.0;
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{3, 0}));
  // One that could not be compared (+∞) is not refined, whatever its equation error; nor is a
  // value per test (not an addition).
  ranking[3].criterion = std::numeric_limits<double>::infinity();
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{0, 1}));
  ranking[3].criterion = 90.0;
  ranking[3].varies = discover::Variation{};
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{0, 1}));
  // Without equation residuals (parametric terms, the damping scale): the count alone.
  for (auto& c : ranking)
    c.equation_residual = std::numeric_limits<double>::quiet_NaN();
  ranking[3].varies.reset();
  EXPECT_EQ(finalists(ranking, 2), (std::vector<std::size_t>{0, 1}));
}

TEST(CrossValidation, LeavesOneTestOutUpTo30TestsElseUsesFolds) {
  EXPECT_TRUE(held_out(3, 10).empty());
  EXPECT_EQ(held_out(4, 10), (std::vector<std::vector<int>>{{0}, {1}, {2}, {3}}));
  EXPECT_EQ(held_out(30, 10).size(), 30u);
  const auto folds = held_out(35, 10);
  ASSERT_EQ(folds.size(), 10u);
  EXPECT_EQ(folds[0], (std::vector<int>{0, 10, 20, 30}));
  EXPECT_EQ(folds[9], (std::vector<int>{9, 19, 29}));
}

std::string fmt_test_name(std::size_t i) {
  std::string name = "t";
  name += std::to_string(i);
  return name;
}

// Six tests at growing amplitude; the coefficient's value in each, 0.1 its standard deviation.
discover::Variation per_test(const std::vector<double>& values) {
  discover::Variation v;
  v.value = values;
  v.std.assign(values.size(), 0.1);
  for (std::size_t i = 0; i < values.size(); ++i) {
    v.tests.push_back(fmt_test_name(i));
    v.amplitude.push_back(1e-3 * static_cast<double>(i + 1));
    v.frequency_hz.push_back(3.2);
  }
  return v;
}

joints::Joint friction_joint() {
  return {"tip",
          7,
          0,
          fem::Dof::uy,
          {Term::k, Term::c, Term::fc},
          {4800.0, 20.0, 2.0},
          {true, true, false},
          {}};
}

TEST(VariesPerTest, ValuesThatAgreeBetweenTheTestsAreRejected) {
  // Values 1, 1.1, 0.9, 1, 1.05, 0.95 (σ 0.1): mean 1, χ² = 0 + 1 + 1 + 0 + 0.25 + 0.25 = 2.5
  // for 5 degrees of freedom, below 5 + 3 √10.
  discover::Candidate c = candidate(Term::fc, 0.0, 0.0);
  State s = test::simulated({});
  s.gap = 0.01, s.criterion = 40.0;
  judge_variation(c, per_test({1.0, 1.1, 0.9, 1.0, 1.05, 0.95}), s, friction_joint());
  EXPECT_NEAR(c.value, 1.0, 1e-14);
  EXPECT_NEAR(c.std, 0.1 / std::sqrt(6.0), 1e-15);
  ASSERT_TRUE(c.varies.has_value());
  EXPECT_NEAR(c.varies->chi2, 2.5, 1e-12);
  EXPECT_EQ(c.varies->dof, 5);
  EXPECT_EQ(c.rejected, "its values agree between the tests (χ² 2.5 for 5 degrees of freedom)");
  EXPECT_EQ(c.name(), "fc at 'tip', a value per test");
}

TEST(VariesPerTest, ValuesThatFallWithTheAmplitudeAreAdmittedAndChosenAsOutside) {
  // Values 3, 2.7, 2.4, 2.1, 1.9, 1.5 (σ 0.1), falling with the amplitude: mean 2.2667,
  // χ² = Σ (v − mean)² / 0.01 ≈ 149, far above 5 + 3 √10.
  const std::vector<double> values{3.0, 2.7, 2.4, 2.1, 1.9, 1.5};
  const double mean = std::accumulate(values.begin(), values.end(), 0.0) / 6.0;
  double chi2 = 0.0;
  for (double v : values)
    chi2 += (v - mean) * (v - mean) / 0.01;
  discover::Candidate c = candidate(Term::fc, 0.0, 0.0);
  State s = test::simulated({});
  s.gap = 0.001, s.criterion = 40.0;
  judge_variation(c, per_test(values), s, friction_joint());
  EXPECT_EQ(c.rejected, "");
  EXPECT_NEAR(c.value, mean, 1e-14);
  EXPECT_NEAR(c.varies->chi2, chi2, 1e-9);
  EXPECT_NEAR(c.varies->amplitude_correlation, -1.0, 1e-15);
  EXPECT_NE(c.varies->description.find("fc at 'tip' is not one number: identified from each "
                                       "test alone it goes from 3 N at the smallest amplitude "
                                       "(0.001 m) to 1.5 N at the largest (0.006 m)"),
            std::string::npos)
      << c.varies->description;
  EXPECT_NE(c.varies->description.find("it falls with the deformation amplitude (rank "
                                       "correlation -1.00)"),
            std::string::npos)
      << c.varies->description;
  // The best by the criterion among the admissible: the loop stops there, adding nothing.
  const State now = current(0.01, 100.0);
  std::vector<discover::Candidate> ranking{candidate(Term::k3, 0.005, 60.0), c};
  const Choice choice = choose(
      ranking, screen(ranking, now, 0.05),
      [](std::size_t) {
        return CrossValidation{0.2, {}};
      },
      [](std::size_t) {
        return CrossValidation{0.1, {}};
      });
  EXPECT_FALSE(choice.chosen.has_value());
  ASSERT_TRUE(choice.outside.has_value());
  EXPECT_EQ(*choice.outside, 1u);
  EXPECT_FALSE(choice.cv_now.has_value()) << "no cross-validation for what is not added";
}

TEST(VariesPerTest, RankCorrelationAgainstHandComputedValues) {
  // Spearman: 1 − 6 Σd² / (n (n² − 1)); ranks 1 2 3 4 against 1 3 2 4: Σd² = 2, 1 − 12/60.
  EXPECT_NEAR(rank_correlation({1.0, 2.0, 3.0, 4.0}, {10.0, 30.0, 20.0, 40.0}), 0.8, 1e-15);
  EXPECT_NEAR(rank_correlation({1.0, 2.0, 3.0}, {3.0, 2.0, 1.0}), -1.0, 1e-15);
  // Ties take their mean rank: ranks 1.5 1.5 3 against 1 2 3 → Pearson of the ranks, √3/2.
  EXPECT_NEAR(rank_correlation({5.0, 5.0, 7.0}, {1.0, 2.0, 3.0}), std::sqrt(3.0) / 2.0, 1e-15);
  EXPECT_EQ(rank_correlation({1.0, 1.0, 1.0}, {1.0, 2.0, 3.0}), 0.0);
}

TEST(VariesPerTest, ATurnIsAnInteriorExtremumBeyondTheNoiseOnBothSides) {
  const std::vector<double> x{1.0, 2.0, 3.0, 4.0}, one(4, 1.0);
  EXPECT_EQ(turning_test(x, {0.0, -10.0, 0.0, 1.0}, one), 1);     // falls 7.1 σ, rises 7.1 σ
  EXPECT_EQ(turning_test(x, {0.0, 10.0, 9.0, 0.0}, one), 1);      // a maximum: the larger turn
  EXPECT_EQ(turning_test(x, {0.0, -4.0, 0.0, 0.5}, one), -1);     // 2.8 σ: within the noise
  EXPECT_EQ(turning_test(x, {0.0, -5.0, -10.0, -20.0}, one), -1); // monotonic
  // The order is x's, not the list's: the same values listed in another order.
  EXPECT_EQ(turning_test({3.0, 1.0, 2.0, 4.0}, {0.0, 0.0, -10.0, 1.0}, one), 2);
  EXPECT_TRUE(monotonic_within_noise(x, {0.0, 5.0, 4.0, 20.0}, one)); // the dip: 0.7 σ
  EXPECT_FALSE(monotonic_within_noise(x, {0.0, 10.0, 4.0, 20.0}, one));
  EXPECT_FALSE(monotonic_within_noise({1.0, 1.0, 2.0, 3.0}, {0.0, 10.0, 11.0, 12.0}, one))
      << "two tests at one x, 7 σ apart: x does not explain them";
  EXPECT_TRUE(monotonic_within_noise({1.0, 1.0, 2.0, 3.0}, {0.0, 1.0, 11.0, 12.0}, one));
}

// The frame example's mount (examples/frame_payload, a run of 2026-12-06): k from each of six
// multisine tests alone, against the fitted substructure, which holds the joint stuck. It falls
// as the friction slips and rises where the clearance closes; the tests' equivalent frequency
// also grows with k but not monotonically (k at 20.94 Hz: -1411 and -5083, 3.7 σ apart in the
// wrong direction), so the turn with the amplitude is what is said.
TEST(VariesPerTest, AStiffnessThatSoftensThenStiffensIsDescribedByItsTurn) {
  discover::Variation v;
  v.value = {45.1, -1615.0, -1411.0, -5083.0, -16753.0, 40093.0};
  v.std = {2822.0, 1244.0, 765.0, 629.0, 664.0, 1018.0};
  v.amplitude = {5.908e-5, 7.166e-5, 7.672e-5, 8.446e-5, 1.263e-4, 5.284e-4};
  v.frequency_hz = {21.208, 21.023, 20.936, 20.937, 20.848, 24.305};
  for (std::size_t i = 0; i < v.value.size(); ++i)
    v.tests.push_back(fmt_test_name(i));
  discover::Candidate c = candidate(Term::k, 0.0, 0.0);
  c.joint = "mount";
  joints::Joint mount = friction_joint();
  mount.name = "mount";
  State s = test::simulated({});
  s.gap = 0.6, s.criterion = 40.0;
  judge_variation(c, v, s, mount);
  ASSERT_TRUE(c.varies.has_value());
  const std::string& d = c.varies->description;
  EXPECT_NE(d.find("k at 'mount' is not one number: identified from each test alone it falls "
                   "from 45.1 N/m at 5.908e-05 m (the smallest deformation amplitude) to "
                   "-1.675e+04 N/m at 0.0001263 m, then rises to 4.009e+04 N/m at 0.0005284 m "
                   "(the largest), beyond the noise on both sides"),
            std::string::npos)
      << d;
  EXPECT_NE(d.find("the library's jenkins and gap together describe it"), std::string::npos) << d;
  EXPECT_EQ(d.find("frequency"), std::string::npos) << d;
  // The same values where the frequency orders them (a stiffness that grows with frequency,
  // the amplitudes scrambled by a resonance): the monotonic law with the frequency is said.
  v.frequency_hz = {12.0, 11.0, 11.5, 10.5, 10.0, 13.0};
  discover::Candidate f = candidate(Term::k, 0.0, 0.0);
  judge_variation(f, v, s, mount);
  EXPECT_NE(f.varies->description.find("it grows with the frequency (rank correlation +1.00)"),
            std::string::npos)
      << f.varies->description;
}

// A pair of parametric terms is tried only where the joint's stiffness turns: it falls to an
// interior least point and rises after it, each by more than a tenth of the largest |Z|.
TEST(Pair, TriedWhereTheStiffnessFallsAndThenRises) {
  const auto points = [](std::vector<double> re) {
    std::vector<identify::EquivalentStiffness> out;
    for (std::size_t i = 0; i < re.size(); ++i) // listed out of the amplitudes' order
      out.push_back({1e-4 * static_cast<double>(re.size() - i), 100.0, {re[i], 0.0}});
    return out;
  };
  // In amplitude order (the list reversed): 0, -5, -17, 40 (k 1e3): falls 17, rises 57.
  EXPECT_TRUE(softens_then_stiffens(points({40.0, -17.0, -5.0, 0.0})));
  EXPECT_FALSE(softens_then_stiffens(points({-40.0, -17.0, -5.0, 0.0}))) << "slip only";
  EXPECT_FALSE(softens_then_stiffens(points({40.0, 17.0, 5.0, 0.0}))) << "contact only";
  EXPECT_FALSE(softens_then_stiffens(points({40.0, -3.0, 0.0, 0.0})))
      << "a fall of 3 where the largest |Z| is 40: within a tenth of it";
  EXPECT_FALSE(softens_then_stiffens(points({-5.0, 0.0})));
}

} // namespace
} // namespace jointid
