// Golden-section search: the minimum of functions whose minimiser is known, its evaluation
// count and its stopping width.
#include "fem/minimise.hpp"

#include <gtest/gtest.h>

#include <cmath>

using jointid::fem::golden_section_minimum;

TEST(GoldenSection, FindsTheMinimumOfAUnimodalFunctionWithinItsBracket) {
  // Each step shrinks the bracket by g = 0.618: after 60 steps from width 3, 3 g^60 ≈ 9e-13.
  // Rounding decides earlier: within δ of the minimiser f differs from its least value 2 by δ²,
  // below f's rounding 2·eps for δ < 2e-8, so the comparisons cannot place it closer.
  int calls = 0;
  auto parabola = [&calls](double x) {
    ++calls;
    return (x - 0.7) * (x - 0.7) + 2.0;
  };
  EXPECT_NEAR(golden_section_minimum(parabola, -1.0, 2.0, 60), 0.7, 3e-8);
  EXPECT_EQ(calls, 62);
  // Asymmetric, non-polynomial: x − ln x has its minimum at 1.
  EXPECT_NEAR(golden_section_minimum([](double x) { return x - std::log(x); }, 0.1, 5.0, 80), 1.0,
              1e-7); // flat bottom: f − f_min ≈ (x − 1)²/2, so rounding limits x to ~√eps
  // A monotone function: the end of the bracket it falls towards (no rounding limit there).
  EXPECT_NEAR(golden_section_minimum([](double x) { return -x; }, 0.0, 1.0, 60), 1.0, 1e-11);
}

TEST(GoldenSection, StopsWhenTheBracketIsNarrowerThanTheWidth) {
  int calls = 0;
  auto f = [&calls](double x) {
    ++calls;
    return std::abs(x - 0.25);
  };
  const double x = golden_section_minimum(f, 0.0, 1.0, 1000, 1e-3);
  EXPECT_NEAR(x, 0.25, 1e-3);
  // 0.618^k < 1e-3 from k = 15: 2 + 15 evaluations, not 1000.
  EXPECT_EQ(calls, 2 + 15);
}
