#pragma once
/// The rules of discovery that need something of the tests, whether these tests have it, and
/// what it means for the result when they do not: each rule that cannot be applied is said, in
/// a sentence, instead of being skipped silently.
#include "discover/discover.hpp"
#include "discover/gap.hpp"

#include <string>
#include <vector>

namespace jointid::discover::detail {

/// The fewest tests that cross-validation and a value per test need: leaving one out must leave
/// at least three, and a trend needs more than two or three points.
inline constexpr int min_tests_held_out = 4;

struct Preconditions {
  int tests = 0;
  /// Additions can be checked against held-out tests (rule 5): four tests or more. Without it
  /// nothing is added: the best candidate is named, to be checked with more tests.
  bool cross_validation = true;
  /// A coefficient identified per test can show a trend: four tests or more.
  bool per_test_values = true;
  /// The tests are at more than one force level (apart by more than 3 %): whether the
  /// disagreement changes with the level can be seen.
  bool several_levels = true;
  /// Every compared value's noise is known (records): the loop can stop at the noise level.
  bool noise_known = true;
  /// Some test has harmonics beyond the fundamental: even terms (a mean and even harmonics) can
  /// be identified and the harmonics judged.
  bool harmonics = true;
  /// The substructure's damping scale is asked for and the substructure has modes to scale.
  bool damping_scale = true;
  /// One sentence per rule that cannot be applied: what is not done, why, and what it means.
  std::vector<std::string> limits;
};

/// From the tests, the values compared, the options and whether the substructure has modes.
Preconditions preconditions(const std::vector<identify::Measurement>& tests,
                            const Compared& compared, const Options& options,
                            bool substructure_has_modes);

/// The tests' force levels (the largest |F₁| of each) grouped within 3 %: the levels' means,
/// ascending.
std::vector<double> force_levels(const std::vector<identify::Measurement>& tests);

} // namespace jointid::discover::detail
