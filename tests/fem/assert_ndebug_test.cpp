// JOINTID_ASSERT in a Release build: this translation unit is compiled with NDEBUG whatever the
// build type (assert_test.cpp is its debug twin), so the check must vanish: neither the
// condition nor the message is evaluated, and a false condition does not abort.
#ifndef NDEBUG
#define NDEBUG
#endif
#include "fem/assert.hpp"

#include <gtest/gtest.h>

#include <string>

TEST(AssertRelease, IsCompiledOutUnderNdebug) {
  int evaluations = 0;
  JOINTID_ASSERT(++evaluations < 0, (++evaluations, std::string("never built")));
  EXPECT_EQ(evaluations, 0); // neither side evaluated, and still alive
}
