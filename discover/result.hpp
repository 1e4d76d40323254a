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

/// The run in one sentence: what was added, how the gap shrank, against the noise level.
std::string summary(const Result& result, const Compared& compared);

} // namespace jointid::discover::detail
