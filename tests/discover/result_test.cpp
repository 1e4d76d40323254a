// What the result says in words and numbers besides the states: the comparison of each test's
// fundamental, a step's finding, the run's summary, and how candidates are named.
#include "discover/result.hpp"

#include "constructed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace jointid {
namespace {

using joints::Term;
using namespace discover::detail;

TEST(Result, ComparisonsOfTheFundamentalAgainstHandComputedErrors) {
  // Measured 1 + i (|X| √2) with a second harmonic 0.1 and a third 0.2i; simulated 2i, no
  // harmonics: amplitude error 2/√2 − 1, phase arg(2i / (1 + i)) = 45°.
  const auto m = test::measurement("a", 3.0, 10.0, {0.0, {1.0, 1.0}, 0.1, {0.0, 0.2}},
                                   {1.0, 1.0, 1.0, 1.0}, false);
  const discover::State s = test::simulated({{0.0, {0.0, 2.0}, 0.0, 0.0}});
  const std::vector<discover::Comparison> c = comparisons({m}, 3, s);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].test, "a");
  EXPECT_EQ(c[0].channel, "x@7:uy");
  EXPECT_EQ(c[0].force, 10.0);
  EXPECT_NEAR(c[0].amplitude_error, std::sqrt(2.0) - 1.0, 1e-15);
  EXPECT_NEAR(c[0].phase_error_deg, 45.0, 1e-12);
  EXPECT_NEAR(c[0].harmonics_measured, std::sqrt(0.05) / std::sqrt(2.0), 1e-15);
  EXPECT_EQ(c[0].harmonics_simulated, 0.0);
}

TEST(Result, AStepsFindingAndTheSummaryInWords) {
  discover::Step step;
  step.added = test::candidate(Term::k3, 0.001, 10.0, 1.5e8, 1.7e8);
  step.added.explained = 0.99;
  step.gap_before = 0.1, step.gap_after = 0.01;
  EXPECT_EQ(finding(step), "Added k3 at 'tip' (cubic stiffness) = 1.6e+08 [1.5e+08, 1.7e+08]: the "
                           "gap fell from 0.1 to 0.01 (99 % of it explained).");
  discover::Result r;
  r.steps = {step};
  r.gap = {0.1, 0.01};
  r.simulation_gap = 0.0;
  r.at_noise_level = true;
  Compared c;
  c.noise_known = true, c.noise_gap = 0.009;
  EXPECT_EQ(summary(r, c), "Added k3 at 'tip': the gap shrank from 0.1 to 0.01 (10× smaller); the "
                           "noise level is 0.009, which it has reached.");
  r.steps.clear();
  r.gap = {0.1};
  c.noise_known = false;
  EXPECT_EQ(summary(r, c), "Nothing was added: the gap stays at 0.1; the noise level is unknown "
                           "(stepped-sine tables).");
}

TEST(Result, AZeroWidthIntervalIsFlaggedNeverPrintedAsAResult) {
  discover::Step step;
  step.added = test::candidate(Term::k3, 0.001, 10.0, 1.6e8, 1.6e8); // zero width
  step.added.value = 1.6e8;
  step.added.explained = 0.99;
  step.gap_before = 0.1, step.gap_after = 0.01;
  EXPECT_FALSE(step.added.determined());
  EXPECT_EQ(finding(step), "Added k3 at 'tip' (cubic stiffness) = 1.6e+08 (its interval "
                           "undetermined: the value is not a result): the gap fell from 0.1 to "
                           "0.01 (99 % of it explained).");
  step.added.ci_high = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(step.added.determined());
  step.added.ci_high = 1.7e8, step.added.std = 0.1e8 / 1.96;
  EXPECT_TRUE(step.added.determined());
}

TEST(Result, CandidatesAreNamedByTheirTermAndJoint) {
  discover::Candidate c = test::candidate(Term::fc, 0.0, 0.0);
  EXPECT_EQ(c.name(), "fc at 'tip'");
  EXPECT_FALSE(c.linear());
  c.varies = discover::Variation{};
  EXPECT_EQ(c.name(), "fc at 'tip', a value per test");
  EXPECT_EQ(c.effect(), "Coulomb friction that changes between tests (no term of the library)");
  const discover::Candidate damping = test::candidate(std::nullopt, 0.0, 0.0);
  EXPECT_EQ(damping.name(), "substructure damping");
  EXPECT_TRUE(damping.linear());
  discover::Candidate refit;
  refit.refit = true;
  EXPECT_EQ(refit.name(), "refit of the starting values");
  EXPECT_TRUE(refit.linear());
  EXPECT_TRUE(test::candidate(Term::c, 0.0, 0.0).linear());
}

} // namespace
} // namespace jointid
