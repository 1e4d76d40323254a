#pragma once
/// What the JSON writers share (io/results_json.cpp, report/discovery_json.cpp): the contracts'
/// key order, non-finite numbers as null, and the text with two-space indents and a final
/// newline. Include only from .cpp files: it brings in nlohmann/json.
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace jointid::io::json {

using Json = nlohmann::ordered_json; // keeps the contract's key order

/// The number, or null when it is NaN or infinite (JSON has neither).
inline Json number(double value) {
  return std::isfinite(value) ? Json(value) : Json(nullptr);
}

inline std::string text(const Json& json) {
  return json.dump(2) + "\n";
}

} // namespace jointid::io::json
