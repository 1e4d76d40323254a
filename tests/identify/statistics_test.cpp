#include "identify/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace jointid::identify;

TEST(Statistics, IncompleteBetaClosedForms) {
  for (double x : {0.1, 0.37, 0.9}) {
    EXPECT_NEAR(incomplete_beta(1.0, 1.0, x), x, 1e-14);                // uniform
    EXPECT_NEAR(incomplete_beta(2.5, 1.0, x), std::pow(x, 2.5), 1e-13); // I_x(a,1) = x^a
    EXPECT_NEAR(incomplete_beta(3.0, 4.5, x), 1.0 - incomplete_beta(4.5, 3.0, 1.0 - x),
                1e-13); // symmetry
  }
}

TEST(Statistics, StudentTQuantilesMatchPublishedTables) {
  // Two-sided 95 % critical values of Student's t (standard tables).
  EXPECT_NEAR(student_t_quantile(0.975, 1), 12.7062047, 1e-6);
  EXPECT_NEAR(student_t_quantile(0.975, 2), 4.30265273, 1e-7);
  EXPECT_NEAR(student_t_quantile(0.975, 10), 2.22813885, 1e-7);
  EXPECT_NEAR(student_t_quantile(0.975, 30), 2.04227246, 1e-7);
  EXPECT_NEAR(student_t_quantile(0.975, 1e7), 1.95996398, 1e-6); // → normal
  EXPECT_NEAR(student_t_quantile(0.5, 7), 0.0, 1e-12);
}
