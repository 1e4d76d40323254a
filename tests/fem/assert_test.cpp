// JOINTID_ASSERT in a debug build: this translation unit is compiled without NDEBUG whatever
// the build type (assert_ndebug_test.cpp is its Release twin), so the check is live here.
#ifdef NDEBUG
#undef NDEBUG
#endif
#include "fem/assert.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

constexpr int assert_line = __LINE__ + 2; // the line of the JOINTID_ASSERT below
void check_size(int rows, int expected) {
  JOINTID_ASSERT(rows == expected, "the block has one row per equation");
}

} // namespace

TEST(AssertDeathTest, AFalseInvariantAbortsNamingTheFileLineConditionAndMessage) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(check_size(3, 4), "fem/assert_test\\.cpp:" + std::to_string(assert_line) +
                                     ": internal invariant violated: rows == expected: the block "
                                     "has one row per equation");
  const std::string computed = "computed message";
  EXPECT_DEATH(JOINTID_ASSERT(1 + 1 == 3, computed + " 42"), "computed message 42");
}

TEST(AssertDeathTest, ATrueInvariantIsEvaluatedOnceAndGoesOn) {
  int evaluations = 0;
  JOINTID_ASSERT(++evaluations == 1, "never shown");
  check_size(4, 4);
  EXPECT_EQ(evaluations, 1);
}
