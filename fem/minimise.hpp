#pragma once
/// One-dimensional minimisation for the small searches of the toolkit (a start's scale, a
/// damping scale, a record's frequency): golden-section search on a bracket.
#include <cmath>

namespace jointid::fem {

/// Golden-section search for a minimum of f on [a, b] (f unimodal there): the bracket shrinks
/// by (√5 − 1)/2 per evaluation, for `iterations` evaluations or until it is narrower than
/// `width`. Returns the final bracket's middle; f is evaluated 2 + iterations times at most,
/// never at a or b.
template <class F>
double golden_section_minimum(F&& f, double a, double b, int iterations, double width = 0.0) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < iterations && b - a > width; ++it) {
    if (f1 < f2)
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = f(x1);
    else
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = f(x2);
  }
  return 0.5 * (a + b);
}

} // namespace jointid::fem
