// Output-error refinement on a substructure whose response is known in closed form: from wrong
// values it reaches the true joint, with intervals that hold it.
#include "discover/refine.hpp"

#include "one_mode.hpp"

#include <gtest/gtest.h>

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

} // namespace
} // namespace jointid
