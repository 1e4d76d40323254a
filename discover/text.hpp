#pragma once
/// The wording that discovery's findings and reasons share: shares, numbers, lists, channels.
#include "identify/measurement.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace jointid::discover::detail {

/// A share as per cent to 3 significant digits: 0.0512 → "5.12 %".
std::string pct(double fraction);
/// A value to 4 significant digits: 1.6e8 → "1.6e+08".
std::string number(double value);
/// "a", "a and b", "a, b and c".
std::string join(const std::vector<std::string>& items);
/// A response channel as the comparisons name it: its measured quantity and DOF, "x@7:uy".
std::string channel_name(const identify::Measurement& test, std::size_t response);

} // namespace jointid::discover::detail
