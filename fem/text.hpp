#pragma once
/// Small text helpers of the libraries' messages and files. For source files only (as
/// fem/constants.hpp).
#include <charconv>
#include <sstream>
#include <string>
#include <string_view>

namespace jointid {

/// The shortest text that reads back as the same double ("0.1", "1e-05", "4800").
inline std::string shortest(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

/// `value` to `digits` significant digits, as printf's %g ("3.14", "1.6e+08").
inline std::string significant(double value, int digits = 6) {
  std::ostringstream s;
  s.precision(digits);
  s << value;
  return s.str();
}

/// A fraction as a percentage to 3 significant digits: 0.0912 → "9.12 %".
inline std::string percent(double fraction) {
  return significant(100.0 * fraction, 3) + " %";
}

/// `s` without leading and trailing blanks (spaces, tabs, carriage returns, newlines).
inline std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

} // namespace jointid
