#pragma once
/// What the result says besides the states: the fundamental of every test measured and simulated,
/// a step's finding, and the run's summary, in sentences.
#include "discover/gap.hpp"

#include <string>
#include <vector>

namespace jointid::discover::detail {

/// The fundamental at every test and channel, measured and simulated by the state (harmonics
/// 2 … K for their content).
std::vector<Comparison> comparisons(const std::vector<identify::Measurement>& tests, int harmonics,
                                    const State& state);

/// "Added k3 at 'tip' (cubic stiffness) = … [lo, hi]: the gap fell from … to … (… explained)."
std::string finding(const Step& step);

/// A refit's finding: "Refitted the starting values: k at 'tip' 1e+04 → 1.2e+04, …: the gap
/// fell from … to … (… explained)." Each value not held fixed, from `before` to `after`.
std::string refit_finding(const Step& step, const std::vector<joints::Joint>& before,
                          const std::vector<joints::Joint>& after);

/// The run in one sentence: what was added, how the gap shrank, against the noise level.
std::string summary(const Result& result, const Compared& compared);

} // namespace jointid::discover::detail
