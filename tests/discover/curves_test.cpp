// The report's response curves on a substructure whose response is known in closed form, and the
// grouping of the tests they sweep through.
#include "discover/curves.hpp"

#include "one_mode.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace jointid {
namespace {

using namespace discover::detail;

TEST(Curves, ClusterGroupsCloseValues) {
  // 10, 10.2 (within 3 %), 40, 41; 80 alone.
  const auto [group, means] = cluster({40.0, 10.0, 80.0, 10.2, 41.0}, 0.03);
  EXPECT_EQ(group, (std::vector<int>{1, 0, 2, 0, 1}));
  ASSERT_EQ(means.size(), 3u);
  EXPECT_DOUBLE_EQ(means[0], 10.1);
  EXPECT_DOUBLE_EQ(means[1], 40.5);
  EXPECT_DOUBLE_EQ(means[2], 80.0);
}

TEST(Curves, ALinearModelsSweepOverFrequencyIsItsReceptance) {
  // Tests at four frequencies and one level: one sweep over 2.5 … 4 Hz at 10 N (the sweep down
  // finds the same branch, so it is not kept), each point F0 sin ωt through the closed form.
  const test::OneMode m;
  const frf::Substructure sub = m.substructure();
  discover::Options o = test::fundamental_only();
  o.curve_points = 7;
  const auto tests = m.tests({2.5, 3.0, 3.5, 4.0}, 10.0);
  Problem problem(sub, {m.joint(0.0, 0.0)}, tests, o);
  const discover::State s = problem.evaluate({m.joint(m.k, m.c)}, problem.simulator(1.0));
  const std::vector<discover::ResponseCurve> c = curves(problem, s);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_TRUE(c[0].over_frequency);
  EXPECT_FALSE(c[0].descending);
  EXPECT_EQ(c[0].level, 10.0);
  EXPECT_EQ(c[0].channels, (std::vector<std::string>{"x@7:uy"}));
  ASSERT_EQ(c[0].x.size(), 7u);
  for (std::size_t p = 0; p < 7; ++p) {
    EXPECT_NEAR(c[0].x[p], 2.5 + 0.25 * static_cast<double>(p), 1e-12);
    ASSERT_TRUE(c[0].converged[p]);
    const std::complex<double> X =
        m.receptance(c[0].x[p], m.k, m.c) * std::complex<double>(0.0, -10.0);
    EXPECT_LT(std::abs(c[0].X1[0][p] - X), 1e-9 * std::abs(X)) << c[0].x[p] << " Hz";
  }
  o.curve_points = 0;
  Problem none(sub, {m.joint(0.0, 0.0)}, tests, o);
  EXPECT_TRUE(curves(none, s).empty());
}

} // namespace
} // namespace jointid
