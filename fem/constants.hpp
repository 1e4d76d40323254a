#pragma once
/// The constants every library's code uses: 2π, and NaN and +∞ (an undetermined value, a state
/// not reached). For source files only: a header that included this would bring the names into
/// every file that says `using namespace jointid`.
#include <limits>
#include <numbers>

namespace jointid {

inline constexpr double two_pi = 2.0 * std::numbers::pi;
inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();
inline constexpr double inf = std::numeric_limits<double>::infinity();

} // namespace jointid
