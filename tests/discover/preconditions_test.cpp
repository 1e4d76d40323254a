// The rules that need something of the tests: which ones the tests allow, counted by hand, and
// the sentence that says what is not done when they do not.
#include "discover/preconditions.hpp"

#include "constructed.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace jointid {
namespace {

using namespace discover::detail;

// `forces.size()` sine tests at 3 Hz with known noise, one per force amplitude.
std::vector<identify::Measurement> at_forces(const std::vector<double>& forces) {
  std::vector<identify::Measurement> out;
  int i = 0;
  for (double F : forces) {
    std::string name = "t"; // (not "t" + to_string: GCC 12's -Wrestrict false positive)
    name += std::to_string(++i);
    out.push_back(
        test::measurement(name, 3.0, F, {0.0, 1e-3 * F, 0.0}, {1e-12, 1e-12, 1e-12}, false));
  }
  return out;
}

bool said(const Preconditions& p, const std::string& words) {
  for (const auto& l : p.limits)
    if (l.find(words) != std::string::npos) return true;
  return false;
}

TEST(Preconditions, FewerThanFourTestsCannotBeCrossValidatedAndItIsSaid) {
  const auto three = at_forces({10.0, 20.0, 40.0});
  const Preconditions p = preconditions(three, compared_values(three, 2), {}, true);
  EXPECT_EQ(p.tests, 3);
  EXPECT_FALSE(p.cross_validation);
  EXPECT_FALSE(p.per_test_values);
  EXPECT_TRUE(p.several_levels);
  EXPECT_TRUE(said(p, "additions are not checked against held-out tests: 3 tests, at least 4 "
                      "needed; so nothing is added"));
  const auto four = at_forces({10.0, 20.0, 40.0, 80.0});
  const Preconditions q = preconditions(four, compared_values(four, 2), {}, true);
  EXPECT_TRUE(q.cross_validation);
  EXPECT_TRUE(q.per_test_values);
  EXPECT_TRUE(q.limits.empty()) << q.limits.front();
}

TEST(Preconditions, TestsWithin3PercentAreOneForceLevel) {
  // 10, 10.2 and 10.25 N are one level (within 3 %); 10.5 N is another.
  const auto one = at_forces({10.0, 10.2, 10.25, 10.1});
  const Preconditions p = preconditions(one, compared_values(one, 2), {}, true);
  EXPECT_FALSE(p.several_levels);
  EXPECT_TRUE(said(p, "the tests are all at one force level")) << p.limits.size();
  const auto two = at_forces({10.0, 10.2, 10.6, 10.1});
  EXPECT_EQ(force_levels(two).size(), 2u);
  EXPECT_TRUE(preconditions(two, compared_values(two, 2), {}, true).several_levels);
}

} // namespace
} // namespace jointid
