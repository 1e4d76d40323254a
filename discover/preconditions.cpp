#include "discover/preconditions.hpp"

#include "discover/curves.hpp"
#include "discover/text.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace jointid::discover::detail {

std::vector<double> force_levels(const std::vector<identify::Measurement>& tests) {
  std::vector<double> levels;
  for (const auto& m : tests)
    levels.push_back(identify::force_level(m));
  return cluster(levels, 0.03).second;
}

Preconditions preconditions(const std::vector<identify::Measurement>& tests,
                            const Compared& compared, const Options& options,
                            bool substructure_has_modes) {
  Preconditions p;
  p.tests = static_cast<int>(tests.size());
  const std::string count = fmt::format("{} test{}", p.tests, p.tests == 1 ? "" : "s");

  p.cross_validation = p.tests >= min_tests_held_out;
  if (!p.cross_validation)
    p.limits.push_back(fmt::format(
        "additions are not checked against held-out tests: {}, at least {} needed; so nothing "
        "is added (the best candidate is named, to be checked with more tests)",
        count, min_tests_held_out));
  p.per_test_values = p.tests >= min_tests_held_out;
  if (!p.per_test_values)
    p.limits.push_back(fmt::format("a coefficient that changes between tests is not looked for: "
                                   "{}, at least {} needed",
                                   count, min_tests_held_out));

  const std::vector<double> levels = force_levels(tests);
  p.several_levels = levels.size() > 1;
  if (!p.several_levels)
    p.limits.push_back(fmt::format(
        "the tests are all at one force level ({} N): they cannot tell whether the disagreement "
        "changes with the level, and the diagnosis does not say",
        number(levels.empty() ? 0.0 : levels.front())));

  p.noise_known = compared.noise_known;
  if (!p.noise_known) {
    int without = 0;
    for (const auto& m : tests) {
      bool known = !m.fundamental_only;
      for (Eigen::Index j = 0; j < m.X_variance.cols() && known; ++j)
        known = m.X_variance(1, j) > 0.0;
      without += known ? 0 : 1;
    }
    p.limits.push_back(fmt::format(
        "the noise level is unknown ({} of {} carry no noise estimate: stepped-sine rows, or "
        "records whose noise could not be estimated): the loop cannot stop at the noise level, "
        "only when no addition is admissible, and the criterion weighs every value alike, by "
        "the residual variance",
        without, count));
  }

  p.harmonics = std::any_of(tests.begin(), tests.end(),
                            [](const identify::Measurement& m) { return !m.fundamental_only; });
  if (!p.harmonics) {
    std::vector<std::string> even;
    for (const joints::Term t : options.terms)
      if (joints::term_info(t).even) even.emplace_back(joints::term_name(t));
    p.limits.push_back(fmt::format(
        "the tests give the fundamental only (stepped-sine rows): harmonics cannot be judged{}",
        even.empty() ? std::string()
                     : fmt::format(", and {} {} not tried (an even force has no fundamental "
                                   "for a sinusoidal deformation: it cannot be identified)",
                                   join(even), even.size() == 1 ? "is" : "are")));
  }

  p.damping_scale = options.substructure_damping && substructure_has_modes;
  if (options.substructure_damping && !substructure_has_modes)
    // emplace_back: a moved temporary gave GCC 12's -Warray-bounds false positive here.
    p.limits.emplace_back("the substructure's damping scale is not tried: the substructure "
                          "(measured FRFs) has no modes whose damping could be scaled");
  return p;
}

} // namespace jointid::discover::detail
