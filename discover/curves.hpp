#pragma once
/// The report's response curves of a model through the tests (discover.hpp's ResponseCurve).
#include "discover/problem.hpp"

#include <utility>
#include <vector>

namespace jointid::discover::detail {

/// Groups of values closer than `tolerance` (relative): each value's group, and the groups'
/// mean values, ascending.
std::pair<std::vector<int>, std::vector<double>> cluster(const std::vector<double>& values,
                                                         double tolerance);

/// The model's response curves through the tests: per force level (within 3 %) over frequency,
/// or per frequency (within 0.01 %) over level, whichever the tests have more of, at the force
/// DOF of the group's first test, by continuation from point to point; swept up, and down where
/// that differs by more than 1 % (another branch). Options::curve_points each, or a point
/// between every two tests of the group where it has more (at most four times as many). None
/// when Options::curve_points < 2, or when a test is periodic (it is at no one frequency).
std::vector<ResponseCurve> curves(const Problem& problem, const State& state);

} // namespace jointid::discover::detail
